"""Where a command may write its files (``plot -o``, ``render -o/--npz``, ``reproduce --out``): checked
before any work, a usage error otherwise (CLI.md: status 2, one line, never a traceback), and never
over a file the command read."""

from __future__ import annotations

import os

from ..cli import UsageError


def inputs_of(args, loaded) -> list[str]:
    """The files a command read: FILE and every module it imports (``--module`` overrides included)."""
    paths = [] if args.file == "-" else [args.file]
    return paths + [m.path for m in loaded.modules.values() if m.path and os.path.isfile(m.path)]


def output_file(path: str, inputs: list[str], option: str, refusal: str) -> str:
    """``path`` if a command may write a file there: refused (a usage error saying ``refusal``,
    before any work) when it is a program (``.lgr``) or one of ``inputs`` (nothing the user wrote
    is overwritten, through a link either), and refused when it is a directory or in a folder that
    does not exist or cannot be written."""
    if path.endswith(".lgr") or (os.path.exists(path) and any(_same(path, f) for f in inputs)):
        raise UsageError(refusal)
    if os.path.isdir(path):
        raise UsageError(f"{option} {path}: is a directory")
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
