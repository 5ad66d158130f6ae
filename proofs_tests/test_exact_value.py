"""A closed form's value at the evaluation point is computed from the point's exact values: a
closed form that is exactly 0 there is 0, not the cancellation noise of substituting 40-digit
floats (`langur show --raw examples/raytrace/scene.lgr` printed −1.17549435082e-38 for a pixel
the depth threshold leaves empty)."""

from __future__ import annotations

from fractions import Fraction

import pytest
import sympy as sp

from langur.denote import denote_program
from langur.frontend import load_text
from langur.symbolic.context import Context
from langur.symbolic.pieces import Method
from langur.timebox import Deadline

# a pixel [px, px + h]² and two half-planes: 7/5 − x − 3y/2 ≥ 0 holds on the pixels below, and
# x ≥ 1/5 + y/3 holds on none of the pixel at px = 0 (x ≤ 3/200), on the right 5/6 of it at px = 1/5:
# ∫₀ʰ (h − y/3) dy / h² = 1 − 1/6
PIXEL = ("param px = 0, py = 0, h = 0.015\n"
         "int ([px, px + h], [py, py + h]) [7/5 - x - 3 / 2 * y >= 0] * [x - 1/3 * y - 2/10 >= 0] / h^2 d(x, y)")


@pytest.mark.parametrize("px, expected", [(Fraction(0), 0.0), (Fraction(1, 5), 5 / 6), (Fraction(3, 10), 1.0)])
def test_a_closed_form_is_evaluated_exactly_at_the_point(px, expected):
    r = denote_program(load_text(PIXEL).program, {"px": px, "py": 0, "h": Fraction(3, 200)})
    assert r.method == Method.CLOSED_FORM
    if expected == 0.0:
        assert r.value == 0.0  # exactly: no 1e-38 of cancellation
    else:
        assert r.value == pytest.approx(expected, rel=1e-14)


def test_exact_value_substitutes_the_rationals_as_they_are():
    a = sp.Symbol("a", real=True)
    ctx = Context({a: sp.Integer(0)}, Deadline(5.0))
    zero = 7 * (a + sp.Rational(1, 3)) ** 2 - 7 * (a ** 2 + 2 * a / 3 + sp.Rational(1, 9))  # ≡ 0, not expanded
    assert ctx.exact_value(zero) == 0
    ctx = Context({a: sp.Rational(1, 7)}, Deadline(5.0))
    assert ctx.exact_value(sp.Max(a, (3 * a + 1) / 7) ** 2) == pytest.approx(100 / 2401, rel=1e-15)
