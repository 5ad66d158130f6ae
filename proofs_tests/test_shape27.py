"""shape27: a term's shape attributes are the public ``t.shape``; term nodes have no ``__dict__``; the
LALR driver reads the end of the input as one more look-ahead.

* ``t.shape`` (``langur.core.attributes``) is read by the engines, the loop template and the type
  system through that public name: no module outside ``langur/core`` reads a private ``_shape``.  Its
  entries are checked against walks written here over the nodes of every example and a fuzz sample
  (size written out as a tree, smoothness, free variables and parameters by the paper's scoping:
  a ``let`` binds a parameter, a diffeomorphic conditional's condition is over its variables).
* Every term node built by loading those programs is slotted (no per-node ``__dict__``).
* The driver (``lalr.driver``) accepts and refuses the prefixes of example programs, cut at every
  token, exactly where lark does, with the same trees: the end of the input (``$END``) is reduced for
  by the same loop as a token, and every prefix ends there.
"""

from __future__ import annotations

import dataclasses
import re

import pytest
from grammar_strategies import tokenize
from paths import EXAMPLES, REPO

from langur import core, frontend
from langur.core import (
    CALLS,
    FP,
    FV,
    SIZE,
    SMOOTH,
    Call,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Let,
    Param,
    Var,
    children,
)
from langur.diagnostics import LangurError
from langur.syntax import lalr, parser

PROGRAMS = sorted(EXAMPLES.rglob("*.lgr"))


def _loaded_bodies() -> list:
    bodies = []
    for path in PROGRAMS:
        try:
            program = frontend.load(str(path)).program
        except LangurError:
            continue  # (a few examples are diagnostics on purpose)
        if program is not None:  # (a module of defs only has none)
            bodies.append(program.body)
    return bodies


def _nodes(root) -> list:
    out, seen, stack = [], set(), [root]
    while stack:
        t = stack.pop()
        if id(t) in seen:
            continue
        seen.add(id(t))
        out.append(t)
        stack.extend(children(t))
        if type(t) is IfDiffeo:
            stack.extend(t.psi.forward)
    return out


def _size(t, memo: dict) -> int:
    """Nodes of ``t`` written out as a tree (a diffeomorphic conditional's condition not counted)."""
    if id(t) not in memo:
        memo[id(t)] = 1 + sum(_size(c, memo) for c in children(t))
    return memo[id(t)]


def _smooth(t) -> bool:
    """No ``ifge0`` and no call anywhere in ``t``."""
    return not any(type(u) in (IfGe0, IfDiffeo, Call) for u in _nodes_tree(t))


def _nodes_tree(t):
    yield t
    for c in children(t):
        yield from _nodes_tree(c)


def _free(t, kind: type) -> frozenset:
    """The names of the ``Var`` (or ``Param``) leaves of ``t`` not bound above them: a ``let`` binds
    a parameter in its body; a diffeomorphic conditional counts its variables and the parameters of
    its Ψ̂'s components; an implicit root binds its variable in its equation (and slope)."""
    match t:
        case Var(name) if kind is Var:
            return frozenset((name,))
        case Param(name) if kind is Param:
            return frozenset((name,))
        case Let(name, bound, body):
            inner = _free(body, kind)
            return _free(bound, kind) | (inner - {name} if kind is Param else inner)
        case IfDiffeo(psi, a, b):
            own = frozenset(psi.variables) if kind is Var else frozenset().union(*(_free(f, Param) for f in psi.forward))
            return own | _free(a, kind) | _free(b, kind)
        case ImplicitRoot():
            kids = children(t)
            own = _free(kids[0], kind) | (_free(kids[4], kind) if len(kids) > 4 else frozenset())
            rest = frozenset().union(*(_free(c, kind) for c in kids[1:4]))
            return (own - {t.variable} if kind is Var else own) | rest
    return frozenset().union(*(_free(c, kind) for c in children(t)))


@pytest.fixture(scope="module")
def bodies():
    found = _loaded_bodies()
    assert len(found) >= 10
    return found


def test_shape_is_public_and_read_by_name_only(bodies):
    assert "shape" in core.attributes._KEPT
    private = re.compile(r"\._shape\b|[\"']_shape[\"']")
    readers = [p for p in (REPO / "langur").rglob("*.py") if private.search(p.read_text(encoding="utf-8"))]
    assert readers == []
    t = bodies[0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        t.shape = t.shape  # read only: the node is frozen


def test_shape_entries_agree_with_walks(bodies):
    checked = 0
    for body in bodies:
        memo: dict = {}
        for t in _nodes(body):
            tree_nodes = _size(t, memo)
            if tree_nodes <= 2000:  # (the walks below are recursive, over the tree written out)
                assert t.shape[SMOOTH] == _smooth(t), t
                assert t.shape[FV] == _free(t, Var), t
                assert t.shape[FP] == _free(t, Param), t
                checked += tree_nodes
            assert t.shape[SIZE] == _size(t, memo)
            assert t.shape[CALLS] is False  # (loaded programs are inlined: no call is left)
            assert not hasattr(t, "__dict__"), type(t)
            checked += 1
    assert checked > 5000


def test_fuzz_sample_nodes_are_slotted():
    from langur.fuzz.campaign import generated

    kinds = set()
    for text in generated(examples=20, seed=5):
        try:
            body = frontend.load_text(text).program.body
        except LangurError:
            continue
        for t in _nodes(body):
            assert not hasattr(t, "__dict__"), type(t)
            assert t.shape[SIZE] == _size(t, {})
            kinds.add(type(t).__name__)
    assert {"Add", "Mul", "Var", "Const", "IfDiffeo"} <= kinds


def _prefixes(text: str) -> list[str]:
    tokens = tokenize(text)
    return [" ".join(tokens[:i]) for i in range(len(tokens) + 1)]


@pytest.mark.parametrize("name", ["fig1.lgr", "window.lgr", "densities.lgr"])
def test_driver_accepts_and_refuses_every_prefix_as_lark_does(name):
    driver = parser._driver()
    assert driver
    lark = parser._lark()
    accepted = refused = 0
    for text in _prefixes((EXAMPLES / name).read_text(encoding="utf-8")):
        with parser._LOCK:
            parser._BUILDER.path = "f.lgr"
            ours = driver(text, "start")
            try:
                theirs = lark.parse(text, start="start")
            except Exception:  # (lark's UnexpectedInput: a syntax error there)
                theirs = lalr.FAILED
        if theirs is lalr.FAILED:
            assert ours is lalr.FAILED, text
            refused += 1
        else:
            assert ours is not lalr.FAILED and ours == theirs, text
            accepted += 1
    assert accepted >= 3 and refused >= 10  # both ends of $END taken: accepted, and not accepted there
