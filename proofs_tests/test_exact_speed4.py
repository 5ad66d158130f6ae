"""The exact engine's shortcuts of issue 15 (fourth pass) give what the slow paths gave: the
shared-aware ``has`` answers sympy's ``has``; lambdify without its docstring computes the same
numbers; ⟦p⟧ near the point (the polygon decided there) is the global closed form near the point;
Theorem 8.1's nearby comparison with a large closed form of ⦇p⦈ uses that form only inside its
cell and then equals the quadrature it stands for; a difference with an implicit root is not handed
to ``simplify``."""

from __future__ import annotations

import inspect
import random

import numpy as np
import pytest
import sympy as sp
from paths import EXAMPLES

from langur import theorem
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load
from langur.implicit import ImplicitRootFn
from langur.symbolic import rational, walks
from langur.symbolic.text import lambdify, shared_lambdify
from langur.sympy_bridge import at_symbols

a, b, c, x = sp.symbols("a b c x", real=True)


def _random_shared(seed: int) -> sp.Expr:
    """A random expression reusing its subtrees, sometimes with a Max, Piecewise or Abs."""
    rng = random.Random(seed)
    pool = [a, b, c, sp.Rational(rng.randint(-9, 9), rng.randint(1, 7))]
    for _ in range(30):
        p, q = rng.choice(pool), rng.choice(pool)
        op = rng.randrange(12)
        if op < 4:
            e = p + q
        elif op < 8:
            e = p * q
        elif op == 8:
            e = p / (q ** 2 + 1)
        elif op == 9:
            e = sp.Max(p, q + 1)
        elif op == 10:
            e = sp.Piecewise((q, a > 0), (p, True))
        else:
            e = sp.Abs(p) + sp.exp(q)
        pool.append(e)
    return sp.Add(*pool[-5:])


@pytest.mark.parametrize("seed", range(20))
def test_has_any_answers_sympys_has(seed):
    e = _random_shared(seed)
    for types in [(sp.Max,), (sp.Piecewise,), (sp.Abs, sp.exp), (sp.Min, sp.DiracDelta), (sp.Heaviside,)]:
        assert walks.has_any(e, types) == e.has(*types)


@pytest.mark.parametrize("seed", range(6))
def test_lambdify_without_docstring_computes_the_same_numbers(seed):
    e = _random_shared(seed)
    rng = random.Random(seed)
    f, g = lambdify([a, b, c], e, modules=["math"]), sp.lambdify([a, b, c], e, modules=["math"])
    for _ in range(5):
        pt = [rng.uniform(-2, 2) for _ in range(3)]
        assert f(*pt) == g(*pt)  # the same generated code: bit for bit


def _nearby(at, n=3, scale=1e-4, seed=1):
    rng = random.Random(seed)
    return [{k: float(v) + rng.uniform(-scale, scale) for k, v in at.items()} for _ in range(n)]


def test_the_denotation_near_the_point_is_the_global_closed_form_there():
    loaded = load(str(EXAMPLES / "triangle.lgr"))
    at = loaded.param_values()
    near = denote_program(loaded.program, at, near=True)
    whole = denote_program(loaded.program, at)
    assert near.method == whole.method == "closed_form"
    assert not near.everywhere and near.cell  # the polygon's cell is said
    assert abs(near.value - whole.value) <= 1e-14
    assert sp.count_ops(near.expr) < sp.count_ops(whole.expr)
    # equal as functions near the point: 30 digits at nearby points (the global form's Max/Min
    # picks the polygon's branch there)
    for q in _nearby(at):
        pt = at_symbols(q)
        va, vb = sp.N(near.expr.xreplace(pt), 30), sp.N(whole.expr.xreplace(pt), 30)
        assert abs(va - vb) <= sp.Float(10) ** -25
    # and its derivative is ⦇p⦈ (Theorem 8.1 holds symbolically, as with the global form)
    th = theorem.check_theorem_8_1(loaded.program, at, {k: int(k == "ax") for k in at}, denotation=near)
    assert th.holds is True and th.how == theorem.How.SYMBOLIC


