"""The exact engine's cheaper certificates for implicit roots (issue 18): brackets certified once
per box of the other symbols' values, sign changes of polynomial equations isolated exactly (a
Sturm sequence), and equations compiled once per shape.  Each is checked against the interval
certification it replaces (:func:`langur.enclosures.certified_brackets`) or against numpy's roots."""

from __future__ import annotations

import random
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp

from langur.core import TooManyRoots
from langur.enclosures import certified_brackets, interval_function
from langur.implicit import evalf, implicit_root, lambdified
from langur.sturm import sturm_brackets


def _poly(rng, deg):
    c = [Fraction(rng.randint(-20, 20), rng.randint(1, 7)) for _ in range(deg + 1)]
    c[0] = c[0] or Fraction(1)
    return c


def test_sturm_brackets_find_the_sign_changes_the_enclosures_certify():
    x = sp.Symbol("x")
    rng = random.Random(3)
    compared = 0
    for _ in range(120):
        deg = rng.randint(1, 6)
        c = _poly(rng, deg)
        f = sum(sp.Rational(v.numerator, v.denominator) * x ** (deg - i) for i, v in enumerate(c))
        got = sturm_brackets(c, Fraction(-2), Fraction(2))
        assert got is not None
        for p, q in got:  # each bracket holds a sign change
            assert (f.subs(x, sp.Rational(p)) < 0) != (f.subs(x, sp.Rational(q)) < 0)
        # the odd-multiplicity real roots in (−2, 2) by numpy: one per bracket
        roots = [r.real for r in np.roots([float(v) for v in c]) if abs(r.imag) < 1e-7 and -2 < r.real < 2]
        try:
            want = certified_brackets(sp.lambdify(x, f, "mpmath"), interval_function(x, f), interval_function(x, sp.diff(f, x)),
                                      0, -2, 2)
        except TooManyRoots:
            continue
        compared += 1
        assert len(got) == len(want) == len(roots), (f, got, want, roots)
    assert compared > 100


def test_sturm_brackets_separate_roots_that_merge_and_count_no_sign_change_at_a_double_root():
    # 3z² − u at u = 1e−20: roots ±5.8e−11, far below any grid the enclosures would use
    found = sturm_brackets([Fraction(3), Fraction(0), -Fraction(1, 10**20)], Fraction(-1), Fraction(1))
    assert found == [(-1, 0), (0, 1)]  # the split point 0 between them; the equation's sign: +, −, +
    assert sturm_brackets([Fraction(3), Fraction(0), Fraction(0)], Fraction(-1), Fraction(1)) == []
    assert sturm_brackets([Fraction(3), Fraction(0), Fraction(0)], Fraction(-1), Fraction(1), squarefree=True) is None
    assert sturm_brackets([Fraction(1), Fraction(0), Fraction(-1)], Fraction(-1), Fraction(1)) is None  # a root at an end


def _indexed(u_values):
    """The 0th and 1st sign changes of 3z² − u on [−1, 1] (the folium's turning points) at each u."""
    z, u = sp.Symbol("z"), sp.Symbol("u")
    out = []
    for k in (0, 1):
        r = implicit_root(3 * z**2 - u, z, sp.Integer(0), sp.Integer(-1), sp.Integer(1), index=k, of=2, lenient=True)
        fn = sp.lambdify([u], r, modules="numpy")
        out.append([float(fn(v)) for v in u_values])
    return np.array(out)


def test_box_certificates_give_the_roots_each_value_certified_alone_gives(monkeypatch):
    us = np.concatenate([np.linspace(-1, 1, 41), [1e-30, 1e-12, 3e-7, 0.0, -1e-15]])
    lambdified._BOXES.clear()
    lambdified._brackets_of.cache_clear()
    boxed = _indexed(us)
    assert any(v is not None for v in lambdified._BOXES.values())  # some boxes certified
    monkeypatch.setattr(lambdified, "BOX_LEVELS", range(0))  # no boxes: each value alone
    monkeypatch.setattr(lambdified, "_exact_brackets", lambda *args: None)  # and no Sturm sequence
    lambdified._brackets_of.cache_clear()
    alone = _indexed(us)
    lambdified._brackets_of.cache_clear()
    want = np.where(us > 0, np.sqrt(np.maximum(us, 0) / 3), 1.0)  # no sign change: the domain's end
    want = np.array([np.where(us > 0, -want, 1.0), want])
    assert np.allclose(boxed, alone, rtol=0, atol=1e-14) and np.allclose(boxed, want, rtol=0, atol=1e-14)


def test_an_equation_with_float_constants_is_compiled_once_for_all_their_values():
    # as a linter's spot values put numbers for a parameter into one root's equation
    z, b = sp.Symbol("z"), sp.Symbol("b")
    root = implicit_root(z**3 - b * z, z, sp.Float(0.01), sp.Integer(-1), sp.Integer(1), index=2, of=3)
    before = evalf._shape_compiled.cache_info().misses
    for c in (0.1, 0.2, 0.3, 0.45):
        r = root.subs(b, sp.Float(c))
        got = float(r.evalf(30))
        roots = sorted(t.real for t in np.roots([1, 0, -c, -0.01]) if abs(t.imag) < 1e-12 and -1 < t.real < 1)
        assert got == pytest.approx(roots[-1], abs=1e-13) and len(roots) == 3
        with mpmath.workdps(40):  # high precision: the root to 30 digits
            assert abs(r.evalf(30) ** 3 - sp.Float(c) * r.evalf(30) - sp.Float(0.01)) < 1e-25
    assert evalf._shape_compiled.cache_info().misses - before <= 1
