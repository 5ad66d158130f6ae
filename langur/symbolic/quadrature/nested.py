"""The nested integral of one problem (paper §8.2: ⟦p⟧ = ∫_box Π[conditions] · weight at the
parameters' values): at each level the range is split at its breakpoints, the conditions tested at
each sub-interval's midpoint, and the inner integral integrated by :func:`_quad` (or one
Gauss–Kronrod panel, or the fold's substitution for a delta through an implicit root).
"""

from __future__ import annotations

import math
import time
from typing import Callable

import numpy as np

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
from langur.symbolic.quadrature.problem import MOST_LEVELS, NumProblem, TooManyLevels, UndefinedIntegral
from langur.symbolic.quadrature.rounding import REACH, end_allowance, flat_size, uncertainty
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
        p.round_last[level] = 0.0  # (read by the outer level, :func:`_stepped`)
        return 0.0
    here = p.here(level)
    tests, reorder = p.tests(level)
    if level not in p.kinks:
        p.kinks[level], p.kink_vary[level] = _kink_functions(p, level)
        if p.folds and level + 2 == len(p.bounds):  # where the fold curve turns, numerically (fold section)
            _add_fold_turns(p, level)
    last = level == len(p.bounds) - 1
    tangent = None if last or p.folds else set()  # (the innermost level has no kinks)
    fixed = p.fixed.get(level)
    if fixed is None:  # the first abscissa: what does not depend on the outer variables, once
        p.fixed_tangent[level] = set()
        fixed = p.fixed[level] = _breakpoints(p, level, prefix, False, p.fixed_tangent[level])
    moving, kinks = _breakpoints(p, level, prefix, True, tangent)
    owners = {**fixed[0]}  # breakpoint -> the conditions it is a root of (:func:`~.rounding.uncertainty`)
    for t, own in moving.items():
        owners[t] = owners[t] | own if t in owners else own
    pts = {lo, hi}
    pts.update(owners)
    spread = p.spread.get(level)
    if spread:  # a range wide for its weight: breakpoints where the mass may hide (:mod:`.wide`)
        p.wide = True
        for t in spread:
            pts.add(t)
            owners.setdefault(t, frozenset())  # (a root of no condition: only its own rounding)
    kinks.update(fixed[1])
    if tangent is not None:
        tangent.update(p.fixed_tangent[level])
    pts = sorted(pts)
    eps = EPSABS * 10 ** (len(p.bounds) - 1 - level)  # inner levels tighter than outer ones
    if level == 0:
        eps *= _OUTER[0]  # (1 but inside :func:`outer_tolerance`)
    if p.folds and len(p.bounds) >= 2:  # the fold's rounding: no tighter than its allowance (fold section)
        eps = max(eps, FOLD_EPS * 10 ** (len(p.bounds) - 1 - level))
    total = 0.0
    err = 0.0
    allow = 0.0  # the breakpoints' rounding times the integrand next to them (:mod:`.rounding`)
    deltas: dict = {}  # breakpoint -> its uncertainty (each shared by two sub-intervals)
    seen = [0.0]  # the largest finite |integrand| sampled on the current sub-interval
    for a, b in zip(pts, pts[1:]):
        if _coincide(b, a):
            if b > a and not p.folds:
                allow += _dropped(p, level, prefix, a, b, hi - lo, deltas, owners)
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
        seen[0] = 0.0
        if last:
            quick = _first_panel(p.vweight, prefix, a, b, eps, seen) if p.vweight is not None and not inside else None
            if quick is UNVECTORIZABLE:
                p.vweight, quick = None, None
            if quick is not None:
                total += quick[0]
                err += quick[1]
                allow += _ends(p, level, prefix, a, b, hi - lo, seen[0], eps * max(1.0, abs(quick[0])), deltas, owners)
                continue

            def h(t):
                if p.folds and time.process_time() > p.until:
                    raise _fold_timeout(p)
                v = p.weight(*prefix, t)
                if p.folds and not math.isfinite(v) and not all(c.f(*prefix, t) > BOUNDARY for c in here):
                    p.fold_hit = True  # the root at its turning point within rounding (see integrate_problem)
                size = abs(v)
                if size > seen[0] and size != math.inf:  # (NaN > s is false)
                    seen[0] = size
                return v
        else:
            inner: list = []  # (t, the inner integral's rounding allowance at t)

            def h(t, inner=inner):
                v = _nested(p, level + 1, prefix + (t,))
                inner.append((t, p.round_last[level + 1]))
                size = abs(v)
                if size > seen[0] and size != math.inf:
                    seen[0] = size
                return v
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
        allow += _ends(p, level, prefix, a, b, hi - lo, seen[0], eps * max(1.0, abs(val)), deltas, owners)
        if not last:  # the inner integrals' allowances, integrated over [a, b]
            allow += _stepped(inner, [a, *inside, b])
    if level == 0:
        p.errors.append(err + allow)
    else:
        p.round_last[level] = allow
    return total


def _stepped(samples: list, cuts: list[float]) -> float:
    """∫ of a nonnegative function known at the abscissae of ``samples`` (``(t, value)``, as an
    outer level's ``quad`` asked for them) over [cuts[0], cuts[-1]], by a step rule that never
    reaches across a cut (an outer kink, where an inner region and its allowance appear): within
    each cell each gap between neighbouring samples counts the larger of its two values, and the
    cell's ends the value of the sample nearest to them (:func:`~.fold._fold_allowance`'s rule,
    cell by cell)."""
    if not samples:
        return 0.0
    samples.sort()
    out = 0.0
    i, n = 0, len(samples)
    for lo, hi in zip(cuts, cuts[1:]):
        cell = []
        while i < n and samples[i][0] <= hi:
            if samples[i][0] >= lo:
                cell.append(samples[i])
            i += 1
        if not cell:
            continue
        out += (cell[0][0] - lo) * cell[0][1] + (hi - cell[-1][0]) * cell[-1][1]
        out += sum((t1 - t0) * max(v0, v1) for (t0, v0), (t1, v1) in zip(cell, cell[1:]))
    return out


