"""Powers too large to compute exactly are refused (T234) where ⟦·⟧ is computed in sympy.

The exact engine and the checker compute with exact rationals: a parameter's value or a constant
raised to ``k`` has about ``k`` times its bits, and ``a ^ 100000000`` or ``10 ^ 10 ^ 10`` took
the checker and the completion of a condition to their time limits (60 s, 600 s).  The bound is
on the exponent multiplied along nested powers and ``let``s (after inlining: calls too), 4096;
a product of powers is not bounded (it adds degrees).  The Monte Carlo engine computes in doubles
and still answers.  Values at the bound are computed exactly (checked against the hand derivative).
"""

import math
from fractions import Fraction

import pytest

from langur import sympy_bridge as sb
from langur import transversality as tv
from langur.diagnostics import LangurError
from langur.exact import exact_deriv
from langur.frontend import load_text
from langur.operational import estimate_derivative

HEAVY = [
    "param a = 0.5\nint ([0, 1]) [x <= a] * (a ^ 64) ^ 65 d(x)\n",
    "param a = 0.5\nint ([0, 1]) [x <= a] * (let y = a ^ 64 in y ^ 65) d(x)\n",
    "def f(t: param) = t ^ 64\nparam a = 0.5\nint ([0, 1]) [x <= a] * f(f(f(a))) d(x)\n",
    "param a = 0.5\nint ([0, 1]) [x <= a] * a ^ 4097 d(x)\n",
    "param a = 0.5\nint ([0, 1]) [x <= a] * a ^ (1/4097) d(x)\n",
]
LIGHT = [
    "param a = 0.5\nint ([0, 1]) [x <= a] * (a ^ 64) ^ 64 d(x)\n",
    "param a = 0.5\nint ([0, 1]) [x <= a] * (let y = a ^ 64 in y ^ 64) d(x)\n",
    "def f(t: param) = t ^ 64\nparam a = 0.5\nint ([0, 1]) [x <= a] * f(f(a)) d(x)\n",
    "param a = 0.5\nint ([0, 1]) [x <= a] * a ^ 4096 * (x ^ 64 + a ^ 64) ^ 64 d(x)\n",  # a product adds
]


@pytest.mark.parametrize("text", HEAVY)
def test_a_power_past_the_bound_is_refused_by_the_exact_engine_and_the_mc_engine_still_answers(text):
    program = load_text(text, "t.lgr").program
    assert sb.exponent_weight(program.body) > sb.MAX_EXPONENT
    with pytest.raises(LangurError) as e:
        exact_deriv(program, {"a": Fraction(1, 2)}, {"a": 1})
    assert [d.code for d in e.value.diagnostics] == ["T234"] and e.value.diagnostics[0].span is not None
    mc = estimate_derivative(program, {"a": 0.5}, {"a": 1.0}, samples=100, seed=0)
    assert math.isfinite(mc.value)


@pytest.mark.parametrize("text", LIGHT)
def test_a_power_at_the_bound_is_computed(text):
    program = load_text(text, "t.lgr").program
    assert sb.exponent_weight(program.body) <= sb.MAX_EXPONENT
    assert math.isfinite(exact_deriv(program, {"a": Fraction(1, 2)}, {"a": 1}, check=False).value)


def test_the_largest_power_is_computed_exactly():
    # ∫₀¹ a^4096 · [x <= 1/2] dx = a^4096 / 2, so d/da = 2048 · a^4095 (by hand)
    text = "param a = 1.0001\nint ([0, 1]) (a ^ 64) ^ 64 * [x <= 1/2] d(x)\n"
    d = exact_deriv(load_text(text, "t.lgr").program, {"a": Fraction(10001, 10000)}, {"a": 1})
    assert d.value == pytest.approx(2048 * math.pow(1.0001, 4095), rel=1e-12)


@pytest.mark.parametrize("text", ["param a = 0.5\nint ([0, 1]) [x <= a ^ 100000000] d(x)\n",
                                  "param a = 0.5\nint ([0, 1]) [x <= 10 ^ 10 ^ 10] * [x <= a] d(x)\n"])
def test_a_huge_power_in_a_condition_is_refused_when_it_is_loaded_or_checked(text):
    # (the hostile corpus runs these through every command in a subprocess: test_hostile)
    try:
        loaded = load_text(text, "t.lgr")
        tv.check_loaded(loaded, at={"a": 0.5}, sources={"t.lgr": text})
    except LangurError as e:
        assert [d.code for d in e.diagnostics] == ["T234"]
    else:
        pytest.fail("no T234")


def test_a_power_combined_by_the_completion_is_refused_at_its_condition():
    # each factor is within the bound, but sympy combines the product into a^1200000 when it solves
    # the condition for x: that power is refused too, located at the condition (it was <unknown>:1:1)
    product = " * ".join(["a^4000"] * 300)
    text = f"param a = 0.7\nint ([0, 1]) [x <= {product}] d(x)\n"
    loaded = load_text(text, "t.lgr")
    with pytest.raises(LangurError) as info:
        tv.check_loaded(loaded, at={"a": 0.7}, sources={"t.lgr": text})
    (d,) = info.value.diagnostics
    assert d.code == "T234" and d.format().startswith("t.lgr:2:14: error T234")  # 2:14: the condition's bracket
    with pytest.raises(LangurError) as info:  # the exact engine, which decomposes the same completion
        exact_deriv(loaded.program, {"a": Fraction(7, 10)}, {"a": 1})
    assert [d.format()[:20] for d in info.value.diagnostics] == ["t.lgr:2:14: error T2"]
