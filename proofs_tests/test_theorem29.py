"""Last bug hunt's exact-engine findings (bench/history/2026-11-29.md#fuzz28 and #fold28; paper §8.3's
Theorem 8.1, §6.3's regions, Fig. 12's ⟦p⟧).

* **F6 with x ∈ [−0.26, −0.24]**: Theorem 8.1's line said ``FAILS: D⟦p⟧ = nan``.  ⟦p⟧'s closed form
  holds square roots of radicands that are exactly 0 (the cylinder's fold a + √0.3 put into
  3 − 10a² + 20a·y − 10y²); sympy's 20 digits of them carry ±10⁻⁴⁸·i, which ``theorem._float`` read
  as "not real": NaN.  Real up to rounding now counts as real, and a D⟦p⟧·γ' that still cannot be
  computed makes the check inconclusive, never a failure.
* **F1**: sympy's ``solve`` gives sin(3z) = −0.16 one period's roots; the root (asin 0.16 − π)/3,
  0.0064 from the box's end −1, was missed (the delta piece's closed form −1 − asin(0.16)/3 was
  wrong, rescued by its cross-check).  A periodic condition's roots are now copied by whole periods
  into the interval.
* **F5**: ``atan2(x − a, −1)`` (desugared to ±acos(−1/√(1 + (x − a)²))) took 36 CPU s for ⦇p⦈: sympy
  timed out, or found antiderivatives valid on one side of x = a only.  The weight is now written
  P + sign(x − a)·Q (atan2's |y| made explicit) and integrated in closed form.

Every value is by hand (formulas in each test); the tests marked "main" failed on main (434dfa9).
"""

from __future__ import annotations

import math

import pytest
import sympy as sp

from langur import exact, theorem
from langur.frontend import load_text
from langur.symbolic import elementary, solving
from langur.symbolic.context import Context
from langur.symbolic.pieces import Method
from langur.sympy_bridge import symbol

# ----------------------------------------------------------------------------------------------
# F6: D⟦p⟧ = nan from rounding of an exactly-zero radicand


def test_a_square_root_of_an_exact_zero_is_real():
    """main: nan.  A term of F6's ⟦p⟧: the radicand −4(√30/10 + 61/100)² + 61√30/125 + 6721/2500 is
    0 by hand (−4·(0.3 + 0.122√30 + 0.3721) + 0.488√30 + 2.6884 = 0), so the term is 0."""
    x = sp.sqrt(30) / 10 + sp.Rational(61, 100)
    radicand = -4 * x**2 + 61 * sp.sqrt(30) / 125 + sp.Rational(6721, 2500)
    assert sp.expand(radicand) == 0  # the premise, exactly
    term = 13 * (-sp.Rational(6721, 15000) - 61 * sp.sqrt(30) / 3000 + 2 * x**2 / 3) * sp.sqrt(radicand) / 100
    assert sp.im(sp.N(term, 20)) != 0  # and sympy's 20 digits of it are not real
    assert theorem._float(term, {}) == 0.0


def test_not_real_still_nan():
    a = symbol("a")
    assert math.isnan(theorem._float(sp.sqrt(a - 1), {"a": 0.5}))
    assert math.isnan(theorem._float(1 / a, {"a": 0}))


FIG1 = "param theta = 0.5\nint ([0, 1]) [x <= theta] d(x)\n"


def test_a_nan_left_side_is_inconclusive_not_a_failure(monkeypatch):
    """main: FAILS.  When D⟦p⟧·γ' from ⟦p⟧'s closed form comes out NaN, the check has no left side:
    not decided, with the reason; ⦇p⦈ = 1 (∫₀¹ [x ≤ θ] = θ) is still reported."""
    monkeypatch.setattr(theorem, "_closed_form_derivative", lambda *a, **k: (math.nan, None))
    p = load_text(FIG1).program
    th = theorem.check_theorem_8_1(p, {"theta": 0.5}, {"theta": 1}, nearby=0)
    assert th.holds is None
    assert th.derivative_denotation == pytest.approx(1.0)
    assert any("could not be computed from the closed form" in n for n in th.notes)


def test_the_check_holds_on_fig1_as_before():
    p = load_text(FIG1).program
    th = theorem.check_theorem_8_1(p, {"theta": 0.5}, {"theta": 1})
    assert th.holds is True and th.d_denotation == pytest.approx(1.0)


