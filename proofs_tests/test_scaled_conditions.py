"""Conditions with tiny coefficients are conditions, not zeros (paper Def. 7.2, §7.3; the delta
pieces of Theorem 7.1).

``[y / 10^13 >= 0]`` is ``[y >= 0]``: the linter's "vanishes identically on the zero set"
(:func:`langur.lint.algebra.vanishes`) and the quadrature's (``deltaproblems._vanishes``) read a
value against the size of the terms it is made of (:func:`langur.sympy_bridge.magnitude`), and the
linter decides a rational function exactly by ``cancel``.  Before, both took every value below an
absolute 10⁻⁸ / 10⁻¹² for 0: the linter reported X301 (two conditions with "the same zero set
x = theta") and the exact engine refused the program, and the quadrature counted the condition
as TRUE on the zero set and doubled the derivative.

The expected values are by hand: d/dθ ∫₀¹∫₋₁¹ [x ≤ θ]·[y ≥ 0] dy dx = ∫₋₁¹ [y ≥ 0] dy = 1.
"""

import math

import pytest
import sympy as sp

from langur import transversality as tv
from langur.exact import exact_deriv
from langur.frontend import load_text
from langur.lint import algebra
from langur.symbolic.quadrature import deltaproblems
from langur.sympy_bridge import magnitude

x, y, t = sp.symbols("x y t", real=True)
TINY = sp.Rational(1, 10**13)

SCALED = """param theta = 0.5
int ([0, 1], [-1, 1]) [x <= theta] * [y / 10000000000000 >= 0] d(x, y)
"""
PLAIN = SCALED.replace("y / 10000000000000", "y")


@pytest.mark.parametrize("text", [SCALED, PLAIN], ids=["scaled", "plain"])
def test_a_scaled_condition_is_transverse_and_its_derivative_is_the_hand_value(text):
    loaded = load_text(text, "t.lgr")
    assert [f.code for f in tv.check_loaded(loaded, at={"theta": 0.5}, sources={"t.lgr": text})] == []
    d = exact_deriv(loaded.program, {"theta": sp.Rational(1, 2)}, {"theta": 1})
    assert d.value == pytest.approx(1.0, abs=1e-12)
    assert not any("internal error" in n for n in d.notes)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds is True


@pytest.mark.parametrize("expr", [y * TINY, x * TINY - y * TINY, (y * TINY) ** 3, y * TINY / (1 + x**2)])
def test_the_linter_decides_a_small_rational_function_is_not_zero(expr):
    assert not algebra.vanishes(expr, (x, y))


@pytest.mark.parametrize("expr", [(x + 1) ** 2 - x**2 - 2 * x - 1, TINY * ((x + y) ** 2 - x**2 - 2 * x * y - y**2),
                                  1 / (x - 3) - 1 / (x - 3)])
def test_the_linter_still_finds_a_rational_function_that_is_zero(expr):
    assert algebra.vanishes(expr, (x, y))


def test_the_linter_reads_a_small_transcendental_value_against_its_terms():
    # simplify cannot show y/10^13·sin(y) is 0 (it is not); its values are all of its size
    assert not algebra.vanishes(y * TINY * sp.sin(y) + TINY * sp.exp(x) * y, (x, y))
    # and a zero that expand and cancel miss but simplify finds still vanishes
    assert algebra.vanishes(TINY * (sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1), (x,))


def test_magnitude_bounds_the_value_and_keeps_a_cancelling_sum_large():
    e = (x + 1) ** 2 - x**2 - 2 * x - 1
    assert e != 0  # (sympy keeps the sum as written)
    m = magnitude(e)
    for xv in (-1.5, 0.25, 3.0):
        assert float(m.subs(x, xv)) >= 1.0
    f = y * TINY * sp.sin(x) - 3 * x**2 * y
    mf = magnitude(f)
    for xv, yv in ((0.3, -0.7), (-1.2, 0.4), (2.0, 1.5)):
        assert abs(float(f.subs({x: xv, y: yv}))) <= float(mf.subs({x: xv, y: yv})) * (1 + 1e-15)
    assert magnitude(y * TINY).subs(y, -2) == 2 * TINY  # a single term is all of its own size


@pytest.mark.parametrize("expr, zero", [(y * TINY, False), (t * TINY - y * TINY, False),
                                        (TINY * ((t + y) ** 2 - t**2 - 2 * t * y - y**2), True),
                                        (sp.Integer(10**6) * ((t + y) ** 2 - t**2 - 2 * t * y - y**2), True)])
def test_the_quadratures_zero_set_test_is_relative_to_the_terms(expr, zero):
    # the delta pieces' front: a condition substituted on another's zero set; t a parameter
    assert deltaproblems._vanishes(expr, [y], [(-1.0, 1.0)], {t: sp.Rational(1, 2)}) is zero
    assert math.isfinite(float(expr.subs({t: 0.5, y: 0.3})))
