"""Exact integration of ``Π [cond ≥ 0] · weight`` over a box by iterated integration (paper §6.3,
Def. 6.1–6.2; LANGUAGE.md §3–§4).

Regions are computed from the conditions, never by handing Piecewise/Heaviside/Min/Max to sympy's
``integrate`` (sympy 1.14 gets those wrong: #26071, #21426, #28091, #17321).  sympy only ever
integrates a SMOOTH weight in one variable
(:func:`~langur.symbolic.antiderivatives.antiderivative`), time-boxed, and the bounds are
substituted afterwards.

* Each condition involving the integration variable ``v`` is solved for ``v`` into alternatives
  ``(extra conditions on the other symbols, lower bounds, upper bounds)``
  (:func:`~langur.symbolic.solving.alternatives`): linear and quadratic polynomials in ``v``
  exactly, a Psi solved for ``v`` with one branch through its inverse (a diffeomorphism's
  condition is monotone in ``v``).  A direction (sign of the derivative) that depends on
  parameters only is decided at the evaluation point; one that depends on outer variables becomes
  a case split.
* Innermost variables: ``v ∈ [max L, min U]`` is split into the cases "``l`` is the largest lower
  and ``u`` the smallest upper bound"; each case adds the comparisons as conditions on the outer
  variables and integrates ``F(u) − F(l)``, a smooth function with plain bounds.
* Outermost variable (only parameters left): ``F(Max(A, B)) − F(A)`` with ``A = Max(L)``,
  ``B = Min(U)`` — valid for all parameter values, e.g. ``∫₀¹[θ − x ≥ 0] = Max(0, Min(1, θ))``.
  Conditions that cannot be solved that way (several branches, transcendental) are handled by
  :func:`_generic_1d`: all roots, ordered at the evaluation point, sign of every condition on each
  sub-interval decided there.
* Every comparison of parameter-only quantities is decided at the evaluation point ``at`` and
  recorded in :attr:`Context.cell`: the closed form is valid in the parameter cell they define.

The records (:class:`Cond`, :class:`Context`, :class:`Deferred`) are in
:mod:`langur.symbolic.context`; solving one condition for one variable, its roots and the sign
probes in :mod:`langur.symbolic.solving`; the antiderivatives of smooth weights in
:mod:`langur.symbolic.antiderivatives`.  This module: the iterated integration itself.
"""

from __future__ import annotations

import itertools
import random
from typing import Sequence

import sympy as sp

from langur.memo import remember as _remember
from langur.symbolic import exact_rules, local, walks
from langur.symbolic.antiderivatives import antiderivative
from langur.symbolic.context import Cond, Context, Deferred, Unsupported, _made
from langur.symbolic.definite import definite as _definite
from langur.symbolic.solving import (
    _away_from_zero,
    _closed_roots,
    _inside,
    _no_missed_root,
    _only_repeats,
    _probe,
    _radicand,
    _roots,
    alternatives,
    poles,
)


def _dedupe(bounds):
    """``bounds`` without repeats: ``b`` is dropped when ``expand(b − o) == 0`` for a bound ``o``
    kept before it.  Two bounds with different exact values at one rational point
    (:func:`_rational_probe`) are not repeats, and are not expanded (expanding the difference of
    two large bounds costs tens of milliseconds); the expansion decides the rest, as before."""
    out, values = [], []
    for b in bounds:
        vb = _rational_probe(b)
        if not any((vb is None or vo is None or vb == vo) and sp.expand(b - o) == 0
                   for o, vo in zip(out, values)):
            out.append(b)
            values.append(vb)
    return out


def _rational_probe(e):
    """``e``'s exact value (a sympy Rational) with each symbol replaced by a fixed rational of its
    own (from its name), or None when that is not a rational number (a root, a pole)."""
    e = sp.sympify(e)
    z = e.xreplace(_probe_point(walks.free_symbols(e)))
    return z if z.is_Rational else None


def _probe_point(symbols) -> dict:
    """:func:`_rational_probe`'s point: each symbol a fixed rational of its own (from its name)."""
    point = {}
    for s in symbols:
        q = _PROBE_RATIONALS.get(s.name)
        if q is None:
            q = _PROBE_RATIONALS[s.name] = sp.Rational(random.Random(s.name).randint(10**5, 10**6), 999983)
        point[s] = q
    return point


#: :func:`_rational_probe`'s value of each symbol, by name.
_PROBE_RATIONALS: dict = {}


def _prefilter(conds, ctx: Context):
    """Drop conditions true at ``at`` (parameter-only) or numerically true; None if one is false."""
    kept = []
    for c in conds:
        e = sp.sympify(c.expr)
        if not (walks.free_symbols(e) - ctx.params):
            if not ctx.decide(e, c.strict):
                return None
            continue
        kept.append(c)
    return kept


