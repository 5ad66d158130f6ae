"""Term nodes without a ``__dict__`` (slots23, issue 15: loading at small n).

Core terms keep their fields and the attributes they compute when built in slots
(``langur.core.slots``), the attributes of their shape as one tuple ``shape`` shared by a loop's
copies (``langur.core.attributes``).  Checked here: no node has a ``__dict__`` whichever way it is
built; what the nodes keep equals an independent recursive walk over their fields; they stay
frozen, equal, hashable, picklable and copyable as the dataclasses they were; the memos start empty
and are written only by their writers.
"""

from __future__ import annotations

import copy
import dataclasses
import pickle
import random
from fractions import Fraction

import pytest

from langur import core, frontend
from langur.core import (
    Add,
    Call,
    Const,
    IfGe0,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Var,
)

_EMPTY = frozenset()


def _walk(t) -> dict:
    """The attributes of ``t`` by a recursive walk over its fields (no kept attribute read): free
    variables and parameters, size, depth, smooth, calls, primitives and binders."""
    match t:
        case Const():
            return dict(fv=_EMPTY, fp=_EMPTY, size=1, depth=1, smooth=True, calls=False, ops=_EMPTY, binders=_EMPTY)
        case Var(name):
            return dict(fv=frozenset({name}), fp=_EMPTY, size=1, depth=1, smooth=True, calls=False, ops=_EMPTY,
                        binders=_EMPTY)
        case Param(name):
            return dict(fv=_EMPTY, fp=frozenset({name}), size=1, depth=1, smooth=True, calls=False, ops=_EMPTY,
                        binders=_EMPTY)
    kids = [_walk(c) for c in core.children(t)]
    out = dict(fv=frozenset().union(*(k["fv"] for k in kids)), fp=frozenset().union(*(k["fp"] for k in kids)),
               size=1 + sum(k["size"] for k in kids), depth=1 + max(k["depth"] for k in kids),
               smooth=all(k["smooth"] for k in kids), calls=any(k["calls"] for k in kids),
               ops=frozenset().union(*(k["ops"] for k in kids)),
               binders=frozenset().union(*(k["binders"] for k in kids)))
    match t:
        case Prim(op, _):
            out["ops"] = out["ops"] | {op}
        case IfGe0():
            out["smooth"] = False
        case Let(name, _, _):
            out["fp"] = kids[0]["fp"] | (kids[1]["fp"] - {name})
            out["binders"] = out["binders"] | {name}
        case Call():
            out["smooth"], out["calls"] = False, True
    return out


