"""sympy's failure to solve an equation for a variable that occurs only inside an implicit root, known
from the equation's shape (issue 15, turning2d's speed, exact14t).

turning2d's delta piece has the condition ``root(_y: _y**3 - _y*u1 - a + u1**3 = 0 in [-1, …]) + 1``
on its zero set's coordinate u1; looking for a closed form, :func:`langur.symbolic.solving._roots`
asked sympy's ``solve`` for its roots in u1, which spent 0.1–0.2 s before raising "No algorithms are
implemented to solve equation …" (the piece then goes to quadrature, and the message is printed as a
note).  :func:`langur.symbolic.unsolvable.unsolvable` now gives that message from the shape ``k·x* + c`` without
asking.  Checked here against sympy itself: on random equations of that shape sympy's ``solve``
raises exactly the message predicted; shapes outside it are not predicted; ``_roots`` raises the same
``Unsupported`` as before without calling ``solve``; turning2d's derivative and its notes unchanged
(the value against the Monte Carlo engine's boundary-free estimate by finite differences is in
test_turning_points; here the note and the method).
"""

from __future__ import annotations

import random

import pytest
import sympy as sp

from langur.failures import WORDS
from langur.implicit import implicit_root
from langur.symbolic.unsolvable import NO_ALGORITHM, unsolvable

Y, U, V, A = sp.symbols("y u1 v a", real=True)


def _sympy_message(expr, v):
    """What sympy's ``solve`` raises for ``expr = 0`` in ``v`` (whitespace collapsed), None when it
    answers."""
    try:
        sp.solve(expr, v, dict=False, check=False, simplify=False)
    except NotImplementedError as exc:
        return " ".join(str(exc).split())
    return None


def _random_root(rng, depth=0):
    """An implicit root in y of a random polynomial in y, u1 and a (integer and rational
    coefficients), its bracket ends rationals or (once) another such root."""
    terms = [Y ** rng.randint(1, 5)]
    for _ in range(rng.randint(1, 3)):
        c = sp.Rational(rng.randint(-5, 5) or 1, rng.choice([1, 1, 2, 3]))
        terms.append(c * Y ** rng.randint(0, 3) * rng.choice([U, U**2, U * A, sp.Integer(1), A]))
    eq = sp.Add(*terms)
    if U not in eq.free_symbols:
        eq += U
    lo, hi = sp.Integer(-2), sp.Integer(2)
    if depth == 0 and rng.random() < 0.4:
        hi = implicit_root(3 * Y**2 - U, Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1), index=0, of=2)
    target = rng.choice([sp.Integer(0), sp.Rational(1, 3), A])
    return implicit_root(eq, Y, target, lo, hi, index=rng.choice([None, None, 0]), of=2)


@pytest.mark.parametrize("seed", range(8))
def test_predicted_failures_are_sympys(seed):
    rng = random.Random(seed)
    root = _random_root(rng)
    k = sp.Rational(rng.choice([-3, -1, 1, 2, 5]), rng.choice([1, 2, 7]))
    c = rng.choice([sp.Integer(1), sp.Integer(-1), sp.Rational(-3, 7), A, A**2 - 2 * V])
    expr = k * root + c
    predicted = unsolvable(expr, U)
    assert predicted is not None
    assert predicted == _sympy_message(expr, U)


def test_turning2d_condition():
    sc = implicit_root(3 * Y**2 - U, Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1), index=0, of=2)
    root = implicit_root(Y**3 - Y * U - A + U**3, Y, sp.Integer(0), sp.Integer(-1), sc)
    for expr in (root + 1, 1 - root, root):
        assert unsolvable(expr, U) == _sympy_message(expr, U)
        assert unsolvable(expr, U).startswith("No algorithms are implemented to solve equation ")


