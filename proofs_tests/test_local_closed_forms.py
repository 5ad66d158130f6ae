"""Closed forms decided at the evaluation point (langur/symbolic/local.py, exact_rules.py,
root_formulas.py; issue 15): the polygon integral, the rational quadrature rules, the roots by
formula and the exact directional derivative, each against an independent computation (scipy
quadrature, numpy roots, sympy, an exact shoelace area of the clipped triangle in Fractions, the
stylization kernel's own numpy reference)."""

from __future__ import annotations

import random
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp
from paths import EXAMPLES
from scipy import integrate as si
from test_stylize import clip

from langur.exact import exact_deriv
from langur.frontend import load, load_text
from langur.symbolic import exact_rules, local, rational, root_formulas
from langur.symbolic.context import Cond, Context
from langur.timebox import Deadline

x, y, v = sp.symbols("x y v", real=True)


@pytest.mark.parametrize("d", range(0, 6))
def test_newton_cotes_is_exact_for_polynomials_of_its_degree(d):
    rng = random.Random(d)
    w = sum(sp.Rational(rng.randint(-9, 9), rng.randint(1, 5)) * v**k for k in range(d + 1))
    a, b = sp.Rational(-1, 3), sp.Rational(7, 4)
    assert sp.expand(exact_rules.newton_cotes(w, v, a, b, d)) == sp.integrate(w, (v, a, b))


@pytest.mark.parametrize("d", range(1, 6))
def test_the_triangle_rule_integrates_monomials_like_scipy(d):
    rule = exact_rules.triangle_rule(d)
    for a in range(d + 1):
        for b in range(d + 1 - a):
            ours = 0.5 * sum(float(w) * float(s) ** a * float(t) ** b for s, t, w in rule)
            ref, _ = si.dblquad(lambda t, s, a=a, b=b: s**a * t**b, 0, 1, 0, lambda s: 1 - s, epsabs=1e-13)
            assert ours == pytest.approx(ref, rel=1e-10, abs=1e-14)


def _ctx(at):
    return Context({sp.Symbol(k, real=True): sp.Rational(val) for k, val in at.items()}, Deadline(20.0),
                   frozenset(sp.Symbol(k, real=True) for k in at))


def _clip_halfplanes(poly, planes):
    """A convex polygon (floats) cut by half-planes g(x, y) ≥ 0 (g affine), Sutherland–Hodgman."""
    for g in planes:
        out = []
        for i, p in enumerate(poly):
            q = poly[i - 1]
            gp, gq = g(*p), g(*q)
            if (gp >= 0) != (gq >= 0):
                t = gq / (gq - gp)
                out.append((q[0] + t * (p[0] - q[0]), q[1] + t * (p[1] - q[1])))
            if gp >= 0:
                out.append(p)
        poly = out
    return poly


def _triangle_quad(f, p0, p1, p2):
    (x0, y0), (x1, y1), (x2, y2) = p0, p1, p2
    jac = abs((x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0))
    part, _ = si.dblquad(lambda t, s: f(x0 + s * (x1 - x0) + t * (x2 - x0), y0 + s * (y1 - y0) + t * (y2 - y0)),
                         0, 1, 0, lambda s: 1 - s, epsabs=1e-13, epsrel=1e-12)
    return jac * part


def test_polygon_integral_against_scipy_on_random_affine_regions():
    a, b, c = sp.symbols("a b c", real=True)
    rng = random.Random(3)
    done = 0
    for _ in range(12):
        at = {"a": Fraction(rng.randint(-9, 9), 10), "b": Fraction(rng.randint(1, 9), 10),
              "c": Fraction(rng.randint(-5, 5), 10)}
        conds = [Cond(y - a * x - b / 2), Cond(c + 1 - x - y), Cond(x + 2 * y - a)]
        weight = (1 + a * x) * (y - c) ** 2 + b * x * y
        ctx = _ctx(at)
        top = float(at["b"]) + 1
        val = local.polygon_integral(conds, weight, x, y, {x: (sp.Integer(-1), sp.Integer(1)),
                                                            y: (sp.Integer(-1), b + 1)}, ctx)
        if val is None:
            continue
        num = {sp.Symbol(k, real=True): float(q) for k, q in at.items()}
        f = sp.lambdify((x, y), weight.xreplace(num))
        gs = [sp.lambdify((x, y), cd.expr.xreplace(num)) for cd in conds]
        poly = _clip_halfplanes([(-1.0, -1.0), (1.0, -1.0), (1.0, top), (-1.0, top)], gs)
        ref = 0.0
        for p1, p2 in zip(poly[1:], poly[2:]):  # scipy over each fan triangle, smooth there
            ref += _triangle_quad(f, poly[0], p1, p2)
        assert float(val.xreplace(ctx.at)) == pytest.approx(ref, rel=1e-10, abs=1e-12)
        # the cell recorded holds at the point
        assert all(bool(rel.xreplace(ctx.at)) for rel in ctx.cell)
        done += 1
    assert done >= 8


