"""deriv21 (issue 15): the quadrature's compiled integrands skip mpmath's second evaluation
(``compiling._in_mpmath``) where it is certain to give ``math``'s NaN again — an expression
``A + c·s**q`` (q not an integer, A real) at ``s < 0`` (``compiling._off_the_reals``): the
values are those of the rescue computed directly (mpmath on the same expression), and of the
expression's own definition (complex there, so NaN)."""

from __future__ import annotations

import math
import random

import mpmath
import pytest
import sympy as sp

from langur.symbolic.quadrature import compiling
from langur.symbolic.text import shared_lambdify

x, y, a = sp.symbols("x y a")


def _rescued(args, e, vals):
    """What the unchanged path gives: math, then (non-finite) mpmath's value as ``_in_mpmath`` takes it."""
    f = shared_lambdify(list(args), e, "math")
    try:
        v = float(f(*vals))
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        v = math.nan
    if v - v == 0.0:
        return v
    return compiling._in_mpmath(shared_lambdify(list(args), e, "mpmath"), tuple(vals), v)


def _random_shape(rng):
    """``A + c·s**q``: A a random polynomial in x, y, a; c a non-zero real number; s one of them."""
    syms = [x, y, a]
    A = sum(sp.Rational(rng.randint(-9, 9), rng.randint(1, 5)) * rng.choice(syms) ** rng.randint(0, 3)
            for _ in range(rng.randint(1, 4)))
    c = rng.choice([sp.Rational(rng.randint(1, 9), rng.randint(1, 9)), -2 * sp.sqrt(3) / 9, sp.Float("0.37")])
    q = rng.choice([sp.Rational(1, 2), sp.Rational(3, 2), sp.Rational(1, 3), sp.Rational(5, 2), sp.Rational(-1, 2),
                    sp.Rational(7, 4)])
    s = rng.choice(syms)
    return A + c * s ** q, syms.index(s)


@pytest.mark.parametrize("seed", range(6))
def test_shape_values_are_the_rescues(seed, monkeypatch):
    rng = random.Random(seed)
    for _ in range(8):
        e, i = _random_shape(rng)
        f = compiling._lambdify([x, y], e, {a: 0.25})
        for _ in range(12):
            vals = [rng.uniform(-2, 2), rng.uniform(-2, 2)]
            full = vals + [0.25]
            want = _rescued((x, y, a), e, full)
            got = f(*vals)
            assert (math.isnan(got) and math.isnan(want)) or got == want, (e, full, got, want)
            if full[i] < 0 and e.subs(dict(zip((x, y, a), full))).has(sp.I):
                # the definition: complex there (s < 0, q not an integer) — so NaN
                assert math.isnan(got)


def _count_again(monkeypatch) -> list:
    """The arguments of every call of ``compiling._in_mpmath`` (mpmath's second evaluation) from now on."""
    calls = []
    real_again = compiling._in_mpmath

    def counted(*args):
        calls.append(args)
        return real_again(*args)
    monkeypatch.setattr(compiling, "_in_mpmath", counted)
    return calls


def test_no_mpmath_evaluation_below_zero(monkeypatch):
    """At s < 0 the expression's value is NaN without mpmath's second evaluation (fails on the old
    code, which re-evaluates every non-finite value)."""
    e = -a + 2 * sp.sqrt(3) * x ** sp.Rational(3, 2) / 9 + x ** 3
    f = compiling._lambdify([x], e, {a: 0.1})
    calls = _count_again(monkeypatch)
    assert all(math.isnan(f(-k / 10)) for k in range(1, 10))
    assert calls == []
    assert f(0.5) == pytest.approx(-0.1 + 2 * math.sqrt(3) / 9 * 0.5 ** 1.5 + 0.125, rel=1e-15)


def test_tiny_base_still_rescued():
    """|s|^q below a double's range: mpmath's imaginary part rounds to 0 as a Python complex and the
    rescue gives the real part (as before): not skipped."""
    e = x ** sp.Rational(3, 2) + 1
    f = compiling._lambdify([x], e, {})
    assert not compiling._off_the_reals(((x,), e), (-1e-300,))
    assert f(-1e-300) == _rescued((x,), e, [-1e-300]) == 1.0
    assert compiling._off_the_reals(((x,), e), (-0.5,))


@pytest.mark.parametrize("e", [
    sp.sqrt(x) * sp.sqrt(x - 1),  # a product of two roots: mpmath makes it real (−√6 at x = −2)
    x ** sp.Rational(1, 2) + x ** sp.Rational(3, 2),  # two such terms: their imaginary parts may cancel
    (x ** sp.Rational(3, 2)) ** 2,  # the power of a complex value: real again
    sp.log(x) + x ** sp.Rational(1, 2),  # a logarithm: complex in mpmath too, but not of this shape
    a * x ** sp.Rational(3, 2) + 1,  # a coefficient holding a symbol (it may be 0)
    sp.sqrt(x - sp.Float(1.5)) + 1,  # a base that is not an argument, with a Float (deriv22 takes bases that are
                                     # polynomials with rational coefficients: test_deriv22)
])
def test_other_shapes_are_not_skipped(e):
    assert compiling._complex_term((x, a), e) is None
    f = compiling._lambdify([x], e, {a: 0.5})
    for v in (-2.0, -0.3, 0.7, 3.0):
        got, want = f(v), _rescued((x, a), e, [v, 0.5])
        assert (math.isnan(got) and math.isnan(want)) or got == want


def test_the_flaw_is_left_as_it_was():
    """√x·√(x − 1) at x = −2: mpmath's i√2·i√3 = −√6 is still taken (a separate matter, not changed)."""
    f = compiling._lambdify([x], sp.sqrt(x) * sp.sqrt(x - 1), {})
    assert f(-2.0) == pytest.approx(float(-mpmath.sqrt(6)), rel=1e-15)
