"""The linter's X313 (Def. 7.2 / Theorem 7.1: ⦇p⦈ must be an integral) looks at each delta term's
weight on each inverse branch of Ψ̂⁻¹ (issue 18: one branch per piece between turning points).  A
branch whose guard is false at the parameters (its piece has no root there) must not be read as
"the weight is undefined on a set of positive measure": its region is empty.  Found by a
``langur fuzz --turning`` campaign (a false X313 on a moving turning point in two variables)."""

import math

from scipy.optimize import brentq

from langur.frontend import load_text
from langur.lint import singular

SOURCE = "param a = 0.5\nparam b = 0.3\nint ([a - 1, 1], [0, 1]) [y ^ 3 - a * y >= b - 0.2] d(x, y)\n"


def test_a_branch_whose_guard_is_false_is_no_blowup():
    loaded = load_text(SOURCE, "guards.lgr")
    res = singular.derivative_integrability(loaded.program, {"a": 0.5, "b": 0.3}, {"a": 1})
    assert res.note is None, res.note
    assert res.divergent == [], res.divergent


def test_its_exact_derivative_is_the_hand_formula():
    """V(a) = (2 − a)(1 − y*(a)), y*³ − a y* = 0.1 on the increasing piece: V' = −(1 − y*) −
    (2 − a) y*/(3y*² − a); the derivative is an integral, so the exact engine gives a number."""
    import sympy as sp

    from langur.exact import exact_deriv

    loaded = load_text(SOURCE, "guards.lgr")
    r = exact_deriv(loaded.program, {"a": sp.Rational(1, 2), "b": sp.Rational(3, 10)}, {"a": 1}, check=False)
    ys = brentq(lambda t: t ** 3 - 0.5 * t - 0.1, 0.41, 1, xtol=1e-15)
    want = -(1 - ys) - 1.5 * ys / (3 * ys * ys - 0.5)
    assert r.value is not None and math.isfinite(float(r.value))
    assert abs(float(r.value) - want) <= 1e-9 + (r.error or 0)
