"""Parser of `.lgr` files (LANGUAGE.md §6) into the surface AST of :mod:`langur.syntax.surface`.

The grammar is ``grammar.lark`` beside this file (its header documents the decisions: reserved
keywords, the soft keyword ``d``, precedence).  It is parsed with lark's LALR(1) tables and an
*inline* transformer, :class:`~langur.syntax.builder.Builder`: its callbacks are called on every
reduction, so no parse tree is built and nothing recurses in Python however deep the input nests.
A valid program is parsed by :mod:`langur.syntax.lalr`'s driver of those tables, generated from
lark as data, without importing lark (issue 15, start-up); lark itself is imported only to report
a syntax error (it parses the text again and raises the error the diagnostic is made from, put in
words by :mod:`langur.syntax.syntaxerrors`), or when the shipped data is stale.  Every node gets an
exact :class:`~langur.diagnostics.Span` (1-based lines and columns, ``end_col`` exclusive).

Public API::

    parse_module(text: str, path: str = "<string>") -> ModuleS
    parse_term(text: str, path: str = "<string>") -> STerm
    parse_bytes(data: bytes, path: str = "<bytes>") -> ModuleS

Every syntax error raises :class:`~langur.diagnostics.LangurError` with one diagnostic, its code
E101–E109 from the catalogue :mod:`langur.codes`.  The limits behind them: a term nests at most
:data:`MAX_DEPTH` levels (E105; long chains such as ``1+1+…+1`` are regrouped into balanced trees
and count only their tree's depth, so recursive consumers stay far from Python's recursion
limit); a number literal has at most :data:`MAX_DIGITS` digits, an exponent within
±\\ :data:`MAX_EXPONENT` and a value within the range of doubles (E106: the Monte Carlo engine
computes in doubles); a source has at most :data:`MAX_SIGNIFICANT` characters outside comments and
white space (E108: a 10 MB file costs a few seconds at worst).
"""

from __future__ import annotations

import gc
import re
import threading

from .. import gcpause
from ..diagnostics import Span, error
from . import lalr
from .builder import MAX_DEPTH, MAX_DIGITS, MAX_EXPONENT, Builder
from .surface import ModuleS, ProgramS, STerm
from .syntaxerrors import KEYWORDS, convert

__all__ = [
    "KEYWORDS",
    "MAX_DEPTH",
    "MAX_DIGITS",
    "MAX_EXPONENT",
    "MAX_SIGNIFICANT",
    "parse_bytes",
    "parse_module",
    "parse_term",
]  # fmt: skip

#: Parse with :mod:`langur.syntax.lalr`'s driver of lark's tables, lark only for syntax errors
#: (False: lark parses every input, as the tests compare).
FAST = True
#: Most characters outside comments and white space that a source may have (E108).
MAX_SIGNIFICANT = 1_000_000

_LOCK = threading.Lock()
#: lark's parser, built on first need (None: not yet): a syntax error to report, FAST off, or stale
#: shipped data
_PARSER = None
#: :mod:`langur.syntax.lalr`'s driver: its parse function, False when the tables cannot be driven
#: (lark then parses every input), None when not made yet
_DRIVER = None
_BUILDER = Builder()


class _FromLark:
    """The builder as lark's parser calls it (a syntax error to report, FAST off, stale shipped
    data): each rule's method of :data:`_BUILDER`, given lark's tokens (a ``str`` subclass) as the
    driver gives its own, tuples of :data:`lalr.TOKEN` (:func:`lalr.token`).  A name the builder has
    no method for raises AttributeError, as on the builder itself (lark then builds a tree, or makes
    no token callback)."""

    def __getattr__(self, name: str):
        method = getattr(_BUILDER, name)

        def callback(children):
            return method([lalr.token(x) if isinstance(x, str) else x for x in children])
        return callback


_FROM_LARK = _FromLark()


def _lark_side():
    """The modules that import lark — ``larkload`` (lark's classes) and ``tables`` (lark's parser
    from the shipped tables or the grammar, and the driver's data derived from it) — imported on
    first need only: to report a syntax error, with FAST off, or when the shipped data is stale.
    The import is here, not at the top, so that parsing a valid program never imports lark
    (issue 15: lark's import and deserialization were ~40 ms of every one-shot process); it is not
    a way around an import cycle."""
    from . import larkload, tables

    return larkload, tables


def _driver():
    """The driver (called under _LOCK): of the data shipped with the package (read without lark),
    or of the same data read off lark's parser when the shipped data is missing, stale or
    malformed."""
    global _DRIVER
    if _DRIVER is None:
        _DRIVER = _drive(lalr.load()) or _drive(_lark_side()[1].driver_data(_lark())) or False
    return _DRIVER


