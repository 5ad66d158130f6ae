"""Issue 18: a delta through an implicit root across a fold curve, in two zero-set coordinates (roots9).

``[x³ − x + y³ − y + z³ − z − a ≥ 0]`` is split along z at the turning points ±1/√3 of z³ − z; the
delta's weight 1/|∂f/∂z(z*)| over (x, y) grows like 1/√ at the fold curve where z* reaches a
turning point, and logarithmically across the points where that curve turns (∂f/∂y = 0 on it).
The exact engine's quadrature substitutes t = c + (d − c)(3s² − 2s³) on each innermost interval
(the 1/√ at a fold end becomes bounded), leaves out only outer abscissae within 10⁻¹² of the
curve's turning points (kinks), and adds the fold ends' rounding to its error bound
(``quadrature.fold._fold_innermost``), the curve's turns found numerically (``_add_fold_turns``).  Checked here against an independent reference: V(a) =
∫∫ L(a − g(x) − g(y)) dx dy with g(t) = t³ − t and L(c) = |{z ∈ [−1, 1] : g(z) ≥ c}| from the
cubic's trigonometric roots (nested scipy ``quad`` with the kinks as breakpoints), dV/da by the
five-point central difference at h = 4·10⁻³ (its error measured at ~3·10⁻⁹ against h = 10⁻³ and
tighter tolerances), and against the Monte Carlo engine.  The 3-D folium (turning points moving
with y, a cusp where they merge) has a value since roots10 (test_folds3d_folium.py); past its CPU
budget it must say "no exact value", not call the integral undefined.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from cubic_reference import L, M, g
from scipy import integrate

from langur import exact as api
from langur import frontend, operational
from langur.ddenote import ddenote_program
from langur.symbolic.quadrature import fold
from langur.symbolic.quadrature.brackets import _implied_by_bracket

TOL = 1e-10
H = 4e-3


def roots_in(c, lo, hi):
    return [float(r.real) for r in np.roots([1, 0, -1, -c]) if abs(r.imag) < 1e-9 and lo < r.real < hi]


def inner(c, lo, hi):
    """∫ L(c − g(y)) dy over [lo, hi], split where c − g(y) crosses L's kinks (−M, 0, M)."""
    pts = sorted({r for k in (-M, M, 0.0) for r in roots_in(c - k, lo, hi)})
    return integrate.quad(lambda y: L(c - g(y)), lo, hi, points=pts or None, limit=200, epsabs=TOL, epsrel=TOL)[0]


def volume(a, bx, by):
    """V(a), the outer integral split where a − g(x) crosses the inner integral's kinks."""
    crit = [g(by[0]), g(by[1]), M, -M]
    kinks = {k + s for k in (-M, M, 0.0) for s in crit}
    pts = sorted({r for k in kinks for r in roots_in(a - k, *bx)})
    return integrate.quad(lambda x: inner(a - g(x), *by), bx[0], bx[1], points=pts or None, limit=400,
                          epsabs=TOL, epsrel=TOL)[0]


def derivative(a, bx, by):
    v = [volume(a + k * H, bx, by) for k in (-2, -1, 1, 2)]
    return (v[0] - 8 * v[1] + 8 * v[2] - v[3]) / (12 * H)


CUBIC = ("param a = 0.3\n"
         "int ([0, 1.5], [0, 1.5], [-1, 1]) [x^3 - x + y^3 - y + z^3 - z - a >= 0] d(x, y, z)\n")
FOLIUM = "param a = 0.1\nint ([-1, 1], [-1, 1], [-1, 1]) [x^3 - x*y + y^3 + z^3 - z*y - a >= 0] d(x, y, z)\n"


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
def test_separable_cubic_across_the_fold_curve_has_a_value():
    loaded = frontend.load_text(CUBIC, "cubic3.lgr")
    r = ddenote_program(loaded.program, {"a": 0.3}, {"a": 1})
    assert r.method == "quadrature" and 0 < r.error < 1e-4, (r.method, r.error)
    ref = derivative(0.3, (0.0, 1.5), (0.0, 1.5))
    assert abs(float(r.value) - ref) <= r.error + 1e-8, (float(r.value), r.error, ref)
    mc = operational.estimate_derivative(loaded, {"a": 0.3}, {"a": 1}, samples=20_000, seed=1)
    assert abs(mc.value - float(r.value)) <= 5 * mc.stderr + 1e-9, (mc.value, mc.stderr, float(r.value))


def test_folium_past_its_budget_is_no_value_not_undefined(monkeypatch):
    monkeypatch.setattr(fold, "FOLD_SECONDS", 1.0)
    program = frontend.load_text(FOLIUM, "folium3.lgr").program
    with pytest.raises(api.ExactUnavailable, match="singular along the fold") as info:
        api.exact_deriv(program, {"a": 0.1}, {"a": 1})
    assert not isinstance(info.value, api.ExactUndefined)


def test_bracket_implies_the_box_condition_on_the_root():
    """``z ≥ −1`` and ``1 − z ≥ 0`` are left out of a branch whose root lies in [−1, −1/√3], and
    so is ``z ≥ −1`` when the bracket's end is a turning point that moves in [−1, 1]; ``z ≥ 0`` is not."""
    from langur.implicit import ImplicitRootFn

    x, y, z, w = sp.symbols("x y z w", real=True)
    root = ImplicitRootFn(sp.Lambda(w, w**3 - w + x), 0, -1, -1 / sp.sqrt(3), -1, 0)
    xs = [x, y, root]
    assert _implied_by_bracket(z + 1, [x, y, z], xs, {})
    assert _implied_by_bracket(1 - z, [x, y, z], xs, {})
    assert not _implied_by_bracket(z, [x, y, z], xs, {})
    assert not _implied_by_bracket(z + 1, [x, y, z], [x, y, z], {})
    turning = ImplicitRootFn(sp.Lambda(w, 3 * w**2 - y), 0, -1, 1, 0, 2)
    moving = ImplicitRootFn(sp.Lambda(w, w**3 - w * y + x), 0, -1, turning, -1, 0)
    assert _implied_by_bracket(z + 1, [x, y, z], [x, y, moving], {})
    assert not _implied_by_bracket(sp.Rational(1, 2) - z, [x, y, z], [x, y, moving], {})
