"""The nested integral of one problem (paper §8.2: ⟦p⟧ = ∫_box Π[conditions] · weight at the
parameters' values): at each level the range is split at its breakpoints, the conditions tested at
each sub-interval's midpoint, and the inner integral integrated by :func:`_quad` (or one
Gauss–Kronrod panel, or the fold's substitution for a delta through an implicit root).
"""

from __future__ import annotations

import math
import time
from typing import Callable

from langur.symbolic.quadrature.adaptive import _name, _quad
from langur.symbolic.quadrature.fold import (
    FOLD_END,
    FOLD_EPS,
    FoldUnresolved,
    _fold_allowance,
    _fold_deadline,
    _fold_innermost,
    _fold_message,
    _fold_outer,
    _fold_timeout,
)
from langur.symbolic.quadrature.foldcurve import _add_fold_turns
from langur.symbolic.quadrature.gausskronrod import UNVECTORIZABLE, _first_panel
from langur.symbolic.quadrature.kinks import _breakpoints, _kink_functions
from langur.symbolic.quadrature.problem import NumProblem, UndefinedIntegral
from langur.symbolic.quadrature.tolerance import _OUTER, BOUNDARY, EPSABS, NARROW


def _holds(v: float) -> bool:
    return not math.isnan(v) and v >= 0


def _coincide(t: float, ref: float) -> bool:
    """Whether ``t`` and ``ref`` are one point for this module: within 10⁻¹⁵ relative to ``ref``
    (a kink found twice by different formulas lands a unit or so in the last place apart)."""
    return abs(t - ref) <= 1e-15 * max(1.0, abs(ref))


def _apart(a: float, inside: list[float], b: float) -> list[float]:
    """The kinks ``inside`` (sorted, in (a, b)) without those within 10⁻¹⁵ relative of the previous
    point kept or of b (the threshold below which :func:`_nested` skips a sub-interval): one kink
    found twice by different formulas, ~10⁻¹⁶ apart, gave ``quad`` a sub-interval it cannot
    subdivide ("extremely bad integrand behavior", the tolerance not reached)."""
    out: list[float] = []
    prev = a
    for q in inside:
        if not _coincide(q, prev) and not _coincide(b, q):
            out.append(q)
            prev = q
    return out


def _nested(p: NumProblem, level: int, prefix: tuple) -> float:
    lo, hi = p.bounds[level]
    if not hi > lo:
        return 0.0
    here = p.here(level)
    tests, reorder = p.tests(level)
    if level not in p.kinks:
        p.kinks[level], p.kink_vary[level] = _kink_functions(p, level)
        if p.folds and level + 2 == len(p.bounds):  # where the fold curve turns, numerically (fold section)
            _add_fold_turns(p, level)
    last = level == len(p.bounds) - 1
    tangent = None if last or p.folds else set()  # (the innermost level has no kinks)
    fixed = p._fixed.get(level)
    if fixed is None:  # the first abscissa: what does not depend on the outer variables, once
        p._fixed_tangent[level] = set()
        fixed = p._fixed[level] = _breakpoints(p, level, prefix, False, p._fixed_tangent[level])
    moving, kinks = _breakpoints(p, level, prefix, True, tangent)
    pts = {lo, hi}
    pts.update(fixed[0])
    pts.update(moving)
    kinks.update(fixed[1])
    if tangent is not None:
        tangent.update(p._fixed_tangent[level])
    pts = sorted(pts)
    eps = EPSABS * 10 ** (len(p.bounds) - 1 - level)  # inner levels tighter than outer ones
    if level == 0:
        eps *= _OUTER[0]  # (1 but inside :func:`outer_tolerance`)
    if p.folds and len(p.bounds) >= 2:  # the fold's rounding: no tighter than its allowance (fold section)
        eps = max(eps, FOLD_EPS * 10 ** (len(p.bounds) - 1 - level))
    total = 0.0
    err = 0.0
    for a, b in zip(pts, pts[1:]):
        if _coincide(b, a):
            continue
        m = 0.5 * (a + b)
        failed = None
        for c in tests:
            if not c.f(*prefix, m) >= 0:  # (NaN >= 0 is false: _holds)
                failed = c
                break
        if failed is not None:
            if reorder and tests[0] is not failed:  # tried first next time (see :meth:`NumProblem.tests`)
                tests.remove(failed)
                tests.insert(0, failed)
            continue
        inside = _apart(a, sorted(q for q in kinks if a < q < b), b)
        if last:
            quick = _first_panel(p.vweight, prefix, a, b, eps) if p.vweight is not None and not inside else None
            if quick is UNVECTORIZABLE:
                p.vweight, quick = None, None
            if quick is not None:
                total += quick[0]
                err += quick[1]
                continue

            def h(t):
                if p.folds and time.process_time() > p.until:
                    raise _fold_timeout(p)
                v = p.weight(*prefix, t)
                if p.folds and not math.isfinite(v) and not all(c.f(*prefix, t) > BOUNDARY for c in here):
                    p.fold_hit = True  # the root at its turning point within rounding (see integrate_problem)
                return v
        else:
            def h(t):
                return _nested(p, level + 1, prefix + (t,))
            if p.folds and len(p.bounds) >= 2:  # an inner integral at the fold within rounding (fold section)
                h = _fold_outer(p, [a, *inside, b], hi - lo, h)
        try:
            if last and p.folds and len(p.bounds) >= 2:  # the fold's 1/√ at the ends substituted (fold section)
                val, e = _fold_innermost(p, level, prefix, a, b, eps, inside, hi - lo)
            elif last and b - a <= NARROW * max(1.0, hi - lo):
                val, e = _narrow(p, h, a, b, eps, inside, level, hi - lo)
            elif tangent and _touches(tangent, a, inside, b):
                val, e = _tangent_quad(h, a, b, eps, inside, tangent, p, level)
            else:
                val, e = _quad(h, a, b, eps, inside, p, level)
        except UndefinedIntegral:
            if b - a > NARROW * max(1.0, hi - lo):
                raise
            p.notes.append(f"left out: sub-intervals of {_name(p, level)} narrower than {NARROW:g} of its range "
                           "where the integrand cannot be evaluated in floating point (rounding at a fold); "
                           "not in the error bound")
            continue
        total += val
        err += e
    if level == 0:
        p.errors.append(err)
    return total


