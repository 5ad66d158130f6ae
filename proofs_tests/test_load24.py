"""Loading at small n, fourth pass (issue 15, branch load24): the fast paths of node construction
give the attributes and small values the general rules give, computed here independently.

- ``Var``/``Param`` keep one shape tuple per name, equal to a leaf's attributes;
- a sum or product with a constant child, or whose right child has no diffeo, primitive nor let,
  and a diffeomorphic conditional with two constant branches, keep the attributes of a walk over
  their fields;
- ``−1`` is one shared ``Fraction`` (``core.MINUS_ONE``): a negation's small value is the exact
  negative, and ``Const(MINUS_ONE)`` is small;
- a program without calls is returned by ``inline`` as it is; one with calls is still inlined;
- a loop's powers of its index are memoized per load by an ``lru_cache`` of ``langur.syntax``
  (emptied with the front end's memos) and equal ``core.index_power_small``'s.
"""

from __future__ import annotations

import functools
import random
import sys
from fractions import Fraction

from langur import core, frontend
from langur.core import MINUS_ONE, Add, Const, IfDiffeo, Mul, Param, Pow, Prim, Var
from langur.core.attributes import SMALL, SMALL_BITS
from langur.syntax import copies

_EMPTY = frozenset()


def _in_range(v: Fraction):
    return v if v.denominator.bit_length() <= SMALL_BITS and abs(v) <= SMALL else False


def _small(t):
    """``core.small_value``'s rule (its docstring), by Fraction arithmetic on the fields: the exact
    value of a constant term when small rationals decide it, ``None`` over a variable or parameter,
    ``False`` when a constant part is not decided so (which a sum or product keeps)."""
    match t:
        case Const(v):
            return _in_range(v) if isinstance(v, Fraction) else False
        case Var() | Param():
            return None
        case Add(a, b) | Mul(a, b):
            x, y = _small(a), _small(b)
            if x is False or y is False:
                return False
            if x is None or y is None:
                return None
            return _in_range(x + y if isinstance(t, Add) else x * y)
        case Pow(a, k):
            x = _small(a)
            if x is None or x is False:
                return x
            if k.denominator == 1 and abs(k) <= 64 and (x != 0 or k > 0):
                return _in_range(x ** int(k))
            return False
        case Prim(_, a):
            return False if _small(a) is not None else None
    raise TypeError(t)


def _walk(t) -> dict:
    """Free variables and parameters, size, depth, smooth, primitives, by a walk over the fields."""
    match t:
        case Const():
            return dict(fv=_EMPTY, fp=_EMPTY, size=1, depth=1, smooth=True, ops=_EMPTY)
        case Var(name):
            return dict(fv=frozenset({name}), fp=_EMPTY, size=1, depth=1, smooth=True, ops=_EMPTY)
        case Param(name):
            return dict(fv=_EMPTY, fp=frozenset({name}), size=1, depth=1, smooth=True, ops=_EMPTY)
    kids = [_walk(c) for c in core.children(t)]
    out = dict(fv=frozenset().union(*(k["fv"] for k in kids)), fp=frozenset().union(*(k["fp"] for k in kids)),
               size=1 + sum(k["size"] for k in kids), depth=1 + max(k["depth"] for k in kids),
               smooth=all(k["smooth"] for k in kids), ops=frozenset().union(*(k["ops"] for k in kids)))
    if isinstance(t, Prim):
        out["ops"] = out["ops"] | {t.op}
    return out


