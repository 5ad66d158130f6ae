"""Issue 15, exact13s: the stylization kernel's first partial derivatives with less sympy work —
integer powers of sums rebuilt without sympy's assumption queries in Newton–Cotes sums
(``walks.shared_xreplace``), a polynomial condition's coefficients without ``Poly``
(``quadrature.roots._expanded_coefficients``), the exact values of subtrees at a point shared between
Theorem 8.1's dual derivatives and exact values (``tape.Tape.values``).  Each gives the same
expressions and numbers as before; checked here against sympy's own ``xreplace``, ``Poly`` and
``integrate``, hand-solved roots, exact derivatives by sympy, the shoelace formula, an independent
numpy integration of the kernel (proofs_tests/test_stylize.py) and the Monte Carlo engine."""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
import sympy as sp
from test_stylize import clip, defaults, kernel

from langur.exact import exact_deriv
from langur.operational.batch import estimate_batch
from langur.symbolic import exact_rules, exactpairs, local, rational, tape, walks
from langur.symbolic.context import Cond, Context
from langur.symbolic.quadrature import roots
from langur.sympy_bridge import symbol
from langur.timebox import Deadline

X, Y, A, B, C = (symbol(n) for n in ("x13", "y13", "a13", "b13", "c13"))


def _random_form(rng: random.Random, depth: int, syms, with_abs: bool = True):
    """A real rational form: symbols and rationals under +, −, ·, integer powers (some of two-term
    sums), quotients and |·|."""
    if depth == 0 or rng.random() < 0.25:
        return rng.choice(list(syms) + [sp.Rational(rng.randint(-4, 4), rng.randint(1, 3))])
    a, b = _random_form(rng, depth - 1, syms, with_abs), _random_form(rng, depth - 1, syms, with_abs)
    op = rng.choice(["+", "-", "*", "pow", "sumpow", "div"] + (["abs"] if with_abs else []))
    if op == "+":
        return a + b
    if op == "-":
        return a - b
    if op == "*":
        return a * b
    if op == "pow":
        return a ** rng.choice([-2, -1, 2, 3])
    if op == "sumpow":
        return (a + rng.choice(list(syms))) ** rng.choice([-2, -1, 2, 3])
    if op == "div":
        return a / (b + rng.choice(list(syms)) + 1)
    return sp.Abs(a)


def _count_add_powers(monkeypatch) -> list:
    """Calls of sympy's ``Add._eval_power`` (the evaluation of a power of a sum) from now on."""
    calls = []
    real = sp.Add._eval_power

    def counted(self, expt):
        calls.append(self)
        return real(self, expt)

    monkeypatch.setattr(sp.Add, "_eval_power", counted)
    return calls


def test_shared_xreplace_is_sympys_xreplace_on_real_rational_forms(monkeypatch):
    rng = random.Random(13)
    forms = [_random_form(rng, 4, (X, Y, A)) for _ in range(150)]
    values = [A + sp.Rational(1, 3) * (B - A), B * C - 2, sp.Rational(5, 7)]
    ours = [[walks.shared_xreplace(e, {X: v}) for v in values] for e in forms]
    # powers of two-term sums (terms of a sum), rebuilt: not through sympy's evaluation of a power
    # of a sum (its queries of the terms' assumptions), which leaves them as they are
    sums = (X * A + Y) ** 2 + sp.Abs(A - B) + (X - B) ** -1 + (X * C + B) ** 3
    calls = _count_add_powers(monkeypatch)
    rebuilt = walks.shared_xreplace(sums, {X: B * C - 2})
    assert not calls
    monkeypatch.undo()
    assert sp.srepr(rebuilt) == sp.srepr(sums.xreplace({X: B * C - 2}))
    for e, row in zip(forms, ours):
        for v, got in zip(values, row):
            assert sp.srepr(got) == sp.srepr(e.xreplace({X: v})), (e, v)


def test_the_powers_of_sums_that_need_sympys_evaluation_still_get_it():
    z = sp.Symbol("z13")  # (not declared real)
    cases = [((X + Y) ** 2 * sp.sqrt(A), {X: B}), ((X + z) ** 2, {X: B}), ((X + Y) ** 2, {X: sp.I * B}),
             ((X + Y) ** 3, {X: sp.Float(0.5)}), ((X + Y) ** 2 + sp.sin(X), {X: B})]
    for e, rule in cases:
        assert not (walks.rational_form(e) and all(walks.rational_form(v) for v in rule.values()))
        got = walks.shared_xreplace(e, rule)
        assert sp.srepr(got) == sp.srepr(e.xreplace(rule))
    # the imaginary unit's case that evaluation rewrites: (a + I·b)^-1 with b infinite
    assert not walks.rational_form(X + sp.I * sp.oo)


def test_newton_cotes_of_a_delta_piece_shaped_weight_is_the_integral():
    # |det|·(polynomial in v with coefficients rational in the parameters), between affine bounds
    v = symbol("v13")
    w = sp.Abs(A - 2 * B) * ((v - A) ** 2 * (B + 1) / (A + 3) + (v * B - 1) ** 3 / (B - A - 5) + (A + v) * C)
    lo, hi = A * B - C, 2 * A + 1
    got = exact_rules.newton_cotes(w, v, lo, hi, 3)
    want = sp.integrate(w, (v, lo, hi))
    rng = random.Random(5)
    for _ in range(12):  # exactly equal at rational points
        pt = {s: sp.Rational(rng.randint(-20, 20), rng.randint(1, 9)) for s in (A, B, C)}
        if (pt[A] + 3) * (pt[B] - pt[A] - 5) == 0:
            continue
        assert got.xreplace(pt) == want.xreplace(pt)


