"""Theorem 8.1's exact values of large rational closed forms by fixed-point balls (issue 15,
stylize/quadratic's one-shot partial derivatives, exact16r).

The check differentiates ⟦p⟧'s closed form along γ' (:func:`langur.theorem._line_derivative`) and
evaluates ⦇p⦈'s and its cell's relations (:func:`langur.theorem._large_closed_form_at`) exactly, at
the parameters and at three nearby float points; it reads only the exact values' doubles and signs.
At the float points (dyadic rationals of ~55 bits) the Fractions carried hundreds of digits and
most of the time went to reducing them.  :mod:`langur.symbolic.rational` now first encloses each
value in a ball of 192-bit fixed-point integers and takes its double when both ends of the ball
round to the same double (rounding is monotone), its sign when the ball excludes 0; otherwise the
exact Fractions as before.  Checked here: every ball operation encloses the exact result (random
rationals, exact arithmetic); the doubles and signs equal those of sympy's own exact values and of
the old exact path on random forms at random float and rational points; the cases a ball cannot
decide (exactly 0, a tie between two doubles, Abs at 0, a division by 0) give the exact path's
answer; stylize/quadratic's check decides without the exact Fractions and its verdict, points and
numbers are the exact path's.
"""

from __future__ import annotations

import random
from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp

from langur import theorem
from langur.symbolic import balls, exactpairs, rational, tape
from langur.symbolic.balls import BALL_BITS
from langur.symbolic.rational import (
    dual_derivative,
    dual_derivative_float,
    float_value,
    rational_value,
    sign_value,
)

X, Y, Z = sp.symbols("x y z", real=True)
SCALE = Fraction(1, 2 ** BALL_BITS)
EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _inside(ball, exact: Fraction) -> bool:
    m, r = ball
    return r >= 0 and (m - r) * SCALE <= exact <= (m + r) * SCALE


def _ball(q: Fraction):
    return balls._bconst(q.numerator, q.denominator)


def _random_rational(rng) -> Fraction:
    if rng.random() < 0.5:  # a float's dyadic rational, as at the check's nearby points
        return Fraction(rng.uniform(-3, 3))
    return Fraction(rng.randint(-50, 50), rng.randint(1, 40))


def test_ball_operations_enclose_the_exact_results():
    rng = random.Random(16)
    for _ in range(400):
        p, q = _random_rational(rng), _random_rational(rng)
        bp, bq = _ball(p), _ball(q)
        assert _inside(bp, p) and _inside(bq, q)
        assert _inside(balls._bmul(bp, bq), p * q)
        # widened balls: the enclosure holds for every point of the operands' balls
        wp, wq = (bp[0], bp[1] + rng.randint(0, 10 ** 6)), (bq[0], bq[1] + rng.randint(0, 10 ** 6))
        for dp in (-wp[1], 0, wp[1]):
            for dq in (-wq[1], 0, wq[1]):
                a, b = Fraction(wp[0] + dp) * SCALE, Fraction(wq[0] + dq) * SCALE
                assert _inside(balls._bmul(wp, wq), a * b)
                for k in (2, 3, 5):
                    assert _inside(balls._bpow(wp, k), a ** k)
                if a != 0 and abs(wp[0]) > wp[1]:
                    assert _inside(balls._binv(wp), 1 / a)
                    assert _inside(balls.BALLS.power(wp, -3), a ** -3)
    with pytest.raises(balls.Uncertain):
        balls._binv((5, 5))  # holds 0
    with pytest.raises(balls.Uncertain):
        balls.BALLS.power((0, 1), -2)


def _random_form(rng, depth=0):
    """A random form of rationals, x, y, z, +, ·, integer powers (some negative) and Abs."""
    if depth > 3 or rng.random() < 0.25:
        return rng.choice([X, Y, Z, sp.Rational(rng.randint(-9, 9), rng.randint(1, 7))])
    kind = rng.randrange(5)
    if kind == 0:
        return sp.Add(*[_random_form(rng, depth + 1) for _ in range(rng.randint(2, 4))])
    if kind == 1:
        return sp.Mul(*[_random_form(rng, depth + 1) for _ in range(rng.randint(2, 3))])
    if kind == 2:
        return sp.Pow(_random_form(rng, depth + 1), rng.choice([2, 3, -1, -2]))
    if kind == 3:
        return sp.Abs(_random_form(rng, depth + 1))
    return _random_form(rng, depth + 1) + 1


def _sympy_slope(form, point, tangent):
    """d/ds form(point + s·tangent) at s = 0 by sympy, exactly (None where sympy gives no finite
    rational: a pole, Abs at 0)."""
    s = sp.Symbol("s", real=True)
    line = form.xreplace({k: v + s * tangent[k] for k, v in point.items()})
    try:
        d = sp.diff(line, s).xreplace({s: 0})
    except ZeroDivisionError:
        return None
    d = sp.nsimplify(d) if d.has(sp.Abs, sp.sign) else d
    return d if isinstance(d, sp.Rational) else None


