"""Where the fold curve turns (issue 18; paper §7.3's delta pieces through an implicit root): the
outer kinks of a ``folds`` problem, where a condition of the innermost level has a critical point
on its zero set (:func:`_add_fold_turns`), and, for a guard through a moving turning point (the
3-D folium's ``sign_change_0(3z² − y)``), its monotone pieces, critical points and jumps
(:func:`_add_fold_guards`).
"""

from __future__ import annotations

import math
import time
from typing import Callable, Sequence

import numpy as np
import sympy as sp
from scipy import optimize as so

from langur.implicit import ImplicitRootFn
from langur.memo import remember
from langur.symbolic.quadrature.compiling import _floats, _lambdify
from langur.symbolic.quadrature.fold import _fold_timeout
from langur.symbolic.quadrature.kinks import RESULTANT_SECONDS, _kink_functions
from langur.symbolic.quadrature.problem import NumProblem
from langur.symbolic.quadrature.roots import _coefficients, _hidden_pairs, _roots, polynomial_roots
from langur.symbolic.walks import free_symbols
from langur.timebox import run_with_timeout

#: Cells of the grid on which :func:`_add_fold_turns` looks for the fold curve's turning points
#: (two in one cell are missed; each point costs one numpy root finding).
FOLD_TURN_GRID = 512


def _fold_grid_sign_changes(groups: Callable[[float], Sequence[list]], lo: float, hi: float) -> list[float]:
    """Where the k-th value of a group of ``groups(x)`` changes sign on [lo, hi]: a grid of
    :data:`FOLD_TURN_GRID` cells, each sign change refined by brentq on that value alone (a cell
    where the group's count changes — a critical point entering or leaving the box — is not a turn
    of the fold curve), and the pairs of sign changes closer than a cell that the grid cannot see
    (:func:`_hidden_pairs` on each value along each run of nodes where its group's count stays
    the same: a tiny closed loop of the fold curve, a bump narrower than a cell — missed, the outer
    quadrature saw the inner integral 0 at all its abscissae and lost the loop's part).  The fold
    curve's turns for :func:`_add_fold_turns` and :func:`_add_fold_guards`."""
    xs = np.linspace(lo, hi, FOLD_TURN_GRID + 1).tolist()
    vals = [groups(x) for x in xs]
    out = []
    for a, b, fa, fb in zip(xs, xs[1:], vals, vals[1:]):
        for g, (ya, yb) in enumerate(zip(fa, fb)):
            if len(ya) != len(yb):
                continue
            n = len(ya)
            for k, (u, w) in enumerate(zip(ya, yb)):
                if not (math.isfinite(u) and math.isfinite(w)) or u == 0.0 or (u < 0) == (w < 0):
                    continue

                def one(x, g=g, k=k, n=n):
                    vs = groups(x)[g]
                    return vs[k] if len(vs) == n else math.nan

                try:
                    out.append(so.brentq(one, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps))
                except (ValueError, RuntimeError):
                    out.append(0.5 * (a + b))
    for g in range(min((len(v) for v in vals), default=0)):
        start = 0
        for end in range(1, len(xs) + 1):  # runs [start, end) of nodes with the same count in group g
            if end < len(xs) and len(vals[end][g]) == len(vals[start][g]):
                continue
            n = len(vals[start][g])
            if end - start >= 2:
                for k in range(n):
                    def one(x, g=g, k=k, n=n):
                        vs = groups(x)[g]
                        return vs[k] if len(vs) == n else math.nan

                    out += _hidden_pairs(one, xs[start:end], [vals[i][g][k] for i in range(start, end)],
                                          flat=False)
            start = end
    return out


