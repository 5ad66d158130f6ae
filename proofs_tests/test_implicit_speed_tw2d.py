"""The per-point root solve's fast path (issue 15/18: scipy's Brent routine called directly, no
closure per root, no ``np.ndim`` per scalar argument) returns bitwise the roots of the slow path
it replaced (``so.brentq`` on a closure), on random points of turning2d's folium."""

from __future__ import annotations

import math
import random

import numpy as np
import scipy.optimize as so
import sympy as sp

from langur.implicit import implicit_root, lambdified
from langur.implicit.solvers import bracketed_root, double_root


def _slow_double_root(f, target, lo, hi):
    """``double_root`` as it was: the public ``so.brentq`` on a closure of ``f``."""
    try:
        a, b = float(lo), float(hi)
        fa, fb = float(f(a)) - target, float(f(b)) - target
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        return math.nan
    if fa == 0:
        return a
    if fb == 0:
        return b
    if math.isnan(fa) or math.isnan(fb) or not (fa < 0) ^ (fb < 0):
        return math.nan

    def g(z):
        v = float(f(z)) - target
        if math.isnan(v):
            raise ValueError
        return v
    try:
        return so.brentq(g, a, b, xtol=1e-300, rtol=4 * np.finfo(float).eps)
    except (ValueError, ZeroDivisionError, OverflowError, TypeError, RuntimeError):
        return bracketed_root(f, target, lo, hi)


def _slow_path(f, target, lo, hi, args=()):
    return _slow_double_root(lambda z: f(z, *args), target, lo, hi)


def _folium(y, u, a):
    return y**3 - y * u + u**3 - a


def _same(p, q) -> bool:
    return (math.isnan(p) and math.isnan(q)) or p == q


def test_double_root_is_bitwise_the_slow_path_on_random_points():
    rng = random.Random(15)
    for _ in range(3000):
        u, a, t = rng.uniform(-1, 1), rng.uniform(-0.5, 1.5), rng.uniform(-1, 1)
        lo, hi = sorted(rng.uniform(-1.2, 1.2) for _ in range(2))
        fast = double_root(_folium, t, lo, hi, (u, a))
        slow = _slow_path(_folium, t, lo, hi, (u, a))
        assert _same(fast, slow), (u, a, t, lo, hi, fast, slow)
    # NaN near the root: Brent's method stops, both fall back to bisection, the same way
    f = lambda z, c: math.nan if abs(z - c - 1) < 0.2 else math.log(z - c)  # noqa: E731
    for c in (0.0, 0.1, 0.37):
        assert _same(double_root(f, 0.0, c + 0.31, 5.0, (c,)), _slow_path(f, 0.0, c + 0.31, 5.0, (c,)))


def test_lambdified_roots_scalar_and_array_are_the_slow_path(monkeypatch):
    y, u, a = sp.symbols("y u a", real=True)
    us = np.random.default_rng(18).uniform(-1, 1, 300)
    # the unique root of a monotone piece (y in [0.6, 1] for u < 1: ∂/∂y = 3y² − u > 0 there), and
    # the k-th sign change of 3y² − u (turning2d's split: brackets certified, then Brent's method)
    roots = [implicit_root(_folium(y, u, a), y, sp.Integer(0), sp.Rational(3, 5), sp.Integer(1))]
    roots += [implicit_root(3 * y**2 - u, y, sp.Integer(0), sp.Integer(-1), sp.Integer(1), index=k, of=2) for k in (0, 1)]
    fns = [sp.lambdify([u, a], r, modules="numpy") for r in roots]

    def solve():
        return [(f(us, 0.3), [float(f(float(v), 0.3)) for v in us]) for f in fns]
    fast = solve()
    monkeypatch.setattr(lambdified, "double_root", _slow_path)
    slow = solve()
    for (fa, fs), (sa, ss) in zip(fast, slow):
        assert all(_same(p, q) for p, q in zip(list(fa) + fs, list(sa) + ss))
    for k, (arr, _) in enumerate(fast[1:]):  # and they are the roots: ∓sqrt(u/3), else the domain's end
        want = np.where(us > 0, (-1) ** (k + 1) * np.sqrt(np.maximum(us, 0) / 3), 1.0)
        assert np.allclose(arr, want, rtol=0, atol=1e-14)
    r, none = fast[0][0], np.isnan(fast[0][0])  # NaN: no root on the piece (no sign change there)
    assert 0 < none.sum() < len(us) and np.allclose(_folium(r[~none], us[~none], 0.3), 0, rtol=0, atol=1e-14)
    assert np.all(_folium(0.6, us[none], 0.3) * _folium(1.0, us[none], 0.3) > 0)
