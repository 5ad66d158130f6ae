"""exact13r (issue 15, raytrace ∂/∂t): the delta pieces' forward Jacobian and the regions' shortcuts.

* ``deltaproblems.cofactor_det`` — det DΨ̂ for the quadrature, by cofactor expansion, nothing
  simplified (sympy's ``Matrix.det`` expands and cancels, a third of a second for the ray tracer's
  shader) — against the Leibniz sum written out here (2×2 … 4×4), against sympy's determinant as a
  rational function (random rational entries, the ray tracer's Jacobians), and end to end: a
  delta integral with a hand value (∂/∂a ∫∫_[0,1]² [xy ≥ a] = log a, Ψ̂ with det = the other
  variable), and the ray tracer's z-depth boundary at a pixel it crosses against the Monte Carlo
  engine (5 standard errors) and the closed form.
* ``Context.value_with(e, numbers)`` is ``value(e.xreplace(numbers))`` (to 25 digits) in one
  substitution, and is remembered.
* ``regions._dedupe`` drops exactly what ``expand(b − o) == 0`` drops; ``_rational_probe`` is the
  exact value at its rational point (None for a root).
"""

from __future__ import annotations

import itertools
import math
import random
from fractions import Fraction
from pathlib import Path

import pytest
import sympy as sp

from langur.ddenote import ddenote_program
from langur.frontend import load, load_text
from langur.operational import estimate_derivative
from langur.symbolic import context, delta
from langur.symbolic.context import Context
from langur.symbolic.quadrature.deltaproblems import _FORWARD_DETS, _forward_det, cofactor_det, jacobian_det
from langur.symbolic.regions import _dedupe, _rational_probe
from langur.timebox import Deadline

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
x, y, z, a, b, t = sp.symbols("x y z a b t", real=True)


def _leibniz(m: sp.Matrix) -> sp.Expr:
    """Σ_σ sgn σ Π m[i, σ(i)] (the definition), the sign by counting inversions."""
    n = m.rows
    total = sp.Integer(0)
    for perm in itertools.permutations(range(n)):
        inversions = sum(1 for i in range(n) for j in range(i + 1, n) if perm[i] > perm[j])
        term = sp.Integer(-1) ** inversions
        for i in range(n):
            term *= m[i, perm[i]]
        total += term
    return total


def test_cofactor_det_is_the_formula_unsimplified():
    m = sp.Matrix([[x, y], [z, a]])
    assert cofactor_det(m) == x * a - y * z
    # nothing cancelled: (x² − 1)/(x − 1) stays as it is (sympy's det would cancel it to x + 1)
    q = (x ** 2 - 1) / (x - 1)
    assert cofactor_det(sp.Matrix([[q, 0], [0, 1]])) == q
    assert cofactor_det(sp.Matrix([[q]])) == q
    with pytest.raises(ValueError):
        cofactor_det(sp.Matrix([[x, y, z], [a, b, t]]))


@pytest.mark.parametrize("n", [2, 3, 4])
def test_cofactor_det_equals_the_leibniz_sum(n):
    rng = random.Random(n)
    syms = [x, y, z, a, b, t]
    for _ in range(6):
        m = sp.Matrix(n, n, lambda i, j: sum(rng.randint(-3, 3) * rng.choice(syms) ** rng.randint(0, 2)
                                             for _ in range(2)))
        assert sp.expand(cofactor_det(m) - _leibniz(m)) == 0


def _points(syms, n, seed):
    rng = random.Random(seed)
    return [{s: sp.Rational(rng.randint(-900, 900), rng.randint(1, 97)) for s in syms} for _ in range(n)]


def _same_function(e1, m: sp.Matrix, syms, seed) -> None:
    """``e1`` = det ``m`` exactly at random rational points (sympy's det of the numeric matrix)."""
    for pt in _points(syms, 4, seed):
        num = m.xreplace(pt)
        if any(not v.is_finite for v in num):
            continue
        assert e1.xreplace(pt) == num.det()


def test_cofactor_det_equals_sympys_determinant_of_rational_entries():
    rng = random.Random(5)
    for n in (2, 3):
        for k in range(5):
            def entry(i, j):
                num = rng.randint(-4, 4) * x + rng.randint(-4, 4) * y + rng.randint(1, 3)
                den = rng.randint(1, 3) * x ** 2 + rng.randint(1, 3) * a + rng.randint(1, 2)
                return num / den
            m = sp.Matrix(n, n, entry)
            _same_function(cofactor_det(m), m, (x, y, a), 10 * n + k)
    m = sp.Matrix([[(x - y) / (x + a), x * y], [1 / (y - a), (x + 1) / (x - 1)]])
    assert sp.cancel(cofactor_det(m) - m.det()) == 0  # as rational functions too


