"""A finding of ``langur check``: a diagnostic plus what ``--prove`` needs."""

from __future__ import annotations

from collections.abc import Mapping

from .. import lazy
from ..diagnostics import Diagnostic, Span, source_lines
from ..records import record
from ..timebox import Clock, Deadline, by_backstop

#: sympy's simplify without its import of physical units (``PerCondition.run``); imported on first
#: use: this module is on ``langur eval``'s path (``commands._defined``), which runs no linter.
nounits = lazy.module("langur.symbolic.nounits")


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
    lines = source_lines(sources[span.path])
    if not 1 <= span.line <= len(lines):
        return None
    line = lines[span.line - 1]
    end = span.end_col if span.end_line == span.line else len(line) + 1
    frag = line[span.col - 1 : end - 1].strip() + (" …" if span.end_line != span.line else "")
    return frag if limit is None or len(frag) <= limit else frag[: limit - 3] + "…"


class PerCondition:
    """The clock of an analysis run condition by condition (double roots, turning points): each
    condition's sympy work within ``limit`` CPU seconds, all of them within ``total`` (a file with
    10⁴ distinct conditions is not 10⁴ × ``limit``); what it could not decide is said in one X310
    (:meth:`unchecked`) instead of being passed over in silence."""

    def __init__(self, what: str, limit: float, total: float):
        self.what, self.limit, self.total = what, limit, total
        self.clock = Deadline(total)
        self.undecided: dict = {}  # condition → its span, for the conditions whose check ran out of its limit
        self.left = 0  # conditions not checked at all: the total was spent
        self.stopped: Clock | None = None  # which limit ended the total (the backstop is said)

    def run(self, condition, span: Span | None, fn):
        """``fn()``, the check of ``condition``, within the limits; None (and remembered) when it did
        not finish or was not run."""
        stopped = self.clock.stopped_by()
        if stopped is not None:
            self.left += 1
            self.stopped = self.stopped or stopped
            return None
        try:
            with nounits.units_unloaded():  # (as ``algebra.timed``: no import of physical units on the clock)
                return self.clock.run(fn, self.limit)
        except TimeoutError:
            self.undecided[condition] = span
            return None

    def unchecked(self, program_span: Span | None) -> list[Finding]:
        """One X310 warning when some condition was not decided, else nothing."""
        if not self.undecided and not self.left:
            return []
        parts = []
        if self.undecided:
            first = next((s for s in self.undecided.values() if s is not None), None)
            parts.append(f"sympy took longer than {self.limit:g} CPU s on {len(self.undecided)} condition(s)"
                         + (f", the first at {first.line}:{first.col}" if first is not None else ""))
        if self.left:
            how = (f"was stopped {by_backstop(self.total)}" if self.stopped is Clock.BACKSTOP
                   else f"stopped after {self.total:g} CPU s")
            parts.append(f"the analysis {how} with {self.left} condition(s) left")
        span = next((s for s in self.undecided.values() if s is not None), program_span)
        return [Finding(span, "warning", "X310", f"{self.what} is unchecked for some conditions "
                                                   f"({'; '.join(parts)}): Theorem 8.1's assumption is unchecked there")]
