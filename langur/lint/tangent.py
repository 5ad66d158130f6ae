"""X305/X306 for conditions completed on monotone pieces: roots that merge at a turning point.

A condition in one variable with no closed-form inverse is completed on the pieces between its
turning points c (zeros of ∂f/∂x; :mod:`langur.syntax.turning`), one implicit-root branch each.
Where ``f(c; θ) = 0`` a root sits on a turning point: two roots merge (or appear, or vanish) as
θ moves, ``∂f/∂x = 0`` on the zero set, Ψ̂ is not a diffeomorphism there (Def. 3.4, §5.2) and the
derivative does not exist (``∫ [x³ − x − a ≥ 0]`` has a square-root corner in ``a`` at
``a = ±2/(3√3)``).  A condition in several variables split along one of them at its turning
points (:func:`langur.syntax.turning.split_along`) is not reported: there a root reaches a strip's
end along a curve of the other variables (a fold of the zero set), where the delta's integral
has an integrable inverse-square-root singularity and the derivative exists; its *critical
points* (the whole gradient vanishes) on the zero set are (:func:`_critical_findings`).  Like a vanishing coefficient (X306/X305 in :mod:`langur.lint.coincidence`):
the set of parameter values where it happens is a warning (X306), and the parameter values given
with ``--at`` lying in it an error (X305), so the engines' numbers there are not taken as a
derivative.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from ..core import IfDiffeo, ImplicitRoot, Program, TooManyRoots, subterms
from ..precise import DIGITS, complex_value, number, sign
from ..sympy_bridge import NotSmooth, symbol, to_sympy
from .findings import Finding, PerCondition

#: CPU seconds of sympy per condition, and for all the conditions of a program (past either: X310).
TIME_LIMIT = 2.0
TOTAL = 15.0
#: A tangent root at the parameters in force: |f(c)| no larger than f(c) moves when the parameters
#: move by this (relative; the digits a default value is written with): ``_on_turning_point``.
TOLERANCE = 1e-9


def tangent_findings(program: Program, point: dict | None, explicit: bool) -> list[Finding]:
    """One finding per turning point of an implicitly completed condition on which a root can
    sit (X306), or sits at the parameter values in force (X305 with ``--at``, else X306)."""
    out, seen = [], set()
    clock = PerCondition("whether a root sits on a turning point (X305, X306)", TIME_LIMIT, TOTAL)
    for t in subterms(program.body):
        if not isinstance(t, IfDiffeo) or t.psi in seen:
            continue
        seen.add(t.psi)
        roots = [c for b in t.psi.branches for c in b.components if isinstance(c, ImplicitRoot)]
        if not roots:
            continue
        try:
            out += clock.run(t.psi, t.span, lambda t=t, roots=roots: _findings(t, roots, point, explicit)) or []
        except (NotSmooth, TypeError, ValueError, TooManyRoots):
            pass
        if len(t.psi.variables) > 1:
            try:
                out += clock.run(t.psi, t.span, lambda t=t: _critical_findings(t, program, point, explicit)) or []
            except (NotSmooth, TypeError, ValueError, NotImplementedError):
                continue
    return out + clock.unchecked(program.span)


def _critical_findings(site: IfDiffeo, program: Program, point, explicit) -> list[Finding]:
    """A condition in several variables completed by implicit roots (proved monotone, or split
    along a variable at turning points that move with the others) whose *gradient* vanishes at a
    point of the box (``x³ − x·y + y³ − a`` at the origin and at (1/3, 1/3)): when that critical
    point lies on the zero set (its value of ``f`` is 0: a set of parameter values), the zero set
    is not a smooth hypersurface there — two sheets cross (a saddle: the length of the level
    sets blows up like a logarithm) or it shrinks to a point (an extremum: the derivative jumps)
    — Ψ̂ is a diffeomorphism in no variable there, and the derivative in the parameters is not
    defined.  A fold (``∂f/∂x = 0`` alone, where a root reaches a strip's end) is no such point.
    The set of parameter values is a warning (X306); the values given with ``--at`` in it, an
    error (X305), as for a root on a turning point in one variable."""
    psi = site.psi
    f = to_sympy(psi.forward[0])
    xs = [symbol(v) for v in psi.variables if symbol(v) in f.free_symbols]
    if len(xs) < 2:
        return []
    sols = sp.solve([sp.diff(f, x) for x in xs], xs, dict=True)
    bounds = {}
    for v, (lo, hi) in zip(program.variables, program.box):
        try:
            bounds[symbol(v)] = (to_sympy(lo), to_sympy(hi))
        except (NotSmooth, TypeError, ValueError):
            continue
    text = sp.sstr(f)
    out = []
    for s in sols:
        if set(s) != set(xs) or not all(e.is_real is not False and not e.has(sp.I) for e in s.values()):
            continue
        if any(e.is_number and x in bounds and all(b.is_number for b in bounds[x])
               and not bounds[x][0] <= e <= bounds[x][1] for x, e in s.items()):
            continue  # outside the box
        value = sp.simplify(f.xreplace(s))
        params = sorted(value.free_symbols - set(xs), key=str)
        if not params:
            continue  # the condition alone: coincident or degenerate everywhere, other checks
        names = tuple(p.name for p in params)
        where = "(" + ", ".join(x.name for x in xs) + ") = (" + ", ".join(sp.sstr(s[x]) for x in xs) + ")"
        hit = point is not None and all(n in point for n in names) and abs(complex_value(
            value.xreplace({p: sp.Float(float(point[p.name]), DIGITS) for p in params}))) <= TOLERANCE
        shown = ", ".join(f"{n} = {float(point[n]):g}" for n in names) if hit else ""
        if hit and explicit:
            out.append(Finding(site.span, "error", "X305",
                               f"at {shown} the zero set of the condition `{text}` passes through its critical "
                               f"point {where} (its gradient vanishes there): the zero set is not smooth, the "
                               "condition is not a diffeomorphism and the derivative is not defined here", (), names))
            continue
        sets = _solve(value, params)
        the_set = " or ".join(", ".join(f"{k} = {sp.sstr(e)}" for k, e in q.items()) for q in sets) \
            or f"{sp.sstr(value)} = 0"
        note = f"; the default values {shown} lie in this set" if hit else ""
        out.append(Finding(site.span, "warning", "X306",
                           f"the zero set of the condition `{text}` passes through its critical point {where} "
                           f"(its gradient vanishes there) when {the_set}: there it is not smooth (two sheets "
                           f"cross, or it shrinks to a point), the condition stops being a diffeomorphism and the "
                           f"derivative is not defined{note}", (), names))
    return out


def _findings(site: IfDiffeo, roots: list[ImplicitRoot], point, explicit) -> list[Finding]:
    v = symbol(roots[0].variable)
    f = to_sympy(site.psi.forward[0])
    text = sp.sstr(f)
    out = []
    # the pieces are consecutive: their inner ends are the turning points (closed forms, or the k-th
    # sign change of ∂f/∂x when they move with the parameters, or with a domain end that moves)
    ends = [(r.hi, to_sympy(r.hi), isinstance(r.hi, ImplicitRoot)) for r in roots[:-1]]
    fixed = _fixed_turning_points(ends, v)
    if fixed is not None:  # ∂f/∂x free of parameters: the slots are its zeros on the line that can be in the domain
        lo, hi = (to_sympy(t) for t in (roots[0].lo, roots[-1].hi))
        ends = [(c, c, False) for c in fixed
                if not (lo.is_number and c < lo) and not (hi.is_number and c > hi)]
    for end, c, moving in ends:
        value = f.xreplace({v: c})
        params = sorted(value.free_symbols, key=str)
        if not params or any(p.name in site.psi.variables for p in params):
            continue  # split along v (several variables): a root on a strip's end is a fold, not a merge
        names = tuple(p.name for p in params)
        where = f"the turning point {v} = {sp.sstr(c)}" if not moving else f"turning point {end.index} (from the left)"
        hit = (point is not None and all(n in point for n in names)
               and _on_turning_point(f, v, c, end, roots, {p: sp.Float(float(point[p.name]), 30) for p in params}))
        shown = ", ".join(f"{n} = {float(point[n]):g}" for n in names) if hit else ""
        if hit and explicit:
            out.append(Finding(site.span, "error", "X305",
                               f"at {shown} a root of the condition `{text}` sits on {where} (∂/∂{v} = 0 there): "
                               "two roots merge, the condition is not a diffeomorphism and the derivative is not "
                               "defined here", (), names))
            continue
        note = f"; the default values {shown} lie in this set" if hit else ""
        if moving:  # the set where a root sits on a moving turning point is not computed: only the point
            if hit:
                out.append(Finding(site.span, "warning", "X306",
                                   f"a root of the condition `{text}` sits on {where} (its turning points move with "
                                   f"the parameters; ∂/∂{v} = 0 on the zero set): two roots merge, it stops being a "
                                   f"diffeomorphism and the derivative is not defined{note}", (), names))
            continue
        sols = _solve(value, params)
        the_set = " or ".join(", ".join(f"{k} = {sp.sstr(e)}" for k, e in s.items()) for s in sols) \
            or f"{sp.sstr(value)} = 0"
        out.append(Finding(site.span, "warning", "X306",
                           f"the condition `{text}` has a root on {where} when {the_set}: there two roots merge "
                           f"(∂/∂{v} = 0 on the zero set), it stops being a diffeomorphism and the derivative is not "
                           f"defined{note}", (), names))
    return out


def _on_turning_point(f, v, c, end, roots, at) -> bool:
    """Does a root of ``f`` sit on the turning point ``c`` at the parameter values ``at``?"""
    try:
        here = number(c.xreplace(at))
        lo, hi = (number(to_sympy(t).xreplace(at)) for t in (roots[0].lo, roots[-1].hi))
    except (TypeError, ValueError, TooManyRoots):  # more turning points than pieces: the engines say so
        return False
    if isinstance(end, ImplicitRoot) and here == hi:
        return False  # a moving slot past the last turning point is the domain's end
    if not lo <= here <= hi:
        return False  # a turning point outside the domain (whose end moves) at these values
    # how far the value at the turning point moves when the parameters move by TOLERANCE (relative):
    # to first order ∂f/∂θ there (∂f/∂x = 0 at c), so a value that no nearby parameter value can
    # make 0 is not a root on the turning point however small it is — six roots 0.01 apart have
    # values ±1e-11 at their turning points for every a, since f depends on x − a only (pole32)
    reach = sum(abs(complex_value(_partial(f, p).xreplace(at).xreplace({v: here}))) * max(1, abs(float(at[p])))
                for p in at)
    return abs(complex_value(f.xreplace(at).xreplace({v: here}))) <= TOLERANCE * reach


@lru_cache(maxsize=1024)
def _partial(f: sp.Expr, p: sp.Symbol) -> sp.Expr:
    """∂f/∂p, made once per condition and parameter (:func:`_on_turning_point` asks it at every
    turning point: 7 of them for a product of 8 moving factors)."""
    return sp.diff(f, p)


def _fixed_turning_points(ends, v) -> list | None:
    """The zeros of ∂f/∂x on the line where it changes sign, when the pieces' ends are its k-th sign
    changes on a domain whose end moves but ∂f/∂x has no parameters (so the turning points are
    fixed, only which of them lie in the domain moves); else None."""
    if not ends or not all(moving for _, _, moving in ends):
        return None
    slope = to_sympy(ends[0][0].equation)
    if slope.free_symbols - {v}:
        return None
    zeros = sp.solveset(slope, v, sp.S.Reals)
    if not isinstance(zeros, sp.FiniteSet) or not all(z.is_real for z in zeros):
        return None
    points = sorted(zeros, key=lambda z: float(z))
    probes = [points[0] - 1] + [(p + q) / 2 for p, q in zip(points, points[1:])] + [points[-1] + 1] if points else []
    signs = [sign(slope.xreplace({v: p})) > 0 for p in probes]
    return [c for k, c in enumerate(points) if signs[k] != signs[k + 1]]


def _solve(value, params) -> list[dict]:
    try:
        sols = sp.solve(value, params, dict=True)
    except NotImplementedError:
        return []
    return [s for s in sols if not any(e.has(sp.I) for e in s.values())]
