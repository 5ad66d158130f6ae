"""Issue 18's conditions in a three-variable program: a cubic with two turning points (x), a sine
whose turning points move with the parameter (y) and a window around a moving point (z, a kink),
all in one integrand whose weight couples the three variables.

    V(a) = ∫∫∫ [x³ − x − a ≥ 0]·[sin(5·a·y) − 0.5 ≥ 0]·[|z − a| ≤ 0.2]·(1 + x·y·z) d(x, y, z)

The reference is independent of both engines: each one-variable set is found by a fine grid and
scipy's ``brentq`` (no implicit roots, no certification), ``V = |X|·|Y|·|Z| + (∫_X x)(∫_Y y)(∫_Z z)``
in closed form on those intervals, and dV/da by central differences (h = 1e−5).  Both engines must
agree with it (the exact one within its error bound, Monte Carlo within 5 standard errors) at
a = 0.35 (the cubic has three roots in the box; the sine one, its turning point π/(10a) inside),
a = 0.6 (the cubic one root; the sine two, on both sides of its turning point) and a = 0.06
(sin(0.3·y) < 0.5 on [−1, 1]: no roots at all, the window clipped at z = 0; the derivative is 0).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from langur import frontend
from langur.ddenote import ddenote_program
from langur.operational import estimate_derivative

TEXT = ("param a = 0.5\nint ([-1.5, 1.5], [-1, 1], [0, 1]) [x^3 - x - a >= 0] * [sin(5 * a * y) - 0.5 >= 0] * "
        "[abs(z - a) <= 0.2] * (1 + x * y * z) d(x, y, z)\n")


def _set(g, lo, hi, n=20001):
    """The intervals of [lo, hi] where g ≥ 0: sign changes on a fine grid, each refined by brentq."""
    xs = np.linspace(lo, hi, n)
    vs = np.array([g(x) for x in xs])
    cuts = [lo]
    for i in range(n - 1):
        if (vs[i] >= 0) != (vs[i + 1] >= 0):
            cuts.append(brentq(g, xs[i], xs[i + 1], xtol=1e-15, rtol=1e-15))
    cuts.append(hi)
    return [(p, q) for p, q in zip(cuts, cuts[1:]) if g(0.5 * (p + q)) >= 0]


def _moments(intervals):
    return sum(q - p for p, q in intervals), sum((q * q - p * p) / 2 for p, q in intervals)


def value(a):
    x0, x1 = _moments(_set(lambda x: x**3 - x - a, -1.5, 1.5))
    y0, y1 = _moments(_set(lambda y: math.sin(5 * a * y) - 0.5, -1.0, 1.0))
    z0, z1 = _moments([(max(0.0, a - 0.2), min(1.0, a + 0.2))] if a - 0.2 < 1 and a + 0.2 > 0 else [])
    return x0 * y0 * z0 + x1 * y1 * z1


def derivative(a, h=1e-5):
    return (value(a + h) - value(a - h)) / (2 * h)


@pytest.fixture(scope="module")
def program():
    return frontend.load_text(TEXT, "three.lgr").program


def test_the_reference_sets_have_the_intended_shapes():
    # the cubic has three roots in the box at a = 0.35 (two intervals) and one at a = 0.6; the
    # sine's set ends at the box at a = 0.35 and between two roots around its turning point
    # 5·a·y = π/2 at a = 0.6; it is empty at a = 0.06
    assert len(_set(lambda x: x**3 - x - 0.35, -1.5, 1.5)) == 2
    assert len(_set(lambda x: x**3 - x - 0.6, -1.5, 1.5)) == 1
    ys = _set(lambda y: math.sin(1.75 * y) - 0.5, -1.0, 1.0)
    assert len(ys) == 1 and ys[0][0] < math.pi / 3.5 < ys[0][1] == 1.0
    ys = _set(lambda y: math.sin(3 * y) - 0.5, -1.0, 1.0)
    assert len(ys) == 1 and 0 < ys[0][0] < math.pi / 6 < ys[0][1] < 1.0
    assert _set(lambda y: math.sin(0.3 * y) - 0.5, -1.0, 1.0) == []


@pytest.mark.parametrize("a", [0.35, 0.6, 0.06])
def test_both_engines_match_finite_differences_of_the_reference(program, a):
    fd = derivative(a)
    exact = ddenote_program(program, {"a": a}, {"a": 1})
    assert abs(float(exact.value) - fd) <= 1e-6 * (1 + abs(fd)) + float(exact.error or 0), (a, exact.value, fd)
    mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=20000, seed=5)
    assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-6 * (1 + abs(fd)), (a, mc.value, mc.stderr, fd)
    if a == 0.06:
        assert fd == 0 and exact.value == 0 and mc.value == 0
