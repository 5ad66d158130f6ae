"""A campaign's unit is one text; a program with modules (§9: ``from lib import g``, separate
compilation) is one text too, a *bundle*: each library module's file as ``#``-comment lines ahead
of the main module, so the bundle is itself the main module's `.lgr` file (the comments are
ignored) and a person reads every module in one place::

    # module lib.lgr:
    #| def g(x: var, qa: param) = [x >= qa]
    param a = 0.37
    from lib import g
    int ([0, 1])
      g(x, a)
    d(x)

:func:`join` writes a bundle, :func:`split` reads it back; :func:`load` writes its files into a
fresh folder of its own, under the campaign's folder when one is open (:func:`campaign_folder`:
what a unit killed at its time limit left is removed with it), loads the main module through the
front end (``from lib import g`` finds ``lib.lgr`` beside it), removes the folder and returns the
loaded program; :func:`sources` gives every module's text by its path from it (for the linter's
quotes).  A text without a bundle header loads as it is (``load_text``), as every campaign's text
did before.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import tempfile

from ..frontend import load as load_file
from ..frontend import load_text
from ..modules import Loaded

#: The line that opens a module's file in a bundle, and the prefix of each of its lines.
HEADER, LINE = "# module ", "#| "
#: The main module's file name in a bundle's folder.
MAIN = "main.lgr"

_FOLDER: dict[str, str | None] = {"root": None}


def join(main: str, libraries: dict[str, str]) -> str:
    """The bundle of ``main`` (the main module's text) and ``libraries`` (file name → text); ``main``
    itself when there are none.  Line ends are the main module's (CRLF stays CRLF)."""
    if not libraries:
        return main
    end = "\r\n" if main.endswith("\r\n") else "\n"
    out = []
    for file, text in libraries.items():
        out.append(f"{HEADER}{file}:{end}")
        out += [f"{LINE}{line}" for line in text.splitlines(keepends=True)]
    return "".join(out) + main


def split(text: str) -> tuple[str, dict[str, str]]:
    """``(main, libraries)`` of a bundle (:func:`join`): ``main`` is ``text`` itself (the library
    lines are comments in it), ``libraries`` each file's text by its name, line ends kept; a
    module's block may follow other comment lines (a counterexample's header, ``langur fuzz --out``)."""
    libraries: dict[str, list[str]] = {}
    current = None
    for line in text.splitlines(keepends=True):
        if line.startswith(HEADER) and line.rstrip("\r\n").endswith(".lgr:"):
            current = line[len(HEADER):].rstrip("\r\n")[:-1]
            libraries[current] = []
        elif current is not None and line.startswith(LINE):
            libraries[current].append(line[len(LINE):])
        else:
            current = None
    return text, {file: "".join(lines) for file, lines in libraries.items()}


@contextlib.contextmanager
def campaign_folder():
    """A temporary folder the units of this process (and the workers forked inside the block) write
    their bundles' files under; removed, with anything a killed unit left, when the block ends."""
    with tempfile.TemporaryDirectory(prefix="langur-fuzz-") as root:
        before, _FOLDER["root"] = _FOLDER["root"], root
        try:
            yield root
        finally:
            _FOLDER["root"] = before


def load(text: str, path: str = "<fuzz>.lgr") -> Loaded:
    """``text`` (a bundle or a plain module, read as the file ``path``) through the front end."""
    main, libraries = split(text)
    if not libraries:
        return load_text(text, path=path)
    folder = tempfile.mkdtemp(prefix="unit-", dir=_FOLDER["root"])
    try:
        for file, body in {**libraries, MAIN: main}.items():
            with open(os.path.join(folder, file), "w", encoding="utf-8", newline="") as fh:
                fh.write(body)
        return load_file(os.path.join(folder, MAIN))
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def sources(loaded: Loaded) -> dict[str, str]:
    """Every module's text by the path its spans name (the folder :func:`load` wrote is gone)."""
    return {m.path: m.source.decode("utf-8", "replace") for m in (loaded.main, *loaded.modules.values())}
