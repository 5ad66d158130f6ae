"""A loop's copies with fewer Python steps (issue 15, branch front6): ``core.like_binary``,
``like_power`` and ``like_leaf`` build a copy's nodes from the first copy's shape, a power of the
index is computed once per copy and exponent, the index's other leaves copy the first one
(``langur/syntax/template.py``).

Each builder is compared with the constructors on random terms (equal, every attribute the
same); loops whose index sits under several powers (some of them not small: a 600-bit index) are
loaded with the instantiation on and off (each copy desugared from the surface, the path before
templates existed); and microbenchmark 1's derivative is checked against the hand formula.
"""

from __future__ import annotations

import math
import random
from fractions import Fraction

import pytest

from langur import core, operational
from langur.frontend import clear_load_cache, load_text
from langur.syntax import copies, template
from langur.syntax.printer import print_program


def _leaf(r: random.Random) -> core.Term:
    k = r.randrange(5)
    if k == 0:
        return core.Var(r.choice("xy"))
    if k == 1:
        return core.Param(r.choice("ab"))
    if k == 2:
        return core.Const(core.PI)
    # small rationals, and some that are not small (a 1,200-bit numerator, a 300-bit denominator)
    return core.Const(r.choice([Fraction(r.randint(-9, 9), r.randint(1, 9)), Fraction(3) ** 760,
                                Fraction(1, 2 ** 300), Fraction(0), Fraction(1)]))


def _term(r: random.Random, depth: int) -> core.Term:
    if depth == 0 or r.random() < 0.2:
        return _leaf(r)
    k = r.randrange(4)
    if k == 0:
        return core.Add(_term(r, depth - 1), _term(r, depth - 1))
    if k == 1:
        return core.Mul(_term(r, depth - 1), _term(r, depth - 1))
    if k == 2:
        return core.Pow(_term(r, depth - 1), Fraction(r.choice([-3, -1, 2, 3, 70])))
    return core.Prim("sin", _term(r, depth - 1))


def _with_span(t: core.Term, span) -> dict:
    d = core.shape_of(t)
    d["span"] = span
    return d


@pytest.mark.parametrize("seed", range(3))
def test_the_builders_give_what_the_constructors_give(seed):
    # like_binary(cls, shape of t with a span, a, b) for children a, b of t's shape (any constants):
    # the node cls(a, b, span=…), every attribute equal; like_power with the small value computed by
    # core.small_power; like_leaf: the Const with the other span
    r = random.Random(seed)
    checked = 0
    for _ in range(300):
        t = _term(r, 3)
        span = object()
        if type(t) in (core.Add, core.Mul):
            # other children of the same shapes: the same term with its constants' values changed
            a, b = _revalued(t.left, r), _revalued(t.right, r)
            if not (core.same_shape(a, t.left) and core.same_shape(b, t.right)):
                continue
            built = core.like_binary(type(t), _with_span(t, span), a, b)
            made = type(t)(a, b, span=span)
        elif type(t) is core.Pow:
            a = _revalued(t.base, r)
            if not core.same_shape(a, t.base):
                continue
            built = core.like_power(_with_span(t, span), a, core.small_power(a.small, t.exponent))
            made = core.Pow(a, t.exponent, span=span)
        elif type(t) is core.Const:
            built, made = core.like_leaf(t, span), core.Const(t.value, span=span)
        else:
            continue
        assert built == made and built.span is span
        assert core.kept_attributes(built) == core.kept_attributes(made), t
        checked += 1
    assert checked >= 100


def _revalued(t: core.Term, r: random.Random) -> core.Term:
    """``t`` with every rational constant replaced by another (small or not)."""
    if type(t) is core.Const:
        return core.Const(r.choice([t.value, Fraction(r.randint(-50, 50), r.randint(1, 7)), Fraction(7) ** 400])
                          if t.value != core.PI else t.value)
    if type(t) in (core.Add, core.Mul):
        return type(t)(_revalued(t.left, r), _revalued(t.right, r))
    if type(t) is core.Pow:
        return core.Pow(_revalued(t.base, r), t.exponent)
    if type(t) is core.Prim:
        return core.Prim(t.op, _revalued(t.arg, r))
    return t