def _dropped(p: NumProblem, level: int, prefix: tuple, a: float, b: float, span: float, deltas: dict,
             owners: dict) -> float:
    """What leaving out [a, b] (two breakpoints within :func:`_coincide`, not integrated) may
    change: nothing where a condition fails at its midpoint m, else (b − a + δ_a + δ_b)·2·|h| when
    the integrand is bounded and nearly constant at m and at m ± D, D = :data:`~.rounding.REACH`
    times the larger of the width and the ends' rounding (:func:`~.rounding.flat_size`): the sliver
    ``θ − 10⁻¹⁵ ≤ x ≤ θ`` under the weight 10¹⁵ is all of a delta piece.  0 where it is not (left out
    as before, no bound): a piece a unit in the last place wide next to the island's 1/√R reads
    |h(m)| = 4.5·10¹⁵ from R's rounding noise, a size that says nothing about its integral."""
    m = 0.5 * (a + b)
    if not all(c.f(*prefix, m) >= 0 for c in p.here(level)):
        return 0.0
    ds = _rounding(p, level, prefix, (a, b), span, deltas, owners)
    reach = REACH * max(b - a, ds[0], ds[1], 4.0 * math.ulp(m))
    try:
        lo, hi = p.bounds[level]  # (the samples inside the range, as :func:`~.rounding.end_allowance`'s;
        size = flat_size(_sampler(p, level, prefix)([max(lo, m - reach), min(hi, m + reach), m]))  # m last: round_last)
    except (UndefinedIntegral, ArithmeticError, ValueError, TypeError, AttributeError):
        return 0.0
    if size is None:
        return 0.0
    inner = 0.0 if level == len(p.bounds) - 1 else p.round_last[level + 1]
    return (size + inner) * 2.0 * (b - a + ds[0] + ds[1])


def _ends(p: NumProblem, level: int, prefix: tuple, a: float, b: float, span: float, size: float, tol: float,
          deltas: dict, owners: dict) -> float:
    """The change of ∫_a^b if its ends move by their rounding (:func:`~.rounding.uncertainty`,
    remembered in ``deltas``; ``owners``: the conditions each breakpoint is a root of, every
    condition at the range's ends), where the integrand is bounded next to them
    (:func:`~.rounding.end_allowance`, ``size`` the largest |integrand| sampled on [a, b], ``tol``
    the tolerance ``quad`` was asked for there); 0 where
    nothing was sampled (the fold's substitution keeps its own allowance, :func:`_fold_innermost`)."""
    if not size > 0.0:
        return 0.0
    ds = _rounding(p, level, prefix, (a, b), span, deltas, owners)
    return end_allowance(ds, a, b, p.bounds[level], size, tol, _sampler(p, level, prefix))


def _rounding(p: NumProblem, level: int, prefix: tuple, ends: tuple[float, float], span: float, deltas: dict,
              owners: dict) -> tuple[float, float]:
    """The two ends' rounding (:func:`~.rounding.uncertainty`), remembered in ``deltas`` (a
    breakpoint ends two sub-intervals)."""
    out = []
    for t in ends:
        d = deltas.get(t)
        if d is None:
            d = deltas[t] = uncertainty(p, level, prefix, t, span, owners.get(t))
        out.append(d)
    return out[0], out[1]


def _sampler(p: NumProblem, level: int, prefix: tuple) -> Callable[[list[float]], list[float]]:
    """The integrand of ``level`` at a few abscissae (:func:`~.rounding.end_allowance`'s local
    samples): the inner integrals, or the weight (vectorized when it is: the scalar weight may not
    be compiled yet)."""
    if level < len(p.bounds) - 1:
        return lambda ts: [_nested(p, level + 1, prefix + (t,)) for t in ts]
    if p.vweight is not None:
        def vectorized(ts):
            with np.errstate(all="ignore"):
                y = np.asarray(p.vweight(*prefix, np.array(ts)), dtype=float)
            return [float(v) for v in np.broadcast_to(y, (len(ts),))]
        return vectorized
    return lambda ts: [p.weight(*prefix, t) for t in ts]


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
    if len(p.bounds) > MOST_LEVELS:
        raise TooManyLevels(f"nested quadrature over {len(p.bounds)} variables is out of reach (at least "
                            f"21^{len(p.bounds)} = {21.0 ** len(p.bounds):.1e} evaluations of the integrand; at most "
                            f"{MOST_LEVELS} variables are tried)")
    p.errors.clear()
    p.narrow_allow = 0.0
    p.round_last.clear()
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
        p.forget_moving()  # (the problem may be kept in _DONE)
    err = sum(p.errors)
    err += p.narrow_allow * math.prod(hi - lo for lo, hi in p.bounds[:-1])  # (every innermost integral)
    if p.folds and len(p.bounds) >= 2:
        err += _fold_allowance(p)  # the ends' rounding at the fold (fold section)
    # Inner levels' errors are not propagated by quad; add a conservative relative allowance.
    return val, err + 1e-10 * (1.0 + abs(val)) * len(p.bounds)