def _drive(data):
    """:func:`lalr.driver` of ``data`` with the builder's callbacks, or ``None`` (no data, or data it
    cannot drive)."""
    callbacks = lalr.callbacks(data, _BUILDER) if data is not None else None
    return None if callbacks is None else lalr.driver(data, callbacks)


def _lark():
    """lark's parser (called under _LOCK): from the tables shipped with the package (data, never a
    pickle: SECURITY.md), or built from the grammar when they are missing or stale."""
    global _PARSER
    if _PARSER is None:
        tables = _lark_side()[1]
        _PARSER = tables.load(_FROM_LARK) or tables.build(transformer=_FROM_LARK)
    return _PARSER


def _parser():
    """lark's parser, with the driver made too (the tests compare both)."""
    _driver()
    return _lark()



_INSIGNIFICANT = re.compile(r"#[^\n]*|\s+")


def _check_size(text: str, path: str) -> None:
    if len(text) <= MAX_SIGNIFICANT:
        return
    significant = len(text) - sum(m.end() - m.start() for m in _INSIGNIFICANT.finditer(text))
    if significant > MAX_SIGNIFICANT:
        raise error(
            Span(path, 1, 1, 1, 1),
            "E108",
            f"source too large: {significant} characters outside comments and white space "
            f"(at most {MAX_SIGNIFICANT})",
        )


#: A carriage return that ends no CRLF.
_LONE_CR = re.compile(r"\r(?!\n)")


def _check_line_ends(text: str, path: str) -> None:
    """E104 at a carriage return not followed by a line feed.  Lines end with LF (CRLF: the CR is
    white space); a file with CR-only line ends, which many editors show as lines, was one line
    here: its findings were reported at 1:COL, quoted from the wrong text and not silenced by the
    ``# noqa`` the user saw on their line (bench/history/2026-11-29.md#hostile33."""
    m = _LONE_CR.search(text)
    if m is None:
        return
    line = text.count("\n", 0, m.start()) + 1
    col = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
    raise error(Span(path, line, col, line, col + 1), "E104", "a carriage return (U+000D) not followed by a line "
                "feed: lines end with LF or CRLF (convert CR-only line ends, as old Mac files have them)")


def _run(text: str, path: str, start: str):
    text = text.removeprefix("\ufeff")
    _check_size(text, path)
    _check_line_ends(text, path)
    with _LOCK:
        driver = _driver()
        _BUILDER.path = path
        # The parse allocates many small objects and no cycles: pausing the cyclic collector
        # makes big inputs several times faster (a load has paused it already: no second pause).
        if not gc.isenabled():
            return text, _parse(driver, text, start, path)
        with gcpause.paused():
            return text, _parse(driver, text, start, path)


def _parse(driver, text: str, start: str, path: str):
    if driver and FAST:
        result = driver(text, start)
        if result is not lalr.FAILED:
            return result
    # a syntax error (or FAST off): lark parses, and its exception is the diagnostic
    larkload = _lark_side()[0]
    try:
        return _lark().parse(text, start=start)
    except larkload.UnexpectedInput as exc:
        raise convert(exc, path) from None


def _end_position(text: str) -> tuple[int, int]:
    line = text.count("\n") + 1
    last = text.rfind("\n")
    return line, len(text) - last  # col after the last character (1-based, exclusive)


def parse_module(text: str, path: str = "<string>") -> ModuleS:
    """Parse a whole `.lgr` file: items, then at most one program (LANGUAGE.md §6)."""
    text, result = _run(text, path, "start")
    program = result[-1] if result and isinstance(result[-1], ProgramS) else None
    items = tuple(result[:-1] if program is not None else result)
    end_line, end_col = _end_position(text)
    return ModuleS(path, items, program, Span(path, 1, 1, end_line, end_col))


def parse_term(text: str, path: str = "<string>") -> STerm:
    """Parse a single term (the ``term`` rule of LANGUAGE.md §6)."""
    _, result = _run(text, path, "term")
    return result.node


def parse_bytes(data: bytes, path: str = "<bytes>") -> ModuleS:
    """Decode ``data`` as UTF-8 (a leading BOM is dropped) and parse it; bad bytes are E101."""
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        before = data[: exc.start]
        line = before.count(b"\n") + 1
        col = len(before[before.rfind(b"\n") + 1 :].decode("utf-8", errors="replace")) + 1
        bad = data[exc.start]
        raise error(
            Span(path, line, col, line, col + 1), "E101", f"the file is not valid UTF-8: byte 0x{bad:02x}"
        ) from None
    return parse_module(text, path)
