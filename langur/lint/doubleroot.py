"""X315: a condition whose zero set is a double root for every parameter value.

A diffeomorphic conditional needs Ψ̂ to be a diffeomorphism (Def. 3.4, §5.2): on its zero set
π₀Ψ̂ = 0 the derivative ∂π₀Ψ̂/∂v in the solved-for variable must not vanish, or δ(π₀Ψ̂) is not
defined there.  ``[t^2 * x^2 - 2*t*x + 1 > 0]`` is ``[(t·x − 1)² > 0]``: its zero set x = 1/t is a
double root whatever t is, ∂Φ/∂x = 2t(t·x − 1) vanishes on it, and no derivative exists (the
exact engine has no closed form, the Monte Carlo engine gives NaN).  X306 covers coefficients that
vanish for *some* parameter values; this is the case where ∂Φ/∂v vanishes on the zero set
identically.

Decided with sympy (time-boxed): for each inverse branch x_b(u') of a completed condition,
``simplify(∂Φ/∂v at Ψ̂_b⁻¹(0, u'))`` is 0 for every branch; a branch where it is real and
nonzero at a random point (compiled spot values) is not, without ``simplify``.
"""

from __future__ import annotations

import sympy as sp

from ..core import IfDiffeo, Program, subterms
from ..sympy_bridge import NotSmooth, symbol, to_sympy
from .algebra import spot_values
from .findings import Finding, PerCondition

#: CPU seconds of sympy per condition, and for all the conditions of a program (past either: X310).
TIME_LIMIT = 2.0
TOTAL = 15.0


def double_root_findings(program: Program) -> list[Finding]:
    """One X315 error per completed condition whose zero set is a double root identically; one
    X310 when some condition could not be decided (:class:`~langur.lint.findings.PerCondition`)."""
    out, seen = [], set()
    clock = PerCondition("whether a condition's zero set is a double root (X315)", TIME_LIMIT, TOTAL)
    for t in subterms(program.body):
        if not isinstance(t, IfDiffeo) or t.psi.solved_for is None or t.psi in seen:
            continue
        seen.add(t.psi)
        try:
            degenerate = clock.run(t.psi, t.span, lambda t=t: _double_root(t.psi))
        except (NotSmooth, TypeError, ValueError):
            continue
        if degenerate:
            out.append(Finding(t.span, "error", "X315",
                               f"the zero set of the condition `{sp.sstr(to_sympy(t.psi.forward[0]))}` is a double root "
                               f"for every parameter value: ∂/∂{t.psi.solved_for} of the condition vanishes on it, so "
                               "it is not a diffeomorphism anywhere and the derivative is not defined (Def. 3.4, "
                               "paper §5.2); write the condition so that it changes sign (e.g. without the square)",
                               (), tuple(sorted(s.name for s in to_sympy(t.psi.forward[0]).free_symbols
                                                 if s.name not in t.psi.variables))))
    return out + clock.unchecked(program.span)


def _double_root(psi) -> bool:
    v = symbol(psi.solved_for)
    phi = to_sympy(psi.forward[0])
    slope = sp.diff(phi, v)
    if slope.is_number:
        return False
    u0 = symbol(psi.inputs[0])
    for b in psi.branches:
        at = {x: to_sympy(c) for x, c in zip((symbol(n) for n in psi.variables), b.components)}
        e = slope.xreplace(at).xreplace({u0: 0})
        if _nonzero_somewhere(e) or sp.simplify(e) != 0:
            return False
    return bool(psi.branches)


#: A spot value (30 digits, :func:`langur.lint.algebra.spot_values`) this far from 0 is no rounding.
_NONZERO = 1e-8


def _nonzero_somewhere(e: sp.Expr) -> bool:
    """Is ``e`` certainly not identically 0: real and nonzero at a random point?  What ``simplify``
    would then not reduce to 0, decided by a few compiled evaluations instead (most conditions'
    slopes are nonzero on their zero sets: this is the common answer)."""
    try:
        return any(abs(v) > _NONZERO for v in spot_values(e, e.free_symbols, points=3))
    except Exception:  # noqa: BLE001 - a point where e cannot be evaluated (an implicit root with more
        return False   # turning points than its split, TooManyRoots): sympy's simplify decides, as before
