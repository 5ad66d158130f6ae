"""Issue 15, exact15s: the polygon closed forms' sums built with fewer sympy operations, and a condition's
coefficient functions compiled by the shared printer.

* ``local.polygon_integral`` adds the terms w·c_ab·Xᵃ·Yᵇ of all the rule points of a triangle in one sum
  (``local._point_terms``) instead of Σ_points w·(Σ_ab c_ab·Xᵃ·Yᵇ) — the same expression (checked here
  against that construction, written out in the test, on random rational forms with sums, numbers,
  symbols and products as coefficients, and numbers, symbols and sums as the point's coordinates);
  no per-point sum is made any more (fails on the old code).
* ``text.shared_lambdify`` of a list of expressions (``roots._coefficients``: a condition's coefficients
  as one function): sympy lambdify's source text and values, without sympy's lambdify (fails on the old
  code, which handed lists to it).

Values are checked independently: the polygon's closed form at the point against the moments of the
clipped polygon by the edge-midpoint and shoelace formulas (exact rationals), the coefficient functions
against sympy's ``Poly`` coefficients evaluated exactly."""

from __future__ import annotations

import gc
import inspect
import random
from fractions import Fraction

import pytest
import sympy as sp

from langur.symbolic import local, text
from langur.symbolic.context import Cond, Context
from langur.symbolic.quadrature import roots
from langur.sympy_bridge import symbol
from langur.timebox import Deadline

X, Y, A, B, C, D = (symbol(n) for n in ("x15", "y15", "a15", "b15", "c15", "d15"))


def _old_sum(points, coeffs):
    """What polygon_integral summed over a triangle before: Σ_points w·(Σ_ab c_ab·Xᵃ·Yᵇ), each product
    and sum built by sympy's operators as the old ``_at_point`` built them."""
    return sp.Add(*[w * sp.Add(*[c * X0 ** a * Y0 ** b for (a, b), c in sorted(coeffs.items())])
                    for w, X0, Y0 in points])


def _random_form(rng: random.Random, depth: int = 2):
    """A random real rational form in the parameters: sums, products, integer powers, rationals (no
    division by an expression that is 0: no infinities)."""
    while True:
        e = _form(rng, depth)
        if not e.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
            return e


def _form(rng: random.Random, depth: int):
    if depth == 0 or rng.random() < 0.25:
        return rng.choice([A, B, C, D, sp.Rational(rng.randint(-4, 4), rng.randint(1, 3))])
    kind = rng.random()
    parts = [_form(rng, depth - 1) for _ in range(rng.randint(2, 3))]
    if kind < 0.5:
        return sp.Add(*parts)
    if kind < 0.85:
        return sp.Mul(*parts)
    return parts[0] ** rng.choice([2, 3, -1])


def _random_coordinate(rng: random.Random):
    """A rule point's coordinate: a sum (as the stylization kernel's), a symbol or a number."""
    r = rng.random()
    if r < 0.7:
        return _random_form(rng, 1) + rng.choice([A, B, C]) * sp.Rational(rng.randint(1, 5), rng.randint(2, 7)) + \
            sp.Rational(rng.randint(-3, 3), 4)
    return rng.choice([A, B, sp.Rational(rng.randint(-5, 5), 3)])


def test_one_sum_of_the_weighted_terms_is_the_old_sum_of_sums():
    rng = random.Random(15)
    checked = fast = 0
    for _ in range(60):
        coeffs = {}
        for a in range(4):
            for b in range(4 - a):
                if rng.random() < 0.85:
                    c = _random_form(rng)
                    if c != 0:
                        coeffs[(a, b)] = c
        if rng.random() < 0.3:  # the constant coefficient a sum, as the kernel's
            coeffs[(0, 0)] = A * B + C - sp.Rational(1, 3)
        points = []
        for _ in range(rng.randint(1, 4)):
            w = sp.Rational(rng.choice([-27, -1, 1, 25, 48]), rng.choice([1, 48, 96]))
            points.append((w, _random_coordinate(rng), _random_coordinate(rng)))
        new = sp.Add(*[t for w, X0, Y0 in points for t in local._point_terms(coeffs, X0, Y0, {}, w)])
        assert sp.srepr(new) == sp.srepr(_old_sum(points, coeffs))
        for _, X0, Y0 in points:
            assert sp.srepr(local._at_point(coeffs, X0, Y0, {})) == sp.srepr(
                sp.Add(*[c * X0 ** a * Y0 ** b for (a, b), c in sorted(coeffs.items())]))
            fast += sum(1 for (a, b), c in coeffs.items() if c.is_Add and (a or b)
                        and not (X0.is_Number or Y0.is_Number))
        checked += 1
    assert checked == 60 and fast > 200  # the one-product path was taken often


def _moment(poly, a: int, b: int) -> Fraction:
    """∫∫ xᵃ yᵇ over the convex polygon (counter-clockwise vertices, Fractions), a + b ≤ 2: Green's
    theorem with Simpson's rule on each edge (exact for the cubic integrand along an edge)."""
    total = Fraction(0)
    for (x0, y0), (x1, y1) in zip(poly, poly[1:] + poly[:1]):
        # ∮ xᵃ⁺¹ yᵇ /(a + 1) dy along the edge, parametrized linearly: Simpson's rule is exact (degree ≤ 3)
        values = []
        for t in (Fraction(0), Fraction(1, 2), Fraction(1)):
            x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
            values.append(x ** (a + 1) * y ** b / (a + 1) * (y1 - y0))
        total += (values[0] + 4 * values[1] + values[2]) / 6
    return total