F6_NARROW = """param a = 0.61, b = 0.79
int ([-0.26, -0.24], [-b, 2 * a], [0, 2]) (if (y - a)^2 + z^2 <= 0.3 then (if x + y + 2 * z <= a + 0.3 then y^2 else 0) else 1) d(x, y, z)
"""


def test_f6_closed_form_of_the_denotation_differentiates_to_a_number():
    """main: nan.  D⟦p⟧ from ⟦p⟧'s (large) closed form, against that form's own central difference
    taken here with 50 digits (h = 10⁻¹², error O(h²)), and against the Monte Carlo engine's
    0.08482 ± 0.00014 (fold28, 200,000 samples)."""
    from langur.denote import denote_program
    at = {"a": 0.61, "b": 0.79}
    den = denote_program(load_text(F6_NARROW).program, at, near=True)
    assert den.method == Method.CLOSED_FORM
    d, _ = theorem._closed_form_derivative(den.expr, at, {"a": 1}, [], across=den.everywhere)
    a, b = symbol("a"), symbol("b")
    h = sp.Rational(1, 10**12)
    point = {b: sp.Rational(79, 100)}
    central = (den.expr.xreplace({**point, a: sp.Rational(61, 100) + h})
               - den.expr.xreplace({**point, a: sp.Rational(61, 100) - h})) / (2 * h)
    assert d == pytest.approx(float(sp.re(sp.N(central, 50))), abs=1e-9)
    assert abs(d - 0.08482) < 4 * 0.00014


# ----------------------------------------------------------------------------------------------
# F1: a periodic condition's roots in one period only


def _ctx(at: dict) -> Context:
    from langur.timebox import Deadline
    return Context({symbol(k): sp.Rational(v) for k, v in at.items()}, Deadline(20.0), frozenset(symbol(k) for k in at))


def test_periodic_roots_are_copied_into_the_interval():
    """sin(3z) + 4/25 on (−1, 1): −asin(0.16)/3, (π + asin(0.16))/3 and (asin(0.16) − π)/3 = −0.99364,
    the last 0.0064 from −1 (main: missing)."""
    from langur.symbolic.context import Cond
    z = symbol("z")
    c = Cond(sp.sin(3 * z) + sp.Rational(4, 25))
    ctx = _ctx({})
    roots = sorted(float(r) for r in solving._roots(c, z, ctx, within=(-1.0, 1.0)))
    alpha = math.asin(0.16)
    want = sorted([-alpha / 3, (math.pi + alpha) / 3, (alpha - math.pi) / 3])
    assert roots == pytest.approx(want, abs=1e-12)


F1 = "param b = 0.29\nint ([b - 1, 1], [-1, 1]) [sin(3 * z) >= -0.16] d(y, z)\n"


def test_f1_delta_piece_has_the_right_closed_form():
    """main: quadrature (its closed form −1 − asin(0.16)/3 disagreed).  ∂b = −|{z ∈ [−1, 1]:
    sin 3z ≥ −0.16}| = −(2 − π/3 + (2/3)·asin 0.16) by hand (the complement is
    ((asin 0.16 − π)/3, −asin(0.16)/3), of length (π − 2·asin 0.16)/3... subtracted from 2)."""
    d = exact.exact_deriv(load_text(F1).program, {"b": 0.29}, {"b": 1}, check=False)
    assert d.method == Method.CLOSED_FORM
    assert d.value == pytest.approx(-(2 - math.pi / 3 + 2 / 3 * math.asin(0.16)), abs=1e-12)
    assert not any("disagrees" in n for n in d.notes)


def test_a_root_near_the_far_end_over_several_periods():
    """main: the piece by quadrature.  sin 2z ≥ 0.3 on z ∈ [−3, 3.3]: [α/2 − π, −π/2 − α/2],
    [α/2, π/2 − α/2] and [α/2 + π, 3.3] (α = asin 0.3; the last 0.006 long, beside the end), total
    3.3 − (5/2)α; ∂b of the box [b − 1, 1] is minus that."""
    text = "param b = 0.29\nint ([b - 1, 1], [-3, 3.3]) [sin(2 * z) >= 0.3] d(y, z)\n"
    d = exact.exact_deriv(load_text(text).program, {"b": 0.29}, {"b": 1}, check=False)
    assert d.method == Method.CLOSED_FORM
    assert d.value == pytest.approx(-(3.3 - 2.5 * math.asin(0.3)), abs=1e-12)


