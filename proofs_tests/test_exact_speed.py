"""The exact engine's shortcuts of issue 15 (third pass) give what the slow paths gave: the shared
printers print sympy's own text and code, the shared substitution builds sympy's own expression,
the Grundmann–Möller rules integrate polynomials exactly (checked against scipy), the root
formulas by coefficient lists find the roots numpy finds, and sympy's roots without its simplify
pass are the same numbers."""

from __future__ import annotations

import inspect
import random

import numpy as np
import pytest
import scipy.integrate as si
import sympy as sp

from langur.symbolic import exact_rules, local, rational, root_formulas, solving, walks
from langur.symbolic.context import Cond, Context
from langur.symbolic.text import shared_lambdify, shared_sstr
from langur.timebox import Deadline

a, b, c, x, y = sp.symbols("a b c x y", real=True)


def _random_shared(seed: int) -> sp.Expr:
    """A random expression that reuses its subtrees (as the local closed forms do)."""
    rng = random.Random(seed)
    pool = [a, b, c, sp.Rational(rng.randint(-9, 9), rng.randint(1, 7)), sp.Float(rng.uniform(-2, 2), 20)]
    for _ in range(40):
        p, q = rng.choice(pool), rng.choice(pool)
        op = rng.randrange(7)
        if op == 0:
            e = p + q
        elif op == 1:
            e = p * q
        elif op == 2:
            e = p - q
        elif op == 3:
            e = p / (q ** 2 + 1)
        elif op == 4:
            e = p ** rng.randint(-2, 3)
        elif op == 5:
            e = sp.exp(p) * sp.sqrt(q ** 2 + 1)
        else:
            e = sp.Abs(p) + sp.Piecewise((q, a > 0), (p, True))
        pool.append(e)
    return sp.Add(*pool[-6:])


@pytest.mark.parametrize("seed", range(12))
def test_the_shared_printer_prints_sympys_text(seed):
    e = _random_shared(seed)
    assert shared_sstr(e) == sp.sstr(e)
    assert shared_sstr(e, order="none") == sp.sstr(e, order="none")


@pytest.mark.parametrize("seed", range(8))
def test_shared_lambdify_generates_sympys_code(seed):
    e = _random_shared(seed)
    args = [a, b, c]
    for module in ("math", "mpmath"):
        ours, theirs = shared_lambdify(args, e, module), sp.lambdify(args, e, modules=[module])
        assert inspect.getsource(ours) == inspect.getsource(theirs)
    f = shared_lambdify(args, e, "math")
    pt = {a: sp.Rational(3, 7), b: sp.Rational(-5, 4), c: sp.Rational(1, 3)}
    try:
        got = f(*[float(pt[s]) for s in args])
    except (ValueError, ZeroDivisionError, OverflowError):
        return
    want = complex(e.xreplace(pt).evalf(30))
    assert got == pytest.approx(want.real, rel=1e-9, abs=1e-12)


@pytest.mark.parametrize("seed", range(12))
def test_shared_substitution_builds_sympys_expression(seed):
    e = _random_shared(seed)
    rule = {a: x + 2 * y, b: x * y - sp.Rational(1, 3)}
    assert walks.shared_xreplace(e, rule) == e.xreplace(rule)


@pytest.mark.parametrize("k", range(0, 4))
def test_grundmann_moeller_rules_integrate_monomials_like_scipy(k):
    rule = exact_rules.grundmann_moeller(k)
    assert len(rule) == (k + 1) * (k + 2) * (k + 3) // 6
    d = 2 * k + 1
    for p in range(d + 1):
        for q in range(d + 1 - p):
            ours = 0.5 * sum(float(w) * float(s) ** p * float(t) ** q for s, t, w in rule)
            ref, _ = si.dblquad(lambda t, s, p=p, q=q: s**p * t**q, 0, 1, 0, lambda s: 1 - s, epsabs=1e-13)
            assert ours == pytest.approx(ref, rel=1e-10, abs=1e-14)


@pytest.mark.parametrize("d", range(1, 7))
def test_the_chosen_triangle_rule_is_exact_on_a_triangle_with_symbolic_vertices(d):
    # the rule as polygon_integral uses it: a random polynomial of degree d over a triangle whose
    # vertices are parameters, against sympy's iterated integral at a point
    rng = random.Random(d)
    w = sum(sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) * x ** i * y ** j
            for i in range(d + 1) for j in range(d + 1 - i))
    verts = [(sp.Integer(0), sp.Integer(0)), (a, sp.Integer(0)), (sp.Integer(0), b)]
    (x0, y0), (x1, y1), (x2, y2) = verts
    jac = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
    form = jac / 2 * sp.Add(*[sp.Rational(wt.numerator, wt.denominator) * w.xreplace(
        {x: x0 + sp.Rational(s.numerator, s.denominator) * (x1 - x0) + sp.Rational(t.numerator, t.denominator) * (x2 - x0),
         y: y0 + sp.Rational(s.numerator, s.denominator) * (y1 - y0) + sp.Rational(t.numerator, t.denominator) * (y2 - y0)})
        for s, t, wt in exact_rules.triangle_rule(d)])
    pt = {a: sp.Rational(3, 2), b: sp.Rational(5, 3)}
    exact = sp.integrate(w.xreplace(pt), (y, 0, pt[b] * (1 - x / pt[a])), (x, 0, pt[a]))
    assert form.xreplace(pt) == exact


