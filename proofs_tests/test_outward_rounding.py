"""Certified enclosures are proofs (issue 18): the certified tapes of
``langur/operational/interval.py`` round every end outward, and both engines read the sign of
``g`` at a cell's end from a point enclosure, not from ``g`` in doubles.

Checked against mpmath at 60 digits (the constants as exact rationals, the arguments as the
doubles they are): every certified enclosure of random terms over random boxes contains every
value at the boxes' corners and inside; the samplers' round-to-nearest tapes do not (which is why
certification does not use them); and a turning point within rounding of a cell's end, where
round-to-nearest arithmetic certifies a bracket that does not hold the zero, is bracketed right
by both engines.
"""

from __future__ import annotations

import itertools
from fractions import Fraction

import mpmath
import numpy as np
import sympy as sp

from langur.core import Add, Const, Mul, Param, Pow, Prim, Var
from langur.enclosures import certified_brackets as exact_brackets
from langur.enclosures import interval_function
from langur.operational.interval import enclose_all, tape_of
from langur.operational.signchanges import certified_brackets as mc_brackets

_PRIMS = ("exp", "sin", "cos", "atan", "tanh", "erf", "log", "sqrt")


def _random_term(rng, depth: int):
    """A random smooth term in x, y and the parameter a (constants: rationals that are no double)."""
    if depth == 0 or rng.random() < 0.2:
        pick = rng.integers(4)
        if pick == 0:
            return Var("x")
        if pick == 1:
            return Var("y")
        if pick == 2:
            return Param("a")
        return Const(Fraction(int(rng.integers(-20, 21)), int(rng.choice([3, 7, 10, 11]))))
    kind = rng.integers(5)
    if kind == 0:
        return Add(_random_term(rng, depth - 1), _random_term(rng, depth - 1))
    if kind == 1:
        return Mul(_random_term(rng, depth - 1), _random_term(rng, depth - 1))
    if kind == 2:
        return Pow(_random_term(rng, depth - 1), Fraction(int(rng.choice([2, 3, -1]))))
    op = str(rng.choice(_PRIMS))
    arg = _random_term(rng, depth - 1)
    if op in ("log", "sqrt"):  # keep the argument positive: 1 + arg²
        arg = Add(Const(Fraction(1)), Pow(arg, Fraction(2)))
    return Prim(op, arg)


def _mp(t, env):
    """⟦t⟧ in mpmath (the working precision), the constants exact."""
    match t:
        case Const(c):
            return mpmath.pi if c == "pi" else mpmath.mpf(c.numerator) / c.denominator
        case Var(name) | Param(name):
            return env[name]
        case Add(a, b):
            return _mp(a, env) + _mp(b, env)
        case Mul(a, b):
            return _mp(a, env) * _mp(b, env)
        case Pow(a, k):
            base = _mp(a, env)
            return mpmath.inf if base == 0 and k < 0 else base ** int(k)
        case Prim(op, a):
            return getattr(mpmath, op)(_mp(a, env))
    raise TypeError(t)


def _violations(tape, terms, boxes, a):
    """How many (term, point) pairs fall outside the tape's enclosure, over the boxes' corners and
    their midpoints (values at 60 digits)."""
    (xl, xh), (yl, yh) = boxes
    out = tape.run({"x": (xl, xh), "y": (yl, yh)}, {"a": a})
    bad = 0
    with mpmath.workdps(60):
        for i in range(len(xl)):
            corners = list(itertools.product((xl[i], xh[i]), (yl[i], yh[i])))
            corners.append(((xl[i] + xh[i]) / 2, (yl[i] + yh[i]) / 2))
            for x, y in corners:
                env = {"x": mpmath.mpf(float(x)), "y": mpmath.mpf(float(y)), "a": mpmath.mpf(float(a))}
                for (lo, hi), t in zip(out, terms):
                    v = _mp(t, env)
                    if not mpmath.isfinite(v):
                        continue
                    lo_i, hi_i = np.broadcast_to(lo, xl.shape)[i], np.broadcast_to(hi, xl.shape)[i]
                    if not (mpmath.mpf(float(lo_i)) <= v <= mpmath.mpf(float(hi_i))):
                        bad += 1
    return bad


def test_certified_enclosures_contain_the_exact_values_and_nearest_ones_do_not():
    rng = np.random.default_rng(2026)
    terms = [_random_term(rng, 4) for _ in range(40)]
    xl = rng.uniform(-2, 2, 30)
    yl = rng.uniform(-2, 2, 30)
    w = rng.choice([0.0, 1e-9, 1e-3, 0.5], 30)  # points, tiny and wide boxes
    boxes = ((xl, xl + w), (yl, yl + w[::-1]))
    a = 0.7
    assert _violations(tape_of(terms, certified=True), terms, boxes, a) == 0
    # round to nearest: some end lies inside the exact range (the test can tell them apart)
    assert _violations(tape_of(terms), terms, boxes, a) > 0