def _near(t: float, tangent: set) -> bool:
    """Whether ``t`` is one of the tangency kinks, (:func:`_coincide`): one kink
    found by two functions (the ball's z = 0 as a box end and as a critical point) a unit in the
    last place apart is kept once, perhaps in its other copy."""
    return any(_coincide(t, q) for q in tangent)


def _touches(tangent: set, a: float, inside: list[float], b: float) -> bool:
    """Whether the sub-interval [a, b] (with its kinks ``inside``) has a tangency kink at an end
    or inside."""
    return _near(a, tangent) or _near(b, tangent) or any(_near(q, tangent) for q in inside)


def _tangent_quad(h: Callable[[float], float], a: float, b: float, eps: float, inside: list[float],
                  tangent: set, p: NumProblem, level: int) -> tuple[float, float]:
    """∫_a^b h (an inner integral) where a tangency kink (:func:`_kink_functions`) ends or lies in
    [a, b]: there a deeper region appears or vanishes (the disc ``y² + z² ≤ a`` at y = ±√a, its
    z-interval [−√(a − y²), √(a − y²)] of zero length) and the inner integral behaves like
    c·√|t − t₀| + smooth: a derivative like 1/√, which Gauss–Kronrod only resolves by halving the
    panel next to t₀ some twenty times at the middle level's tolerance (the nested discs of issue
    13's seed-1 campaign: ~60 panels per middle integral).

    [a, b] is split at its tangency kinks; each piece [c, d] with a tangency end c is integrated in
    u ∈ [0, 1] with t = c + (d − c)·u² (at d: t = d − (d − c)·u²; at both ends: split at the
    midpoint first), dt = 2(d − c)·u du, so that √(t − c) = √(d − c)·u and any half-integer power
    of t − c becomes a polynomial in u: the transformed integrand is smooth and ``quad`` stops
    after a few panels.  The other kinks keep their places (u = √((q − c)/(d − c))).  Pieces without
    a tangency end are integrated as before.

    The bound stays honest: the substitution is an exact change of variables, ∫_c^d h(t) dt =
    ∫_0^1 h(t(u))·t'(u) du for a monotone C¹ map t of [0, 1] onto [c, d], so the transformed
    integral *is* the original number, and ``quad``'s error estimate of it (asked for the same
    absolute and relative tolerance) is an estimate of the same error; each piece's estimate is
    added.  Nothing else changes: where the integrand is not finite at t, it is not finite at
    u(t) (a null set maps to a null set), and an end growth |t − c|^-α becomes u^(1 − 2α), which
    diverges (exponent ≤ −1) exactly when α ≥ 1 — :func:`_quad`'s diagnostics decide the same
    (where ``quad`` does not converge, its measured exponent 2α − 1 is held to the same
    :data:`~.adaptive.GROWTH_SLACK`, i.e. α ≥ 0.99 instead of 0.98 counts as a pole).
    Issue 13 (tang13)."""
    cuts = [a, *(q for q in inside if _near(q, tangent)), b]
    rest = [q for q in inside if not _near(q, tangent)]
    total = err = 0.0
    for c, d in zip(cuts, cuts[1:]):
        at_c, at_d = _near(c, tangent), _near(d, tangent)
        if at_c and at_d:
            m = 0.5 * (c + d)
            ends = [(c, m, True, False), (m, d, False, True)]
        else:
            ends = [(c, d, at_c, at_d)]
        for c, d, at_c, at_d in ends:
            inner = [q for q in rest if c < q < d]
            if at_c or at_d:
                w = d - c
                e0, s = (c, 1.0) if at_c else (d, -1.0)

                def g(u, h=h, e0=e0, s=s, w=w):
                    return h(e0 + s * w * u * u) * (2.0 * w * u)
                inner = sorted(math.sqrt(abs(q - e0) / w) for q in inner)
                val, e = _quad(g, 0.0, 1.0, eps, [u for u in inner if 0.0 < u < 1.0], p, level)
            else:
                val, e = _quad(h, c, d, eps, inner, p, level)
            total += val
            err += e
    return total, err


