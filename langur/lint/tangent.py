"""X305/X306 for conditions completed on monotone pieces: roots that merge at a turning point.

A condition in one variable with no closed-form inverse is completed on the pieces between its
turning points c (zeros of ∂f/∂x; :mod:`langur.syntax.turning`), one implicit-root branch each.
Where ``f(c; θ) = 0`` a root sits on a turning point: two roots merge (or appear, or vanish) as
θ moves, ``∂f/∂x = 0`` on the zero set, Ψ̂ is not a diffeomorphism there (Def. 3.4, §5.2) and the
derivative does not exist (``∫ [x³ − x − a ≥ 0]`` has a square-root corner in ``a`` at
``a = ±2/(3√3)``).  Like a vanishing coefficient (X306/X305 in :mod:`langur.lint.coincidence`):
the set of parameter values where it happens is a warning (X306), and the parameter values given
with ``--at`` lying in it an error (X305), so the engines' numbers there are not taken as a
derivative.
"""

from __future__ import annotations

import sympy as sp

from ..core import IfDiffeo, ImplicitRoot, Program, subterms
from ..sympy_bridge import NotSmooth, symbol, to_sympy
from ..timebox import run_with_timeout
from .findings import Finding

#: Seconds of sympy per condition.
TIME_LIMIT = 2.0
#: |f(c)| below this (relative to the scale of f) at the parameters in force: a tangent root.
TOLERANCE = 1e-9


def tangent_findings(program: Program, point: dict | None, explicit: bool) -> list[Finding]:
    """One finding per turning point of an implicitly completed condition on which a root can
    sit (X306), or sits at the parameter values in force (X305 with ``--at``, else X306)."""
    out, seen = [], set()
    for t in subterms(program.body):
        if not isinstance(t, IfDiffeo) or t.psi in seen:
            continue
        seen.add(t.psi)
        roots = [c for b in t.psi.branches for c in b.components if isinstance(c, ImplicitRoot)]
        if not roots:
            continue
        try:
            out += run_with_timeout(lambda t=t, roots=roots: _findings(t, roots, point, explicit), TIME_LIMIT)
        except (TimeoutError, NotSmooth, TypeError, ValueError):
            continue
    return out


def _findings(site: IfDiffeo, roots: list[ImplicitRoot], point, explicit) -> list[Finding]:
    v = symbol(roots[0].variable)
    f = to_sympy(site.psi.forward[0])
    turning = [to_sympy(r.hi) for r in roots[:-1]]  # the pieces are consecutive: their inner ends
    out = []
    for c in turning:
        value = f.xreplace({v: c})
        params = sorted(value.free_symbols, key=str)
        if not params:
            continue
        names = tuple(p.name for p in params)
        where = f"{v} = {sp.sstr(c)}"
        hit = False
        if point is not None and all(n in point for n in names):
            at = {p: sp.Float(float(point[p.name]), 30) for p in params}
            scale = 1 + abs(complex(f.xreplace({v: c}).xreplace({p: 0 for p in params}).evalf(20)))
            hit = abs(complex(value.xreplace(at).evalf(30))) <= TOLERANCE * scale
        shown = ", ".join(f"{n} = {float(point[n]):g}" for n in names) if hit else ""
        if hit and explicit:
            out.append(Finding(site.span, "error", "X305",
                               f"at {shown} a root of the condition `{sp.sstr(f)}` sits on its turning point {where} "
                               f"(∂/∂{v} = 0 there): two roots merge, the condition is not a diffeomorphism and the "
                               "derivative is not defined here", (), names))
            continue
        try:
            sols = sp.solve(value, params, dict=True)
        except NotImplementedError:
            sols = []
        sols = [s for s in sols if not any(e.has(sp.I) for e in s.values())]
        the_set = " or ".join(", ".join(f"{k} = {sp.sstr(e)}" for k, e in s.items()) for s in sols) \
            or f"{sp.sstr(value)} = 0"
        note = f"; the default values {shown} lie in this set" if hit else ""
        out.append(Finding(site.span, "warning", "X306",
                           f"the condition `{sp.sstr(f)}` has a root on its turning point {where} when {the_set}: "
                           f"there two roots merge (∂/∂{v} = 0 on the zero set), it stops being a diffeomorphism "
                           f"and the derivative is not defined{note}", (), names))
    return out