def integrate_vars(conds, weight, variables: Sequence, box: dict, ctx: Context):
    """∫ over ``box`` of Π conds · weight in ``variables`` (innermost last); params decided at at."""
    conds = _prefilter(conds, ctx)
    if conds is None:
        return sp.Integer(0)
    if not variables:
        return _made(weight)
    if weight == 0:  # (a Deferred weight is not 0)
        return sp.Integer(0)
    v, outer = variables[-1], list(variables[:-1])
    dep = [c for c in conds if v in walks.free_symbols(c.expr)]
    rest = [c for c in conds if v not in walks.free_symbols(c.expr)]
    lo, hi = box[v]
    if not outer:
        if rest:
            raise Unsupported("condition on a variable outside the integration order")
        return _outermost(dep, weight, v, lo, hi, ctx)
    weight = _made(weight)
    F = None  # computed on first use: empty cases need no antiderivative
    total = sp.Integer(0)
    for combo in itertools.product(*[alternatives(c, v, outer, ctx) for c in dep]):
        extra = [x for alt in combo for x in alt.extra]
        L = _dedupe([lo] + [b for alt in combo for b in alt.lowers])
        U = _dedupe([hi] + [b for alt in combo for b in alt.uppers])
        for i, l in enumerate(L):
            for j, u in enumerate(U):
                new = [Cond(l - l2, strict=k < i) for k, l2 in enumerate(L) if k != i]
                new += [Cond(u2 - u, strict=k < j) for k, u2 in enumerate(U) if k != j]
                new.append(Cond(u - l))
                case = _prefilter(extra + new, ctx)
                if case is None:
                    continue
                if F is None:
                    F = antiderivative(weight, v, ctx)
                g = _definite(F, v, l, u, ctx)
                total += integrate_vars(rest + case, g, outer, box, ctx)
    return total


#: sympy's Max/Min of symbolic bounds by their arguments: building one compares every pair of
#: arguments (seconds on a campaign's program), and the same bounds come back for the value, each
#: partial derivative and the checks.
_EXTREMA: dict = {}


def _extremum(fn, args):
    """``fn(*args)`` (``sp.Max`` or ``sp.Min``), remembered."""
    key = (fn, tuple(args))
    out = _EXTREMA.get(key)
    if out is None:
        out = fn(*args)
        _remember(_EXTREMA, key, out)
    return out


def _outermost(conds, weight, v, lo, hi, ctx: Context):
    """Last variable: ``F(Max(A, B)) − F(A)`` per alternative, else the generic 1-D method (at
    once for large conditions: their Max/Min nests cost minutes, :mod:`langur.symbolic.local`).
    A :class:`Deferred` weight stays unmade when the conditions alone are large (then so are the
    conditions with any weight)."""
    exprs = [c.expr for c in conds]
    if isinstance(weight, Deferred) and not local.is_large(exprs, ctx.params):
        weight = weight.made()
    if isinstance(weight, Deferred) or local.is_large(exprs + [sp.sympify(weight)], ctx.params):
        return _generic_1d(conds, weight, v, lo, hi, ctx)
    sub = Context(ctx.at, ctx.deadline, ctx.params)
    try:
        alts = [alternatives(c, v, [], sub) for c in conds]
        F = None
        total = sp.Integer(0)
        for combo in itertools.product(*alts):
            extra = _prefilter([x for alt in combo for x in alt.extra], sub)
            if extra is None:
                continue
            A = _extremum(sp.Max, _dedupe([lo] + [b for alt in combo for b in alt.lowers]))
            B = _extremum(sp.Min, _dedupe([hi] + [b for alt in combo for b in alt.uppers]))
            top = _extremum(sp.Max, (A, B))
            if top == A:
                continue  # empty for every parameter value
            if F is None:
                F = antiderivative(weight, v, sub)
            total += _definite(F, v, A, top, ctx)
        ctx.cell.extend(r for r in sub.cell if r not in ctx.cell)
        return total
    except Unsupported:
        return _generic_1d(conds, weight, v, lo, hi, ctx)