#: Distances (relative to the variable's range) from a narrow piece's midpoint at which
#: :func:`_narrow` measures the weight's 1/√ growth.
NARROW_PROBES = (1e-4, 1e-6, 1e-8)


def _narrow(p: NumProblem, h: Callable[[float], float], a: float, b: float, eps: float,
            inside: list[float], level: int, span: float) -> tuple[float, float]:
    """∫_a^b h on an innermost piece narrower than :data:`NARROW` of the range: ``quad``, or, where
    it does not converge (two estimates of one root of a guard a few units in the last place
    apart, the weight's 1/√ at that root evaluated from the guard's rounding noise in between), 0
    with a bound.  If |h| ≤ A/√|t − t₀| next to the piece (the fold's growth, :mod:`.fold`), its
    integral is at most 2A·√δ, δ = its width plus the root's uncertainty (:data:`FOLD_END`); A is
    the largest |h(t)|·√|t − m| measured at t = m ± span·:data:`NARROW_PROBES` (m the midpoint),
    finite samples only, and no bound where it more than doubles from the farthest to the nearest
    probe on one side (a growth faster than 1/√).  The bound joins :attr:`NumProblem.narrow_allow` (integrated over the
    outer variables by :func:`integrate_problem`).  With no finite sample, no bound: the
    non-convergence stands."""
    converged, notes = p.converged, len(p.notes)
    val, e = _quad(h, a, b, eps, inside, p, level)
    if p.converged or not converged:
        return val, e
    m = 0.5 * (a + b)
    growth = []
    for side in (-1.0, 1.0):
        series = []
        for k in NARROW_PROBES:
            t = m + side * span * k
            try:
                v = abs(h(t))
            except (UndefinedIntegral, ArithmeticError, ValueError):
                continue
            if math.isfinite(v):
                series.append(v * math.sqrt(abs(t - m)))
        if len(series) >= 2 and series[-1] > 2.0 * series[0]:
            return val, e  # growing faster than 1/√ towards the piece: no bound
        growth += series
    if not growth:
        return val, e
    p.converged = True
    del p.notes[notes:]
    delta = (b - a) + FOLD_END * max(1.0, abs(a), abs(b))
    p.narrow_allow = max(p.narrow_allow, 2.0 * max(growth) * math.sqrt(delta))
    note = (f"left out: pieces of {_name(p, level)} narrower than {NARROW:g} of its range where quadrature "
            "does not converge (a root of a guard found twice within rounding); bounded in the error")
    if note not in p.notes:
        p.notes.append(note)
    return 0.0, 0.0


def integrate_problem(p: NumProblem) -> tuple[float, float]:
    """Value and error estimate of ``∫_bounds Π[conds] · weight``."""
    if any(c.level < 0 and not _holds(c.f()) for c in p.conds):
        return 0.0, 0.0
    if not p.bounds:
        v = p.weight()
        if not math.isfinite(v):
            raise UndefinedIntegral(f"the integrand is undefined ({v}) at the evaluation point")
        return v, 0.0
    p.errors.clear()
    p.narrow_allow = 0.0
    try:
        if p.folds and len(p.bounds) >= 2:  # (one coordinate: the fold is a point, quad resolves it)
            p.until = _fold_deadline()
            p.fold_allow.clear()
            p.fold_extra = 0.0
            try:
                val = _nested(p, 0, ())
            except UndefinedIntegral as exc:
                if not p.fold_hit:
                    raise
                raise FoldUnresolved(_fold_message(p, "met the fold within rounding, where the root cannot be "
                                                      "bracketed, at ever more points")) from exc
        else:
            val = _nested(p, 0, ())
    finally:
        p._moving.clear()  # the roots remembered by outer abscissae (the problem may be kept in _DONE)
    err = sum(p.errors)
    err += p.narrow_allow * math.prod(hi - lo for lo, hi in p.bounds[:-1])  # (every innermost integral)
    if p.folds and len(p.bounds) >= 2:
        err += _fold_allowance(p)  # the ends' rounding at the fold (fold section)
    # Inner levels' errors are not propagated by quad; add a conservative relative allowance.
    return val, err + 1e-10 * (1.0 + abs(val)) * len(p.bounds)

