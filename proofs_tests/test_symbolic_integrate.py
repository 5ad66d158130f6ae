"""The exact integrator (langur.symbolic.integrate) against values computed by hand.

Every expected value below is derived in the comment next to it; none comes from the integrator.
Delta pieces follow LANGUAGE.md §4: ∫ h δ(π₀Ψ̂) dx = Σ_b ∫ h(Ψ̂_b⁻¹(0,u')) |det DΨ̂_b⁻¹(0,u')| du'.
"""

import math

import mpmath
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from langur.symbolic import antiderivatives, regions
from langur.symbolic.integrate import (
    ALL_PARAMS,
    CELL_PREFIX,
    integrate_delta_pieces,
    integrate_pieces,
)
from langur.symbolic.pieces import Branch, Condition, DeltaPiece, Piece, Psi

x, y, z = sp.symbols("x y z", real=True)
theta, a, r, t, k, s, mu, lo, hi = sp.symbols("theta a r t k s mu a_lo a_hi", real=True)
u0, u1, u2 = sp.symbols("u0 u1 u2", real=True)
ONE = sp.Integer(1)
half = sp.Rational(1, 2)


def completed(cond, v, variables, inverse, guards=()):
    """Psi of a condition completed by solving for v: forward = (cond, other variables)."""
    others = tuple(w for w in variables if w != v)
    inputs = (u0, u1, u2)[: len(variables)]
    branches = []
    for comp in inverse:
        inv = {v: comp}
        inv.update({w: u for w, u in zip(others, inputs[1:])})
        branches.append(Branch(tuple(inv.items()), tuple(guards)))
    return Psi(tuple(variables), (cond,) + others, inputs, tuple(branches), v)


# ---------------------------------------------------------------------------------------------
# Fig. 1: ∫₀¹ [θ − x ≥ 0] dx = length of [0, 1] ∩ (−∞, θ] = Min(Max(θ, 0), 1) for every θ.


@pytest.mark.parametrize("th, expected", [(-1, 0), (half, half), (2, 1)])
def test_fig1_closed_form_for_all_theta(th, expected):
    res = integrate_pieces([Piece((Condition(theta - x),), ONE)], (x,), ((0, 1),), {theta: th})
    assert res.method == "closed_form"
    assert res.value == pytest.approx(float(expected), abs=1e-15)
    assert res.notes[0] == ALL_PARAMS
    e = res.expr
    assert e.free_symbols == {theta}
    assert not e.has(sp.Piecewise, sp.Heaviside)
    # the expression itself is Min(Max(θ, 0), 1): equal at every rational point, exactly
    for q in [sp.Rational(n, 7) for n in range(-14, 22)]:
        assert e.subs(theta, q) == sp.Min(sp.Max(q, 0), 1)


def test_pieces_are_summed():
    # [θ − x ≥ 0]·1 + [x − θ ≥ 0]·2 on [0, 1] at θ = 1/4: θ + 2(1 − θ) = 2 − θ = 7/4
    pieces = [Piece((Condition(theta - x),), ONE), Piece((Condition(x - theta),), 2 * ONE)]
    res = integrate_pieces(pieces, (x,), ((0, 1),), {theta: sp.Rational(1, 4)})
    assert res.method == "closed_form" and res.value == pytest.approx(1.75, abs=1e-15)
    assert res.expr.subs(theta, sp.Rational(1, 2)) == sp.Rational(3, 2)


def test_empty_sum_is_exactly_zero():
    res = integrate_pieces([], (x,), ((0, 1),), {})
    assert res.expr == 0 and res.value == 0.0 and res.method == "closed_form"
    res = integrate_delta_pieces([], (x,), ((0, 1),), {})
    assert res.expr == 0 and res.method == "closed_form"


# ---------------------------------------------------------------------------------------------
# Sifting: ∫₀¹ δ(θ − x) dx = 1 if θ ∈ [0, 1] else 0 (|∂ₓ(θ − x)| = 1).


@pytest.mark.parametrize("th, expected", [(-1, 0), (half, 1), (2, 0)])
def test_sifting(th, expected):
    psi = completed(theta - x, x, (x,), [theta - u0])
    res = integrate_delta_pieces([DeltaPiece(psi, (), ONE)], (x,), ((0, 1),), {theta: th})
    assert res.method == "closed_form"
    assert res.value == pytest.approx(expected, abs=1e-15)
    for q, want in [(sp.Rational(-1, 3), 0), (sp.Rational(1, 3), 1), (sp.Rational(4, 3), 0)]:
        assert res.expr.subs(theta, q) == want


