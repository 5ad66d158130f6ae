"""exact10 (issue 15): work the exact engine repeats, remembered without changing a result.

* ``context.Context.value`` remembers its 30-digit values per (expression, point): each value is
  sympy's own ``evalf`` of the expression with the point's 40-digit floats put in (computed here
  independently), Floats of other precisions are not confused, and another point is another key.
"""

from __future__ import annotations

import sympy as sp

from langur.symbolic import context, solving
from langur.timebox import Deadline


def _ctx(at):
    return context.Context(dict(at), Deadline(5.0), frozenset(at))


def _by_sympy(expr, at) -> complex:
    # independently: the point's values as 40-digit floats, sympy's evalf to 30 digits
    return complex(sp.sympify(expr).subs({k: sp.Float(float(v), 40) for k, v in at.items()}).evalf(30))


def test_value_is_sympys_evalf_and_repeats_give_the_same():
    a, b = sp.symbols("a b")
    at = {a: sp.Rational(3, 7), b: sp.Rational(-2, 5)}
    ctx = _ctx(at)
    for e in [sp.sqrt(a**2 + b**2) - a / 3, sp.exp(a) * sp.cos(b), (a - b) / (a + 2 * b + 1), sp.log(a) + sp.I * b]:
        first = ctx.value(e)
        assert first == _by_sympy(e, at)
        assert ctx.value(e) == first  # remembered
        assert _ctx(at).value(e) == first  # another context at the same point
    # a value asked again at another point is that point's
    other = {a: sp.Rational(1, 2), b: sp.Rational(1, 3)}
    e = sp.sqrt(a**2 + b**2) - a / 3
    assert _ctx(other).value(e) == _by_sympy(e, other) != ctx.value(e)
    assert abs(_ctx(other).value(e) - (sp.sqrt(sp.Rational(13, 36)) - sp.Rational(1, 6))) < 1e-15


def test_floats_of_other_precisions_are_other_keys():
    a = sp.Symbol("a")
    at = {a: sp.Rational(1, 3)}
    ctx = _ctx(at)
    lo, hi = sp.Float("0.1", 3) * a, sp.Float("0.1", 40) * a  # 0.1 rounded to 3 and 40 digits
    assert lo != hi
    assert ctx.value(lo) == _by_sympy(lo, at)
    assert ctx.value(hi) == _by_sympy(hi, at)
    assert ctx.value(hi) != ctx.value(lo)


def test_no_value_is_an_error_each_time():
    a, z = sp.symbols("a z")
    ctx = _ctx({a: sp.Rational(1, 2)})
    for _ in range(2):
        try:
            ctx.value(a + z)
        except ValueError as e:
            assert "z" in str(e)
        else:
            raise AssertionError("a free symbol has no value")


def test_closed_roots_remembered_per_point():
    # x² − a: roots ±√a where a > 0 (by hand), none where a < 0; (x − a)/(x − 2a): root a, pole 2a
    x, a = sp.symbols("x a")
    cond = context.Cond(x**2 - a)
    for _ in range(2):
        four = _ctx({a: sp.Integer(4)})
        rs = solving._closed_roots(cond, x, four)
        assert sorted(complex(four.value(r)).real for r in rs) == [-2.0, 2.0]
        assert solving._closed_roots(cond, x, _ctx({a: sp.Integer(-1)})) == []
        rat = context.Cond((x - a) / (x - 2 * a))
        rs = solving._closed_roots(rat, x, _ctx({a: sp.Rational(1, 3)}))
        assert [sp.simplify(r - w) for r, w in zip(rs, [a, 2 * a])] == [0, 0]
    # a root that does not vanish at the point is not one (the check is per point, not per formula)
    assert not solving._vanishes_at(x**2 - a, x, sp.sqrt(a), _ctx({a: sp.Integer(-1)}))
    assert solving._vanishes_at(x**2 - a, x, sp.sqrt(a), _ctx({a: sp.Integer(2)}))


def test_shared_lambdify_gives_the_function_in_use_and_its_values():
    # the same (arguments, expression, module) while the first function is in use: that function;
    # its values are sympy.lambdify's and math's, computed independently
    import math

    from langur.symbolic.text import shared_lambdify

    x, a = sp.symbols("x a")
    e = sp.sqrt(x**2 + a) * sp.cos(x) - a / (x + 2)
    f = shared_lambdify([x, a], e, "math")
    assert shared_lambdify([x, a], e, "math") is f
    assert shared_lambdify([a, x], e, "math") is not f  # other arguments: another function
    ref = sp.lambdify([x, a], e, modules=["math"])
    for xv, av in [(0.3, 1.5), (-1.25, 0.5), (2.0, 7.0)]:
        assert f(xv, av) == ref(xv, av)
        assert abs(f(xv, av) - (math.sqrt(xv**2 + av) * math.cos(xv) - av / (xv + 2))) < 1e-12
    lo = shared_lambdify([x], sp.Float("0.1", 3) * x, "math")
    hi = shared_lambdify([x], sp.Float("0.1", 40) * x, "math")
    assert lo is not hi  # Floats of other precisions: other functions, each sympy.lambdify's
    for fn, c in ((lo, sp.Float("0.1", 3)), (hi, sp.Float("0.1", 40))):
        assert fn(3.0) == sp.lambdify([x], c * x, modules=["math"])(3.0)


def test_shared_lambdify_makes_a_gone_function_again():
    import gc

    from langur.symbolic.text import shared_lambdify

    x = sp.Symbol("x")
    e = sp.exp(x) - 3 * x
    name = shared_lambdify([x], e, "math").__code__.co_filename  # not kept by anything
    gc.collect()
    g = shared_lambdify([x], e, "math")
    same = g.__code__.co_filename == name
    value = g(0.5)
    assert not same
    assert value == sp.lambdify([x], e, modules=["math"])(0.5)
