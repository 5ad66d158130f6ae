"""Source spans and diagnostics shared by every stage (CLI.md, "Diagnostics").

A diagnostic prints as ``PATH:LINE:COL: SEVERITY CODE message``; lines and columns are 1-based.
Codes: ``E1xx`` syntax, ``T2xx`` typing (including diffeomorphism checks and compact support),
``X3xx`` transversality.  Every user-facing failure is a :class:`LangurError` carrying one or
more diagnostics, never a traceback.
"""

from __future__ import annotations

from dataclasses import field

from .records import frozen

#: How :class:`Span`'s ``__init__`` sets its frozen slots (as dataclass's generated ``__init__`` does).
_set = object.__setattr__


@frozen(slots=True)
class Span:
    """A region of a source file: 1-based, end exclusive of nothing (end_col is the last col + 1).

    Frozen and slotted, without a per-span ``__dict__``; the parser, which makes one for every node
    (issue 15), fills a :class:`SpanSlots` and makes it a ``Span`` by assigning its class, without a
    call of ``__init__`` (parse25: ≈ 1.7 k instructions a span instead of ≈ 4.1 k)."""

    path: str
    line: int
    col: int
    end_line: int
    end_col: int

    def __init__(self, path, line, col, end_line, end_col):  # (records: a slotted record writes its own)
        _set(self, "path", path)
        _set(self, "line", line)
        _set(self, "col", col)
        _set(self, "end_line", end_line)
        _set(self, "end_col", end_col)

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}"


class SpanSlots:
    """A :class:`Span`'s slots, writable: filled, then made a ``Span`` by ``s.__class__ = Span``
    (the same slots, so Python allows the assignment), a span made without a Python call::

        s = SpanSlots()
        s.path, s.line, s.col, s.end_line, s.end_col = path, line, col, end_line, end_col
        s.__class__ = Span

    Never kept as it is: only the parser makes spans so (``langur.syntax.parser``, ``chains``)."""

    __slots__ = ("col", "end_col", "end_line", "line", "path")


@frozen
class Diagnostic:
    span: Span | None
    severity: str  # "error" | "warning"
    code: str  # E1xx, T2xx, X3xx
    message: str
    related: tuple[Span, ...] = field(default=())  # other source places the message is about

    def format(self) -> str:
        where = str(self.span) if self.span is not None else "<unknown>:1:1"
        return f"{where}: {self.severity} {self.code} {self.message}"

    def to_json(self) -> dict:
        return {**span_json(self.span), "severity": self.severity, "code": self.code, "message": self.message}


def source_lines(text: str, keepends: bool = False) -> list[str]:
    """The lines of a source as spans number them: ended by a line feed only — the parser's lines
    (a CRLF's carriage return is white space at the end of its line, dropped here unless
    ``keepends``).  ``str.splitlines`` also ends a line at a lone CR, a form feed, U+0085, U+2028 …,
    which a comment may hold and the parser does not count: a comment with U+2028 on line 1 made
    ``# noqa`` on line 2 silence a finding on line 3, and quotes quote the wrong text
    (bench/history/2026-11-29.md#hostile33."""
    parts = text.split("\n")
    lines = [p + "\n" for p in parts[:-1]] + ([parts[-1]] if parts[-1] else [])  # (a final LF starts no line)
    return lines if keepends else [ln.rstrip("\n").removesuffix("\r") for ln in lines]


def span_json(s: Span | None) -> dict:
    """The location fields of CLI.md's JSON diagnostics (all None when the place is unknown)."""
    return {
        "path": s.path if s else None,
        "line": s.line if s else None,
        "col": s.col if s else None,
        "end_line": s.end_line if s else None,
        "end_col": s.end_col if s else None,
    }


class LangurError(Exception):
    """Bad input: one or more error diagnostics.  The CLI prints them and exits with status 1."""

    def __init__(self, diagnostics: Diagnostic | list[Diagnostic]):
        if isinstance(diagnostics, Diagnostic):
            diagnostics = [diagnostics]
        self.diagnostics = list(diagnostics)
        super().__init__("\n".join(d.format() for d in self.diagnostics))


def error(span: Span | None, code: str, message: str, related: tuple[Span, ...] = ()) -> LangurError:
    """Build (not raise) a one-diagnostic :class:`LangurError`."""
    return LangurError(Diagnostic(span, "error", code, message, related))


def located(err: LangurError, span: Span | None) -> LangurError:
    """``err`` with ``span`` given to its diagnostics that have no place: an error about a term that
    sympy built (a completion's inverse, with powers combined beyond T234's bound) is reported at
    the source term it came from.  ``err`` itself when there is nothing to add."""
    if span is None or all(d.span is not None for d in err.diagnostics):
        return err
    return LangurError([d if d.span is not None else Diagnostic(span, d.severity, d.code, d.message, d.related)
                        for d in err.diagnostics])
