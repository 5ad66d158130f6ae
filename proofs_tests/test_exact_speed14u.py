"""Issue 15, exact14u: the root formulas of a large condition (``root_formulas._root_formulas``, ⟦p⟧'s and
⦇p⦈'s 1-D steps for the ray tracer, paper §10.2) with its parameter-only parts held by a fixed pool
of dummies, the i-th part met taking the i-th (sympy orders dummies of one name by creation, as it
ordered the new dummies of each call before), and the formulas remembered by the abstracted shape.
Checked here: the same expressions (srepr) as with new dummies per call, on random conditions; two
conditions of one shape computing their formulas once; the roots found vanishing at random rational
points (exact rationals, by hand); a condition that holds a dummy of the pool's name taking the old
path."""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
import sympy as sp

from langur.symbolic import root_formulas
from langur.sympy_bridge import symbol

X, A, B, C = (symbol(n) for n in ("x14u", "a14u", "b14u", "c14u"))


def _part(rng: random.Random):
    """A parameter-only part that is not an atom (abstracted by a dummy)."""
    k = [sp.Rational(rng.randint(-9, 9) or 1, rng.randint(1, 5)) for _ in range(3)]
    return rng.choice([k[0] * A + k[1], k[0] * A * B + k[2], (k[0] * B + k[1]) * (C + k[2]), A ** 2 + k[1] * C + 1])


def _condition(seed: int):
    """A condition of degree ≤ 2 in X after clearing parameter-only denominators, shaped like the
    ray tracer's (nested fractions), or a rational function with a linear denominator."""
    rng = random.Random(seed)
    p = [_part(rng) for _ in range(6)]
    match seed % 4:
        case 0:
            return p[0] * X + p[1]
        case 1:
            return p[0] * X ** 2 + p[1] * X + p[2]
        case 2:
            return X * p[0] + (p[1] * X + p[2]) * (p[3] * X + p[4]) / p[5] - B
        case _:
            return (p[0] * X + p[1]) / (p[2] * X + p[3]) + C


def _fresh(monkeypatch) -> None:
    """The old behaviour: a new dummy for every part of every call, nothing remembered."""
    monkeypatch.setattr(root_formulas, "_pooled", lambda pool, i: sp.Dummy("k"))
    monkeypatch.setattr(root_formulas, "_SHAPES", {})


def test_pooled_formulas_are_those_of_new_dummies(monkeypatch):
    exprs = [_condition(s) for s in range(60)]
    root_formulas._SHAPES.clear()
    pooled = [root_formulas._root_formulas.__wrapped__(e, X) for e in exprs]
    pooled_again = [root_formulas._root_formulas.__wrapped__(e, X) for e in exprs]  # (now from the memo)
    _fresh(monkeypatch)
    fresh = [root_formulas._root_formulas.__wrapped__(e, X) for e in exprs]
    assert sum(f is not None for f in fresh) >= 50
    for e, got, again, want in zip(exprs, pooled, pooled_again, fresh):
        assert sp.srepr(got) == sp.srepr(want), e
        assert sp.srepr(again) == sp.srepr(want), e


def _value(e, point: dict) -> Fraction:
    q = sp.sympify(e).xreplace(point)
    assert q.is_Rational
    return Fraction(int(q.p), int(q.q))


def test_two_conditions_of_one_shape_compute_formulas_once(monkeypatch):
    # c·x + d and e·x + f with c, d, e, f different parameter-only sums: one shape
    rng = random.Random(7)
    pairs = [(A * B + 2, (C + 1) * (B - 3)), (A + 5, (B + 4) * (A - 2))]
    exprs = [p * X + q for p, q in pairs]
    calls = []
    real = root_formulas._direct_formulas
    monkeypatch.setattr(root_formulas, "_direct_formulas", lambda e, v: calls.append(e) or real(e, v))
    root_formulas._SHAPES.clear()
    root_formulas._root_formulas.cache_clear()
    found = [root_formulas.closed_roots(e, X, lambda z: 1) for e in exprs]
    assert len(calls) == 1  # the second condition's formulas came from the first's
    for (p, q), (roots, poles) in zip(pairs, found):
        assert poles == []
        (root,) = roots
        for _ in range(5):
            point = {s: sp.Rational(rng.randint(-20, 20), rng.randint(1, 7)) for s in (A, B, C)}
            pv, qv = _value(p, point), _value(q, point)
            if pv == 0:
                continue
            assert _value(root, point) == -qv / pv  # p·x + q = 0 by hand


@pytest.mark.parametrize("seed", range(1, 40, 4))
def test_quadratic_roots_vanish_at_rational_points(seed):
    expr = _condition(seed)  # (seed % 4 == 1: quadratic)
    root_formulas._root_formulas.cache_clear()
    found = root_formulas.closed_roots(expr, X, lambda z: 1)
    assert found is not None
    roots, _ = found
    rng = random.Random(seed)
    point = {s: sp.Rational(rng.randint(-20, 20), rng.randint(1, 7)) for s in (A, B, C)}
    a2, a1, a0 = (expr.coeff(X, k).xreplace(point) for k in (2, 1, 0))
    if a2 == 0:
        return
    disc = a1 ** 2 - 4 * a2 * a0
    # the two roots by hand: their sum -a1/a2 and product a0/a2, exactly (disc may not be a square)
    r = [root.xreplace(point) for root in roots]  # (exact: rationals and a square root)
    assert sp.expand(r[0] + r[1]) == -a1 / a2
    assert sp.expand(r[0] * r[1]) == a0 / a2
    assert sp.expand((r[1] - r[0]) ** 2) == disc / a2 ** 2


def test_a_condition_holding_a_dummy_of_the_pools_name_takes_the_old_path(monkeypatch):
    k = sp.Dummy("k")
    expr = (A + k) * X + (B * C + 1)
    root_formulas._SHAPES.clear()
    root_formulas._root_formulas.cache_clear()
    roots, poles = root_formulas.closed_roots(expr, X, lambda z: 1)
    assert root_formulas._SHAPES == {}  # not remembered
    assert poles == []
    point = {A: sp.Rational(1, 3), k: sp.Rational(2, 5), B: sp.Integer(3), C: sp.Rational(-1, 7)}
    assert _value(roots[0], point) == -(Fraction(3) * Fraction(-1, 7) + 1) / (Fraction(1, 3) + Fraction(2, 5))
    _fresh(monkeypatch)
    root_formulas._root_formulas.cache_clear()
    assert sp.srepr(root_formulas.closed_roots(expr, X, lambda z: 1)) == sp.srepr((roots, poles))