def test_a_vertex_on_a_line_is_a_tie_not_a_closed_form():
    a = sp.Symbol("a", real=True)
    ctx = _ctx({"a": Fraction(1, 2)})
    # the line x = a passes through the corner (1/2, 0) of the clipped region x + y ≤ 1/2: a tie
    assert local.polygon_integral([Cond(x - a), Cond(Fraction(1, 2) - x - y)], sp.Integer(1), x, y,
                                  {x: (sp.Integer(0), sp.Integer(1)), y: (sp.Integer(0), sp.Integer(1))}, ctx) is None


def test_closed_roots_and_poles_match_numpy():
    a, b = sp.symbols("a b", real=True)
    expr = a - b / (v**2 - 3 * v + a)  # numerator a·(v² − 3v + a) − b: degree 2
    at = {a: sp.Rational(1, 3), b: sp.Rational(5, 7)}
    roots, poles = root_formulas.closed_roots(expr, v, lambda e: complex(e.xreplace(at).evalf(30)))
    num, _ = sp.fraction(sp.together(expr.xreplace(at)))
    want = sorted(np.roots([float(k) for k in sp.Poly(num, v).all_coeffs()]), key=lambda z: (z.real, z.imag))
    got = sorted((complex(r.xreplace(at).evalf(30)) for r in roots), key=lambda z: (z.real, z.imag))
    want = [z for z in want if abs(z.imag) < 1e-12]  # the roots checked at the point: the real ones
    assert got == pytest.approx(want)
    pol = sorted(complex(p.xreplace(at).evalf(30)).real for p in poles)
    assert pol == pytest.approx(sorted(np.roots([1, -3, 1 / 3]).real))


def test_closed_roots_refuses_a_cubic_numerator():
    a = sp.Symbol("a", real=True)
    assert root_formulas.closed_roots(v**3 - a * v + 1, v, lambda e: 1) is None


def test_dual_derivative_is_sympys_derivative():
    a, b, c = sp.symbols("a b c", real=True)
    e = (a**2 * b - 3 * c) / (a + b + 2) ** 3 + sp.Abs(a - c) * (b + 1) ** -2
    at = {a: sp.Rational(1, 3), b: sp.Rational(-2, 5), c: sp.Rational(3, 2)}
    tangent = {a: sp.Integer(1), b: sp.Rational(1, 2), c: sp.Integer(-2)}
    want = sum(sp.diff(e, s) * tangent[s] for s in at).xreplace(at)
    want = sp.Rational(want)
    assert rational.dual_derivative(e, at, tangent) == Fraction(int(want.p), int(want.q))
    assert rational.dual_derivative(sp.sqrt(a) + b, at, tangent) is None


def _clipped_area(tri, lo=Fraction(0), hi=Fraction(1)):
    """Exact area of a triangle cut to [lo, hi]² (test_stylize's Sutherland–Hodgman, here on
    Fractions, and the shoelace formula)."""
    poly = clip(list(tri), (lo, lo), (hi, hi))
    return abs(sum(p[0] * q[1] - q[0] * p[1] for p, q in zip(poly, poly[1:] + poly[:1]))) / 2


TRIANGLE = """param ax = 0.1, ay = -0.2, bx = 1.3, by = 0.4, cx = 0.3, cy = 0.8
int ([0, 1], [0, 1])
  let a = (ax, ay, 0) in let b = (bx, by, 0) in let c = (cx, cy, 0) in let p = (x, y, 0) in
  [cross(b - a, p - a).z >= 0 & cross(c - b, p - b).z >= 0 & cross(a - c, p - c).z >= 0]
d(x, y)
"""


@pytest.mark.parametrize("wrt", ["ax", "by", "cy"])
def test_clipped_triangle_area_derivative_against_exact_finite_differences(wrt):
    loaded = load_text(TRIANGLE, path="<triangle>.lgr")
    at = loaded.param_values()
    r = exact_deriv(loaded.program, at, {k: int(k == wrt) for k in at}, check=False)
    assert r.method == "closed_form"

    def area(shift):
        q = {k: Fraction(str(val)) + (shift if k == wrt else 0) for k, val in at.items()}
        return _clipped_area([(q["ax"], q["ay"]), (q["bx"], q["by"]), (q["cx"], q["cy"])])

    h = Fraction(1, 10**6)  # the area is piecewise quadratic: the central difference is exact but for
    # a switch of the clipped polygon within h (none here), so compare to rounding
    fd = (area(h) - area(-h)) / (2 * h)
    assert r.value == pytest.approx(float(fd), abs=1e-12)


def test_stylize_derivatives_against_the_numpy_kernel():
    from test_stylize import kernel

    loaded = load(str(EXAMPLES / "stylize" / "linear.lgr"))
    at = loaded.param_values()
    prm = {k: float(val) for k, val in loaded.params.items()}
    for wrt in ("ax", "pr"):
        r = exact_deriv(loaded.program, at, {k: int(k == wrt) for k in at}, check=False)
        assert r.method == "closed_form"
        step = 1e-6
        fd = (kernel({**prm, wrt: prm[wrt] + step}, False) - kernel({**prm, wrt: prm[wrt] - step}, False)) / (2 * step)
        assert r.value == pytest.approx(fd, abs=1e-7)
