"""What the Monte Carlo engine returns (§9): estimates with their standard errors, typed.

``to_json`` gives CLI.md's ``mc`` objects of ``langur eval --json`` and ``langur deriv --json``.
"""

from __future__ import annotations

from dataclasses import field

from ..records import frozen


@frozen
class Estimate:
    """An unbiased estimate and its standard error."""

    value: float
    stderr: float

    def to_json(self) -> dict:
        return {"value": self.value, "stderr": self.stderr}


@frozen
class ValueEstimate(Estimate):
    """⟦p⟧ ≈ ``value`` ± ``stderr`` from ``samples`` points of a ``method`` design drawn with
    ``seed``.  ``finite_variance`` is False when the caller's analysis knows the integrand is not
    square-integrable (then the standard error means nothing); ``notes`` say so, and what the
    samples show (non-finite values, a heavy tail)."""

    samples: int = 0
    seed: int = 0
    method: str = "uniform"
    finite_variance: bool = True
    notes: tuple[str, ...] = field(default=())
    #: every sample was 0 (the standard error 0 then bounds nothing: a note says so)
    all_zero: bool = False

    def _tail(self) -> dict:
        out: dict = {"samples": self.samples, "seed": self.seed, "method": self.method}
        if not self.finite_variance:
            out["finite_variance"] = False
        if self.notes:
            out["notes"] = list(self.notes)
        return out

    def to_json(self) -> dict:
        return {**super().to_json(), **self._tail()}


@frozen
class DerivativeEstimate(ValueEstimate):
    """⦇p⦈(γ, γ') ≈ ``regular`` + ``boundary`` (Theorem 7.1's split: the delta-free tangent and the
    zero-set estimates); ``standard_ad`` is the regular part alone (the paper's Dˢ)."""

    regular: Estimate = Estimate(0.0, 0.0)
    boundary: Estimate = Estimate(0.0, 0.0)

    @property
    def standard_ad(self) -> Estimate:
        return self.regular

    def to_json(self, *, standard_ad: bool = True) -> dict:
        """CLI.md's object; ``standard_ad=False`` leaves out the standard AD estimate (``langur
        deriv`` reports it beside both engines)."""
        out = {"value": self.value, "stderr": self.stderr, "regular": self.regular.to_json(),
               "boundary": self.boundary.to_json()}
        if standard_ad:
            out["standard_ad"] = self.regular.to_json()
        return {**out, **self._tail()}