def test_the_ray_tracers_forward_determinants_equal_sympys():
    loaded = load(str(EXAMPLES / "raytrace" / "scene.lgr"))
    at = loaded.param_values()
    _FORWARD_DETS.clear()
    res = ddenote_program(loaded.program, at, {k: int(k == "t") for k in at})
    # (made when a quadrature first needs a weight, since exact14r: this pixel's regions are empty)
    for piece in res.normal_form.deltas:
        _forward_det(piece.psi)
    # 3 edges, the depth boundary and (since pole31) the depth shader's pole n·d = 0 (the ray parallel to the
    # triangle's plane): it moves with t, so the shader is split there into conditionals on its factors' signs
    # (docs/language.md "Signs of factors") and the pole is a Ψ̂ of its own
    assert len(_FORWARD_DETS) == 5
    # independently, from the scene's vertices A, B, C: one forward condition is a constant times n·d
    A = sp.Matrix([-sp.Rational(9, 20) - 3 * t / 10, -sp.Rational(9, 20) - 3 * t / 10, 2 - 3 * t / 5])
    B = sp.Matrix([sp.Rational(11, 20) + 3 * t / 10, -sp.Rational(1, 4), 3])
    C = sp.Matrix([-sp.Rational(3, 20), sp.Rational(3, 5) + 3 * t / 10, 3])
    n_dot_d = (B - A).cross(C - A).dot(sp.Matrix([x, y, 1]))
    assert sum(not sp.cancel(forward[0] / n_dot_d).free_symbols for forward, _ in _FORWARD_DETS) == 1
    for (forward, variables), det in _FORWARD_DETS.items():
        jac = sp.Matrix(forward).jacobian(list(variables))
        assert det == jacobian_det(forward, variables)  # the formula, not sympy's cancelled form (new)
        _same_function(det, jac, sorted(jac.free_symbols, key=str), 7)  # the same function


def test_jacobian_det_differentiates_only_what_the_expansion_multiplies():
    f = (a * x + b * y) ** 3 / (x - y + 2)
    assert jacobian_det((f, x), (x, y)) == -sp.diff(f, y)  # Ψ̂ = (f, x): ∂f/∂x is not needed
    rng = random.Random(9)
    syms = [x, y, z]
    for n in (2, 3):
        for _ in range(6):
            fs = [sum(rng.randint(-3, 3) * rng.choice(syms[:n]) ** rng.randint(0, 2) * rng.choice([1, a])
                      for _ in range(2)) for _ in range(n)]
            jac = sp.Matrix(fs).jacobian(syms[:n])
            assert sp.expand(jacobian_det(fs, syms[:n]) - _leibniz(jac)) == 0


def _old_jacobian(comps, inputs):
    """delta._jacobian as it was: every entry differentiated, then sympy's det (on the zero set)."""
    return sp.Matrix([[sp.diff(e, u) for u in inputs] for e in comps]).det().xreplace({inputs[0]: sp.Integer(0)})


@pytest.mark.parametrize("example", ["raytrace/scene.lgr", "fig9.lgr", "window.lgr", "adapters/programs/disk.lgr"])
def test_inverse_jacobians_are_sympys_determinants_as_before(example, monkeypatch):
    # det DΨ̂⁻¹ is printed in closed forms: it must stay sympy's determinant of the full matrix
    # (the entries whose partner is 0 are no longer differentiated)
    seen = []
    original = delta._jacobian

    def spy(comps, inputs, ctx):  # (the call's context since budget33: its budget bounds sympy's det)
        seen.append((comps, inputs))
        return original(comps, inputs, ctx)

    monkeypatch.setattr(delta, "_jacobian", spy)
    delta._JACOBIANS.clear()
    loaded = load(str(EXAMPLES / example))
    at = loaded.param_values()
    if example.startswith("raytrace"):
        # a pixel the depth boundary crosses (since exact14r a constant Jacobian is only made for a
        # region that is not empty at the point, and the default pixel's are all empty)
        at.update(px=0, py=-0.06)
    ddenote_program(loaded.program, at, {k: int(k == next(iter(at))) for k in at})
    assert seen
    ctx = Context({}, Deadline(60.0))  # time enough for sympy's det (past it: cofactors, test_budget33)
    for comps, inputs in seen:
        assert sp.srepr(original(comps, inputs, ctx)) == sp.srepr(_old_jacobian(comps, inputs))
    comps, inputs = (y, (x ** 2 + a) / (y + b) + x), (x, y)  # ∂y/∂x = 0: ∂(second)/∂y is not needed
    assert sp.srepr(original(comps, inputs, ctx)) == sp.srepr(_old_jacobian(comps, inputs))


def test_a_delta_integral_with_a_hand_value():
    # ∂/∂a ∫∫_[0,1]² [xy ≥ a] = ∂/∂a (1 − a + a log a) = log a: the delta piece δ(xy − a) has
    # Ψ̂ = (xy − a, ·) with det DΨ̂ = the other variable, 1/|det| the weight on the zero set
    loaded = load_text("param a = 0.3\nint ([0, 1], [0, 1]) [x * y - a >= 0] d(x, y)\n", "hand.lgr")
    at = loaded.param_values()
    res = ddenote_program(loaded.program, at, {"a": 1})
    assert res.boundary.check == pytest.approx(math.log(0.3), rel=1e-9)  # the quadrature (forward det)
    assert float(res.value) == pytest.approx(math.log(0.3), rel=1e-12)  # the closed form


