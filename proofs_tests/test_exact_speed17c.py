"""Issue 15, exact17c: the quadrature cross-check's setup made cheaper for a one-shot ``langur deriv``.

* ``roots._expanded_coefficients``: a condition's coefficients in one variable from the factors of its
  expanded terms (``roots._split_power``) instead of ``Expr.as_coeff_exponent`` (which runs ``collect``
  on every term).  Checked against sympy's ``Poly(expr, v).all_coeffs()`` (the same expressions) on
  random polynomials, and that ``as_coeff_exponent`` is no longer called (fails on the old code).
"""

from __future__ import annotations

import random

import sympy as sp

from langur.symbolic.quadrature import roots
from langur.sympy_bridge import symbol

V = symbol("v17")
P = [symbol(f"p17_{i}") for i in range(5)]


def _random_polynomial(rng: random.Random) -> sp.Expr:
    """A product/sum of affine and quadratic factors in V and the P's with rational coefficients,
    unexpanded (as the conditions of affine and polynomial regions come)."""
    syms = [V, *P]

    def affine():
        return sp.Add(*[sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) * s for s in rng.sample(syms, 3)],
                      sp.Rational(rng.randint(-3, 3), rng.randint(1, 3)))

    terms = []
    for _ in range(rng.randint(1, 3)):
        factors = [affine() for _ in range(rng.randint(1, 3))]
        if rng.random() < 0.3:
            factors.append(affine() ** 2)
        terms.append(sp.Rational(rng.randint(-4, 4) or 1, rng.randint(1, 3)) * sp.Mul(*factors))
    return sp.Add(*terms) + V * rng.choice(P)  # (degree ≥ 1 in V)


def test_coefficients_are_polys_and_as_coeff_exponent_is_not_called(monkeypatch):
    calls = []
    real = sp.Expr.as_coeff_exponent

    def counted(self, x):
        calls.append(self)
        return real(self, x)

    monkeypatch.setattr(sp.Expr, "as_coeff_exponent", counted)
    rng = random.Random(17)
    checked = 0
    for _ in range(60):
        e = _random_polynomial(rng)
        got = roots._expanded_coefficients(e, V)
        want = sp.Poly(e, V).all_coeffs()
        if not 1 <= len(want) - 1 <= 8:
            assert got is None
            continue
        assert got is not None
        assert len(got) == len(want)
        for g, w in zip(got, want):
            assert g == w  # the same expression, so the same compiled code
            assert sp.expand(g - w) == 0
        checked += 1
    assert checked >= 50
    assert calls == []


def test_split_power_refuses_what_is_not_a_power_of_the_variable():
    assert roots._split_power(sp.Rational(3, 2) * V**3 * P[0] ** 2, V) == (3, [sp.Rational(3, 2), P[0] ** 2])
    assert roots._split_power(-V, V) == (1, [sp.Integer(-1)])
    assert roots._split_power(P[1], V) == (0, [P[1]])
    assert roots._split_power(P[1] * sp.sin(V), V) == (None, [])
    assert roots._split_power(P[1] / V, V) == (None, [])
    assert roots._expanded_coefficients(sp.sin(V) + V, V) is None  # (not a polynomial: Poly's path)
