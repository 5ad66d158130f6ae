"""Geometry of zero sets for the transversality checker (paper Def. 7.2).

Restriction of a condition to another's zero set through its inverse branches
``x = Ψ̂_b⁻¹(0, u′)`` (LANGUAGE.md §4), whether a zero set moves with the parameters, which sides
two coincident conditions are ``≥ 0`` on, and whether a zero set meets the box of integration at
given parameter values.
"""

from __future__ import annotations

import random
from collections.abc import Mapping

import sympy as sp

from ..diagnostics import Span
from ..sympy_bridge import magnitude, symbol, to_sympy
from . import algebra
from .algebra import vanishes
from .collect import Occurrence


def restrict(expr: sp.Expr, branch) -> sp.Expr:
    comps, _ = branch
    return expr.xreplace(comps)


def xsyms(variables) -> tuple[sp.Symbol, ...]:
    return tuple(symbol(x) for x in variables)


def moving(occ: Occurrence, variables) -> bool:
    """Does the zero set move with the parameters (is ``D_γ π₀Ψ̂`` nonzero somewhere on it)?  Decided
    once per occurrence (kept in :attr:`Occurrence.moves`; not when the decision was interrupted)."""
    if occ.moves is None:
        occ.moves = _moves(occ, variables)
    return occ.moves


def _moves(occ: Occurrence, variables) -> bool:
    xs = set(xsyms(variables))
    params = [s for s in occ.f.free_symbols if s not in xs]
    for p in params:
        d = sp.diff(occ.f, p)
        for br in occ.branches:
            if not vanishes(restrict(d, br), occ.uprime + tuple(params), br[1]):
                return True
    return False


def params_of(*occs: Occurrence, variables) -> list[sp.Symbol]:
    xs = set(xsyms(variables))
    out: set[sp.Symbol] = set()
    for o in occs:
        out |= {s for s in o.f.free_symbols if s not in xs}
        uprime = set(o.uprime)  # (once per occurrence, not once per symbol: 41 variables, bench/history/2026-11-29.md#hostile32
        for comps, guards in o.branches:
            for e in list(comps.values()) + list(guards):
                out |= {s for s in e.free_symbols if s not in xs and s not in uprime}
    return sorted(out, key=str)


def orientation(c: Occurrence, g: Occurrence, branch, variables, fixed: dict | None = None) -> int:
    """+1 when the two conditions are ≥ 0 on the same side of their common zero set, −1 when on
    opposite sides (sign of ∇f·∇g there), 0 when it cannot be told."""
    xs = xsyms(variables)
    dot = sum(sp.diff(c.f, x) * sp.diff(g.f, x) for x in xs)
    e = restrict(dot, branch)
    if fixed:
        e = e.subs(fixed)
    if e == 0:
        return 0
    syms = e.free_symbols
    # each value against the size of its terms (magnitude): the normals of [x >= a] and
    # [x / 10^6 >= b] have the dot product 10⁻⁶, small but not 0
    vals = algebra.spot_values(e / magnitude(e), syms, [gd.subs(fixed or {}) for gd in branch[1]], seed=7)
    vals = [v.real for v in vals if abs(v.real) > 1e-9]
    if not vals:
        return 0
    pos = sum(1 for v in vals if v > 0)
    return 1 if pos * 2 >= len(vals) else -1


def in_box(xvals: Mapping[sp.Symbol, sp.Expr], box, point, variables) -> bool:
    tol = 1e-9
    for x, (lo, hi) in zip(variables, box):
        try:
            v = complex(sp.sympify(xvals[symbol(x)]).subs(point).evalf())
            lo_v = float(lo.subs(point)) if lo.free_symbols else float(lo)
            hi_v = float(hi.subs(point)) if hi.free_symbols else float(hi)
        except (TypeError, ValueError, KeyError):
            return True  # cannot tell: assume it can happen
        if abs(v.imag) > 1e-9 or v.real < lo_v - tol or v.real > hi_v + tol:
            return False
    return True


def meets_box(c: Occurrence, branch, box, point, variables, extra_eq: sp.Expr | None = None) -> bool:
    """Does the branch's piece of c's zero set meet the closed box at the parameter ``point``?"""
    return next(zero_set_points(c, branch, box, point, variables, extra_eq), None) is not None


def zero_set_points(c: Occurrence, branch, box, point, variables, extra_eq: sp.Expr | None = None,
                    samples: int = 60):
    """Points ({x: value}) of the branch's piece of c's zero set inside the closed box at the
    parameter ``point`` (``extra_eq`` also vanishing there); an empty ``{}`` when the box cannot
    be evaluated (then it may meet it anywhere)."""
    comps, guards = branch
    if not c.uprime:
        if any(num(gd.subs(point)) < 0 for gd in guards if num(gd.subs(point)) is not None):
            return
        if in_box(comps, box, point, variables):
            yield {x: e.subs(point) for x, e in comps.items()}
        return
    # Sample the box, map each sample to u′ (the other components of Ψ̂), come back to the zero set.
    rng = random.Random(3)
    fwd = [to_sympy(t) for t in c.psi.forward[1:]]
    xs = xsyms(variables)
    boxv = []
    for lo, hi in box:
        lo_v, hi_v = num(lo.subs(point)), num(hi.subs(point))
        if lo_v is None or hi_v is None:
            yield {}
            return
        boxv.append((lo_v, hi_v))
    for _ in range(samples):
        xpt = {x: sp.Float(rng.uniform(lo, hi), 12) for x, (lo, hi) in zip(xs, boxv)}
        upt = {u: F.subs(point).subs(xpt) for u, F in zip(c.uprime, fwd)}
        if any(num(gd.subs(point).subs(upt)) is None or num(gd.subs(point).subs(upt)) < 0 for gd in guards):
            continue
        image = {x: e.subs(point).subs(upt) for x, e in comps.items()}
        if extra_eq is not None:
            v = num(extra_eq.subs(point).subs(upt))
            if v is None or abs(v) > 1e-7:
                continue
        if in_box(image, box, {}, variables):
            yield image


def num(e) -> float | None:
    try:
        v = complex(sp.sympify(e).evalf())
    except (TypeError, ValueError):
        return None
    if abs(v.imag) > 1e-9:
        return None
    return v.real


def is_linear(f: sp.Expr, xs) -> bool:
    """Whether ``f`` is a polynomial of degree ≤ 1 in the variables ``xs`` (its coefficients may be
    anything else).  Only the variables ``f`` contains are the polynomial's generators: a dense
    polynomial in all 41 of a program's variables cost 4 ms per condition (bench/history/2026-11-29.md#hostile32."""
    gens = [x for x in xs if x in f.free_symbols]
    if not gens:
        return True  # (constant in xs: degree 0)
    try:
        return sp.Poly(f, *gens).total_degree() <= 1
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return False


def span_key(span: Span | None) -> tuple:
    return (span.path, span.line, span.col) if span is not None else ("", 0, 0)
