"""Where a command may write its files (``plot -o``, ``render -o/--npz``, ``reproduce --out``): checked
before any work, a usage error otherwise (CLI.md: status 2, one line, never a traceback), and never
over a file the command read or a file of another kind (a picture only over a picture, an array file
only over one)."""

from __future__ import annotations

import os
from contextlib import contextmanager

from ..cli import UsageError


def inputs_of(args, loaded) -> list[str]:
    """The files a command read: FILE and every module it imports (``--module`` overrides included)."""
    paths = [] if args.file == "-" else [args.file]
    return paths + [m.path for m in loaded.modules.values() if m.path and os.path.isfile(m.path)]


#: The first bytes of each kind of file the commands write, by extension (the pictures matplotlib
#: writes, numpy's ``.npz``): an existing file is written over only when it is empty or begins with
#: them — a previous output of the same kind — so that a file the user wrote, given to ``-o`` or
#: ``--npz`` by mistake (``-o notes.txt``, ``--npz data`` over ``data.npz`` of one's own), is kept.
SIGNATURES: dict[str, tuple[bytes, ...]] = {
    ".png": (b"\x89PNG\r\n\x1a\n",), ".pdf": (b"%PDF",), ".svg": (b"<?xml", b"<svg"), ".svgz": (b"\x1f\x8b",),
    ".eps": (b"%!PS",), ".ps": (b"%!PS",), ".jpg": (b"\xff\xd8\xff",), ".jpeg": (b"\xff\xd8\xff",),
    ".tif": (b"II*\x00", b"MM\x00*"), ".tiff": (b"II*\x00", b"MM\x00*"), ".webp": (b"RIFF",), ".gif": (b"GIF8",),
    ".npz": (b"PK\x03\x04", b"PK\x05\x06"),
}
#: The picture formats ``plot -o`` and ``render -o`` write (matplotlib's, by extension).
PICTURES = tuple(ext for ext in SIGNATURES if ext != ".npz")


def picture_file(path: str, inputs: list[str], option: str, refusal: str) -> str:
    """:func:`output_file` for a picture: ``path``, with ``.png`` added when it has no extension (as
    matplotlib adds it: the file really written), refused when its extension is not a picture format."""
    ext = os.path.splitext(path)[1].lower()
    if os.path.isdir(path) or ext in PICTURES:
        return output_file(path, inputs, option, refusal)
    if not ext:
        return output_file(path + ".png", inputs, option, refusal)
    _refuse_inputs(path, inputs, refusal)  # (that refusal first: over a program, or a file read)
    raise UsageError(f"{option} {path}: {ext} is not a picture format (use {', '.join(PICTURES)})")


def output_file(path: str, inputs: list[str], option: str, refusal: str) -> str:
    """``path`` if a command may write a file there: refused (a usage error saying ``refusal``,
    before any work) when it is a program (``.lgr``) or one of ``inputs`` (nothing the user wrote
    is overwritten, through a link either), refused when it exists and is not a file of the kind
    written (:data:`SIGNATURES`), and refused when it is a directory or in a folder that
    does not exist or cannot be written."""
    _refuse_inputs(path, inputs, refusal)
    if os.path.isdir(path):
        raise UsageError(f"{option} {path}: is a directory")
    if os.path.lexists(path) and not _previous_output(path):
        raise UsageError(f"{option} {path}: exists and is not a {os.path.splitext(path)[1] or 'picture'} file "
                         "(a file of the kind this command writes): it is never overwritten")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise UsageError(f"{option} {path}: no such folder {folder}")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise UsageError(f"{option} {path}: cannot write into {folder}")
    return path


def output_folder(path: str, option: str) -> str:
    """``path`` made a folder a command may write into (a usage error, before any work, otherwise)."""
    if os.path.exists(path) and not os.path.isdir(path):
        raise UsageError(f"{option} {path}: exists and is not a directory (it is never overwritten)")
    try:
        os.makedirs(path, exist_ok=True)
    except OSError as e:
        raise UsageError(f"{option} {path}: cannot create the directory ({e.strerror})") from None
    if not os.access(path, os.W_OK | os.X_OK):
        raise UsageError(f"{option} {path}: cannot write into this directory")
    return path


def _same(a: str, b: str) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _refuse_inputs(path: str, inputs: list[str], refusal: str) -> None:
    """A usage error saying ``refusal`` when ``path`` is a program (``.lgr``) or one of ``inputs``."""
    if path.endswith(".lgr") or (os.path.exists(path) and any(_same(path, f) for f in inputs)):
        raise UsageError(refusal)


def _previous_output(path: str) -> bool:
    """Is the existing ``path`` a regular file that is empty or begins as a file of its extension's
    kind does (:data:`SIGNATURES`)?"""
    signatures = SIGNATURES.get(os.path.splitext(path)[1].lower())
    if signatures is None or not os.path.isfile(path):
        return False
    try:
        with open(path, "rb") as fh:
            head = fh.read(16)
    except OSError:
        return False
    return not head or head.startswith(signatures)


@contextmanager
def writing(path: str, option: str):
    """Writing ``path`` (given as ``option``): an OSError of the write — a folder that accepts no new
    file though :func:`output_file` found it writable (``/proc`` for root: ``access`` says yes), a
    full disk, a quota — is a usage error naming the file and the reason, not an internal error
    (bench/history/2026-11-29.md#hostile33."""
    try:
        yield
    except OSError as e:
        raise UsageError(f"{option} {path}: cannot write this file ({e.strerror or e})") from None