def test_the_triangle_closed_form_makes_no_per_point_sum_and_has_the_polygons_moments(monkeypatch):
    # the kernel's shape: [edge ≥ 0]·(c20·x² + c11·x·y + c02·y² + c10·x + c01·y + c00) over a box, each
    # coefficient a sum of parameters; one edge x + y ≤ s cuts the box [0, 1]² (a pentagon at the point)
    s = A + B
    weight = (A + C) * X ** 2 + (B - C) * X * Y + (C + D) * Y ** 2 + (A - D) * X + (B + D) * Y + (A * B + 1)
    at = {A: sp.Rational(3, 4), B: sp.Rational(1, 2), C: sp.Rational(-1, 3), D: sp.Rational(2, 5)}

    def refuse(*args, **kwargs):
        raise AssertionError("a per-point sum was made")

    for name in ("_LINES", "_VERTICES", "_RELATIONS", "_TRIANGLES", "_MONOMIALS"):
        getattr(local, name).clear()
    monkeypatch.setattr(local, "_at_point", refuse)
    ctx = Context(at, Deadline(20.0), frozenset(at))
    form = local.polygon_integral([Cond(s - X - Y)], weight, X, Y, {X: (sp.Integer(0), sp.Integer(1)), Y: (sp.Integer(0), sp.Integer(1))}, ctx)
    assert form is not None
    sv = Fraction(5, 4)
    poly = [(Fraction(0), Fraction(0)), (Fraction(1), Fraction(0)), (Fraction(1), sv - 1),
            (sv - 1, Fraction(1)), (Fraction(0), Fraction(1))]
    q = {k: Fraction(int(v.p), int(v.q)) for k, v in at.items()}
    want = ((q[A] + q[C]) * _moment(poly, 2, 0) + (q[B] - q[C]) * _moment(poly, 1, 1)
            + (q[C] + q[D]) * _moment(poly, 0, 2) + (q[A] - q[D]) * _moment(poly, 1, 0)
            + (q[B] + q[D]) * _moment(poly, 0, 1) + (q[A] * q[B] + 1) * _moment(poly, 0, 0))
    assert form.xreplace(at) == sp.Rational(want.numerator, want.denominator)
    assert all(rel.lhs.xreplace(at) > 0 for rel in ctx.cell)


def test_shared_lambdify_of_a_list_is_sympys_code_without_sympys_lambdify(monkeypatch):
    exprs = [A * X ** 2 + B * X / 3 - 1, sp.sqrt(A + B) * X, sp.Rational(1, 7), (A - B) ** -2 * Y + sp.Abs(C),
             sp.exp(A) - sp.loggamma(B)]
    args = [X, Y, A, B, C]
    want = {mod: sp.lambdify(args, exprs, modules=[mod]) for mod in ("math", "numpy", "mpmath")}
    for mod in want:
        text.shared_lambdify(args, A + X, mod)  # (the module's namespace, which sympy's lambdify gives once)
    monkeypatch.setattr(sp, "lambdify", lambda *a, **k: pytest.fail("sympy's lambdify was called"))
    monkeypatch.setattr(text.sp, "lambdify", lambda *a, **k: pytest.fail("sympy's lambdify was called"))
    point = (0.5, 0.25, 0.3, 0.7, -0.2)
    for mod, f in want.items():
        g = text.shared_lambdify(args, list(exprs), mod)
        assert inspect.getsource(g) == inspect.getsource(f)
        assert [complex(v) for v in g(*point)] == [complex(v) for v in f(*point)]


def test_a_conditions_coefficient_function_gives_polys_coefficients(monkeypatch):
    roots._COEFFICIENTS.clear()
    text.shared_lambdify([X], X, "math")  # (the module's namespace, which sympy's lambdify gives once)
    monkeypatch.setattr(text.sp, "lambdify", lambda *a, **k: pytest.fail("sympy's lambdify was called"))
    rng = random.Random(3)
    for _ in range(12):
        e = sum((sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) * rng.choice([A, B, A * B, sp.Integer(1)])
                 * Y ** k for k in range(rng.randint(2, 4))), sp.Integer(0)) + X * Y * A - B
        fn = roots._coefficients(e, (X, Y), 1, (A, B))
        cs = sp.Poly(e, Y).all_coeffs()
        vals = {X: sp.Rational(1, 3), A: sp.Rational(-2, 7), B: sp.Rational(5, 4)}
        got = fn(float(vals[X]), float(vals[A]), float(vals[B]))
        assert len(got) == len(cs)
        for g, c in zip(got, cs):
            assert g == pytest.approx(float(c.xreplace(vals)), rel=1e-14, abs=1e-14)


def test_a_compiled_lists_key_is_not_hashed_again_when_its_function_goes(monkeypatch):
    # text.shared_lambdify's weak dictionary hashes a key again when the function goes (at worst at
    # interpreter shutdown, where a bare Float's hash, recomputed through mpmath, failed): the key's
    # hash is computed once, when the function is made
    x = sp.Symbol("x")
    weight = sp.Float(0.123456789, 30)  # a Float not in any earlier key
    fn = text.shared_lambdify([x], [weight, x + 1], "math")
    assert fn(1.0) == [float(weight), 2.0]
    before = len(text._FUNCTIONS)
    hashed = []
    real = sp.Float.__hash__
    monkeypatch.setattr(sp.Float, "__hash__", lambda self: hashed.append(self) or real(self))
    del fn
    gc.collect()
    assert len(text._FUNCTIONS) == before - 1  # the entry went
    assert hashed == []
