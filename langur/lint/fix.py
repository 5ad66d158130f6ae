"""``langur check --fix`` / ``--diff``: the transverse rewrite (``langur.lint.rewrite``) as a file.

Like a linter's autofix (ruff's ``--fix``), and careful with the user's text:

* the fix is a **patch of the source**: each outermost rewritten subterm's text is replaced by the
  printed rewrite in parentheses, so comments, ``param`` lines, defs and imports stay as written.
  The patched text is loaded again and must give exactly the rewritten core program; when it
  does not (the subterm came from a def, or from a declared diffeo), the whole program is printed
  instead (defs inlined, a comment says so), and that too must load back to the same program;
* ``--diff`` prints a unified diff and writes nothing;
* ``--fix`` writes a **new file** ``NAME.fixed.lgr`` and refuses to overwrite one that exists;
  ``--fix --in-place`` rewrites ``NAME.lgr`` itself, only if it has not changed since it was read,
  after keeping it as ``NAME.lgr.bak`` (refusing when a different backup exists).
"""

from __future__ import annotations

import difflib
import os
import stat
import tempfile
from dataclasses import dataclass

from .. import frontend
from ..diagnostics import LangurError, source_lines
from ..syntax.printer import print_core, print_program
from .rewrite import Rewritten, transverse

HEADER = "# The transverse rewrite of this program (paper §7.3.2), written by `langur check --fix`;\n" \
         "# its defs are inlined.\n"


class FixError(Exception):
    """The fix cannot be written (the message says why); a usage error."""


@dataclass
class Fix:
    path: str
    before: str
    after: str
    rewritten: Rewritten
    whole: bool  # the whole program was printed (the source could not be patched)

    def diff(self, target: str | None = None) -> str:
        return "".join(difflib.unified_diff(self.before.splitlines(keepends=True),
                                            self.after.splitlines(keepends=True),
                                            fromfile=self.path, tofile=target or self.path))


def _offset(lines: list[str], line: int, col: int) -> int:
    return sum(len(s) for s in lines[: line - 1]) + col - 1


def _same(text: str, path: str, modules, loaded, program) -> bool:
    """Does ``text`` load back to ``program``?  Its imports are the modules ``loaded`` read, not read
    again (a named pipe's bytes come once: the rewrite waited for a writer until check's wall-clock
    backstop, bench/history/2026-11-29.md#hostile33."""
    try:
        again = frontend.load_text(text, path, modules=modules, files=loaded.files())
    except LangurError:
        return False
    return again.program == program


def _inside(s, outer) -> bool:
    return outer is not None and (s.line, s.col) >= (outer.line, outer.col) and \
        (s.end_line, s.end_col) <= (outer.end_line, outer.end_col)


def _patched(text: str, path: str, rw: Rewritten, program_span) -> str | None:
    """The source with each rewritten subterm of the program's own text replaced (a subterm of a
    def's body is not patched: the def has other callers and its own argument names)."""
    lines = source_lines(text, keepends=True)
    cuts = []
    for original, new in rw.replaced:
        s = original.span
        if s is None or s.path != path or not _inside(s, program_span):
            return None
        cuts.append((_offset(lines, s.line, s.col), _offset(lines, s.end_line, s.end_col), new))
    cuts.sort(key=lambda c: c[0], reverse=True)
    out = text
    last = len(text) + 1
    for start, end, new in cuts:
        if end > last:  # overlapping replacements: not a patch
            return None
        # (in parentheses unless an atom: a bracket [t >= 0] needs none — fold31 prints
        # ifge0 t then 1 else 0 as one, where before fold31 the patch was (ifge0 t then 1 else 0))
        out = out[:start] + print_core(new, operand=True) + out[end:]
        last = start
    return out


def _whole(loaded, rw: Rewritten) -> str:
    body = print_program(rw.program, loaded.params)
    lines = body.splitlines()
    kept = {w.strip().split("=")[0].strip() for ln in lines if ln.startswith("param ")
            for w in ln[len("param "):].split(",")}
    missing = [n for n in loaded.params if n not in kept]  # a parameter the rewrite no longer reads
    if missing:
        decl = ", ".join(n if loaded.params[n] is None else f"{n} = {float(loaded.params[n])!r}" for n in missing)
        lines.insert(0, f"param {decl}")
    return HEADER + "\n".join(lines) + "\n"


def fix(text: str, path: str, loaded, modules=None) -> Fix | None:
    """The fixed text of a file whose program has something to rewrite, or None.  Raises
    :class:`FixError` when no text loads back to the rewritten program."""
    if loaded.program is None:
        return None
    rw = transverse(loaded.program)
    if not rw.changed:
        return None
    main = loaded.main.program
    patched = _patched(text, path, rw, main.span if main is not None else None)
    if patched is not None and _same(patched, path, modules, loaded, rw.program):
        return Fix(path, text, patched, rw, False)
    whole = _whole(loaded, rw)
    if _same(whole, path, modules, loaded, rw.program):
        return Fix(path, text, whole, rw, True)
    raise FixError(f"{path}: the rewrite cannot be written as a program that loads back to it")


def target(path: str, in_place: bool) -> str:
    if in_place:
        return path
    root, ext = os.path.splitext(path)
    return f"{root}.fixed{ext or '.lgr'}"


def check_writable(f: Fix, in_place: bool) -> None:
    """Refuse before anything is written (see the module docstring)."""
    dest = target(f.path, in_place)
    if not in_place:
        if os.path.exists(dest):
            raise FixError(f"{dest} exists: not overwritten (remove it, or use --diff)")
        return
    try:
        if not stat.S_ISREG(os.stat(f.path).st_mode):  # a named pipe: reading it again waits for a writer
            raise FixError(f"{f.path} is not a regular file: not rewritten in place (use --fix without --in-place)")
        with open(f.path, encoding="utf-8") as fh:
            now = fh.read()
    except OSError as e:
        raise FixError(f"{f.path}: cannot read ({e.strerror})") from None
    if now != f.before:
        raise FixError(f"{f.path} changed since it was read: not overwritten")
    backup = f.path + ".bak"
    if os.path.exists(backup):
        with open(backup, encoding="utf-8", errors="replace") as fh:
            if fh.read() != f.before:
                raise FixError(f"{backup} exists and differs from {f.path}: not overwritten")


def write(f: Fix, in_place: bool) -> str:
    """Write the fix (after :func:`check_writable`); returns the path written."""
    dest = target(f.path, in_place)
    if in_place:
        _atomic(f.path + ".bak", f.before, like=f.path)
        _atomic(os.path.realpath(f.path), f.after)  # through a link: the file it names, the link kept
        return dest
    with open(dest, "x", encoding="utf-8") as fh:  # never over an existing file
        fh.write(f.after)
    return dest


def _atomic(path: str, text: str, like: str | None = None) -> None:
    """``text`` written to ``path`` at once (a temporary file renamed), with the permissions of
    ``like`` (default: ``path``) where it exists — mkstemp's file is 0600."""
    d = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(dir=d, prefix=".langur-fix-")
    try:
        like = like or path
        if os.path.exists(like):
            os.chmod(tmp, os.stat(like).st_mode & 0o7777)
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