# ---------------------------------------------------------------------------------------------
# [a − x² ≥ 0] on [−1, 1]: the interval [−√a, √a], length 2√a for 0 < a < 1.
# Its a-derivative: δ(a − x²)·1, roots ±√a, |∂ₓ(a − x²)| = 2√a at both: Σ = 2/(2√a) = 1/√a
# (= d/da 2√a).


def test_parabola_region_and_its_delta():
    res = integrate_pieces([Piece((Condition(a - x**2),), ONE)], (x,), ((-1, 1),), {a: half})
    assert res.method == "closed_form"
    assert res.value == pytest.approx(2 * math.sqrt(0.5), rel=1e-14)
    assert res.expr.subs(a, sp.Rational(1, 4)) == 1  # 2·√(1/4)
    assert res.expr.subs(a, sp.Rational(9, 16)) == sp.Rational(3, 2)
    psi = completed(a - x**2, x, (x,), [sp.sqrt(a - u0), -sp.sqrt(a - u0)], guards=[a - u0])
    d = integrate_delta_pieces([DeltaPiece(psi, (), ONE)], (x,), ((-1, 1),), {a: half})
    assert d.method == "closed_form"
    assert d.value == pytest.approx(1 / math.sqrt(0.5), rel=1e-14)
    assert sp.simplify(d.expr.subs(a, sp.Rational(1, 4)) - 2) == 0  # 1/√(1/4)
    # a < 0: no real root, the guard a − u0 ≥ 0 fails at u0 = 0: nothing to sift
    d = integrate_delta_pieces([DeltaPiece(psi, (), ONE)], (x,), ((-1, 1),), {a: -half})
    assert d.method == "closed_form" and d.value == 0.0


# ---------------------------------------------------------------------------------------------
# [t·x − 1 ≥ 0] on [0, 1], t > 1: x ≥ 1/t, length 1 − 1/t.  Delta: D_t(t x − 1) = x, root x* = 1/t,
# |∂ₓ(t x − 1)| = t: x*/t = 1/t² (= d/dt (1 − 1/t)).


def test_parametric_slope():
    psi = completed(t * x - 1, x, (x,), [(u0 + 1) / t])
    res = integrate_pieces([Piece((Condition(t * x - 1, psi),), ONE)], (x,), ((0, 1),), {t: 4})
    assert res.value == pytest.approx(0.75, abs=1e-14) and res.method == "closed_form"
    assert res.expr.subs(t, 2) == half
    # the sign of the slope t was decided at the evaluation point: that is the cell
    assert res.notes[0].startswith(CELL_PREFIX) and "t > 0" in res.notes[0]
    d = integrate_delta_pieces([DeltaPiece(psi, (), x)], (x,), ((0, 1),), {t: 4})
    assert d.value == pytest.approx(1 / 16, abs=1e-15)
    assert d.expr.subs(t, 2) == sp.Rational(1, 4)


# ---------------------------------------------------------------------------------------------
# Leibniz: ∫₀² [k − x ≥ 0]·k·x dx = k·k²/2 = k³/2 for 0 < k < 2.  Its k-derivative 3k²/2 is the
# regular piece [k − x ≥ 0]·x (→ k²/2) plus the delta piece δ(k − x)·1·k·x (→ k·k = k²).


def test_leibniz_rule():
    psi = completed(k - x, x, (x,), [k - u0])
    cond = Condition(k - x, psi)
    val = integrate_pieces([Piece((cond,), k * x)], (x,), ((0, 2),), {k: 1})
    assert val.value == pytest.approx(0.5, abs=1e-15)
    assert val.expr.subs(k, sp.Rational(3, 2)) == sp.Rational(27, 16)
    reg = integrate_pieces([Piece((cond,), x)], (x,), ((0, 2),), {k: 1})
    bnd = integrate_delta_pieces([DeltaPiece(psi, (), k * x)], (x,), ((0, 2),), {k: 1})
    assert reg.value == pytest.approx(0.5, abs=1e-15)
    assert bnd.value == pytest.approx(1.0, abs=1e-15)
    assert (reg.expr + bnd.expr).subs(k, sp.Rational(3, 2)) == sp.Rational(27, 8)  # 3k²/2