def _shape(seed: int):
    """A condition shaped like the ray tracer's: nested fractions with parameter-only denominators,
    of degree ≤ 2 in x after clearing them."""
    rng = random.Random(seed)

    def k():
        return sp.Rational(rng.randint(-9, 9), rng.randint(1, 5)) * a + sp.Rational(rng.randint(1, 9), rng.randint(1, 5))

    inner = (k() * x + k()) / (k() * a + 3)
    return x * k() + (k() * x + k()) * inner / (a ** 2 + 2) + k() * b


@pytest.mark.parametrize("seed", range(10))
def test_root_formulas_by_coefficient_lists_find_numpys_roots(seed):
    expr = _shape(seed)
    at = {a: sp.Rational(5, 11), b: sp.Rational(-1, 4)}  # (no coefficient of _shape vanishes there)
    found = root_formulas.closed_roots(expr, x, lambda e: complex(sp.sympify(e).xreplace(at).evalf(30)))
    assert found is not None
    roots, poles = found
    num, _ = sp.fraction(sp.together(expr.xreplace(at)))
    coeffs = [float(cf) for cf in sp.Poly(num, x).all_coeffs()]
    want = sorted(r.real for r in np.roots(coeffs) if abs(r.imag) < 1e-9)
    got = sorted(complex(r.xreplace(at).evalf(30)).real for r in roots
                 if abs(complex(r.xreplace(at).evalf(30)).imag) < 1e-9)
    assert got == pytest.approx(want, rel=1e-9, abs=1e-12)
    assert poles == []


def test_sympys_roots_without_its_simplify_pass_are_the_same_numbers():
    r = sp.Symbol("r", real=True)
    at = {r: sp.Rational(5, 4)}
    ctx = Context(at, Deadline(20.0), frozenset(at))
    for e in (1 - sp.sqrt(r**2 - x**2), sp.sqrt(4 * r**2 - 4 * x**2) / 2 - 1, r**2 - x**2, x**3 - r * x):
        quick = sorted(complex(ctx.value(z)).real for z in solving._roots(Cond(e), x, ctx, tidy=False))
        tidy = sorted(complex(ctx.value(z)).real for z in solving._roots(Cond(e), x, ctx))
        assert quick == pytest.approx(tidy, rel=1e-12, abs=1e-15)
        assert quick  # each has real roots at r = 5/4


def test_exact_values_and_dual_derivatives_by_integer_pairs_match_sympys_rationals():
    # rational.rational_value / dual_derivative (unreduced integer pairs) against sympy's exact
    # substitution and its derivative along the line, on random rational forms
    pt = {a: sp.Rational(3, 7), b: sp.Rational(-5, 4), c: sp.Rational(11, 3)}
    tg = {a: 1, b: sp.Rational(1, 2), c: 0}
    s = sp.Symbol("s", real=True)
    rng = random.Random(1)
    checked = 0
    for _ in range(60):
        pool = [a, b, c, sp.Rational(rng.randint(-9, 9), rng.randint(1, 7))]
        for _ in range(25):
            p, q = rng.choice(pool), rng.choice(pool)
            pool.append([p + q, p * q, p - q, p / (q**2 + 1), p ** rng.randint(-2, 3)][rng.randrange(5)])
        e = sp.Add(*pool[-5:]) + sp.Abs(pool[-1] + 100)
        if e.has(sp.zoo, sp.nan, sp.oo):
            continue
        want = e.xreplace(pt)
        assert want.is_Rational
        assert rational.rational_value(e, pt) == want
        slope = sp.diff(e.xreplace({k: v + s * tg[k] for k, v in pt.items()}), s).subs(s, 0).doit()
        assert rational.dual_derivative(e, pt, tg) == slope
        checked += 1
    assert checked >= 50


@pytest.mark.parametrize("seed", range(8))
def test_monomials_of_a_polynomial_weight_sum_back_to_it(seed):
    rng = random.Random(seed)
    pool = [x, y, a, b * x - c, (a + 1) / (b**2 + 1), x * y - a]
    for _ in range(8):
        p, q = rng.choice(pool), rng.choice(pool)
        pool.append([p + q, p * q, (p - q) ** 2][rng.randrange(3)])
    w = pool[-1] + pool[-2]
    coeffs = local.monomials(w, x, y)
    assert sp.expand(sum(co * x**i * y**j for (i, j), co in coeffs.items()) - w) == 0
    assert all(not (co.free_symbols & {x, y}) for co in coeffs.values())
