"""Issue 15, exact16s: a one-shot ``langur deriv`` of the stylization kernel made cheaper.

* ``local._near_form``: the polygon closed form that only Theorem 8.1's check reads (⟦p⟧ near the point,
  ``local.cell_forms``) is built as Σ_ab c_ab·M_ab over the polygon's moments, its sums and products
  unevaluated, when it and the canonical form are both certainly large (``local.NEAR_LARGE``); else the
  canonical form, as before.  Checked here: the two forms are the same function (exact values and exact
  directional derivatives by dual numbers at random rational points), the small case keeps the canonical
  tree, and the stylize kernel's partial derivative and Theorem 8.1's numbers are the same with and without
  it (fails on the old code, which has no ``near`` form).
* ``local._residue`` (values modulo a prime that tell expressions apart): the exact value reduced modulo
  the prime, None for what is not a rational form.
* ``pieceproblems.piece_problem``: a rational weight's scalar ``math`` function compiled at its first
  call (``compiling.OnFirstCall``): the stylize kernel's regular pieces never call it (fails on the old
  code, which compiled it at once); when called it gives ``_lambdify``'s values.
"""

from __future__ import annotations

import os
import random
from fractions import Fraction

import sympy as sp

from langur import denote, theorem
from langur.exact import exact_deriv
from langur.frontend import load
from langur.symbolic import context, local, rational, tape, walks
from langur.symbolic.context import Cond, Context
from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature import compiling, nested, pieceproblems
from langur.sympy_bridge import symbol
from langur.timebox import Deadline

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")
X, Y = symbol("x16"), symbol("y16")
P = [symbol(f"p16_{i}") for i in range(8)]
UNIT = {X: (sp.Integer(0), sp.Integer(1)), Y: (sp.Integer(0), sp.Integer(1))}


def _clear():
    for name in ("_LINES", "_VERTICES", "_RELATIONS", "_TRIANGLES", "_MONOMIALS"):
        getattr(local, name).clear()


def _triangle_problem(big: bool):
    """A triangle with parametric vertices (p0, p1), (p2, p3), (p4, p5) inside the unit box, and a
    quadratic weight whose coefficients are sums of parameters (long ones when ``big``)."""
    (ax, ay, bx, by, cx, cy) = P[:6]
    edges = [(cx - bx) * (Y - by) - (cy - by) * (X - bx), (ax - cx) * (Y - cy) - (ay - cy) * (X - cx),
             (bx - ax) * (Y - ay) - (by - ay) * (X - ax)]
    if big:
        s = [sp.Add(*[(k + 1) * P[(i + k) % 8] * P[(i + 2 * k + 1) % 8] for k in range(8)]) for i in range(6)]
    else:
        s = [sp.Integer(1), sp.Integer(0), sp.Integer(0), sp.Integer(0), sp.Integer(0), sp.Integer(0)]
    weight = s[0] + s[1] * X + s[2] * Y + s[3] * X ** 2 + s[4] * X * Y + s[5] * Y ** 2
    at = dict(zip(P, [sp.Rational(1, 10), sp.Rational(3, 20), sp.Rational(17, 20), sp.Rational(3, 10),
                      sp.Rational(7, 20), sp.Rational(9, 10), sp.Rational(1, 2), sp.Rational(-1, 3)]))
    return [Cond(e) for e in edges], weight, at


def _polygon(big: bool, near: bool):
    conds, weight, at = _triangle_problem(big)
    _clear()
    ctx = Context(at, Deadline(60.0), frozenset(at))
    with local.cell_forms():
        form = local.polygon_integral(conds, weight, X, Y, UNIT, ctx, near=near)
    return form, ctx.cell, at


def _nearby(at: dict, rng: random.Random) -> dict:
    return {k: v + sp.Rational(rng.randint(-50, 50), 100_000) for k, v in at.items()}


def test_the_near_form_is_the_canonical_form_as_a_function():
    canonical, cell, at = _polygon(True, near=False)
    made = []
    real = local._near_form

    def spy(*args):
        made.append(real(*args))
        return made[-1]

    local._near_form = spy
    try:
        near, near_cell, _ = _polygon(True, near=True)
    finally:
        local._near_form = real
    assert made and made[0] is near  # the moments' form was taken
    assert walks.tree_size(near) >= local.NEAR_LARGE and walks.tree_size(canonical) >= local.NEAR_LARGE
    assert near_cell == cell  # the same cell
    rng = random.Random(16)
    point = {k: Fraction(int(v.p), int(v.q)) for k, v in at.items()}
    for q in [at] + [_nearby(at, rng) for _ in range(6)]:
        qs = {k: Fraction(int(v.p), int(v.q)) for k, v in q.items()}
        assert rational.rational_value(near, qs) == rational.rational_value(canonical, qs)
        # sympy's own substitution of the canonical form (an independent evaluation)
        assert rational.rational_value(near, qs) == Fraction(str(canonical.xreplace(q)))
    for _ in range(4):
        tangent = {s: Fraction(rng.randint(-3, 3)) for s in P}
        d = rational.dual_derivative(near, point, tangent)
        assert d is not None and d == rational.dual_derivative(canonical, point, tangent)


def test_a_small_polygon_keeps_the_canonical_tree():
    canonical, _, _ = _polygon(False, near=False)
    near, _, _ = _polygon(False, near=True)
    assert walks.tree_size(canonical) < local.NEAR_LARGE
    assert sp.srepr(near) == sp.srepr(canonical)