def test_parametric_box_bounds():
    # ∫₀^k x dx = k²/2 for k > 0 (box bounds may be parametric).
    res = integrate_pieces([Piece((), x)], (x,), ((0, k),), {k: 3})
    assert res.value == pytest.approx(4.5, abs=1e-14)
    assert res.expr.subs(k, 5) == sp.Rational(25, 2)


# ---------------------------------------------------------------------------------------------
# The disk [r − x² − y² ≥ 0] ⊂ [−1, 1]² for r < 1: area π r.  Its r-derivative is
# ∫∫ δ(r − x² − y²) = circumference 2π√r / |∇(r − x² − y²)| (= 2√r) = π.  Psi solved for y:
# y = ±√(r − u0 − u1²), x = u1; |det DΨ̂⁻¹(0, u1)| = 1/(2√(r − u1²)); ∫_{−√r}^{√r} of it = π/2 per
# branch.


def test_disk_area_and_circumference():
    root = sp.sqrt(r - u0 - u1**2)
    psi = completed(r - x**2 - y**2, y, (x, y), [root, -root], guards=[r - u0 - u1**2])
    box = ((-1, 1), (-1, 1))
    res = integrate_pieces([Piece((Condition(r - x**2 - y**2, psi),), ONE)], (x, y), box, {r: half})
    assert res.method == "closed_form"
    assert res.value == pytest.approx(math.pi / 2, rel=1e-13)
    assert sp.simplify(res.expr.subs(r, sp.Rational(1, 4)) - sp.pi / 4) == 0
    d = integrate_delta_pieces([DeltaPiece(psi, (), ONE)], (x, y), box, {r: half})
    assert d.method == "closed_form"
    assert d.value == pytest.approx(math.pi, rel=1e-13)


# ---------------------------------------------------------------------------------------------
# Simplex: vol{x, y, z ≥ 0, x + y + z ≤ s} = s³/6 for 0 ≤ s ≤ 1 (1/6 at s = 1); its s-derivative,
# the area of the slice x + y + z = s measured by δ(s − x − y − z) (Jacobian 1), is s²/2.


def test_simplex_volume_and_slice():
    box = ((0, 1), (0, 1), (0, 1))
    res = integrate_pieces([Piece((Condition(1 - x - y - z),), ONE)], (x, y, z), box, {})
    assert res.expr == sp.Rational(1, 6)
    res = integrate_pieces([Piece((Condition(s - x - y - z),), ONE)], (x, y, z), box, {s: half})
    assert res.value == pytest.approx(1 / 48, abs=1e-15)
    assert res.expr.subs(s, sp.Rational(1, 3)) == sp.Rational(1, 162)
    psi = completed(s - x - y - z, z, (x, y, z), [s - u0 - u1 - u2])
    d = integrate_delta_pieces([DeltaPiece(psi, (), ONE)], (x, y, z), box, {s: half})
    assert d.method == "closed_form"
    assert d.value == pytest.approx(1 / 8, abs=1e-15)
    assert d.expr.subs(s, sp.Rational(1, 3)) == sp.Rational(1, 18)


# ---------------------------------------------------------------------------------------------
# Fig. 9: f(θ) = ∫∫_{[−1,1]²} [x + θ − y ≥ 0](1 + θ + x + y).  For 0 ≤ θ ≤ 2 the complement is
# {y > x + θ}; with w = x + θ, ∫_{w}^{1}(1 + θ + x + y) dy = (3/2)(1 − w²), so
# f(θ) = 4(1 + θ) − (3/2)[2/3 − (θ − 1) + (θ − 1)³/3]:  f(0) = 2,  f(1/2) = 69/16.
# f'(θ) = 11/2 − (3/2)(θ − 1)²: f'(0) = 4 = regular [y ≤ x] (area 2) + delta ∫_{−1}^{1}(1 + 2x)dx (2);
# f'(1/2) = 41/8 = area 4 − (3/2)²/2 = 23/8 plus ∫_{−1}^{1/2}(2 + 2x)dx = 9/4.


@pytest.mark.parametrize("th, f, reg, bnd", [(0, 2, 2, 2), (half, sp.Rational(69, 16), sp.Rational(23, 8),
                                                             sp.Rational(9, 4))])