def _generic_1d(conds, weight, v, lo, hi, ctx: Context):
    """Roots of all conditions, ordered at ``at``; conditions decided per sub-interval at ``at``.
    A :class:`Deferred` weight (the conditions alone large) is made for the first non-empty
    sub-interval, if any."""
    lo_v, hi_v = ctx.value(lo).real, ctx.value(hi).real
    pts = [(lo_v, lo), (hi_v, hi)]
    if isinstance(weight, Deferred) and not local.is_large([c.expr for c in conds], ctx.params):
        weight = weight.made()
    large = isinstance(weight, Deferred) or \
        local.is_large([c.expr for c in conds] + [sp.sympify(weight)], ctx.params)
    unsure = []  # conditions whose roots sympy solved (it may miss some): sign changes looked for
    seen: set = set()  # the conditions whose roots are among pts
    for c in conds:
        rs = _closed_roots(c, v, ctx) if large else None
        if rs is None:
            # sympy's roots untidied first: when none lies inside (lo, hi) here, none enters the
            # closed form, and solve's simplify pass (most of its time) is not needed; nor solve
            # itself when the condition is seen to stay away from 0 there
            # (nor either solve when every root it could add is a certain repeat of a point there)
            known = {p[0] for p in pts}
            base = _radicand(c, v, seen)
            if base is not None and _only_repeats(base, v, lo_v, hi_v, known, ctx):
                rs = []  # k·√P whose P came before: P's roots, all repeats
            else:
                rs = [] if _away_from_zero(c, v, lo_v, hi_v, ctx) else \
                    _roots(c, v, ctx, tidy=False, within=(lo_v, hi_v))
                if any(_inside(r, lo_v, hi_v, ctx) for r in rs) and \
                        not _only_repeats(c.expr, v, lo_v, hi_v, known, ctx):
                    rs = _roots(c, v, ctx, within=(lo_v, hi_v))
            unsure.append(c)
            rs = rs + poles(c, v, ctx, (lo_v, hi_v))  # (sign changes without a root)
        seen.add(c.expr)
        for r in rs:
            if _inside(r, lo_v, hi_v, ctx):
                pts.append((ctx.value(r).real, r))
    pts.sort(key=lambda p: p[0])
    uniq = []
    for p in pts:
        if uniq and abs(p[0] - uniq[-1][0]) < 1e-13 * max(1.0, abs(p[0])):
            continue
        uniq.append(p)
    for (a, ea), (b, eb) in zip(uniq, uniq[1:]):
        if not (eb - ea).is_number:
            if large:  # (expanding the difference of two large bounds costs seconds)
                rel = sp.StrictGreaterThan(eb - ea, 0, evaluate=False)  # (undecidable: not tried)
                if rel not in ctx.cell:
                    ctx.cell.append(rel)
            else:
                ctx.record(">", eb - ea)
        _no_missed_root(unsure, v, a, b, ctx)
    ctx.generic = True
    total = sp.Integer(0)
    start = None
    F = None
    made = None  # (the weight, its degree when large) once an interval needs it

    def definite(a, b):
        nonlocal F, made
        if made is None:
            w = sp.sympify(_made(weight))
            made = (w, walks.degree(w, frozenset((v,))) if large else None)
        w, deg = made
        if deg is not None and deg <= exact_rules.MAX_DEGREE:  # a large polynomial: never expanded
            return exact_rules.newton_cotes(w, v, a, b, deg)
        F = F if F is not None else antiderivative(w, v, ctx)
        return _definite(F, v, a, b, ctx)
    for (a, ea), (b, eb) in zip(uniq, uniq[1:]):
        m = (a + b) / 2
        ok = True
        for c in conds:
            z = _probe(c.expr, v, m, ctx)
            if z is None:
                raise Unsupported(f"{c.expr} has no value at {v} = {m:.6g} at the evaluation point")
            if abs(z.imag) > 1e-20 or not (z.real > 0 or (z.real == 0 and not c.strict)):
                ok = False
                break
        if ok and start is None:
            start = ea
        if not ok and start is not None:
            total += definite(start, ea)
            start = None
    if start is not None:
        total += definite(start, uniq[-1][1])
    return total


def integrate_region(conds: Sequence[Cond], weight, variables: Sequence, box: dict, ctx: Context):
    """Exact ∫ Π conds · weight over ``box``, trying each integration order.

    Parameter-only conditions of the input stay exact as a Piecewise factor; comparisons made
    during the decomposition are decided at ``at`` (``ctx.cell``); a :class:`Deferred` weight
    is made here unless there is one variable."""
    if isinstance(weight, Deferred) and len(variables) != 1:
        weight = weight.made()
    top = []
    others = []
    for c in conds:
        e = sp.sympify(c.expr)
        if walks.free_symbols(e) & set(variables):
            others.append(c)
        elif e.is_number:
            if not ctx.decide(e, c.strict):
                return sp.Integer(0)
        else:
            top.append(e > 0 if c.strict else e >= 0)
    if len(variables) == 2 and ((others and local.wants_cell_forms()) or
                                local.is_large([c.expr for c in others] + [sp.sympify(weight)], ctx.params)):
        # a convex polygon decided at the point (large affine regions: Max/Min nests cost minutes)
        sub = Context(ctx.at, ctx.deadline, ctx.params)
        # (⟦p⟧ near the point, a form only Theorem 8.1's check reads, as sums of moments when large;
        # not under a parameter-only Piecewise, which that check's localization would rebuild)
        val = local.polygon_integral(others, sp.sympify(weight), *variables, box, sub,
                                     near=local.wants_cell_forms() and not top)
        if val is not None:
            ctx.cell.extend(r for r in sub.cell if r not in ctx.cell)
            return sp.Piecewise((val, sp.And(*top)), (0, True)) if top else val
    failures = []
    orders = list(itertools.permutations(variables))
    orders.sort(key=lambda o: o != tuple(variables))
    for order in orders:
        sub = Context(ctx.at, ctx.deadline, ctx.params)
        try:
            val = integrate_vars(others, weight, list(order), box, sub)
        except Unsupported as exc:
            failures.append(str(exc))
            if ctx.deadline.remaining() <= 0:
                break
            continue
        ctx.cell.extend(r for r in sub.cell if r not in ctx.cell)
        ctx.generic = ctx.generic or sub.generic
        if top:
            val = sp.Piecewise((val, sp.And(*top)), (0, True))
        return val
    raise Unsupported(failures[0] if failures else "no integration order")
