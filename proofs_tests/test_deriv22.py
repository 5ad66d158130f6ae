"""deriv22 (issue 15): the grid search of :func:`langur.symbolic.quadrature.roots._roots` stops its
bisection on a condition's state (definedness or sign) once the bracket's ends are neighbouring
doubles (its midpoint is one of them): every further step evaluated the condition at that same
point and kept the bracket.  The roots found are those of the unchanged search, written out here
as it was (80 halvings, every one evaluated), on conditions with definedness boundaries (square
roots of affine and quadratic functions: NaN on part of the range), sign changes the grid sees,
and ends at or across 0."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from scipy import optimize as so

from langur.symbolic.quadrature import roots


def _unchanged(g, lo: float, hi: float) -> list[float]:
    """``_roots`` as it was before deriv22 (the bisection always takes its 80 steps)."""
    xs = np.linspace(lo, hi, roots.GRID + 1).tolist()
    vals = [g(x) for x in xs]
    out = roots._hidden_pairs(g, xs, vals)
    for i in range(roots.GRID):
        a, b, fa, fb = xs[i], xs[i + 1], vals[i], vals[i + 1]
        if fa == 0.0 and i > 0:
            out.append(a)
        sa, sb = roots._state(fa), roots._state(fb)
        if sa == sb:
            continue
        if sa != 0 and sb != 0 and fa != 0.0 and fb != 0.0:
            try:
                out.append(so.brentq(g, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps))
                continue
            except (ValueError, RuntimeError):
                pass
        for _ in range(80):
            m = 0.5 * (a + b)
            if roots._state(g(m)) == sa:
                a = m
            else:
                b = m
        out.append(0.5 * (a + b))
    return out


class _Counted:
    """``f`` with a count of its evaluations."""

    def __init__(self, f):
        self.f, self.calls = f, 0

    def __call__(self, x):
        self.calls += 1
        return self.f(x)


def _sqrt_or_nan(v: float) -> float:
    return math.sqrt(v) if v >= 0 else math.nan


def _reciprocal(v: float) -> float:
    return math.inf if v == 0 else 1.0 / v


def _conditions(rng: random.Random):
    """Conditions with definedness boundaries (NaN beyond them) and sign changes."""
    r, s = rng.uniform(-1, 1), rng.uniform(-1, 1)
    k = rng.uniform(0.1, 3)
    c = rng.uniform(-0.5, 0.5)
    return [
        lambda x: _sqrt_or_nan(x - r) - c,                     # defined from r on, a sign change maybe
        lambda x: _sqrt_or_nan(k * (x - r) * (s - x)) - 0.1,    # defined between r and s
        lambda x: _sqrt_or_nan(r - x) * k - c,                  # defined up to r
        lambda x: _reciprocal(_sqrt_or_nan(x - r)) - k,         # defined from r on (a pole at r)
        lambda x: _sqrt_or_nan(x * x - r * r) - abs(c),         # two boundaries, at ±r
    ]


@pytest.mark.parametrize("seed", range(8))
def test_the_same_roots_as_the_unchanged_search(seed):
    rng = random.Random(seed)
    for lo, hi in [(-1.0, 1.0), (-2.0, 0.5), (0.0, 1.0), (-1.0, 0.0), (1e-3, 2e-3)]:
        for g in _conditions(rng):
            got = roots._roots(g, lo, hi)
            want = _unchanged(g, lo, hi)
            assert [x.hex() for x in got] == [x.hex() for x in want]


def test_a_boundary_at_a_node_and_at_zero():
    # definedness from 0 on (an end of the bracket at 0: the bisection runs to the signed zeros)
    for g in (lambda x: _sqrt_or_nan(x), lambda x: _sqrt_or_nan(-x), lambda x: _sqrt_or_nan(x) - 0.25):
        for lo, hi in [(-1.0, 1.0), (-0.7, 0.3), (-1e-300, 1e-300)]:
            assert [t.hex() for t in roots._roots(g, lo, hi)] == [t.hex() for t in _unchanged(g, lo, hi)]


def test_the_bisection_stops_at_neighbouring_doubles():
    # √(x − 0.3): defined from 0.3 on; the grid on [-1, 1] has its nodes 0.05 apart, and a bracket
    # 0.05 wide reaches neighbouring doubles near 0.3 after ~52 halvings, not 80
    r = 0.3
    old, new = _Counted(lambda x: _sqrt_or_nan(x - r)), _Counted(lambda x: _sqrt_or_nan(x - r))
    want = _unchanged(old, -1.0, 1.0)
    got = roots._roots(new, -1.0, 1.0)
    assert got == want
    (t,) = got
    assert abs(t - r) <= 2 * math.ulp(r)  # the boundary, to the last place or so
    assert new.calls < old.calls - 20  # (80 halvings before, about 52 now)
