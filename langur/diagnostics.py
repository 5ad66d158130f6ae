"""Source spans and diagnostics shared by every stage (CLI.md, "Diagnostics").

A diagnostic prints as ``PATH:LINE:COL: SEVERITY CODE message``; lines and columns are 1-based.
Codes: ``E1xx`` syntax, ``T2xx`` typing (including diffeomorphism checks and compact support),
``X3xx`` transversality.  Every user-facing failure is a :class:`LangurError` carrying one or
more diagnostics, never a traceback.
"""

from __future__ import annotations

from dataclasses import field

from .records import frozen


@frozen
class Span:
    """A region of a source file: 1-based, end exclusive of nothing (end_col is the last col + 1)."""

    path: str
    line: int
    col: int
    end_line: int
    end_col: int

    def __init__(self, path, line, col, end_line, end_col):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["path"], d["line"], d["col"], d["end_line"], d["end_col"] = path, line, col, end_line, end_col

    def __str__(self) -> str:
        return f"{self.path}:{self.line}:{self.col}"


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
