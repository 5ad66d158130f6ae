"""Definitions inlined with sharing (§9): a call with the same arguments as an earlier one is the
same subterm, so a program is a DAG whose distinct nodes are as many as its definitions' text,
and the passes over it cost once per distinct node (``langur.core.shared``)."""

from __future__ import annotations

import os
import pickle
import subprocess
import sys
import time

import sympy as sp

from langur.core import Add, Mul, Param, Var, shared, subterms, tree_size
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load_text


def doubling(n: int, inside: str = "") -> str:
    lines = [f"def f0(x: var, a: param) = x * a{inside}"]
    lines += [f"def f{i}(x: var, a: param) = f{i - 1}(x, a) + f{i - 1}(x, a)" for i in range(1, n + 1)]
    return "\n".join(lines + ["param a = 0.5", f"int ([0, 1]) f{n}(x, a) d(x)"]) + "\n"


def test_inlining_shares_a_definition_called_twice_alike():
    p = load_text(doubling(40)).program
    distinct = list(subterms(p.body))
    assert len(distinct) < 200  # 40 sums, one x·a, the domain's factors
    assert tree_size(p.body) > 2**42  # the same term written out
    # ⟦p⟧ = 2^40·∫₀¹ x·a dx = 2^39·a (by hand), from the shared term
    r = denote_program(p, {"a": 0.5})
    assert float(r.value) == 2**38 and r.method == "closed_form"
    (a,) = r.expr.free_symbols
    assert sp.simplify(r.expr - sp.Integer(2) ** 39 * a) == 0


def test_the_exact_derivative_of_a_shared_program():
    # f0 = x·a·[x ≤ a]: ⟦p⟧ = 2^40·a·a²/2 on [0, 1], so d/da = 3·2^39·a² (= 3·2^37 at a = 1/2):
    # regular part 2^40·a²/2, boundary (the delta at x = a) 2^40·a·a
    p = load_text(doubling(40, " * [x <= a]")).program
    d = ddenote_program(p, {"a": 0.5}, {"a": 1})
    assert float(d.value) == 3 * 2**37
    assert float(d.regular.value) == 2**40 / 8 and float(d.boundary.value) == 2**40 / 4


def test_a_pass_runs_once_per_distinct_node():
    leaf = Mul(Var("x"), Param("a"))
    t = leaf
    for _ in range(60):
        t = Add(t, t)
    calls = []

    @shared
    def size(u):
        calls.append(u)
        return 1 + sum(size(c) for c in (getattr(u, "left", None), getattr(u, "right", None)) if c is not None)

    counted, written = size(t), tree_size(t)  # (never repr a DAG in an assertion: 2^60 paths)
    assert counted == written == 2**62 - 1  # 3 nodes for x·a, then n ↦ 2n + 1 sixty times
    assert len(calls) == 63  # 60 sums, the product, x, a


def test_hash_and_equality_of_a_deep_dag_are_linear():
    t = Mul(Var("x"), Param("a"))
    u = Mul(Var("x"), Param("a"))
    for _ in range(200):
        t, u = Add(t, t), Add(u, u)
    start = time.process_time()
    same, equal, different = hash(t) == hash(u), t == u, t != Add(u, Var("x"))
    assert same and equal and different
    assert time.process_time() - start < 5  # 2^200 paths: anything per path would never end


def test_a_pickled_term_keeps_no_hash_from_another_process():
    t = Add(Var("x"), Param("a"))
    hash(t)
    back = pickle.loads(pickle.dumps(t))
    assert back._hash is None  # (comparing computes it again)
    assert back == t and hash(back) == hash(t)
    code = ("import pickle, sys; t = pickle.loads(sys.stdin.buffer.read()); "
            "from langur.core import Add, Var, Param; print(t == Add(Var('x'), Param('a')), hash(t) == hash(Add(Var('x'), Param('a'))))")
    r = subprocess.run([sys.executable, "-c", code], input=pickle.dumps(t), capture_output=True, timeout=60,
                       env={**os.environ, "PYTHONHASHSEED": "123"})
    assert r.stdout.split() == [b"True", b"True"], r.stderr


def test_lets_bound_differently_around_one_shared_call():
    # w(x, b) is one shared subterm under two lets that bind b differently: the passes are
    # memoized per node and context, so each scope sees its own b (by hand: ∫₀¹ x dx + ∫₀¹ 2x dx = 1.5)
    text = ("def w(x: var, b: param) = x * b\n"
            "int ([0, 1]) (let b = 1 in w(x, b)) + (let b = 2 in w(x, b)) d(x)\n")
    p = load_text(text).program
    assert denote_program(p, {}).expr == sp.Rational(3, 2)


def test_the_repr_of_a_large_shared_term_is_a_summary():
    t = Mul(Var("x"), Param("a"))
    assert repr(t) == "Mul(left=Var(name='x'), right=Param(name='a'))"
    for _ in range(60):
        t = Add(t, t)
    assert repr(t) == f"<Add: {2**62 - 1:,} nodes written out>"
