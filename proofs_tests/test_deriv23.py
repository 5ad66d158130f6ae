"""deriv23 (issue 15): the quadrature's compiled integrands skip mpmath's second evaluation
(``compiling._in_mpmath``) of ``A + c·R`` — ``R`` an implicit root of a polynomial equation whose
bracket's ends are integers, arguments or indexed roots (turning2d's substituted box conditions
``root(…) ± 1``) — where the equation certainly has one sign at both ends of the bracket
(``compiling._RootTerm``): mpmath finds no root there either, so its value is NaN, which is
``math``'s.  The values are compared with the unchanged path (math, then mpmath's rescue computed
directly), and where the skip is taken the definition is checked in exact rational arithmetic: the
equation's exact values at the bracket's two ends (the doubles the root finder uses) have one sign,
so there is no sign change for Brent's method to find."""

from __future__ import annotations

import math
import random
from fractions import Fraction

import pytest
import sympy as sp
from test_deriv21 import _count_again, _rescued  # (the unchanged path: math, then mpmath as _again takes it)

from langur.implicit import implicit_root
from langur.symbolic.quadrature import compiling
from langur.symbolic.text import shared_lambdify

x, a, Y = sp.symbols("x a Y")


def _turning(k: int):
    """turning2d's k-th turning point of y ↦ y³ − x·y (a sign change of 3y² − x on [−1, 1])."""
    return implicit_root(3 * Y ** 2 - x, Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1), index=k, of=2, lenient=True)


def _turning2d_roots():
    """The three branches of turning2d's folium x³ − x·y + y³ = a in y, between its turning points."""
    eq = Y ** 3 - Y * x - a + x ** 3
    ends = [sp.Integer(-1), _turning(0), _turning(1), sp.Integer(1)]
    return [implicit_root(eq, Y, sp.Integer(0), lo, hi) for lo, hi in zip(ends, ends[1:])], eq


def _same(got, want):
    return (math.isnan(got) and math.isnan(want)) or got == want


def test_turning2d_box_conditions_are_the_rescues(monkeypatch):
    """``root(…) + 1`` and ``1 − root(…)`` on each branch, at 400 abscissae across [−1.2, 1.2] (the
    grid searches' range and beyond): the unchanged path's values; fewer mpmath evaluations (fails on
    the old code, which re-evaluates every NaN)."""
    roots, _ = _turning2d_roots()
    xs = [-1.2 + 2.4 * i / 399 for i in range(400)]
    for r in roots:
        for e in (r + 1, 1 - r):
            f = compiling._lambdify([x], e, {a: 0.1})
            want = [_rescued((x, a), e, (v, 0.1)) for v in xs]
            calls = _count_again(monkeypatch)
            got = [f(v) for v in xs]
            monkeypatch.undo()
            assert all(_same(g, w) for g, w in zip(got, want)), e
            nans = sum(map(math.isnan, got))
            assert nans > 20  # (the branch does not exist over part of the range)
            assert len(calls) < nans // 2, (e, len(calls), nans)


def _exact_sign(poly: sp.Expr, point: dict) -> int:
    """The sign of ``poly`` at ``point`` (doubles), in exact rational arithmetic."""
    v = poly.xreplace({k: sp.Rational(Fraction(float(w))) for k, w in point.items()})
    return int(sp.sign(v))


def test_skipped_only_where_the_ends_have_one_sign(monkeypatch):
    """Wherever the skip is taken (no ``_again`` call for a NaN), the equation's exact values at the
    bracket's two ends have one sign and neither is 0: the definition of the root's absence."""
    roots, eq = _turning2d_roots()
    rng = random.Random(3)
    checked = 0
    for r in roots:
        e = r + 1
        f = compiling._lambdify([x], e, {a: 0.1})
        lo, hi = r.args[2], r.args[3]
        ends = [shared_lambdify([x], end, "math") for end in (lo, hi)]
        for _ in range(150):
            v = rng.uniform(-1.1, 1.1)
            calls = _count_again(monkeypatch)
            got = f(v)
            monkeypatch.undo()
            if math.isnan(got) and not calls:
                signs = {_exact_sign(eq, {Y: end(v), x: v, a: 0.1}) for end in ends}
                assert len(signs) == 1 and 0 not in signs, (r, v, signs)
                checked += 1
    assert checked > 50


def _random_polynomial(rng, syms):
    return sum(sp.Rational(rng.randint(-9, 9), rng.randint(1, 4)) * sp.Mul(*[s ** rng.randint(0, 3) for s in syms])
               for _ in range(rng.randint(2, 5)))


@pytest.mark.parametrize("seed", range(8))
def test_random_roots_are_the_rescues(seed):
    """Random polynomial equations in Y with coefficients polynomial in x and a, brackets with
    integer, argument and indexed-root ends, ``A + c·R`` with A a random polynomial and c a real
    constant: the unchanged path's values at 40 points each, NaN or not."""
    rng = random.Random(seed)
    for _ in range(5):
        eq = _random_polynomial(rng, [Y, x, a]) + Y ** 3
        lo, hi = rng.choice([(sp.Integer(-2), sp.Integer(2)), (sp.Integer(-1), x), (_turning(0), sp.Integer(2)),
                             (sp.Integer(-2), _turning(1)), (_turning(0), _turning(1))])
        r = implicit_root(eq, Y, sp.Integer(rng.choice([0, 1, -2])), lo, hi)
        A = _random_polynomial(rng, [x, a])
        c = rng.choice([sp.Integer(1), sp.Integer(-1), sp.Rational(3, 7), 2 * sp.sqrt(3) / 9])
        e = A + c * r
        f = compiling._lambdify([x], e, {a: 0.37})
        for _ in range(40):
            v = rng.uniform(-1.5, 1.5)
            want = _rescued((x, a), e, (v, 0.37))
            assert _same(f(v), want), (e, v, f(v), want)


def test_uncertain_ends_are_rescued_as_before(monkeypatch):
    """An end where the equation is too small for the rounding bound (|Y − x| = 1e-300 at Y = 0,
    below the certified magnitudes), and shapes that are not of the kind (an end that is a sum, a
    Float in the equation, two roots, a root squared): mpmath's second evaluation as before."""
    r = implicit_root(Y - x, Y, sp.Integer(0), sp.Integer(0), sp.Integer(1))
    f = compiling._lambdify([x], r + 1, {})
    calls = _count_again(monkeypatch)
    assert math.isnan(f(-1e-300))
    assert len(calls) == 1
    monkeypatch.undo()
    eq = Y ** 3 - Y * x - a + x ** 3
    others = [implicit_root(eq, Y, sp.Integer(0), sp.Integer(-1), x + 1) + 1,
              implicit_root(eq + sp.Float("0.5"), Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1)) + 1,
              implicit_root(eq, Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1)) ** 2 + 1,
              implicit_root(eq, Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1))
              + implicit_root(eq, Y, sp.Integer(0), sp.Integer(1), sp.Integer(2))]
    for e in others:
        assert not isinstance(compiling._complex_term((x, a), e), compiling._RootTerm), e
        f = compiling._lambdify([x], e, {a: 5.0})  # (a = 5: no root of the cubic in [−1, 1] near x = 0)
        calls = _count_again(monkeypatch)
        got = f(0.1)
        monkeypatch.undo()
        assert _same(got, _rescued((x, a), e, (0.1, 5.0)))
        if math.isnan(got):
            assert calls, e