def _same_everywhere(s: core.Term, t: core.Term) -> None:
    stack, seen = [(s, t)], set()
    while stack:
        a, b = stack.pop()
        if (id(a), id(b)) in seen:
            continue
        seen.add((id(a), id(b)))
        assert a == b
        assert core.kept_attributes(a) == core.kept_attributes(b), (a, b)
        stack.extend(zip(core.children(a), core.children(b)))


def _load(text: str, enabled: bool):
    template.ENABLED = enabled
    clear_load_cache()
    try:
        return load_text(text, "t.lgr")
    finally:
        template.ENABLED = True


BIG = 2 ** 500 + 1  # 1/i and i^-2 have 501- and 1,001-bit denominators: not small (i^2 is, narrowly)


@pytest.mark.parametrize("lo, body, instantiated", [
    (10, "[x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x)", 3),          # MB1's body: 1/i twice
    (2, "[x - i^-2 - a/i >= 0] * (i^2 * x + 1/i + i^-2)", 3),       # three exponents, each twice
    (2, "[2*x + 1/(i + 1) >= a] * (x / i) * i^3", 3),               # a power of a sum: not the index itself
    (BIG, "[x + 1/i - a >= 0] * (i^2 + x) * i^-2", 3),              # powers that are not small
    # i = 0: 0^-1, not small (nan both ways); since fold31 the copies at i = 0 and 1, and since diag32 at
    # i = -1, are desugared on their own (there the index folds): of -3..0 only i = -2 is instantiated
    (-3, "[x + i/3 >= a] * (i^-1 + 1) + i^2", 1),
], ids=["mb1", "three-exponents", "power-of-a-sum", "not-small", "zero"])
def test_copies_with_powers_of_the_index_are_the_desugared_copies(lo, body, instantiated):
    text = f"param a = 0.5\nint ([0, 1]) (sum i in {lo}..{lo + 3}: {body}) d(x)\n"
    count = copies.STATS["instantiated"]
    new = _load(text, True)
    assert copies.STATS["instantiated"] == count + instantiated  # (on: the copies but the first instantiated)
    count = copies.STATS["instantiated"]
    old = _load(text, False)
    assert copies.STATS["instantiated"] == count  # (off: nothing instantiated)
    assert new.program == old.program
    _same_everywhere(new.program.body, old.program.body)
    assert print_program(new.program) == print_program(old.program)
    at, d = new.param_values({}), {"a": 1.0}
    x = operational.estimate_derivative(new, at, d, samples=64, seed=3)
    y = operational.estimate_derivative(old, at, d, samples=64, seed=3)
    assert repr((x.value, x.regular, x.boundary)) == repr((y.value, y.regular, y.boundary))  # (0^-1: nan both)


def test_microbenchmark_one_derivative_by_hand():
    # d/da ∫₋₁¹ Σᵢ [x + aᵢ ≥ 0](aᵢ + x) + Σᵢ [x + aᵢ ≥ 0](aᵢ − x) dx, aᵢ = 1/i + a − 1, at a = 1:
    # each jump at x = −aᵢ gives the integrand there ((aᵢ + x) = 0 and (aᵢ − x) = 2aᵢ) and the
    # regular part ∫_{−aᵢ}^{1} 1 dx = 1 + aᵢ for each sum: Σᵢ (1 + aᵢ) + (2aᵢ + 1 + aᵢ)
    n = 25
    text = (f"param a = 1\nint ([-1, 1]) (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x))"
            f" + (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")
    expected = math.fsum((1 + 1 / i) + (3 / i + 1) for i in range(10, 10 + n))
    loaded = _load(text, True)
    est = operational.estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=4000, seed=0)
    assert abs(est.value - expected) <= 5 * est.stderr + 1e-9
    # the boundary part alone: Σᵢ 0 + 2aᵢ, exact at every sample (a point mass per jump)
    assert est.boundary.value == pytest.approx(math.fsum(2 / i for i in range(10, 10 + n)), rel=1e-12)