def _term(r: random.Random, n: int):
    """A random term of Const (small integers, −1 shared or not, fractions), Var, Param, sums,
    products, negations (``core.neg``), integer powers and primitives."""
    if n <= 1:
        k = r.randrange(6)
        if k == 0:
            return Const(MINUS_ONE if r.random() < 0.5 else Fraction(-1))
        if k == 1:
            return Const(core.INT_FRACTIONS[r.randrange(3)])
        if k == 2:
            return Const(Fraction(r.randint(-7, 7), r.randint(1, 5)))
        return Var(r.choice("xy")) if k == 3 else (Param(r.choice("ab")) if k == 4 else Const(Fraction(r.randint(2, 9))))
    k = r.randrange(6)
    m = n - 1
    if k <= 1:
        return (Add if k == 0 else Mul)(_term(r, m // 2), _term(r, m - m // 2))
    if k == 2:
        return core.neg(_term(r, m))
    if k == 3:
        return Pow(_term(r, m), Fraction(r.choice([-2, -1, 1, 2, 3])))
    if k == 4:
        return Prim(r.choice(["sin", "exp"]), _term(r, m))
    return Mul(Const(core.INT_FRACTIONS[1]), _term(r, m))


def test_sums_products_and_negations_keep_the_attributes_and_values_of_a_walk():
    r = random.Random(24)
    for _ in range(400):
        t = _term(r, r.randint(1, 20))
        for u in core.subterms(t):
            w = _walk(u)
            assert (core.free_vars(u), core.free_params(u), core.tree_size(u), core.depth(u), core.smooth(u),
                    core.kept_attributes(u)["_ops"]) == (w["fv"], w["fp"], w["size"], w["depth"], w["smooth"], w["ops"])
            expected = _small(u)
            got = core.small_value(u)
            assert got == expected and type(got) is type(expected), (u, got, expected)


def test_variables_and_parameters_share_one_shape_per_name():
    for make, name in ((Var, "x"), (Var, "zz_load24"), (Param, "a"), (Param, "pp_load24")):
        t, s = make(name), make(name, None)
        assert t.shape is s.shape  # one tuple per name
        w = _walk(t)
        kept = core.kept_attributes(t)
        assert (kept["_fv"], kept["_fp"], kept["_size"], kept["_depth"], kept["_smooth"], kept["_calls"]) == (
            w["fv"], w["fp"], 1, 1, True, False)
        assert core.small_value(t) is None and core.all_small(t)
    assert Var("a").shape != Param("a").shape


def test_minus_one_is_shared_and_a_negation_is_exact():
    assert MINUS_ONE == -1 and Const(MINUS_ONE).small == -1 and core.all_small(Const(MINUS_ONE))
    for v in (Fraction(0), Fraction(1), Fraction(3, 7), Fraction(-5, 2), Fraction(10**300)):
        n = core.neg(Const(v))
        assert n.left.value is MINUS_ONE
        assert core.small_value(n) == -v and type(core.small_value(n)) is Fraction
    huge = Const(Fraction(2**2000))  # beyond SMALL: not decided so
    assert core.small_value(core.neg(huge)) is False


def test_a_conditional_with_constant_branches_keeps_a_walks_attributes():
    t = frontend.core_term_from_text("[x + 2*y - a >= 1/3]", variables=("x", "y"), params=("a",))
    assert isinstance(t, IfDiffeo) and isinstance(t.then, Const) and isinstance(t.orelse, Const)
    kept = core.kept_attributes(t)
    cond = t.psi.condition
    assert kept["_fv"] == {"x", "y"} and kept["_fp"] == {"a"}
    assert kept["_size"] == 3 and kept["_depth"] == 1 + max(1, core.depth(cond))
    assert kept["_psi_vars"] == {("x", "y")} and kept["_binders"] == _EMPTY and not kept["_smooth"]
    assert kept["_scoped"] and core.small_value(t) is None
    # the same conditional with a non-constant branch: the general rule, the same sets joined
    u = IfDiffeo(t.psi, Var("x"), Const(Fraction(0)))
    ku = core.kept_attributes(u)
    assert (ku["_fv"], ku["_fp"], ku["_psi_vars"], ku["_ops"], ku["_dfp"], ku["_scoped"]) == (
        kept["_fv"], kept["_fp"], kept["_psi_vars"], kept["_ops"], kept["_dfp"], kept["_scoped"])


def test_inline_returns_a_program_without_calls_and_still_inlines_calls(tmp_path):
    plain = frontend.load_text("param a = 1\nint ([0, 1]) [x >= a/2] * x d(x)\n")
    main = plain.main.program
    assert plain.program is main  # returned as it is
    with_call = frontend.load_text("def f(x: var, a: param) = a * x\nparam a = 1\nint ([0, 1]) f(x, a) + 1 d(x)\n")
    assert not any(isinstance(u, core.Call) for u in core.subterms(with_call.program.body))
    assert with_call.program.integrand == Add(Mul(Param("a"), Var("x")), Const(Fraction(1)))


def test_powers_of_a_loop_index_memoized_per_load_and_emptied_with_the_front_ends_memos():
    assert isinstance(copies.index_power, functools._lru_cache_wrapper)
    for v in (10, 11, 0, 3, 2**40):
        for e in (-2, -1, 1, 2):
            if v == 0 and e < 0:
                continue
            assert copies.index_power(v, e) == core.index_power_small(v, e)
    sys.path.insert(0, "bench")
    try:
        from bench_peers import langur_text
        from bench_text_to_number import cold
    finally:
        sys.path.remove("bench")
    text = langur_text(10)
    cold()
    assert copies.index_power.cache_info().currsize == 0  # cold() empties it
    first = frontend.load_text(text)
    assert copies.index_power.cache_info().hits >= 9  # the second sum's copies find the first's
    frontend.CACHE.clear()
    again = frontend.load_text(text)  # with the memo warm: the same program
    cold()
    assert first.program == again.program == frontend.load_text(text).program
