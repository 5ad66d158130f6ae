"""A finding of ``langur check``: a diagnostic plus what ``--prove`` needs."""

from __future__ import annotations

from collections.abc import Mapping

from ..diagnostics import Diagnostic, Span
from ..records import record


@record
class Finding:
    """One diagnostic of the checker, with what ``--prove`` needs (the parameters it is about)."""

    span: Span | None
    severity: str
    code: str
    message: str
    related: tuple[Span, ...] = ()
    params: tuple[str, ...] = ()
    prove: dict | None = None

    def diagnostic(self) -> Diagnostic:
        return Diagnostic(self.span, self.severity, self.code, self.message, self.related)


def quote(span: Span | None, sources: Mapping[str, str], *, limit: int | None = 60,
          multiline: bool = False) -> str | None:
    """The user's text at ``span`` (stripped; cut to ``limit`` characters), for messages; None
    when the source is not at hand.  A span over several lines is quoted by its first line and
    `` …`` when ``multiline``, else not at all."""
    if span is None or span.path not in sources or (span.line != span.end_line and not multiline):
        return None
    lines = sources[span.path].splitlines()
    if not 1 <= span.line <= len(lines):
        return None
    line = lines[span.line - 1]
    end = span.end_col if span.end_line == span.line else len(line) + 1
    frag = line[span.col - 1 : end - 1].strip() + (" …" if span.end_line != span.line else "")
    return frag if limit is None or len(frag) <= limit else frag[: limit - 3] + "…"
