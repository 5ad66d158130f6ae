"""A finding of ``langur check``: a diagnostic plus what ``--prove`` needs."""

from __future__ import annotations

from dataclasses import dataclass

from ..diagnostics import Diagnostic, Span


@dataclass
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
