"""``langur check --prove``: is the derivative actually wrong where a finding says Def. 7.2 fails?

Def. 7.2 is sufficient, not necessary (LANGUAGE.md §5).  For each finding this evaluates the
Theorem 8.1 check of the symbolic engine (``langur.exact.exact_deriv``: ``D_γ⟦p⟧·γ'``
against ``⦇p⦈(γ, γ')``) at the parameter values in force (defaults, or ``--at``), in the direction
of each parameter the finding is about, and summarizes it: ``wrong`` (some direction disagrees),
``right`` (every direction agrees) or ``unknown`` (the engine could not decide).  Results are
cached per file and direction, and every call is time-boxed.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from .. import failures
from ..exact import exact_deriv
from ..lint.algebra import describe_point
from ..timebox import run_with_timeout

#: Seconds allowed for one derivative + Theorem 8.1 check.
TIME_LIMIT = 30.0


def _fmt(v) -> str:
    try:
        return f"{float(v):.6g}"
    except (TypeError, ValueError):
        return str(v)


class Prover:
    """Theorem 8.1 checks for one program at one parameter point."""

    def __init__(self, program, point: Mapping[str, object] | None):
        self.program = program
        self.point = dict(point) if point is not None else None
        self.cache: dict[str, dict] = {}
        self.shown: dict[str, str] = {}  # D_name⟦p⟧ as the summary shows it (TheoremCheck.left_side)

    def direction(self, name: str) -> dict:
        if name in self.cache:
            return self.cache[name]
        try:
            res = run_with_timeout(lambda: exact_deriv(self.program, self.point, {name: 1}), TIME_LIMIT)
            thm = res.theorem_8_1
            if thm is None:
                out = {"holds": None, "reason": "the Theorem 8.1 check could not be computed"}
            else:
                decided = all(math.isfinite(v) for v in (thm.d_denotation, thm.derivative_denotation))
                out = {
                    "holds": bool(thm.holds) if decided else None,
                    "d_denotation": thm.d_denotation,
                    "derivative_denotation": thm.derivative_denotation,
                    "how": thm.how,
                    **({"error": thm.error} if thm.error is not None else {}),
                }
                self.shown[name] = thm.left_side(6, name)
                if not decided:
                    out["reason"] = "D⟦p⟧ is not a finite number here (no derivative, or not computed)"
        except Exception as e:  # the engine's failures are reported, never raised
            out = {"holds": None, "reason": failures.why(e)}
        self.cache[name] = out
        return out

    def prove(self, names) -> dict:
        """``{"params", "directions": {name: check}, "verdict", "summary"}`` for a finding."""
        if self.point is None:
            return {
                "verdict": "unknown",
                "summary": "no parameter values to check at (give --at)",
                "directions": {},
            }
        names = [n for n in names if n in self.point] or list(self.point)
        if not names:
            return {"verdict": "unknown", "summary": "the program has no parameters", "directions": {}}
        checks = {n: self.direction(n) for n in names}
        at = describe_point(self.point, list(self.point))
        parts = []
        for n, c in checks.items():
            if c.get("holds") is None:
                parts.append(f"D_{n}: undecided ({c.get('reason', 'unknown')})")
            else:
                rel = ("≈" if "error" in c else "=") if c["holds"] else "≠"  # (≈: within the error estimate)
                parts.append(f"{self.shown[n]} {rel} ⦇p⦈ = {_fmt(c['derivative_denotation'])}")
        if any(c.get("holds") is False for c in checks.values()):
            verdict, tail = "wrong", "the derivative denotation is wrong here"
        elif all(c.get("holds") is True for c in checks.values()):
            verdict, tail = "right", "Theorem 8.1's equation holds here nevertheless"
        else:
            verdict, tail = "unknown", "could not decide whether the derivative is right here"
        summary = f"at {at}: {'; '.join(parts)}: {tail}"
        return {
            "params": {k: float(v) for k, v in self.point.items()},
            "directions": checks,
            "verdict": verdict,
            "summary": summary,
        }