def test_the_ray_tracers_depth_boundary_against_monte_carlo():
    # the pixel [0, 0.015] × [−0.06, −0.045] at t = 0: the depth k/(n·d) crosses zth = 2.6 in it,
    # so the shader's delta piece (the 274-operation forward Jacobian) is integrated
    loaded = load(str(EXAMPLES / "raytrace" / "scene.lgr"))
    at = dict(loaded.param_values())
    at["py"] = Fraction(-6, 100)
    res = ddenote_program(loaded.program, at, {k: int(k == "t") for k in at})
    assert res.boundary.inconsistent == ()
    assert res.boundary.check == pytest.approx(float(res.boundary.value), rel=1e-9, abs=1e-12)
    assert abs(float(res.boundary.value)) > 0.5  # not a vanishing piece
    mc = estimate_derivative(loaded, {k: float(v) for k, v in at.items()}, {"t": 1}, samples=20000, seed=3)
    assert abs(float(res.value) - mc.value) <= 5 * mc.stderr + 1e-9


def _ctx():
    at = {a: sp.Rational(3, 10), b: sp.Rational(-7, 4)}
    return Context(at, Deadline(20.0), frozenset(at))


def test_value_with_is_value_of_the_substitution_and_is_remembered():
    ctx = _ctx()
    rng = random.Random(3)
    exprs = [(a * x + b) ** 2 / (x - a) + sp.sqrt(x ** 2 + b ** 2), sp.exp(a * x) - b * x ** 3,
             (x - a) * (x + b) / (a ** 2 + 1)]
    for e in exprs:
        for _ in range(4):
            num = {x: sp.Float(rng.uniform(-2, 2), 40)}
            want = ctx.value(e.xreplace(num))
            got = ctx.value_with(e, num)
            assert abs(got - want) <= 1e-25 * max(1.0, abs(want))
            key = (e, tuple(num.items()), tuple(ctx.at.items()))
            assert context._VALUES[key] == got


def _old_dedupe(bounds):
    out = []
    for bd in bounds:
        if not any(sp.expand(bd - o) == 0 for o in out):
            out.append(bd)
    return out


def test_dedupe_drops_what_expansion_drops():
    cases = [
        [x, x + 0, 2 * x / 2, a * (x + 1) - a * x - a + x, x + 1],
        [(x ** 2 - 1) / (x - 1), x + 1, (x + 1) * (x - 1) / (x - 1)],  # equal values, not expanded equal
        [sp.sqrt(a) * x, x * sp.sqrt(a), sp.sqrt(a) * (x + 1) - sp.sqrt(a)],  # roots: no probe value
        [0, sp.Integer(0), a - a, b, (b * (x + 1) - b) / x],
        [(a * x + b) / (a + 1), (a * x + b) / (1 + a) + 0, a * x / (a + 1) + b / (a + 1), x],
    ]
    for bounds in cases:
        assert _dedupe(bounds) == _old_dedupe(bounds)


def test_rational_probe_is_the_exact_value_at_its_point():
    e = (a * x + b) / (x ** 2 + 1) - 3 * a
    got = _rational_probe(e)
    point = {s: _rational_probe(s) for s in (a, b, x)}  # each symbol's own probe value
    assert all(isinstance(v, sp.Rational) and 0 < v < 2 for v in point.values())
    assert len(set(point.values())) == 3
    want = (point[a] * point[x] + point[b]) / (point[x] ** 2 + 1) - 3 * point[a]
    assert got == want
    assert _rational_probe(sp.sqrt(a) + x) is None
    assert _rational_probe(sp.Integer(7)) == 7


def test_cell_relations_are_canonical_and_remembered():
    ctx = _ctx()
    ctx.record(">", 4 * a + 4)
    ctx.record(">", 2 * (a + 1) * 2)  # the same relation, unexpanded
    assert ctx.cell == [sp.StrictGreaterThan(a + 1, 0)]
    ctx.record("=", -b - 1)
    ctx.record("=", b + 1)  # -(b + 1) = 0 is already there
    assert ctx.cell == [sp.StrictGreaterThan(a + 1, 0), sp.Eq(-b - 1, 0)]
    for kind, e in ((">", (a - b) * (a + b) * 6), (">=", 3 * a ** 2 - 9 * b), ("=", (a + 1) ** 2 / 2)):
        p, rel = context._canonical(kind, e)
        assert context._CANONICAL[(kind, e)] == (p, rel)
        _, fresh = sp.expand(e).as_content_primitive()  # the rule, computed afresh
        assert p == fresh and rel.lhs == fresh and rel.rhs == 0