def _add_fold_turns(p: NumProblem, level: int) -> None:
    """Kinks of ``level`` (the one outside the innermost) where a condition of the innermost level,
    a polynomial in its variable v, has a critical point in v on its zero set: there the fold curve
    turns (∂f/∂v = 0 on it) and the inner integral grows like log.  :func:`_kink_functions` finds
    them from sympy's ``solve`` within a wall-clock limit, so under load they could be missing and
    the outer quadrature not converge; here they are the sign changes in the outer variable of
    e(…, v_c) at each real critical point v_c in the box (numpy's roots of ∂e/∂v), on a grid of
    :data:`FOLD_TURN_GRID` cells refined by ``brentq``."""
    v = p.syms[level + 1]
    vlo, vhi = p.bounds[level + 1]
    for c in p.here(level + 1):
        if c.expr is None:
            continue
        try:
            dfn = _coefficients(sp.diff(c.expr, v), tuple(p.syms), level + 1)
        except (TypeError, ValueError):
            continue
        if dfn is None:
            continue

        def turns(*args, c=c, dfn=dfn):
            """e(…, v_c) at each real critical point v_c in the box, in increasing v_c."""
            *prefix, t = args
            try:
                cs = [float(q) for q in dfn(*prefix, t)]
            except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                return []
            return [c.f(*prefix, t, r) for r in sorted(polynomial_roots(cs)) if vlo < r < vhi]

        def roots(*prefix, turns=turns):
            """Where one of them changes sign (each on its own: at x = −0.7865 in the separable
            cubic two change sign at once, and their product would not)."""
            return _fold_grid_sign_changes(lambda x: (turns(*prefix, x),), *p.bounds[level])

        def kink(*args, turns=turns):  # (the kink's value, for callers that search it themselves)
            vals = turns(*args)
            return math.prod(vals) if vals else math.nan

        p.kinks[level].append((kink, roots))
        p.kink_vary[level].append(tuple(range(level)))
    _add_fold_guards(p, level)


#: A bracket end that jumps (an indexed root appearing or vanishing: the turning points ±√(y/3) of
#: z³ − yz appear at y = 0) is looked at this far on either side, relative to max(1, |d|).
FOLD_JUMP = 1e-9


#: The step of :func:`_add_fold_guards`' central differences (relative to max(1, |v|)); critical
#: points this close to a jump (×64) are the jump's, not the factor's.
FOLD_STEP = 1e-7


def _bracket_jumps(e: sp.Expr, v: sp.Symbol, lo: float, hi: float, at: dict) -> list[float]:
    """Where a moving turning point in ``e`` (an indexed root, ``sign_change_k(3z² − y)``) appears
    or vanishes as ``v`` moves in (lo, hi): its equation g(z; v) = 0 has a double root (the resultant
    of g and ∂g/∂z in z vanishes) or a root at its bracket's end — there the bracket end, and with
    it the guard, jumps (the folium's cusp at y = 0).  Only for an equation polynomial in z whose
    other symbols are v and the parameters, with constant bracket ends; roots by numpy."""
    out: set = set()
    for r in e.atoms(ImplicitRootFn):
        lam, target, blo, bhi, index, _ = r.args
        if int(index) < 0 or not (sp.sympify(blo).is_number and sp.sympify(bhi).is_number):
            continue
        (z,), f = lam.variables, lam.expr
        g = sp.expand((f - target).xreplace(_floats(at)))
        if not free_symbols(g) <= {z, v}:
            continue
        try:
            exprs = [run_with_timeout(lambda g=g, z=z: sp.resultant(g, sp.diff(g, z), z), RESULTANT_SECONDS, cpu=True),
                     g.xreplace({z: blo}), g.xreplace({z: bhi})]
        except Exception:  # noqa: BLE001 - sympy fails in many ways; then no jump is known (as before)
            continue
        for q in exprs:
            q = sp.expand(sp.sympify(q))
            if v not in free_symbols(q):
                continue
            try:
                cs = [float(k) for k in sp.Poly(q, v).all_coeffs()]
            except (sp.PolynomialError, TypeError):
                continue
            out.update(t for t in polynomial_roots(cs) if lo < t < hi)
    return sorted(out)


