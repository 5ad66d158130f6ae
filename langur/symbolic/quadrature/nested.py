"""The nested integral of one problem (paper §8.2: ⟦p⟧ = ∫_box Π[conditions] · weight at the
parameters' values): at each level the range is split at its breakpoints, the conditions tested at
each sub-interval's midpoint, and the inner integral integrated by :func:`_quad` (or one
Gauss–Kronrod panel, or the fold's substitution for a delta through an implicit root).
"""

from __future__ import annotations

import math
import time

from langur.symbolic.quadrature.adaptive import _name, _quad
from langur.symbolic.quadrature.fold import (
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
    fixed = p._fixed.get(level)
    if fixed is None:  # the first abscissa: what does not depend on the outer variables, once
        fixed = p._fixed[level] = _breakpoints(p, level, prefix, False)
    moving, kinks = _breakpoints(p, level, prefix, True)
    pts = {lo, hi}
    pts.update(fixed[0])
    pts.update(moving)
    kinks.update(fixed[1])
    pts = sorted(pts)
    last = level == len(p.bounds) - 1
    eps = EPSABS * 10 ** (len(p.bounds) - 1 - level)  # inner levels tighter than outer ones
    if level == 0:
        eps *= _OUTER[0]  # (1 but inside :func:`outer_tolerance`)
    if p.folds and len(p.bounds) >= 2:  # the fold's rounding: no tighter than its allowance (fold section)
        eps = max(eps, FOLD_EPS * 10 ** (len(p.bounds) - 1 - level))
    total = 0.0
    err = 0.0
    for a, b in zip(pts, pts[1:]):
        if b - a <= 1e-15 * max(1.0, abs(a)):
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
        inside = sorted(q for q in kinks if a < q < b)
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
    if p.folds and len(p.bounds) >= 2:
        err += _fold_allowance(p)  # the ends' rounding at the fold (fold section)
    # Inner levels' errors are not propagated by quad; add a conservative relative allowance.
    return val, err + 1e-10 * (1.0 + abs(val)) * len(p.bounds)

