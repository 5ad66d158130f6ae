"""Values that leave the floating-point range on the way (§8.2's quadrature at the parameter values).

The exact engine cross-checks a closed form against a floating-point quadrature.  Where an
integrand's *intermediate* values overflow although its value does not (``exp(800 x)·exp(−800 x)``
is ``inf · 0`` in floating point), or a condition's value overflows (``exp(1000 x) − a`` near
``x = 1``), the quadrature used to see NaN: it called a finite integral undefined, or put a jump in
the wrong place and reported a wrong value with a tight bound.  Such points are now evaluated
again by mpmath (unbounded exponents).  An integrand whose values themselves exceed the float
range gives no value (``ExactUnavailable``), never "undefined".  Every expected value is worked
out by hand in the test.
"""

from __future__ import annotations

import math

import pytest

from langur import exact as api
from langur import frontend
from langur.cli import main
from langur.commands import _common as c


def _program(text: str):
    return frontend.load_text(text).program


def test_intermediate_overflow_is_not_undefined():
    # ∫₀¹ exp(800 x)·exp(−800 x + a) dx = e^a (by hand); in floats the product is inf·0 for x > 0.89
    p = _program("param a = 0.5\nint ([0, 1]) exp(800 * x) * exp(-800 * x + a) d(x)\n")
    r = api.exact_eval(p, {"a": 0.5})
    assert abs(float(r.value) - math.exp(0.5)) <= 1e-12
    # ∫₀² e^{400x}/(e^{400x} + a) dx = [log(e^{400x} + a)/400]₀² = (800 + log1p(a e^{-800}) − log(1 + a))/400
    p = _program("param a = 0.5\nint ([0, 2]) exp(400 * x) / (exp(400 * x) + a) d(x)\n")
    r = api.exact_eval(p, {"a": 0.5})
    assert abs(float(r.value) - (800 - math.log(1.5)) / 400) <= 1e-12


def test_the_quadrature_itself_values_an_intermediate_overflow():
    # the number the closed form is checked against: quadrature alone (no closed form sought)
    from langur.denote import denote_program

    p = _program("param a = 0.5\nint ([0, 1]) exp(800 * x) * exp(-800 * x + a) d(x)\n")
    q = denote_program(p, {"a": 0.5}, symbolic=False)
    assert abs(q.value - math.exp(0.5)) <= q.error + 1e-12 and q.error < 1e-6


def test_a_condition_whose_value_overflows_is_cut_at_its_root():
    # [exp(1000 x) ≥ a] on [0, 1]: x ≥ log(a)/1000, so ⟦p⟧ = 1 − log(a)/1000 and d/da = −1/(1000 a) (by
    # hand).  The quadrature used to read NaN past x ≈ 0.71 (exp overflows) and report 0.708 ± 2e-10.
    p = _program("param a = 5\nint ([0, 1]) [exp(1000 * x) - a >= 0] d(x)\n")
    r = api.exact_eval(p, {"a": 5})
    assert abs(float(r.value) - (1 - math.log(5) / 1000)) <= 1e-12 and not r.inconsistent
    d = api.exact_deriv(p, {"a": 5}, {"a": 1})
    assert abs(float(d.value) + 1 / 5000) <= 1e-12


def test_values_beyond_the_float_range_give_no_value_not_undefined():
    # ∫₀¹ exp(1000 x + a) dx = (e^{1000+a} − e^a)/1000 ≈ 3.2e431: it exists, a float cannot hold it
    p = _program("param a = 0.5\nint ([0, 1]) exp(1000 * x + a) d(x)\n")
    with pytest.raises(api.ExactUnavailable, match="too large for a float") as info:
        api.exact_eval(p, {"a": 0.5})
    assert not isinstance(info.value, api.ExactUndefined)


def test_an_integrand_undefined_on_an_interval_stays_undefined():
    # sqrt(x − 2) is not real anywhere on [0, 1]: NaN, which mpmath does not turn into a number
    p = _program("int ([0, 1]) sqrt(x - 2) d(x)\n")
    with pytest.raises(api.ExactUndefined):
        api.exact_eval(p, {})


def test_eval_says_no_value_and_not_undefined(tmp_path, capsys):
    f = tmp_path / "big.lgr"
    f.write_text("param a = 0.5\nint ([0, 1]) exp(1000 * x + a) d(x)\n")
    main(["eval", str(f), "--samples", "1000"])
    out, err = capsys.readouterr()
    assert "no exact value" in err and "too large for a float" in err
    assert "exact : undefined" not in out and "does not exist" not in out


def test_tiny_and_huge_estimates_in_scientific_notation():
    # the value to the place of the standard error's second digit: 2.911e-73 ± 2.4e-74 → 2.91e-73
    assert (c.fmt_mc(2.911e-73, 2.4e-74), c.fmt_se(2.4e-74, 2.911e-73)) == ("2.91e-73", "2.4e-74")
    assert (c.fmt_mc(1.23456789e20, 1.5e17), c.fmt_se(1.5e17, 1.23456789e20)) == ("1.2346e+20", "1.5e+17")
    assert (c.fmt_mc(3.992450112, 0.0305), c.fmt_se(0.0305, 3.992450112)) == ("3.992", "0.030")  # as before


def test_monte_carlo_says_when_a_delta_score_is_too_large_for_a_float():
    # the delta on x + y = 2a + 1/2 is scored with exp(500 x + 500 y)·exp(−500 x − 500 y): inf·0 in doubles
    # for x + y > 1.42, which is where that line lies (x + y = 1.5): the boundary estimate is NaN, and says why
    from langur import operational

    loaded = frontend.load_text("param a = 0.5\nint ([0, 1], [0, 1]) [x + y <= 2 * a + 0.5] * "
                                "exp(500 * x + 500 * y) * exp(-500 * x - 500 * y) d(x, y)\n")
    d = operational.estimate_derivative(loaded, {"a": 0.5}, {"a": 1.0}, samples=2000, seed=1)
    assert not math.isfinite(d.boundary.value)
    assert any("on the discontinuities are not finite" in n for n in d.notes)
    ok = frontend.load_text("param a = 0.5\nint ([0, 1], [0, 1]) [x + y <= 2 * a + 0.5] d(x, y)\n")
    d = operational.estimate_derivative(ok, {"a": 0.5}, {"a": 1.0}, samples=2000, seed=1)
    assert not any("not finite" in n for n in d.notes)
    # ∂/∂a of the area of {x + y ≤ 2a + 1/2} in [0,1]² at a = 1/2: (2 − 1.5)·2 = 1 (by hand)
    assert abs(d.value - 1.0) <= 5 * d.stderr + 1e-9