def _term(r: random.Random, n: int):
    """A random term of about ``n`` nodes over x, y, a, b, with every kind of node but the
    diffeomorphic conditional and the implicit root."""
    if n <= 1:
        k = r.randrange(4)
        if k == 0:
            return Const(Fraction(r.randint(-5, 5), r.randint(1, 4)))
        if k == 1:
            return Const(core.PI) if r.random() < 0.2 else core.index_const(r.randint(0, 200))
        return Var(r.choice("xy")) if k == 2 else Param(r.choice("ab"))
    k = r.randrange(8)
    m = n - 1
    if k <= 1:
        cls = Add if k == 0 else Mul
        return cls(_term(r, m // 2), _term(r, m - m // 2))
    if k == 2:
        return Prim(r.choice(["sin", "exp", "log"]), _term(r, m))
    if k == 3:
        return Pow(_term(r, m), Fraction(r.randint(-3, 3), r.choice([1, 2])))
    if k == 4:
        return IfGe0(Param(r.choice("ab")), _term(r, m // 2), _term(r, m - m // 2))
    if k == 5:
        return Let(r.choice("cab"), Add(Param("a"), Const(Fraction(1))), _term(r, m))
    if k == 6:
        return Call("m", "f", (_term(r, m // 2), _term(r, m - m // 2)))
    return Add(_term(r, m), Var("x"))


def _terms(count: int = 300):
    r = random.Random(23)
    return [_term(r, r.randint(1, 25)) for _ in range(count)]


def test_no_term_node_has_a_dict_whichever_way_it_is_built():
    # (on the code before slots23 every node kept its fields and attributes in its __dict__)
    t = Add(Mul(Const(Fraction(2)), Var("x")), Param("a"))
    shape = core.shape_with_span(t)
    built = [t, *core.like_binary_many(Add, shape, [Var("x")] * 3, [Param("b")] * 3),
             core.like_binary(Add, shape, Var("y"), Param("a")), core.like_leaf(Const(Fraction(3)), None),
             core.index_const(7), core.like_power(core.shape_with_span(Pow(Var("x"), Fraction(2))), Var("y"), None)]
    for u in _terms(100) + built:
        for v in core.subterms(u):
            assert not hasattr(v, "__dict__"), type(v)
            with pytest.raises(TypeError):
                vars(v)


def test_kept_attributes_are_those_of_a_walk_over_the_fields():
    for t in _terms():
        w = _walk(t)
        kept = core.kept_attributes(t)
        assert (kept["_fv"], kept["_fp"], kept["_size"], kept["_depth"], kept["_smooth"], kept["_calls"],
                kept["_ops"], kept["_binders"]) == (w["fv"], w["fp"], w["size"], w["depth"], w["smooth"],
                                                    w["calls"], w["ops"], w["binders"]), t
        assert (core.free_vars(t), core.free_params(t), core.tree_size(t), core.depth(t), core.smooth(t),
                core.has_calls(t)) == (w["fv"], w["fp"], w["size"], w["depth"], w["smooth"], w["calls"])


def test_copies_share_their_templates_shape_and_equal_the_constructors_nodes():
    x, a = Var("x"), Param("a")
    first = Add(Mul(Const(Fraction(1, 3)), x), a)
    shape = core.shape_with_span(first)
    lefts = [Mul(core.index_const(i), x) for i in range(2, 12)]
    copies = core.like_binary_many(Add, shape, lefts, [a] * len(lefts))
    for c, left in zip(copies, lefts):
        made = Add(left, a)
        assert c == made and core.kept_attributes(c) == core.kept_attributes(made)
        assert c.shape is first.shape  # (one tuple for all the copies)
        assert _walk(c)["size"] == core.tree_size(c) == 5


def test_nodes_stay_frozen_records():
    t = Let("c", Param("a"), Add(Param("c"), Var("x")))
    for name in ("name", "bound", "span", "shape", "small", "_hash", "typed", "memo", "anything"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(t, name, None)
        with pytest.raises(dataclasses.FrozenInstanceError):
            delattr(t, name)
    assert [f.name for f in dataclasses.fields(t)] == ["name", "bound", "body", "span"]
    assert Let.__match_args__ == ("name", "bound", "body", "span")
    changed = dataclasses.replace(t, body=Add(Param("b"), Var("x")))  # (the constructor: attributes again)
    assert core.free_params(changed) == {"a", "b"} and core.free_params(t) == {"a"}


def test_pickled_and_copied_nodes_are_rebuilt_by_their_constructors():
    for t in _terms(60):
        hash(t)
        for back in (pickle.loads(pickle.dumps(t)), copy.copy(t), copy.deepcopy(t)):
            assert back == t and hash(back) == hash(t) and type(back) is type(t)
            assert core.kept_attributes(back) == core.kept_attributes(t)
        assert pickle.loads(pickle.dumps(t))._hash is None  # (computed again when asked)


def test_memos_start_empty_and_are_written_by_their_writers():
    t = Add(Var("x"), Param("a"))
    assert (t._hash, t.typed, t.memo) == (None, None, None)
    h = hash(t)
    assert t._hash == h == hash((t.left, t.right))
    core.keep_memo(t, {"k": 1})
    core.keep_typed(t, frozenset({(frozenset(), frozenset({"a"}))}))
    assert t.memo == {"k": 1} and t.typed == {(frozenset(), frozenset({"a"}))}
    loaded = frontend.load_text("param a = 1\nint ([0, 1]) x * a + x d(x)\n")
    for u in core.subterms(loaded.program.body):  # (a load hashes nodes, keeps no engine's memo)
        assert u.memo is None and u._hash in (None, hash(tuple(getattr(u, f.name) for f in dataclasses.fields(u)
                                                                 if f.compare)))