def test_expanded_coefficients_are_polys_own():
    rng = random.Random(7)
    checked = 0
    for _ in range(300):
        e = _random_form(rng, 4, (X, Y, A, B), with_abs=False)
        for v in (X, Y):
            out = roots._expanded_coefficients(e, v)
            if out is None:
                continue
            checked += 1
            assert [sp.srepr(c) for c in out] == [sp.srepr(c) for c in sp.Poly(e, v).all_coeffs()], e
    assert checked > 50
    # left to Poly: Floats, roots, a denominator in the variable, constants, degree > 8
    for e in (X * sp.Float(0.5) + A, sp.sqrt(A) * X + 1, X + 1 / X, A + B, X ** 9 + A):
        assert roots._expanded_coefficients(e, X) is None


def test_affine_conditions_roots_by_hand():
    # the stylization kernel's edge condition (bx - ax)(y - ay) - (x - ax)(by - ay) in x: one root
    ax, ay, bx, by = (symbol(n) for n in ("ax13", "ay13", "bx13", "by13"))
    cond = (bx - ax) * (Y - ay) - (X - ax) * (by - ay)
    at = {ax: Fraction(1, 10), ay: Fraction(3, 20), bx: Fraction(17, 20), by: Fraction(3, 10)}
    fn = roots._poly_roots(cond, [Y, X], 1, {k: float(v) for k, v in at.items()})
    for yv in (0.25, 0.5, 0.7):
        (r,) = fn(yv)
        hand = at[ax] + (Fraction(yv) - at[ay]) * (at[bx] - at[ax]) / (at[by] - at[ay])
        assert r == pytest.approx(float(hand), rel=1e-14, abs=1e-15)


def test_tape_values_are_shared_with_exact_values_at_the_point():
    vertex = (A * B - C) / (A - B + 3)
    f = (vertex ** 2 + C) * (X - vertex) + sp.Abs(B - 7) * vertex ** 3
    g = vertex ** 3 * (Y + A) - C * vertex
    point = {A: sp.Rational(3, 7), B: sp.Rational(-5, 11), C: sp.Rational(2, 13), X: sp.Rational(1, 3),
             Y: sp.Rational(7, 5)}
    tangent = {A: 1, B: 0, C: 0, X: 0, Y: 0}
    d = rational.dual_derivative(f, point, tangent)
    assert d == Fraction(str(sp.diff(f, A).xreplace(point)))
    # the tape left its subtrees' values for the other form at the same point
    memo = tape.point_memo(exactpairs.EXACT, point)
    assert memo.get(A * B - C) is not None and memo.get(f) is not None
    assert rational.rational_value(g, point) == Fraction(str(g.xreplace(point)))


def test_polygon_of_the_triangle_in_the_pixel_has_the_shoelace_area():
    # ∫∫ [edges ≥ 0] · 1 over the pixel: the clipped triangle's area by the shoelace formula
    _, prm = defaults("linear")
    q = {k: Fraction(v).limit_denominator(1000) for k, v in prm.items()}
    ax, ay, bx, by, cx, cy, px, py, h, x, y = (symbol(n) for n in ("ax", "ay", "bx", "by", "cx", "cy", "px", "py",
                                                                   "h", "x", "y"))
    conds = [Cond((cx - bx) * (y - by) - (cy - by) * (x - bx)), Cond((ax - cx) * (y - cy) - (ay - cy) * (x - cx)),
             Cond((bx - ax) * (y - ay) - (by - ay) * (x - ax))]
    at = {symbol(k): sp.Rational(v.numerator, v.denominator) for k, v in q.items()}
    area = local.polygon_integral(conds, sp.Integer(1), x, y, {x: (px, px + h), y: (py, py + h)},
                                  Context(at, Deadline(20.0), frozenset(at)))
    poly = clip([(q["ax"], q["ay"]), (q["bx"], q["by"]), (q["cx"], q["cy"])], (q["px"], q["py"]),
                (q["px"] + q["h"], q["py"] + q["h"]))
    shoelace = abs(sum(p[0] * r[1] - r[0] * p[1] for p, r in zip(poly, poly[1:] + poly[:1]))) / 2
    assert len(poly) >= 5 and area.xreplace(at) == sp.Rational(shoelace.numerator, shoelace.denominator)


@pytest.mark.parametrize("name", ["linear", "quadratic"])
def test_stylize_dax_against_numpy_and_monte_carlo(name):
    loaded, prm = defaults(name)
    r = exact_deriv(loaded.program, loaded.param_values(), {k: int(k == "ax") for k in loaded.params})
    step = 1e-6
    fd = (kernel({**prm, "ax": prm["ax"] + step}, name == "quadratic")
          - kernel({**prm, "ax": prm["ax"] - step}, name == "quadratic")) / (2 * step)
    assert r.value == pytest.approx(fd, rel=1e-6, abs=1e-9)
    assert r.theorem_8_1 is not None and r.theorem_8_1.holds is True
    grid = {"px": [prm["px"]], "py": [prm["py"]], "h": prm["h"]}
    mc = estimate_batch(loaded, grid, direction={"ax": 1.0}, samples=20000, seed=13)
    assert abs(mc.derivative[0] - r.value) <= 5 * mc.derivative_stderr[0] + 1e-9
