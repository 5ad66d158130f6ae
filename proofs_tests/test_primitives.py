"""The primitive registry (``langur.primitives``, LANGUAGE.md §1): every interpreter covers every
primitive, and each entry's facts agree with each other and with sympy.

For each primitive f and a point a inside its domain, the program ``int f(a)·[0 ≤ x ≤ 1] d(x)``
has value f(a) and derivative f'(a) in the parameter a.  The exact engine (sympy), the compiled
Monte Carlo engine and the naive evaluator must all give them (the integrand is constant in x, so
the Monte Carlo estimates have no variance and must agree to rounding).  The values are checked
against Python's ``math`` module and against sympy's own derivative — computed independently of
the registry's numpy rules.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from langur import operational
from langur.core import Const, Mul, Param, Prim, Program, Var
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import core_term_from_text
from langur.lint.domains import _Eval
from langur.operational import naive
from langur.operational.interval import enclose
from langur.primitives import ALL_PRIMITIVES, PRIMITIVES, REGISTRY, Image, Inverse, Periodic
from langur.sympy_bridge import FUNCTIONS, from_sympy, to_sympy
from langur.syntax.printer import print_core

#: A point inside each domain, and one outside (None: defined everywhere).
INSIDE = {"erf": 0.7, "exp": 0.7, "log": 1.7, "sin": 0.7, "cos": 0.7, "tan": 0.7, "sqrt": 1.7, "tanh": 0.7,
          "atan": 0.7, "asin": 0.3, "acos": 0.3, "atanh": 0.3}
OUTSIDE = {"log": -0.5, "sqrt": -0.5, "asin": 1.5, "acos": -1.5, "atanh": 1.5}
#: f(a) by Python's math module (independent of numpy and sympy).
MATH = {"erf": math.erf, "exp": math.exp, "log": math.log, "sin": math.sin, "cos": math.cos, "tan": math.tan,
        "sqrt": math.sqrt, "tanh": math.tanh, "atan": math.atan, "asin": math.asin, "acos": math.acos,
        "atanh": math.atanh}


def _program(op: str) -> Program:
    return Program(Mul(Prim(op, Param("a")), Const(Fraction(1))), ("x",), ((Const(Fraction(0)), Const(Fraction(1))),))


def _derivative_by_sympy(op: str, a: float) -> float:
    y = sp.Symbol("y", real=True)
    return float(sp.diff(FUNCTIONS[op](y), y).subs(y, sp.Rational(repr(a))).evalf(30))


def test_the_surface_primitives_are_the_languages():
    """LANGUAGE.md §1's eight, then those issue 19 adds (each one registry entry): erf, and the
    inverses asin, acos, atanh that completion already used."""
    assert PRIMITIVES == ("exp", "log", "sin", "cos", "tan", "sqrt", "tanh", "atan", "erf", "asin", "acos", "atanh")
    assert set(ALL_PRIMITIVES) == set(MATH)


@pytest.mark.parametrize("op", ALL_PRIMITIVES)
def test_every_engine_computes_each_primitive_and_its_derivative(op):
    a = INSIDE[op]
    value, slope = MATH[op](a), _derivative_by_sympy(op, a)
    program = _program(op)
    exact = denote_program(program, {"a": a})
    assert exact.value == pytest.approx(value, rel=1e-12)
    d_exact = ddenote_program(program, {"a": a}, {"a": 1})
    assert d_exact.value == pytest.approx(slope, rel=1e-12)
    mc = operational.estimate_derivative(program, {"a": a}, {"a": 1.0}, samples=64, seed=1)
    assert mc.value == pytest.approx(slope, rel=1e-12)
    assert operational.estimate_value(program, {"a": a}, samples=64, seed=1).value == pytest.approx(value, rel=1e-12)
    nv = naive.naive_value(program, {"a": a}, samples=8, seed=1)
    nd = naive.naive_derivative(program, {"a": a}, {"a": 1.0}, samples=8, seed=1)
    assert nv.value == pytest.approx(value, rel=1e-12)
    assert nd.value == pytest.approx(slope, rel=1e-12)
    # the linter's numpy evaluator and the registry's scalar rule
    lint = _Eval({"x": np.zeros(1)}, {"a": a}, np.ones(1, dtype=bool)).value(Prim(op, Param("a")), np.ones(1, dtype=bool))
    assert float(lint[0]) == pytest.approx(value, rel=1e-12)
    assert REGISTRY[op].scalar(a) == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize("op", sorted(OUTSIDE))
def test_outside_the_domain_every_numeric_rule_says_undefined(op):
    p, a = REGISTRY[op], OUTSIDE[op]
    assert not p.domain.everywhere
    assert math.isnan(p.scalar(a))
    with np.errstate(all="ignore"):
        assert np.isnan(p.value(np.array([a])))[0]
    assert p.domain.outside_closure(np.array([a]))[0]
    assert p.domain.why
    # sympy agrees that the real function is undefined there
    assert not FUNCTIONS[op](sp.Rational(repr(a))).is_extended_real


@pytest.mark.parametrize("op", ALL_PRIMITIVES)
def test_interval_images_contain_the_function(op):
    p = REGISTRY[op]
    lo, hi = INSIDE[op] - 0.2, INSIDE[op] + 0.2
    ilo, ihi = p.interval(lo, hi)
    ys = [MATH[op](lo + (hi - lo) * k / 50) for k in range(51)]
    assert ilo <= min(ys) and max(ys) <= ihi
    if p.image in (Image.INCREASING, Image.DECREASING):
        assert (ilo, ihi) == pytest.approx((min(ys), max(ys)), rel=1e-12)
    # the Monte Carlo engine's enclosure reads the same fact
    assert enclose(Prim(op, Var("x")), {"x": (lo, hi)}, {}) == (ilo, ihi)


@pytest.mark.parametrize("op", ALL_PRIMITIVES)
def test_exact_values_are_sympys(op):
    for a, b in REGISTRY[op].exact:
        assert FUNCTIONS[op](sp.Rational(a.numerator, a.denominator)) == sp.Rational(b.numerator, b.denominator)


@pytest.mark.parametrize("op", [n for n, p in REGISTRY.items() if p.inverse is not None])
def test_inverses_invert_where_their_guards_hold(op):
    p, u = REGISTRY[op], sp.Rational(3, 10)
    match p.inverse:
        case Inverse(name, guard):
            assert guard is None or guard(u, sp.pi) >= 0
            assert sp.simplify(FUNCTIONS[op](FUNCTIONS[name](u)) - u) == 0
        case Periodic(period, branches, guard):
            assert guard is None or guard(u, sp.pi) >= 0
            for b in branches:
                x = b.sign * FUNCTIONS[b.inverse](u) + b.offset * sp.pi
                assert float(FUNCTIONS[op](x)) == pytest.approx(float(u), rel=1e-12)
                assert float(b.lo) * math.pi <= float(x) <= float(b.hi) * math.pi
                shifted = x + period * sp.pi
                assert float(FUNCTIONS[op](shifted)) == pytest.approx(float(u), rel=1e-12)


@pytest.mark.parametrize("op", ALL_PRIMITIVES)
def test_the_sympy_bridge_goes_both_ways(op):
    t = Prim(op, Param("a"))
    e = to_sympy(t)
    assert e == FUNCTIONS[op](sp.Symbol("a", real=True))
    assert to_sympy(from_sympy(e, (), ("a",))) == e


@pytest.mark.parametrize("op", PRIMITIVES)
def test_the_front_end_reads_and_prints_each_surface_primitive(op):
    t = core_term_from_text(f"{op}(x + 1)", variables=("x",))
    assert isinstance(t, Prim) and t.op == op
    assert core_term_from_text(print_core(t), variables=("x",)) == t