def test_constants_that_are_no_double_are_enclosed_by_the_doubles_around_them():
    third, tenth = Const(Fraction(1, 3)), Const(Fraction(1, 10))
    [(lo, hi), (plo, phi)] = enclose_all(tape_of([third, Const("pi")], certified=True), {}, {})
    assert Fraction(float(lo)) < Fraction(1, 3) < Fraction(float(hi))
    assert mpmath.mpf(float(plo)) < mpmath.pi < mpmath.mpf(float(phi))
    # 1/10 + 2/10 = 3/10: in doubles 0.30000000000000004, whose interval must still hold 3/10
    s = Add(tenth, Const(Fraction(2, 10)))
    [(lo, hi)] = enclose_all(tape_of([s], certified=True), {}, {})
    assert Fraction(float(lo)) <= Fraction(3, 10) <= Fraction(float(hi))
    [(lo, hi)] = enclose_all(tape_of([s]), {}, {})
    assert not Fraction(float(lo)) <= Fraction(3, 10) <= Fraction(float(hi))
    # a double constant stays a point
    [(lo, hi)] = enclose_all(tape_of([Const(Fraction(1, 4))], certified=True), {}, {})
    assert lo == hi == 0.25


def _zero_near_a_grid_point():
    """Rationals c1, c2 and a double b with c1 + c2 < b < fl(fl(c1) + fl(c2)): the zero of
    g = x − (c1 + c2) lies just below b, but g(b) in doubles is negative."""
    for i in range(1, 200):
        for j in range(1, 200):
            c1, c2 = Fraction(i, 97), Fraction(j, 89)
            below = np.nextafter(float(c1) + float(c2), -np.inf)
            if Fraction(float(below)) > c1 + c2:
                return c1, c2, float(below)
    raise AssertionError("no such pair")


def test_a_zero_within_rounding_of_a_cell_end_is_bracketed_right_by_both_engines():
    c1, c2, b = _zero_near_a_grid_point()
    zero = c1 + c2
    g = Add(Var("x"), Mul(Const(Fraction(-1)), Add(Const(c1), Const(c2))))
    lo, hi = np.array([b - 1.0]), np.array([b + 15.0])  # 16 cells of width 1: b is the 2nd's start

    def value(at, rows):
        return at - (float(c1) + float(c2))

    def holds(brackets):
        return [Fraction(float(p)) <= zero <= Fraction(float(q)) for p, q in brackets]

    _, a_, b_ = mc_brackets(value, tape_of([g, Const(Fraction(1))], certified=True), "x", np.zeros(1), lo, hi, {})
    assert holds(zip(a_, b_)) == [True]
    # the same certifier on round-to-nearest enclosures: one bracket, and the zero is not in it
    _, a_, b_ = mc_brackets(value, tape_of([g, Const(Fraction(1))]), "x", np.zeros(1), lo, hi, {})
    assert holds(zip(a_, b_)) == [False]
    # the exact engine, on mpmath intervals
    x = sp.Symbol("x")
    gs = x - sp.Rational(c1.numerator, c1.denominator) - sp.Rational(c2.numerator, c2.denominator)
    out = exact_brackets(sp.lambdify(x, gs, "mpmath"), interval_function(x, gs), interval_function(x, sp.diff(gs, x)),
                         0, lo[0], hi[0])
    assert holds(out) == [True]


def test_the_exact_engines_interval_functions_contain_mpmath_values():
    x = sp.Symbol("x")
    rng = np.random.default_rng(5)
    exprs = [sp.sin(3 * x) * sp.exp(x) - sp.Rational(1, 3), sp.atan(x ** 3 - x / 7) + sp.tanh(x),
             sp.erf(x) * x ** 2 - sp.cos(x / 3), sp.sqrt(1 + x ** 2) - sp.log(2 + x ** 2)]
    for e in exprs:
        f_iv = interval_function(x, e)
        for lo in rng.uniform(-2, 2, 15):
            for w in (0.0, 1e-10, 0.3):
                X = mpmath.iv.mpf([lo, lo + w])
                out = f_iv(X)
                with mpmath.workdps(60):
                    for p in (lo, lo + w, lo + w / 2):
                        v = sp.N(e.subs(x, sp.Float(float(p), 60)), 60)
                        assert mpmath.mpf(out.a) <= mpmath.mpf(str(v)) <= mpmath.mpf(out.b)


def test_a_let_bound_to_a_range_is_enclosed_over_it():
    from langur.core import Let
    # let z = a + 1/3 in z·x: the bound is a range once rounded outward; its body is enclosed over it
    t = Let("z", Add(Param("a"), Const(Fraction(1, 3))), Mul(Param("z"), Var("x")))
    [(lo, hi)] = enclose_all(tape_of([t], certified=True), {"x": (np.array([0.5]), np.array([2.0]))}, {"a": 0.1})
    exact = [(Fraction(0.1) + Fraction(1, 3)) * Fraction(x) for x in (0.5, 2.0)]
    assert Fraction(float(lo[0])) <= min(exact) and max(exact) <= Fraction(float(hi[0]))
    assert hi[0] - lo[0] < 1e-12 + (max(exact) - min(exact))