def test_fig9(th, f, reg, bnd):
    box = ((-1, 1), (-1, 1))
    psi = completed(x + theta - y, y, (x, y), [u1 + theta - u0])
    cond = Condition(x + theta - y, psi)
    val = integrate_pieces([Piece((cond,), 1 + theta + x + y)], (x, y), box, {theta: th})
    assert val.value == pytest.approx(float(f), abs=1e-13)
    assert val.expr.subs(theta, th) == f
    r_ = integrate_pieces([Piece((cond,), ONE)], (x, y), box, {theta: th})
    d = integrate_delta_pieces([DeltaPiece(psi, (), 1 + theta + x + y)], (x, y), box, {theta: th})
    assert r_.expr.subs(theta, th) == reg
    assert d.expr.subs(theta, th) == bnd
    assert d.value == pytest.approx(float(bnd), abs=1e-13)


# ---------------------------------------------------------------------------------------------
# Declared Psi (k − 2x + y, x + 2y), inverse x = (u1 − 2u0 + 2k)/5, y = (u0 − k + 2u1)/5.
# By hand (integrate y first, |∂_y(k − 2x + y)| = 1): ∫∫_{[0,1]²} δ(k − 2x + y) h = ∫ h(x, 2x − k)
# [0 ≤ 2x − k ≤ 1] dx; at k = 1/2, x ∈ [1/4, 3/4]: h = 1 → 1/2; h = x·y → ∫ 2x² − x/2 = 7/48.


@pytest.mark.parametrize("h, expected", [(ONE, half), (x * y, sp.Rational(7, 48))])
def test_declared_rotated_psi(h, expected):
    psi = Psi((x, y), (k - 2 * x + y, x + 2 * y), (u0, u1),
              (Branch(((x, (u1 - 2 * u0 + 2 * k) / 5), (y, (u0 - k + 2 * u1) / 5))),), None)
    d = integrate_delta_pieces([DeltaPiece(psi, (), h)], (x, y), ((0, 1), (0, 1)), {k: half})
    assert d.method == "closed_form"
    assert d.value == pytest.approx(float(expected), abs=1e-14)
    assert sp.nsimplify(d.expr.subs(k, half)) == expected


# ---------------------------------------------------------------------------------------------
# Coincident conditions (examples/degenerate/coincident.lgr): ⦇[x ≥ a]·[x ≥ a]⦈ has two delta
# pieces δ(x − a)·(−1)·[x − a ≥ 0]; the condition evaluated on its own zero set is 0 ≥ 0, TRUE
# (the paper's convention), so the boundary part is −2, not −1.


def test_coincident_conditions_count_twice():
    psi = completed(x - a, x, (x,), [u0 + a])
    piece = DeltaPiece(psi, (Condition(x - a, psi),), -ONE)
    d = integrate_delta_pieces([piece, piece], (x,), ((0, 1),), {a: half})
    assert d.value == pytest.approx(-2.0, abs=1e-15)


# ---------------------------------------------------------------------------------------------
# A Gaussian window (paper §2): ∫_a^b exp(−(x − μ)²/50) dx = 5√(π/2)(erf((b − μ)/(5√2)) −
# erf((a − μ)/(5√2))).


def test_gaussian_window_closed_form():
    w = sp.exp(-((x - mu) / 5) ** 2 / 2)
    piece = Piece((Condition(x - lo), Condition(hi - x)), w)
    res = integrate_pieces([piece], (x,), ((-10, 10),), {lo: -1, hi: 4, mu: 1})
    want = 5 * math.sqrt(math.pi / 2) * (math.erf(3 / (5 * math.sqrt(2))) - math.erf(-2 / (5 * math.sqrt(2))))
    assert res.method == "closed_form" and res.expr.has(sp.erf)
    assert res.value == pytest.approx(want, rel=1e-13)


# ---------------------------------------------------------------------------------------------
# Fallbacks.


def test_non_elementary_weight_falls_back_to_quadrature():
    # ∫₀¹ exp(x³) dx has no elementary antiderivative; mpmath's tanh-sinh gives the reference.
    want = float(mpmath.quad(lambda v: mpmath.exp(v**3), [0, 1]))
    res = integrate_pieces([Piece((), sp.exp(x**3)), Piece((Condition(theta - x),), ONE)], (x,), ((0, 1),),
                           {theta: half})
    assert res.method == "quadrature" and res.expr is None
    assert 0 < res.error < 1e-8
    assert res.value == pytest.approx(want + 0.5, abs=1e-9)
    assert any("exp(x**3)" in n for n in res.notes)
    assert any(n.startswith("exact part") and "Max(0, Min(1, theta))" in n for n in res.notes)