def test_a_large_closed_form_of_the_derivative_stands_for_quadrature_only_inside_its_cell():
    loaded = load(str(EXAMPLES / "stylize" / "linear.lgr"))
    at = loaded.param_values()
    direction = {k: int(k == "ax") for k in at}
    der = ddenote_program(loaded.program, at, direction)
    assert der.method == "closed_form"
    assert walks.size(der.expr, theorem.SYMBOLIC_OPS) >= theorem.SYMBOLIC_OPS  # too large for simplify
    q = _nearby(at, n=1, scale=1e-6)[0]
    closed = theorem._large_closed_form_at(der, q)
    assert closed is not None
    quad = ddenote_program(loaded.program, q, direction, symbolic=False)
    assert abs(closed[0] - quad.value) <= 1e-9 + 10 * quad.error
    # a point outside one of the cell's relations: no closed form there (quadrature instead)
    rel = next(r for r in tuple(der.regular.cell) + tuple(der.boundary.cell) if r.rel_op == ">")
    far = dict(q)
    shifted = None
    for k in at:
        for step in (1.0, -1.0, 3.0, -3.0):
            trial = {**q, k: q[k] + step}
            v = rational.rational_value(rel.lhs - rel.rhs, at_symbols(trial))
            if v is not None and v <= 0:
                shifted = trial
                break
        if shifted:
            break
    assert shifted is not None
    far.update(shifted)
    assert theorem._large_closed_form_at(der, far) is None


def test_a_difference_with_an_implicit_root_is_not_simplified(monkeypatch):
    lam = sp.Lambda(x, x ** 3 - x - a)
    r = ImplicitRootFn(lam, 0, -2, -sp.sqrt(3) / 3, -1, 0)
    called = []
    monkeypatch.setattr(theorem.sp, "simplify", lambda e, *k, **kw: called.append(e) or e)
    lhs = sp.exp(r / 2) / sp.Abs(3 * r ** 2 - 1)
    rhs = sp.exp(r / 2) / (3 * r ** 2 - 1)
    assert theorem.symbolic_difference(lhs, rhs) is None
    assert not called
    assert theorem.symbolic_difference(lhs, lhs) == 0
    assert theorem.symbolic_difference(a ** 2 - 1, (a - 1) * (a + 1)) == 0  # no root: as before


def test_turning_points_theorem_8_1_still_holds_numerically():
    loaded = load(str(EXAMPLES / "turning.lgr"))
    at = loaded.param_values()
    th = theorem.check_theorem_8_1(loaded.program, at, {"a": 1})
    assert th.holds is True and th.how == theorem.How.NUMERIC
    # D⟦p⟧ by central differences of ⟦p⟧'s values (independent of both closed forms)
    h = 1e-5
    up = denote_program(loaded.program, {"a": float(at["a"]) + h}, symbolic=False).value
    down = denote_program(loaded.program, {"a": float(at["a"]) - h}, symbolic=False).value
    assert abs((up - down) / (2 * h) - th.derivative_denotation) <= 1e-5


@pytest.mark.parametrize("seed", range(12))
def test_shared_free_symbols_are_sympys(seed):
    e = _random_shared(seed)
    lam = sp.Lambda(x, x ** 3 - x - a)
    extra = [ImplicitRootFn(lam, b, -2, 2, -1, 0), sp.Integral(x * c, (x, 0, b)), sp.Lambda(x, x * a)]
    for f in [e, e + extra[0], e * extra[1], sp.exp(extra[0]) + extra[1] ** 2]:
        assert walks.free_symbols(f) == f.free_symbols
    assert walks.free_symbols(extra[2]) == extra[2].free_symbols


@pytest.mark.parametrize("seed", range(4))
def test_shared_numpy_lambdify_generates_sympys_code(seed):
    e = _random_shared(seed)
    f, g = shared_lambdify([a, b, c], e, "numpy"), sp.lambdify([a, b, c], e, modules=["numpy"])
    assert inspect.getsource(f) == inspect.getsource(g)
    pts = np.linspace(0.1, 0.9, 4)
    assert np.array_equal(f(0.3, -0.7, pts), g(0.3, -0.7, pts), equal_nan=True)
