"""The quadrature's error bound holds whatever the program's scale (paper §8.2's ⟦p⟧ at a point,
§7.3's delta pieces; the standards: a numeric value carries an error bound, and the bound is true).

A breakpoint of the nested quadrature is a root computed in doubles; where the integrand is h next
to it, its rounding δ changes the integral by |h|·δ (:mod:`langur.symbolic.quadrature.rounding`).
``[x − θ + y/10¹³ ≥ 0]``'s delta piece integrates the Jacobian weight 10¹³ over the sliver
x ∈ [θ − 10⁻¹³, θ]: the float root 0.4999999999999 of ``10¹³·x − 4999999999999 ≥ 0`` is 2.4·10⁻¹⁷
from the true one, 2.4·10⁻⁴ of the sliver, and the quadrature gave −0.99976 "± 2e-10" against
the closed form −1: the cross-check refused the (right) closed form and Theorem 8.1 failed.

Hand values: the region of t4 is the sliver θ − y/10¹³ ≤ x ≤ θ (y ≥ 0) of area ∫₀¹ y/10¹³ dy,
independent of θ, so d/dθ = 0 (+1 from [x ≤ θ]'s delta, −1 from the other's); Monte Carlo
(:mod:`langur.operational`) agrees within 5 standard errors.
"""

import math

import pytest
import sympy as sp

from langur import operational
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.symbolic.quadrature.compiling import _lambdify
from langur.symbolic.quadrature.nested import _stepped, integrate_problem
from langur.symbolic.quadrature.problem import NumCond, NumProblem

T4 = """param theta = 0.5
int ([0, 1], [-1, 1]) [x <= theta] * [x - theta + y / 10000000000000 >= 0] d(x, y)
"""

x, y = sp.symbols("x y", real=True)


def _problem(conds, weight, bounds, syms):
    """A NumProblem of polynomial conditions ``expr >= 0`` (each at the level of its last variable)."""
    out = []
    for e in conds:
        lv = max(i for i, s in enumerate(syms) if s in e.free_symbols)
        out.append(NumCond(_lambdify(syms[: lv + 1], e, {}), lv, None, e, sym=e))
    return NumProblem(out, _lambdify(syms, weight, {}), bounds, syms=list(syms), at={}, sbounds=list(bounds))


def test_t4_derivative_is_the_hand_value_and_the_closed_form_is_kept():
    loaded = load_text(T4, "t4.lgr")
    at = loaded.param_values({})
    d = exact_deriv(loaded.program, at, {"theta": 1})
    assert d.value == 0.0
    assert str(d.method) == "closed_form"
    assert not any("internal error" in n or "disagrees" in n for n in d.notes)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds is True
    mc = operational.estimate_derivative(loaded, at, {"theta": 1.0}, samples=20000, seed=3)
    assert abs(mc.value - 0.0) <= 5 * mc.stderr + 1e-9
    assert abs(mc.value - d.value) <= 5 * mc.stderr + 1e-9


def test_t4_value_is_the_sliver_area():
    loaded = load_text(T4, "t4.lgr")
    v = exact_eval(loaded.program, loaded.param_values({}))
    assert v.value == pytest.approx(5e-14, rel=1e-9)


def test_a_sliver_with_a_large_weight_is_within_its_bound():
    # ∫ over [1/2 − 10⁻¹³, 1/2] of 10¹³ = 1: the breakpoint 4999999999999/10¹³ rounds by ~2e-17
    p = _problem([10**13 * x - 4999999999999, sp.Rational(1, 2) - x], sp.Integer(10**13), [(0.0, 1.0)], (x,))
    val, err = integrate_problem(p)
    assert abs(val - 1.0) <= err
    assert abs(val - 1.0) > 1e-6  # (the rounding is real: a bound of 2e-10 was not true)
    assert err < 0.1  # and the bound is still a bound one can use


def test_the_bound_is_carried_out_of_an_inner_level():
    # the same sliver in y for every x in [0, 2]: 2
    p = _problem([10**13 * y - 4999999999999, sp.Rational(1, 2) - y], sp.Integer(10**13),
                 [(0.0, 2.0), (0.0, 1.0)], (x, y))
    val, err = integrate_problem(p)
    assert abs(val - 2.0) <= err
    assert err < 0.2


def test_an_ordinary_problem_keeps_its_tight_bound():
    # ∫₀^½ (x² + 1) dx = 1/24 + 1/2 and ∫∫ [x + y ≤ 1] = 1/2 on [0, 1]²: bounds of ~1e-10 as before
    p = _problem([sp.Rational(1, 2) - x], x**2 + 1, [(0.0, 1.0)], (x,))
    val, err = integrate_problem(p)
    assert abs(val - (1 / 24 + 0.5)) <= err <= 1e-9
    q = _problem([1 - x - y], sp.Integer(1), [(0.0, 1.0), (0.0, 1.0)], (x, y))
    val, err = integrate_problem(q)
    assert abs(val - 0.5) <= err <= 1e-9


def test_the_inner_allowance_is_integrated_cell_by_cell():
    # an allowance of 1 on [0.4, 0.5] only (a cut at 0.4), sampled coarsely outside: about 0.1,
    # not the 0.5 of its largest value times the whole interval
    samples = [(t / 100, 0.0) for t in range(0, 40, 7)] + [(0.4 + k / 1000, 1.0) for k in range(1, 100, 9)]
    got = _stepped(samples, [0.0, 0.4, 0.5])
    assert got == pytest.approx(0.1, rel=1e-12)
    assert math.isclose(_stepped([(0.25, 2.0)], [0.0, 1.0]), 2.0)


@pytest.mark.parametrize("width", [14, 15])
def test_thinner_slivers_keep_the_closed_form(width):
    # 10⁻¹⁵ wide at x = 1/2 is ~9 units in the last place: the two breakpoints coincide within
    # 10⁻¹⁵ and the sub-interval was left out with nothing in the bound (quadrature 0 ± 1e-10
    # against the closed form −1, and the derivative 1 instead of 0)
    text = T4.replace("10000000000000", "1" + "0" * width)
    loaded = load_text(text, "t.lgr")
    at = loaded.param_values({})
    d = exact_deriv(loaded.program, at, {"theta": 1})
    assert d.value == 0.0
    assert not any("internal error" in n for n in d.notes)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds is True
    mc = operational.estimate_derivative(loaded, at, {"theta": 1.0}, samples=20000, seed=5)
    assert abs(mc.value - d.value) <= 5 * mc.stderr + 1e-9
