"""Deciding early that sympy will not find an antiderivative, and the antiderivatives found
without sympy's integrate (langur/symbolic/elementary.py, issue 15).

Antiderivatives are checked by differentiating them (sympy's diff, independent of how they were
found) and, on a definite integral, against mpmath quadrature; the classification against
textbook facts (erf, Ei, Fresnel, elliptic integrals have no elementary form)."""

from __future__ import annotations

import mpmath
import pytest
import sympy as sp

from langur.symbolic.elementary import (
    affine_power_antiderivative,
    exponential_antiderivative,
    gaussian_antiderivative,
    hopeless,
    polynomial_antiderivative,
)

x, a, b = sp.symbols("x a b")


@pytest.mark.parametrize("w", [
    sp.sqrt(x + sp.Rational(3, 2)) * sp.exp(3 * x / 2 - b),  # √x·eˣ: erf
    sp.exp(x) / (x + a),  # Ei
    sp.sin(x**2),  # Fresnel
    sp.exp(x**3),
    sp.sqrt(1 + x**3),  # elliptic
    sp.cos(a * x**2 + x),
    2 * sp.sqrt(a + x**2) * sp.atan(a + x**2),
    sp.atan(a + x) / x,  # dilogarithm
    sp.log(a + x**3) * sp.cos(b * x),
    x + sp.exp(-a + x) * sp.sqrt(x + 1),  # one hopeless term is enough
])
def test_hopeless_shapes_are_recognised(w):
    assert hopeless(w, x).startswith("no elementary antiderivative expected")


@pytest.mark.parametrize("w", [
    x**3 - a * x,
    (a * x + 2) * sp.sin(x + a * x),
    x * sp.exp(3 * x / 2 - b) * sp.cos(2 * x),  # products of exponentials: by parts
    sp.exp(-(x - a) ** 2),  # a Gaussian: erf, which the engine integrates
    x * (x + sp.Rational(3, 2)) ** sp.Rational(3, 2),
    (x + 2) / (2 * sp.sqrt(a + x**2)),
    sp.atan(a + x * b),
    x**2 * sp.log(1 + x**2),
    1 / (x**2 + 1) / (x + 2),  # a rational function after all
    sp.sin(a) * x,  # constant factors are polynomial
    1 / (x * sp.log(x) ** 2),  # (−1/log x)': shapes it does not classify are left to sympy
    x**2 * sp.sqrt(x**3 + 1),  # substitution u = x³ + 1
    sp.sqrt((x + 1) ** 3),  # not square-free: (x + 1)^(3/2)
])
def test_integrable_shapes_are_let_through(w):
    assert hopeless(w, x) == ""


@pytest.mark.parametrize("w", [
    sp.Rational(7, 10) * (a * x + 2) * sp.sin(x + a * x),
    x**3 * sp.exp(2 * x - a) + 5 * x,
    (x + 1) * sp.cosh(3 * x) + sp.cos(x) - sp.sinh(a * x - 1) * x**2,
])
def test_exponential_antiderivative_differentiates_back(w):
    F = exponential_antiderivative(w, x)
    assert F is not None
    assert sp.simplify(sp.diff(F, x) - w) == 0
    # and as a definite integral at a parameter value, against mpmath's quadrature
    at = {a: sp.Rational(83, 100), b: sp.Rational(41, 100)}
    exact = float((F.subs(x, 1) - F.subs(x, 0)).subs(at))
    f = sp.lambdify(x, w.subs(at), "mpmath")
    assert exact == pytest.approx(float(mpmath.quad(f, [0, 1])), rel=1e-12, abs=1e-12)


def test_exponential_antiderivative_declines_other_shapes():
    assert exponential_antiderivative(sp.exp(x) * sp.sin(x), x) is None  # two transcendental factors
    assert exponential_antiderivative(sp.sin(x**2), x) is None
    assert exponential_antiderivative(x**2 + 1 / x, x) is None