def test_time_limit_falls_back_to_quadrature(monkeypatch):
    # ∫₀¹ x/(1 + x²) dx = log(2)/2, computed by quadrature when there is no time for sympy (a
    # polynomial times exp or sin of an affine argument needs no sympy: symbolic/elementary.py).
    monkeypatch.setattr(antiderivatives, "_CACHE", {})  # no antiderivative remembered from other tests
    res = integrate_pieces([Piece((), x / (1 + x**2))], (x,), ((0, 1),), {}, timeout=1e-6)
    assert res.method == "quadrature"
    assert res.value == pytest.approx(math.log(2) / 2, abs=1e-9)
    assert any("timed out" in n or "time" in n for n in res.notes)


def test_wrong_closed_form_is_caught(monkeypatch):
    # A deliberately wrong antiderivative (twice the right one) must not pass the cross-check:
    # ∫₀¹ [θ − x ≥ 0]·x dx = θ²/2 = 1/8 at θ = 1/2; the broken closed form says 1/4.  The closed
    # form is discarded, the quadrature reported, and the result says what disagreed.
    good = regions.antiderivative
    monkeypatch.setattr(regions, "antiderivative", lambda w, v, ctx: 2 * good(w, v, ctx))
    res = integrate_pieces([Piece((Condition(theta - x),), x)], (x,), ((0, 1),), {theta: half})
    assert res.method == "quadrature" and res.expr is None
    assert res.value == pytest.approx(0.125, abs=1e-10)
    (why,) = res.inconsistent
    assert "closed form 0.25" in why and "disagrees with quadrature 0.125" in why


# ---------------------------------------------------------------------------------------------
# Property: closed forms of random affine regions in 2-D agree with the independent quadrature
# (integrate_* record an inconsistency otherwise), and with an exact hand formula for the
# half-plane y ≤ p·x + q (clipped to the unit square) in the simplest case.

coef = st.integers(-3, 3)


@settings(max_examples=12, deadline=None)
@given(coef, coef, coef, coef, coef, coef, st.fractions(-2, 2, max_denominator=4))
def test_random_affine_regions_agree_with_quadrature(a1, b1, c1, a2, b2, c2, th):
    conds = [Condition(a1 * x + b1 * y + c1 * theta + 1), Condition(a2 * x + b2 * y + c2 - theta)]
    res = integrate_pieces([Piece(tuple(conds), 1 + x * y)], (x, y), ((0, 1), (0, 1)),
                           {theta: sp.Rational(th.numerator, th.denominator)})
    assert not res.inconsistent, res.inconsistent
    if res.method == "closed_form":
        assert res.value == pytest.approx(res.check, abs=1e-7)


def test_undefined_integrand_is_reported():
    # log(x) on [−1, 1] is undefined for x < 0 (LANGUAGE.md §1): no value, a reason instead
    with pytest.raises(ValueError, match="undefined"):
        integrate_pieces([Piece((), sp.log(x))], (x,), ((-1, 1),), {})
    # on [1/2, 1] it is fine: [x log x − x] = (−1) − (½ log ½ − ½) = −½ + ½ log 2
    res = integrate_pieces([Piece((), sp.log(x))], (x,), ((half, 1),), {})
    assert res.value == pytest.approx(-0.5 + 0.5 * math.log(2), abs=1e-15)


def test_ball_falls_back_to_accurate_quadrature():
    # [r − x² − y² − z² ≥ 0] in [−1, 1]³ at r = 1/2: the ball of radius √r, volume (4/3)π r^{3/2}.
    # The inner bounds ±√(r − x² − y²) compared with the box ends are not solved in closed form
    # (yet): quadrature, whose error bound must be honest.
    r_ = sp.Rational(1, 2)
    res = integrate_pieces([Piece((Condition(r - x**2 - y**2 - z**2),), ONE)], (x, y, z), ((-1, 1),) * 3, {r: r_})
    want = 4 / 3 * math.pi * 0.5**1.5
    assert res.method == "quadrature"
    assert abs(res.value - want) <= res.error + 1e-12 and res.error < 1e-7


