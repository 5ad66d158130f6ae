"""Issue 18: the 3-D folium ``[x³ − xy + y³ + z³ − zy − a ≥ 0]``, a delta through an implicit root whose
turning points ±√(y/3) move with y and merge at the cusp y = 0 (roots10).

z is split at ``sign_change_k(3z² − y)``, so each branch's guard is not a polynomial in (x, y): the
exact engine's quadrature splits it at its factors' critical points in y (central differences: the
implicit function theorem's derivative of a turning point is wrong where it does not exist) and at
the jump y = 0 where the turning points appear (``quadrature.foldcurve._bracket_jumps``), finds the fold
curve's turns as outer kinks (``quadrature.foldcurve._add_fold_guards``).  Checked against an independent
reference, written out here with no engine involved: dV/da = −∫dy ∫dx Σ 1/|3z² − y| over the roots
z ∈ [−1, 1] of z³ − yz = a − y³ − (x³ − yx) (trigonometric / Cardano roots, the kinks of the inner
integrand as scipy ``quad`` breakpoints); on [−1, 1]³ it agrees with the five-point difference of
the value's nested quadrature to 5·10⁻⁸ (bench/history/2026-11-27.md#roots10).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import sympy as sp
from scipy import integrate, optimize

from langur import frontend, operational
from langur.ddenote import ddenote_program
from langur.implicit import ImplicitRootFn
from langur.symbolic.quadrature import deltaproblems, pieceproblems
from langur.symbolic.quadrature.foldcurve import _add_fold_turns, _bracket_jumps
from langur.symbolic.quadrature.kinks import _kink_functions
from langur.symbolic.quadrature.nested import _nested

A = 0.1
XS, YS = (0.3, 0.7), (-0.2, 0.6)  # around the cusp (x, y) = (a^⅓, 0) and the turn near (0.5635, 0.43)
BOX = ("param a = 0.1\n"
       "int ([0.3, 0.7], [-0.2, 0.6], [-1, 1]) [x^3 - x*y + y^3 + z^3 - z*y - a >= 0] d(x, y, z)\n")


def cubic_roots(y, c):
    """The real roots of z³ − yz = c: trigonometric (three) or Cardano (one), Newton-polished."""
    if y > 0:
        t = math.sqrt(y / 3)
        m = 2 * t**3
        if abs(c) < m:
            th = math.acos(c / m) / 3
            return [2 * t * math.cos(th - 2 * math.pi * k / 3) for k in range(3)]
    s = math.sqrt(max(c * c / 4 - y**3 / 27, 0.0))
    r = float(np.cbrt(c / 2 + s) + np.cbrt(c / 2 - s))
    d = 3 * r * r - y
    return [r - (r**3 - y * r - c) / d if d != 0 else r]


def kinks(y):
    """Where |{z ∈ [−1, 1] : z³ − yz ≥ c}| is not smooth in c: g(±1) and ±2(y/3)^{3/2} for y > 0."""
    return [1 - y, y - 1] + ([2 * (y / 3) ** 1.5, -2 * (y / 3) ** 1.5] if y > 0 else [])


def density(y, c):
    return sum(1 / abs(3 * z * z - y) for z in cubic_roots(y, c) if -1 <= z <= 1)


def inner(y, tol):
    c = A - y**3
    pts = {r.real for k in kinks(y) for r in np.roots([1, 0, -y, -(c - k)])
           if abs(r.imag) < 1e-7 and XS[0] < r.real < XS[1]}
    if y > 0:
        pts |= {s for s in (-math.sqrt(y / 3), math.sqrt(y / 3)) if XS[0] < s < XS[1]}
    return integrate.quad(lambda x: density(y, c - (x**3 - y * x)), *XS, points=sorted(pts) or None,
                          limit=400, epsabs=tol, epsrel=tol)[0]


def outer_kinks():
    """y where the inner integrand's kinks merge or reach the x box (a − y³ = k₁ + k₂, k₁ a kink of
    the z-length, k₂ a critical value of x³ − yx or its value at a box end), and the cusp y = 0."""
    def ks(y):
        crit = [2 * (y / 3) ** 1.5, -2 * (y / 3) ** 1.5] if y > 0 else [math.nan, math.nan]
        return kinks(y)[:2] + crit, crit + [xe**3 - y * xe for xe in XS]
    out = {0.0}
    grid = np.linspace(*YS, 2001)
    for i in range(4):
        for j in range(4):
            def f(y, i=i, j=j):
                k1, k2 = ks(y)
                return A - y**3 - k1[i] - k2[j]
            vals = [f(y) for y in grid]
            for y0, y1, f0, f1 in zip(grid, grid[1:], vals, vals[1:]):
                if math.isfinite(f0) and math.isfinite(f1) and f0 * f1 < 0:
                    out.add(optimize.brentq(f, y0, y1, xtol=1e-15))
    return sorted(p for p in out if YS[0] < p < YS[1])


def reference(tol=1e-10):
    return -integrate.quad(lambda y: inner(y, tol), *YS, points=outer_kinks(), limit=800,
                           epsabs=10 * tol, epsrel=10 * tol)[0]


def inner_in_y(x, tol=1e-11):
    """The reference's integrand the other way round: ∫ Σ 1/|3z² − y| dy over YS at one x, split at
    y = 0 and where a − x³ + xy − y³ reaches a kink of the z-length."""
    def c(y):
        return A - x**3 + x * y - y**3
    grid = np.linspace(*YS, 4001)
    pts = {0.0}
    for i in range(4):
        def f(y, i=i):
            ks = kinks(y)
            return c(y) - ks[i] if i < len(ks) else math.nan
        vals = [f(y) for y in grid]
        for y0, y1, f0, f1 in zip(grid, grid[1:], vals, vals[1:]):
            if math.isfinite(f0) and math.isfinite(f1) and f0 * f1 < 0:
                pts.add(optimize.brentq(f, y0, y1, xtol=1e-15))
    cuts = sorted({*YS, *(q for q in pts if YS[0] < q < YS[1])})
    return sum(integrate.quad(lambda y: density(y, c(y)), lo, hi, limit=200, epsabs=tol, epsrel=tol)[0]
               for lo, hi in zip(cuts, cuts[1:]))


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_folium_inner_integrals_and_outer_kinks(monkeypatch):
    """The three branch problems' inner integrals over y, summed, on both sides of the cusp x = a^⅓
    and of the fold curve's turn, against the reference; the cusp and the turn among the outer kinks.
    (The problems are built, not integrated: a few seconds.)"""
    problems = []
    for front in (pieceproblems, deltaproblems):
        monkeypatch.setattr(front, "integrate_problem", lambda p: (problems.append(p), (0.0, 0.0))[1])
    ddenote_program(frontend.load_text(BOX, "folium_box.lgr").program, {"a": A}, {"a": 1})
    folds = [p for p in problems if p.folds]
    assert len(folds) == 3
    kinks0 = set()
    for p in folds:
        p.until = math.inf
        p.kinks[0], p.kink_vary[0] = _kink_functions(p, 0)
        _add_fold_turns(p, 0)
        kinks0 |= {r for _, roots in p.kinks[0] if roots is not None for r in roots()}
    cusp = A ** (1 / 3)
    assert min(abs(k - cusp) for k in kinks0) < 1e-8, sorted(kinks0)
    # the turn: where the fold 3z² = y on the middle branch's lower end reaches a critical point in y
    turn = [k for k in kinks0 if 0.56 < k < 0.57]
    assert turn, sorted(kinks0)
    for x in (cusp - 1e-3, cusp + 1e-3, 0.5, turn[0] - 1e-3, turn[0] + 1e-3, 0.68):
        engine = sum(_nested(p, 1, (x,)) for p in folds)
        assert abs(-engine - inner_in_y(x)) < 1e-7, (x, engine, inner_in_y(x))


#: A smaller box for the whole value (1.5 CPU s, against about 30 for BOX): it still holds the cusp
#: (a^⅓ ≈ 0.4642, 0), the fold curve's turn near (0.5635, 0.43), and z's whole interval.
SMALL = ((0.45, 0.58), (-0.05, 0.45))


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_folium_across_its_cusp_and_fold_turn_has_a_value(monkeypatch):
    (x0, x1), (y0, y1) = SMALL
    monkeypatch.setitem(globals(), "XS", SMALL[0])  # the reference integrates over XS × YS
    monkeypatch.setitem(globals(), "YS", SMALL[1])
    text = (f"param a = 0.1\nint ([{x0}, {x1}], [{y0}, {y1}], [-1, 1]) "
            "[x^3 - x*y + y^3 + z^3 - z*y - a >= 0] d(x, y, z)\n")
    loaded = frontend.load_text(text, "folium_small.lgr")
    r = ddenote_program(loaded.program, {"a": A}, {"a": 1})
    assert r.method == "quadrature" and 0 < r.error < 1e-4, (r.method, r.error)
    ref = reference()
    assert abs(float(r.value) - ref) <= r.error + 1e-8, (float(r.value), r.error, ref)
    mc = operational.estimate_derivative(loaded, {"a": A}, {"a": 1}, samples=20_000, seed=1)
    assert abs(mc.value - float(r.value)) <= 5 * mc.stderr + 1e-9, (mc.value, mc.stderr, float(r.value))


def test_turning_points_appear_where_their_equation_has_a_double_root():
    """``sign_change_0(3w² − y)`` on [−1, 1] exists for 0 < y < 3: the guard jumps at y = 0 (in the
    box [−1, 1]), not at y = 3 (outside), and an unindexed root gives no jump."""
    y, w = sp.symbols("y w", real=True)
    turning = ImplicitRootFn(sp.Lambda(w, 3 * w**2 - y), 0, -1, 1, 0, 2)
    assert _bracket_jumps(y**3 - y * turning, y, -1.0, 1.0, {}) == [0.0]
    assert _bracket_jumps(y - turning, y, -1.0, 4.0, {}) == [0.0, 3.0]
    root = ImplicitRootFn(sp.Lambda(w, w**3 + w - y), 0, -1, 1, -1, 0)
    assert _bracket_jumps(root - y, y, -1.0, 1.0, {}) == []