def test_too_many_periods_are_not_enumerated():
    """sin 10z has period π/5: on (−20, 20) its roots kπ/10, |k| ≤ 63 (127 of them, 63.7 periods);
    on (−40, 40) 127 periods, more than MAX_PERIODS: Unsupported, the piece goes to quadrature."""
    from langur.symbolic.context import Cond, Unsupported
    z = symbol("z")
    c = Cond(sp.sin(10 * z))
    assert len(solving._roots(c, z, _ctx({}), within=(-20.0, 20.0))) == 127
    with pytest.raises(Unsupported):
        solving._roots(c, z, _ctx({}), within=(-40.0, 40.0))


# ----------------------------------------------------------------------------------------------
# F5: atan2 of an affine argument


def test_sign_split_of_atan2s_angle():
    """acos(−1/√(1 + (x − a)²)) = π − sign(x − a)·atan(x − a) (atan2(y, −1) = π − atan y for
    y ≥ 0, −π − atan y below: the angle is its absolute value); its derivative's weight
    (2a − 2x)/(2√(1 − 1/q)·q^(3/2)) = −sign(x − a)/q."""
    x, a = symbol("x"), symbol("a")
    q = (x - a) ** 2 + 1
    s = elementary.sign_split(sp.acos(-1 / sp.sqrt(q)), x)
    assert sp.simplify(s.s - (x - a)) == 0 and s.P == sp.pi and sp.simplify(s.Q + sp.atan(x - a)) == 0
    s = elementary.sign_split((2 * a - 2 * x) / (2 * sp.sqrt(1 - 1 / q) * q ** sp.Rational(3, 2)), x)
    assert s.P == 0 and sp.simplify(s.Q + 1 / q) == 0
    assert elementary.sign_split(sp.acos(x / sp.sqrt(x**2 + 1)), x) is None  # (smooth: not this shape)
    assert elementary.sign_split(sp.sqrt(x**2 + 1), x) is None


def _f5(a: float):
    return load_text(f"param a = {a}\nint ([-1, 1]) atan2(x - a, -1) d(x)\n").program


@pytest.mark.parametrize("a", [0.3, -0.4])
def test_f5_derivative_in_closed_form(a):
    """main: quadrature after ~36 CPU s.  ⟦p⟧ = ∫ −π − atan(x − a) below a, π − atan(x − a) above:
    ∂a = −2π (the jump's delta) + atan(1 − a) + atan(1 + a)."""
    d = exact.exact_deriv(_f5(a), {"a": a}, {"a": 1})
    assert d.method == Method.CLOSED_FORM
    assert d.value == pytest.approx(-2 * math.pi + math.atan(1 - a) + math.atan(1 + a), abs=1e-12)
    assert d.boundary == pytest.approx(-2 * math.pi, abs=1e-12)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds is True


def _g(t: float) -> float:  # ∫ atan t dt
    return t * math.atan(t) - math.log1p(t * t) / 2


@pytest.mark.parametrize("a", [0.3, 1.5])
def test_f5_value_in_closed_form(a):
    """⟦p⟧ = −π(min(a, 1) + 1) + π(1 − min(a, 1)) − [t·atan t − ½log(1 + t²)] from −1 − a to 1 − a
    (a = 1.5: no jump in the box, −2π − that)."""
    v = exact.exact_eval(_f5(a), {"a": a})
    m = min(a, 1.0)
    assert v.method == Method.CLOSED_FORM
    assert v.value == pytest.approx(-math.pi * (m + 1) + math.pi * (1 - m) - (_g(1 - a) - _g(-1 - a)), abs=1e-12)


def test_atan2_with_a_positive_x_and_a_scaled_y():
    """atan2(2x − a, 3) = atan((2x − a)/3) (no jump): ∂a ∫_{−1}^{1} = −(atan((2 − a)/3) +
    atan((2 + a)/3))/2 by hand (u = 2x − a)."""
    text = "param a = 0.3\nint ([-1, 1]) atan2(2 * x - a, 3) d(x)\n"
    d = exact.exact_deriv(load_text(text).program, {"a": 0.3}, {"a": 1}, check=False)
    assert d.method == Method.CLOSED_FORM
    assert d.value == pytest.approx(-(math.atan(1.7 / 3) + math.atan(2.3 / 3)) / 2, abs=1e-12)
