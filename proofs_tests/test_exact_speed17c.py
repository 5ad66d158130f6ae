"""Issue 15, exact17c: the quadrature cross-check's setup made cheaper for a one-shot ``langur deriv``.

* ``roots._expanded_coefficients``: a condition's coefficients in one variable from the factors of its
  expanded terms (``roots._split_power``) instead of ``Expr.as_coeff_exponent`` (which runs ``collect``
  on every term).  Checked against sympy's ``Poly(expr, v).all_coeffs()`` (the same expressions) on
  random polynomials, and that ``as_coeff_exponent`` is no longer called (fails on the old code).
* ``compiling.at_floats``: a condition with the point's Floats substituted, remembered by (condition,
  point): the delta pieces' problems substitute the same conditions again.  The same expression as
  ``xreplace``; a second call does not substitute again (fails on the old code, which has no
  ``at_floats``); another point gives its own values; the stylize kernel's partial derivative and
  Theorem 8.1's numbers are the same with it and with a plain ``xreplace`` each time.
"""

from __future__ import annotations

import os
import random

import sympy as sp

from langur import denote
from langur.exact import exact_deriv
from langur.frontend import load
from langur.symbolic import rational
from langur.symbolic.quadrature import compiling, deltaproblems, pieceproblems, roots
from langur.sympy_bridge import symbol

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")
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


def test_at_floats_substitutes_once_per_condition_and_point(monkeypatch):
    e = (P[0] - V) * (P[1] + sp.Rational(1, 3)) - P[2] * V**2
    at1 = {P[0]: sp.Rational(1, 7), P[1]: sp.Rational(-2, 3), P[2]: 0.25}
    at2 = {P[0]: sp.Rational(1, 7), P[1]: sp.Rational(-2, 3), P[2]: 0.5}
    compiling._AT_FLOATS.clear()
    first = compiling.at_floats(e, at1)
    assert first == e.xreplace(compiling._floats(at1))
    fresh = {P[0]: sp.Float(1 / 7, 30), P[1]: sp.Float(-2 / 3, 30), P[2]: sp.Float(0.25, 30)}
    assert first == e.xreplace(fresh)

    substituted = []
    real = sp.Basic.xreplace

    def counted(self, rule, **kw):
        substituted.append(self)
        return real(self, rule, **kw)

    monkeypatch.setattr(sp.Basic, "xreplace", counted)
    assert compiling.at_floats(e, dict(at1)) is first  # (an equal point: the same answer, not rebuilt)
    assert substituted == []
    second = compiling.at_floats(e, at2)
    monkeypatch.setattr(sp.Basic, "xreplace", real)
    assert second == e.xreplace(compiling._floats(at2)) != first


def test_the_kernels_derivative_and_theorem_numbers_are_those_of_plain_substitution():
    loaded = load(os.path.join(EXAMPLES, "stylize", "linear.lgr"))
    at = loaded.param_values()
    direction = {q: int(q == "ax") for q in at}
    real = compiling.at_floats
    hits = []

    def spy(expr, point):
        before = len(compiling._AT_FLOATS)
        out = real(expr, point)
        hits.append(len(compiling._AT_FLOATS) == before)
        return out

    def plain(expr, point):
        return expr.xreplace(compiling._floats(point))

    answers = []
    for fake in (spy, plain):
        deltaproblems.at_floats = pieceproblems.at_floats = fake
        try:
            denote._remembered.clear()
            rational._TAPES.clear()
            compiling._AT_FLOATS.clear()
            r = exact_deriv(loaded.program, at, direction)
        finally:
            deltaproblems.at_floats = pieceproblems.at_floats = real
        th = r.theorem_8_1
        answers.append((r.value, r.method, r.error, th.holds, th.how, th.d_denotation, th.derivative_denotation,
                        [(p.d_denotation, p.derivative_denotation) for p in th.points], th.notes))
    assert any(hits)  # a condition substituted at a point it had been substituted at
    assert answers[0] == answers[1]
    assert answers[0][3] is True