def test_residues_are_the_exact_values_modulo_the_prime():
    rng = random.Random(7)
    point = {s: sp.Rational(rng.randint(-9, 9), rng.randint(1, 7)) for s in P[:4]}
    res = {s: local._residue(v, {}, {}) for s, v in point.items()}
    for _ in range(200):
        e = sp.Integer(rng.randint(-3, 3))
        for _ in range(rng.randint(1, 4)):
            f = rng.choice(P[:4]) ** rng.choice([1, 1, 2, 3, -1])
            e = e + rng.randint(-5, 5) * f if rng.random() < 0.5 else e * (f + sp.Rational(rng.randint(1, 9), 4))
        v = sp.sympify(e).xreplace(point)
        if v.is_zero is False or v == 0:
            q = Fraction(str(v))
            got = local._residue(sp.sympify(e), res, {})
            if q.denominator % local._PRIME and got is not None:
                assert got == q.numerator * pow(q.denominator, -1, local._PRIME) % local._PRIME
    assert local._residue(sp.Abs(P[0] - 1), res, {}) is None
    assert local._residue(sp.sqrt(P[0]), res, {}) is None
    assert local._residue(sp.Float(0.5) * P[0], res, {}) is None
    assert local._residue(P[5], res, {}) is None  # no value


def test_the_kernels_derivative_and_theorem_numbers_are_those_of_the_canonical_form():
    loaded = load(os.path.join(EXAMPLES, "stylize", "linear.lgr"))
    at = loaded.param_values()
    direction = {q: int(q == "ax") for q in at}
    real = local._near_form
    taken = []

    def spy(*args):
        taken.append(real(*args))
        return taken[-1]

    def canonical(*args):
        return None

    answers = []
    for fake in (spy, canonical):
        local._near_form = fake
        try:
            denote._remembered.clear()
            tape.TAPES.clear()
            r = exact_deriv(loaded.program, at, direction)
        finally:
            local._near_form = real
        th = r.theorem_8_1
        answers.append((r.value, r.method, th.holds, th.how, th.d_denotation, th.derivative_denotation,
                        [(p.d_denotation, p.derivative_denotation) for p in th.points], th.notes))
    assert any(t is not None for t in taken)  # the moments' form was used for ⟦p⟧ near the point
    assert answers[0] == answers[1]
    assert answers[0][2] is True


def test_a_rational_weight_is_compiled_at_its_first_call():
    conds, weight, at = _triangle_problem(True)
    pc = Piece((Condition(conds[0].expr), Condition(conds[1].expr), Condition(conds[2].expr)), weight)
    prob = pieceproblems.piece_problem(pc, [X, Y], [(0, 1), (0, 1)], at)
    assert isinstance(prob.weight, compiling.OnFirstCall)
    value, error = nested.integrate_problem(prob)
    assert prob.weight._f is None  # the vectorized weight integrated every innermost interval
    eager = compiling._lambdify([X, Y], weight, at)
    for u, v in [(0.2, 0.3), (0.5, 0.5), (0.7, 0.1)]:
        assert prob.weight(u, v) == eager(u, v)
        assert abs(eager(u, v) - float(weight.xreplace({**at, X: sp.Float(u), Y: sp.Float(v)}))) <= 1e-12 * (
            1 + abs(eager(u, v)))
    # the value: the canonical polygon form at the point (exact) within the quadrature's error
    form, _, _ = _polygon(True, near=False)
    exact = float(rational.rational_value(form, {k: Fraction(int(v.p), int(v.q)) for k, v in at.items()}))
    assert abs(value - exact) <= max(1e-7, 10 * error) * (1 + abs(exact))


def test_a_value_at_the_point_rebuilds_each_distinct_subtree_once(monkeypatch):
    # a root formula's shape: the same radicand and denominator in both roots
    a, b, c = P[:3]
    disc = sp.sqrt(b ** 2 - 4 * a * c)
    expr = (-b + disc) / (2 * a) + (-b - disc) / (2 * a) * (b ** 2 - 4 * a * c) + disc ** 3
    at = {a: sp.Rational(1, 3), b: sp.Rational(5, 2), c: sp.Rational(-7, 4)}
    calls = []
    real = walks.shared_xreplace
    monkeypatch.setattr(walks, "shared_xreplace", lambda *args: calls.append(1) or real(*args))
    context._VALUES.clear()
    got = Context(at, Deadline(20.0), frozenset(at)).value(expr)
    assert calls  # (the old code used sympy's xreplace)
    want = complex(sp.N(expr.xreplace(at), 40))  # exact rationals substituted, then 40 digits
    assert abs(got - want) <= 1e-25 * abs(want)
    # a form holding a Float keeps sympy's own substitution
    calls.clear()
    context._VALUES.clear()
    Context(at, Deadline(20.0), frozenset(at)).value(expr + sp.Float("0.1", 15) * a)
    assert not calls


def test_the_near_forms_threshold_covers_every_size_that_changes_how_a_form_is_used():
    # Theorem 8.1's symbolic comparison (theorem.SYMBOLIC_OPS), integrate._tidy's simplify (1,000 nodes),
    # Context.exact_value's rational path (local.LARGE_OPS): a form of NEAR_LARGE nodes or more is past all
    assert local.NEAR_LARGE >= theorem.SYMBOLIC_OPS >= 1000 >= local.LARGE_OPS
