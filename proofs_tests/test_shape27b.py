"""shape27b: what the front end, the type system and the engines read of core objects has a public
name declared by the core; no module outside ``langur/core`` reads or writes a private attribute of
a core object.

* A term node's small exact value (``t.small``, ``t.small_all``: ``small_value``, ``all_small``),
  the type system's memo (``t.typed``) and the engines' memo (``t.memo``) are public slots,
  documented in ``langur.core`` (shape27 did the same for ``t.shape``).
* What the front end solved to complete a condition is kept on the ``Diffeo`` by
  ``core.keep_solved`` and read back by ``core.kept_solved`` (it wrote ``psi.__dict__["_solved"]``):
  not compared, hashed nor pickled.
* ``t.small`` is checked against exact rational arithmetic written here over the nodes of every
  example; ``t.typed`` against the typing rules; ``t.memo`` against the engine's constant folding.
"""

from __future__ import annotations

import dataclasses
import pickle
import re
from fractions import Fraction

import pytest
from paths import EXAMPLES, REPO
from test_shape27 import _nodes  # (every node of a term, its diffeos' terms included)

from langur import core, frontend, observe, typesys
from langur.core import Add, Const, Diffeo, IfDiffeo, Mul, Param, Pow, Var, children
from langur.diagnostics import LangurError
from langur.frontend import core_term_from_text
from langur.operational import sharing
from langur.syntax import affine

#: Private attributes of core objects (term nodes, Diffeo, InverseBranch) that readers used to name.
_PRIVATE = ("shape", "small", "small_all", "memo", "typed", "hash", "solved", "summary")
_READ = re.compile(r"(?<!self)\._(%s)\b" % "|".join(_PRIVATE))
_KEY = re.compile(r"[\"']_(%s)[\"']" % "|".join(_PRIVATE))


@pytest.fixture(scope="module")
def nodes() -> list:
    found, bodies = {}, 0
    for path in sorted(EXAMPLES.rglob("*.lgr")):
        try:
            program = frontend.load(str(path)).program
        except LangurError:
            continue  # (a few examples are diagnostics on purpose)
        if program is not None:
            bodies += 1
            for t in _nodes(program.body):
                found[id(t)] = t
    assert bodies >= 10
    return list(found.values())


def test_no_module_outside_core_reads_a_private_attribute_of_a_core_object():
    readers = []
    for p in sorted((REPO / "langur").rglob("*.py")):
        if (REPO / "langur" / "core") in p.parents:
            continue
        text = p.read_text(encoding="utf-8")
        for pattern in (_READ, _KEY):
            readers += [f"{p.relative_to(REPO)}: {m.group(0)}" for m in pattern.finditer(text)]
        readers += [f"{p.relative_to(REPO)}: psi.__dict__" for _ in re.finditer(r"\bpsi\.__dict__", text)]
    assert readers == []


def test_the_public_names_are_declared_and_documented_by_the_core():
    assert set(core.attributes._KEPT) == {"shape", "small", "small_all"}
    assert {"typed", "memo"} <= set(core.slots._MEMOS)
    assert {"keep_solved", "kept_solved", "keep_memo", "keep_typed"} <= set(core.__all__)
    for name in ("t.small", "t.small_all", "t.typed", "t.memo", "keep_solved", "kept_solved"):
        assert name in core.__doc__, name
    t = Add(Var("x"), Param("a"))
    for name in ("small", "small_all", "typed", "memo"):
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(t, name, None)  # read only: the node is frozen


def _exact(t):
    """The exact value of ``t`` by rational arithmetic over constants, sums, products and integer
    powers, with the ranges of ``core.attributes`` (magnitude ≤ SMALL, denominator ≤ SMALL_BITS bits,
    |exponent| ≤ SMALL_EXPONENT); ``False`` for any other variable- and parameter-free term (π, a
    primitive, a fractional power, a conditional, a let, a value out of range)."""
    def ranged(v):
        v = Fraction(v)
        return v if abs(v) <= core.SMALL and v.denominator.bit_length() <= core.SMALL_BITS else False

    match t:
        case Const(value):
            return ranged(value) if isinstance(value, (int, Fraction)) else False
        case Add(a, b) | Mul(a, b):
            x, y = _exact(a), _exact(b)
            if x is False or y is False:
                return False
            return ranged(x + y if type(t) is Add else x * y)
        case Pow(a, k):
            x = _exact(a)
            if x is False or Fraction(k).denominator != 1 or abs(k) > core.SMALL_EXPONENT or (x == 0 and k <= 0):
                return False
            return ranged(x ** int(k))
    return False