def test_polynomial_antiderivative():
    F = polynomial_antiderivative(2 * a - x**2 - x * sp.sqrt(a), x)
    assert sp.expand(sp.diff(F, x) - (2 * a - x**2 - x * sp.sqrt(a))) == 0
    assert polynomial_antiderivative(sp.sin(x), x) is None
    assert polynomial_antiderivative(x ** sp.Rational(3, 2), x) is None


@pytest.mark.parametrize("w", [
    sp.Rational(7, 10) * (a * x + 2) * x * (x + sp.Rational(3, 2)) ** sp.Rational(3, 2),
    x * sp.sqrt(2 * x + 3) - x**2,
    1 / sp.sqrt(a * x + 1),
])
def test_affine_power_antiderivative_differentiates_back(w):
    F = affine_power_antiderivative(w, x)
    assert F is not None
    assert sp.simplify(sp.diff(F, x) - w) == 0
    at = {a: sp.Rational(83, 100)}
    exact = float((F.subs(x, 1) - F.subs(x, 0)).subs(at))
    f = sp.lambdify(x, w.subs(at), "mpmath")
    assert exact == pytest.approx(float(mpmath.quad(f, [0, 1])), rel=1e-12, abs=1e-12)


def test_affine_power_antiderivative_declines_other_shapes():
    assert affine_power_antiderivative(sp.sqrt(x**2 + 1), x) is None  # not affine
    assert affine_power_antiderivative(sp.sqrt(x) * sp.sqrt(x + 1), x) is None  # two powers


def test_antiderivatives_learned_in_one_process_are_handed_on(monkeypatch):
    # langur fuzz's workers hand back what sympy found (langur/fuzz/compare.py), and the units forked
    # after them start with it: here the hand-over itself, on a weight that needs sympy
    from langur.symbolic import antiderivatives, context
    from langur.timebox import Deadline

    monkeypatch.setattr(antiderivatives, "_CACHE", {})
    known = antiderivatives.antiderivatives_known()
    w = x / (1 + x**2)
    F = antiderivatives.antiderivative(w, x, context.Context({}, Deadline(20.0), frozenset()))
    learned = antiderivatives.antiderivatives_since(known)
    assert learned and all(k[0] == w for k in learned)
    monkeypatch.setattr(antiderivatives, "_CACHE", {})
    antiderivatives.learn_antiderivatives(learned)
    # with no time at all, the learned answer is still there (sympy is not asked again)
    again = antiderivatives.antiderivative(w, x, context.Context({}, Deadline(0.0), frozenset()))
    assert sp.simplify(again - F) == 0 and sp.simplify(sp.diff(F, x) - w) == 0


def test_gaussian_antiderivative_differentiates_back():
    # risk.lgr's weights: a polynomial times a product of normal densities in x (completing the
    # square; erf for the even part), for every value of the mean
    mu = sp.Symbol("mu")
    w = ((x - mu) / 25 * sp.exp(-(x - mu) ** 2 / 50) * sp.exp(-(x - 2) ** 2 / 50) / (50 * sp.pi)
         + x**2 * sp.exp(-x**2 / 3 + x))
    F = gaussian_antiderivative(w, x)
    assert F is not None and F.has(sp.erf)
    d = sp.diff(F, x) - w
    for px, pmu in [(0.3, 1.7), (-2.5, 0.1), (4.0, -1.2)]:
        assert abs(complex(sp.N(d.subs({x: px, mu: pmu}), 30))) < 1e-13
    at = {mu: 1}
    exact = float((F.subs(x, 3) - F.subs(x, -3)).subs(at))
    f = sp.lambdify(x, w.subs(at), "mpmath")
    assert exact == pytest.approx(float(mpmath.quad(f, [-3, 3])), rel=1e-12)
    assert gaussian_antiderivative(sp.exp(a * x**2), x) is None  # the sign of A depends on a parameter