def test_doubles_and_signs_equal_the_exact_values_on_random_forms():
    rng = random.Random(1616)
    compared = 0
    for _ in range(250):
        form = _random_form(rng)
        point = {v: sp.Rational(_random_rational(rng)) for v in (X, Y, Z)}
        tangent = {v: sp.Rational(rng.choice([0, 1, -2, Fraction(1, 3)])) for v in (X, Y, Z)}
        exact = rational_value(form, point)
        truth = form.xreplace(point)  # sympy's exact value
        if exact is not None:
            assert exact == Fraction(int(truth.p), int(truth.q))
            assert float_value(form, point) == float(exact)
            assert sign_value(form, point) == (exact > 0) - (exact < 0)
        else:
            assert float_value(form, point) is None and sign_value(form, point) is None
        slope = dual_derivative(form, point, tangent)
        got = dual_derivative_float(form, point, tangent)
        assert got == (None if slope is None else float(slope))
        if slope is not None and not form.has(sp.Abs):
            d = _sympy_slope(form, point, tangent)
            assert d is not None and Fraction(int(d.p), int(d.q)) == slope
            compared += 1
    assert compared > 50


def test_what_a_ball_cannot_decide_is_the_exact_answer():
    zero = sp.Add((X + 1) ** 2, -X ** 2, -2 * X, -1, evaluate=False)  # exactly 0 at every point
    at = {X: sp.Rational(Fraction(0.3))}
    assert float_value(zero, at) == 0.0 and sign_value(zero, at) == 0
    assert dual_derivative_float(zero * X, at, {X: 1}) == 0.0
    tie = X + sp.Rational(1, 2 ** 53)  # 1 + 2⁻⁵³ at x = 1: halfway between two doubles
    assert float_value(tie, {X: sp.Integer(1)}) == float(Fraction(2 ** 53 + 1, 2 ** 53)) == 1.0
    above = X + sp.Rational(1, 2 ** 53) + sp.Rational(1, 2 ** 300)  # just above the tie: rounds up
    assert float_value(above, {X: sp.Integer(1)}) == 1.0 + 2.0 ** -52
    assert float_value(1 / (X - 1), {X: sp.Integer(1)}) is None  # division by 0
    assert dual_derivative_float(sp.Abs(X - 1), {X: sp.Integer(1)}, {X: 1}) is None  # Abs at 0
    assert dual_derivative_float(sp.sin(X), {X: sp.Integer(1)}, {X: 1}) is None  # not rational
    assert float_value(X * Y, {X: sp.Integer(1)}) is None  # y has no value


def _stylize_check(monkeypatch, exact_only: bool):
    from langur.exact import exact_deriv
    from langur.frontend import load

    for memo in (tape.TAPES, exactpairs.VALUES, balls.BALL_VALUES):
        memo.clear()
    if exact_only:  # the old path: the exact Fractions' doubles and signs
        monkeypatch.setattr(theorem, "dual_derivative_float", lambda e, p, t: (
            None if (v := dual_derivative(e, p, t)) is None else float(v)))
        monkeypatch.setattr(theorem, "float_value", lambda e, p: (
            None if (v := rational_value(e, p)) is None else float(v)))
        monkeypatch.setattr(theorem, "sign_value", lambda e, p: (
            None if (v := rational_value(e, p)) is None else (v > 0) - (v < 0)))
    else:  # the balls decide every value: the exact Fractions are never made
        def refuse(*args, **kwargs):
            raise AssertionError("the exact path was taken")
        monkeypatch.setattr(rational, "dual_derivative", refuse)
        monkeypatch.setattr(rational, "rational_value", refuse)
    loaded = load(str(EXAMPLES / "stylize" / "quadratic.lgr"))
    at = loaded.param_values()
    r = exact_deriv(loaded.program, at, {q: int(q == "ay") for q in at})
    th = r.theorem_8_1
    return (r.value, th.holds, str(th.how), th.d_denotation, th.derivative_denotation, th.notes,
            [(p.params, p.d_denotation, p.derivative_denotation) for p in th.points])


def test_stylize_quadratic_check_unchanged(monkeypatch):
    with monkeypatch.context() as m:
        old = _stylize_check(m, exact_only=True)
    with monkeypatch.context() as m:
        new = _stylize_check(m, exact_only=False)
    assert new == old
    assert old[1] is True and old[2] == "numeric" and len(old[6]) == 4
    assert "at 3 of them ⦇p⦈ is its closed form, exactly" in old[5][-1]