def test_other_shapes_not_predicted():
    root = implicit_root(Y**3 + Y - U, Y, sp.Integer(0), sp.Integer(-2), sp.Integer(2))
    no_u = implicit_root(Y**3 + Y - A, Y, sp.Integer(0), sp.Integer(-2), sp.Integer(2))
    assert unsolvable(root - U, U) is None  # u1 outside the root too
    assert unsolvable(root * U + 1, U) is None
    assert unsolvable(root**2 + 1, U) is None
    assert unsolvable(root + sp.Float(0.5), U) is None  # solve rewrites Floats
    assert unsolvable(no_u + 1, U) is None  # (no u1 at all: solve answers [])
    assert _sympy_message(no_u + 1, U) is None
    assert unsolvable(root + sp.sqrt(2), U) is None
    floaty = implicit_root(Y**3 + sp.Float(0.5) * Y - U, Y, sp.Integer(0), sp.Integer(-2), sp.Integer(2))
    assert unsolvable(floaty + 1, U) is None
    assert unsolvable(U**2 - 1, U) is None
    assert unsolvable(2 * root, U) is None  # (solve names the factor, not the product)


def test_roots_raise_without_asking_sympy(monkeypatch):
    from langur.symbolic import solving
    from langur.symbolic.context import Cond, Context, Unsupported
    from langur.timebox import Deadline

    root = implicit_root(Y**5 + Y - U, Y, sp.Integer(0), sp.Integer(-2), sp.Integer(2))
    expr = root + sp.Rational(1, 2)
    assert _sympy_message(expr, U) is not None  # sympy fails on it; the note says so in words (failures.why)
    want = f"cannot solve {expr} = 0 for {U}: {WORDS['NotImplementedError']}"
    ctx = Context({A: sp.Rational(1, 10)}, Deadline(20.0), frozenset({A}))

    def refuse(*args, **kwargs):
        raise AssertionError("sympy's solve called")

    monkeypatch.setattr(solving.sp, "solve", refuse)
    with pytest.raises(Unsupported) as info:
        solving._roots(Cond(expr), U, ctx, tidy=False)
    assert str(info.value) == want


def test_turning2d_note_unchanged():
    from pathlib import Path

    from langur.exact import exact_deriv
    from langur.frontend import load

    path = Path(__file__).resolve().parent.parent / "examples" / "turning2d.lgr"
    loaded = load(str(path))
    at = loaded.param_values()
    r = exact_deriv(loaded.program, at, {"a": 1})
    assert str(r.method) == "quadrature"
    notes = [n for n in r.notes if "cannot solve" in n]
    assert len(notes) == 1
    lhs = notes[0].split("cannot solve ", 1)[1].split(" = 0 for u1: ", 1)
    assert lhs[1] == WORDS["NotImplementedError"]  # sympy's "no algorithms" failure, in words (words30)
    assert NO_ALGORITHM.strip() not in notes[0]


def test_theorem_forms_remembered(monkeypatch):
    """Theorem 8.1's check asks whether a closed form holds a switch and whether it is large at every
    point it compares: answered once per form, the same answers as the walks themselves."""
    from langur import theorem
    from langur.symbolic.walks import has_any, size

    x, b = sp.symbols("x b", real=True)
    small = sp.Max(x, b) + x**2
    big = sp.Add(*[sp.Rational(k, 3) * x**k * b for k in range(1, 800)])  # ~4000 nodes
    edge = sp.Add(*[x**k for k in range(2, 1002)])  # 1 + 1000·3 - … nodes around the limit
    for e in (small, big, edge, x * b, sp.Piecewise((x, b > 0), (0, True)), sp.Heaviside(x - b)):
        want_switch = has_any(e, (sp.Max, sp.Min, sp.Heaviside, sp.DiracDelta, sp.Piecewise))
        want_large = size(e, theorem.SYMBOLIC_OPS) >= theorem.SYMBOLIC_OPS
        assert theorem._switches(e) is want_switch
        assert theorem._large(e) is want_large
    walks = []
    monkeypatch.setattr(theorem, "has_any", lambda *a: walks.append(a) or True)
    monkeypatch.setattr(theorem, "size", lambda *a: walks.append(a) or 0)
    for _ in range(3):  # remembered: no walk again
        assert theorem._switches(big) is False
        assert theorem._large(big) is True
    assert walks == []
    assert theorem.localize(x * b, {b: sp.Integer(1)}) == x * b