@settings(max_examples=10, deadline=None)
@given(st.integers(-3, 3), st.sampled_from([-2, -1, 1, 3]), coef, coef, coef,
       st.fractions(-2, 2, max_denominator=4))
def test_random_affine_delta_pieces_agree_with_quadrature(a1, b1, a2, b2, c2, th):
    # δ(a1 x + b1 y + θ) [a2 x + b2 y + c2 ≥ 0] (1 + x) on [0,1]², Psi solved for y
    cond = a1 * x + b1 * y + theta
    psi = completed(cond, y, (x, y), [(u0 - a1 * u1 - theta) / b1])
    piece = DeltaPiece(psi, (Condition(a2 * x + b2 * y + c2),), 1 + x)
    res = integrate_delta_pieces([piece], (x, y), ((0, 1), (0, 1)),
                                 {theta: sp.Rational(th.numerator, th.denominator)})
    assert not res.inconsistent, res.inconsistent
    if res.method == "closed_form":
        assert res.value == pytest.approx(res.check, abs=1e-7)


def test_parameter_value_where_sympys_generic_antiderivative_is_singular():
    # ∫₀² cos(θx) dx = sin(2θ)/θ for θ ≠ 0, and 2 (cos 0 = 1) at θ = 0, where sympy's generic
    # answer sin(θx)/θ is 0/0: the case θ = 0 must be taken, not the generic one.
    res = integrate_pieces([Piece((), sp.cos(theta * x))], (x,), ((0, 2),), {theta: 0})
    assert res.method == "closed_form" and res.value == pytest.approx(2.0, abs=1e-15)
    res = integrate_pieces([Piece((), sp.cos(theta * x))], (x,), ((0, 2),), {theta: 1})
    assert res.value == pytest.approx(math.sin(2.0), abs=1e-15)


@settings(max_examples=15, deadline=None)
@given(coef, coef, coef, coef, st.sampled_from(["theta - x", "x - theta/2", "exp(x) - theta - 2", "x**3 - theta"]),
       st.sampled_from(["1", "x", "exp(-x**2)", "1/(3 + x)", "cos(theta*x)"]),
       st.fractions(-3, 3, max_denominator=4))
def test_random_one_dimensional_regions_agree_with_quadrature(a_, b_, c_, d_, e2, w, th):
    # a quadratic and a monotone condition on [−2, 2]; integrate_pieces records an inconsistency
    # when a closed form disagrees with the quadrature
    ns = {"x": x, "theta": theta}
    conds = (Condition(a_ * x**2 + b_ * x + c_ * theta + d_), Condition(sp.sympify(e2, locals=ns)))
    res = integrate_pieces([Piece(conds, sp.sympify(w, locals=ns))], (x,), ((-2, 2),),
                           {theta: sp.Rational(th.numerator, th.denominator)})
    assert not res.inconsistent, res.inconsistent
    if res.method == "closed_form":
        assert res.value == pytest.approx(res.check, abs=1e-7)


@pytest.mark.parametrize("rad", ["0.5001", "0.501", "0.51"])
def test_quadrature_finds_a_region_that_appears_inside_the_outer_interval(rad):
    # `sqrt(x² + y²) < rad` has no closed-form solution for y the engine uses, so ⟦p⟧ is integrated
    # numerically, x outside, y inside.  On the pixel [0.5, 1] × [−0.2, 0.2] the disk shows only a
    # cap over x ∈ [0.5, rad]: the inner region vanishes at x = rad, where ∂/∂y of the condition
    # is 0 (y = 0).  Before the quadrature looked for such critical points it sampled x past the
    # cap and reported 0 ± 2e-10.  The weight 1 + x·y integrates to the cap's area (x·y is odd in
    # y), r²·acos(d/r) − d·√(r² − d²) with d = 0.5, by hand.
    from langur.denote import denote_program
    from langur.frontend import load_text

    loaded = load_text(f"param rad = {rad}\nint ([0.5, 1], [-0.2, 0.2]) [sqrt(x^2 + y^2) < rad] * (1 + x * y) d(x, y)\n")
    r, d = float(rad), 0.5
    area = r * r * math.acos(d / r) - d * math.sqrt(r * r - d * d)
    got = denote_program(loaded.program, {"rad": rad})
    assert abs(got.value - area) <= got.error + 1e-12 * area
    assert area > 1e-6