def _add_fold_guards(p: NumProblem, level: int) -> None:
    """The fold curve's turns for an innermost condition that is not a polynomial (its guard
    contains a moving turning point, the 3-D folium's ``sign_change_0(3z² − y)``): on each of its
    factors φ, the special points in the innermost variable v at each outer abscissa are the
    critical points of φ (zeros of ∂φ/∂v, the implicit root differentiated by the implicit
    function theorem, found by :func:`_roots`) and the two sides of each point where a turning
    point appears (:func:`_bracket_jumps`).  Between two of them φ is monotone, so

    * the condition's roots in v are one ``brentq`` per factor and interval (its root finder,
      instead of a grid search of the product);
    * the critical points are innermost kinks: there the weight peaks like 1/√(Δ + β(v − v_c)²)
      when the fold curve nearly turns, and :func:`_fold_innermost` splits at them;
    * where φ at a special point changes sign in the outer variable, the fold curve turns or
      meets the cusp: outer kinks, on a grid of :data:`FOLD_TURN_GRID` cells refined by ``brentq``."""
    inner = level + 1
    v = p.syms[inner]
    vlo, vhi = p.bounds[inner]
    names = p.syms[: inner + 1]
    if inner not in p.kinks:
        p.kinks[inner], p.kink_vary[inner] = _kink_functions(p, inner)
    for c in p.here(inner):
        if c.expr is None or c.roots is not None or _coefficients(c.expr, tuple(p.syms), inner) is not None:
            continue
        factors = [f for f in sp.Mul.make_args(c.expr) if v in free_symbols(f)]
        if not factors or not any(f.has(ImplicitRootFn) for f in factors):
            continue
        parts = []
        for f in factors:
            jumps = _bracket_jumps(f, v, vlo, vhi, p.at)
            sides = [(d - FOLD_JUMP * max(1.0, abs(d)), d + FOLD_JUMP * max(1.0, abs(d))) for d in jumps]
            phi = _lambdify(names, f, p.at)

            def dphi(*args, phi=phi):
                """∂φ/∂v by a central difference: the implicit function theorem's derivative of
                ``sign_change_k`` is wrong where the turning point does not exist (the root is then
                its bracket's end, a constant)."""
                *outer, t = args
                h = FOLD_STEP * max(1.0, abs(t))
                return (phi(*outer, t + h) - phi(*outer, t - h)) / (2.0 * h)

            parts.append((phi, dphi, jumps, sides))
        last: dict = {}

        def crits(*args, parts=parts, last=last):
            """Each factor's critical points in v at the outer abscissae ``args`` (the last asked kept)."""
            out = last.get(args)
            if out is None:
                out = []
                for _, dphi, jumps, _ in parts:
                    found = _roots(lambda t, dphi=dphi: dphi(*args, t), vlo, vhi)
                    out.append([t for t in found if all(abs(t - d) > FOLD_STEP * 64 * max(1.0, abs(d)) for d in jumps)])
                remember(last, args, out, 1)
            return out

        def roots(*args, parts=parts, crits=crits):
            """The condition's roots in v: each factor's, one per monotone interval."""
            out = []
            for (phi, _, jumps, sides), cs in zip(parts, crits(*args)):
                pts = sorted({vlo, vhi, *cs, *(q for ab in sides for q in ab if vlo < q < vhi)})
                vals = [phi(*args, t) for t in pts]
                if not all(math.isfinite(w) for w in vals):
                    out += _roots(lambda t, phi=phi: phi(*args, t), vlo, vhi)
                    continue
                for a, b, fa, fb in zip(pts, pts[1:], vals, vals[1:]):
                    if fa == 0.0:
                        out.append(a)
                    if fa == 0.0 or fb == 0.0 or (fa < 0) == (fb < 0):
                        continue
                    jump = next((d for d, ab in zip(jumps, sides) if ab == (a, b)), None)
                    if jump is not None:  # the guard jumps here: its sign changes at the jump
                        out.append(jump)
                        continue
                    try:
                        out.append(so.brentq(lambda t, phi=phi: phi(*args, t), a, b, xtol=1e-15,
                                             rtol=4 * np.finfo(float).eps))
                    except (ValueError, RuntimeError):
                        out.append(0.5 * (a + b))
            return out

        c.roots = roots

        def inner_kinks(*args, parts=parts, crits=crits):
            return [t for cs in crits(*args) for t in cs] + [d for _, _, jumps, _ in parts for d in jumps]

        p.kinks[inner].append((None, inner_kinks))
        p.kink_vary[inner].append(tuple(range(inner)))

        def specials(*args, parts=parts, crits=crits):
            """φ at each factor's special points: (values at critical points, values at jump sides)."""
            if time.process_time() > p.until:  # (the outer kinks' grid is part of the problem's budget)
                raise _fold_timeout(p)
            out = []
            for (phi, _, _, sides), cs in zip(parts, crits(*args)):
                out.append(([phi(*args, t) for t in cs], [phi(*args, q) for ab in sides for q in ab]))
            return out

        def outer_roots(*prefix, specials=specials):
            return _fold_grid_sign_changes(
                lambda x: [values for part in specials(*prefix, x) for values in part], *p.bounds[level])

        p.kinks[level].append((None, outer_roots))
        p.kink_vary[level].append(tuple(range(level)))