def test_small_is_the_exact_value_of_every_constant_node(nodes):
    decided = undecided = 0
    for t in nodes:
        # all_small: every subterm's small value is not False (the children's say it of theirs)
        assert t.small_all == (t.small is not False and all(c.small_all for c in children(t))), t
        assert (t.small, t.small_all) == (core.small_value(t), core.all_small(t))
        if core.free_vars(t) or core.free_params(t):
            assert t.small is None or t.small is False, t  # not a constant: no value
            continue
        expected = _exact(t)
        if expected is False:
            undecided += 1
            assert t.small is False, t
        else:
            decided += 1
            assert type(t.small) is Fraction and t.small == expected, t
    assert decided >= 20 and undecided >= 1, (decided, undecided)


def test_typed_holds_contexts_the_rules_accept():
    loaded = frontend.load_text("param a = 1\nint ([0, 1]) let c = a * 2 in x * c + (ifge0 x - 1/2 then x else a) d(x)\n")
    assert loaded.program is not None
    gamma = frozenset({"a"})  # (the declared parameters)
    assert all(t.typed is None for t in _nodes(loaded.program.body))  # (the attributes sufficed)
    with observe.counted():  # the rules applied node by node (not read off the attributes): then kept
        assert typesys.type_program(loaded.program, gamma) == []
    typed = [t for t in _nodes(loaded.program.body) if t.typed is not None]
    assert typed, "the type system keeps the contexts it checked nodes in"
    for t in typed:
        for delta, gamma_ in t.typed:
            assert core.free_vars(t) <= delta and core.free_params(t) <= gamma_, t
            out: list = []
            typesys.type_term(delta, gamma_, t, out)
            assert out == [], (t, out)
            assert typesys.well_typed(delta, gamma_, t)
    assert any(type(t) is IfDiffeo for t in typed) and any(core.free_vars(t) for t in typed)


def test_memo_is_the_engines_dict_of_derived_facts():
    t = Add(Mul(Const(Fraction(1, 2)), Const(Fraction(3))), Pow(Const(Fraction(2)), Fraction(-1)))
    assert t.memo is None
    v = sharing.constant(t)
    assert v == 0.5 * 3.0 + 0.5  # (1/2)·3 + 2⁻¹, by hand
    memo = t.memo
    assert type(memo) is dict and memo["folded"] == v
    assert sharing.constant(t) == v and t.memo is memo  # read back from the same dict
    assert Add(Var("x"), Const(Fraction(1))).memo is None
    assert sharing.constant(Add(Var("x"), Const(Fraction(1)))) is None


@pytest.mark.parametrize("text", ["x + 1/7 + a - 1", "2*x - y + 3*a - 1/5"])
def test_a_diffeo_keeps_what_was_solved_through_the_cores_api(text):
    cond = core_term_from_text(text, params=("a",), variables=("x", "y"))
    psi = affine.complete(cond, ("x", "y"))
    assert type(psi) is Diffeo
    assert core.kept_solved(psi) == affine.solve(cond, ("x", "y")) is not None
    # a memo, not a field: the same Diffeo without it is equal, hashes alike, and pickling drops it
    plain = Diffeo(psi.variables, psi.forward, psi.inputs, psi.branches, psi.solved_for, psi.name,
                   psi.nonzero, psi.span)
    assert core.kept_solved(plain) is None and plain == psi and hash(plain) == hash(psi)
    back = pickle.loads(pickle.dumps(psi))
    assert back == psi and core.kept_solved(back) is None
    core.keep_solved(plain, ("anything", 0))
    assert core.kept_solved(plain) == ("anything", 0)
