"""``langur.records.frozen`` and ``record`` behave as ``dataclass(frozen=True)`` and ``dataclass``
(issue 15, start-up), and lark is imported without the ``regex`` module only where Langur's grammar
does not need it.

Each check builds the same class twice, once with each decorator, and compares what a user of the
class can observe: construction (positional, by name, defaults, errors), equality, hashes (the
order of sets and dicts keyed by nodes depends on them), ``repr``, frozenness, ``match``,
``dataclasses.fields``/``replace``/``is_dataclass``, pickling and deep copies, the docstring.
Then the real node classes: every ``@frozen`` class of core, surface, modules, primitives and
diagnostics compared field for field with a ``dataclass(frozen=True)`` twin.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import pickle
import sys
from dataclasses import dataclass, field
from fractions import Fraction

import pytest

from langur import core, diagnostics, modules, primitives
from langur.records import frozen, record
from langur.syntax import surface


def _make(deco):
    @deco
    class Rec:
        value: Fraction
        name: str = "x"
        span: object = field(default=None, compare=False, repr=False)

    @deco
    class Box:
        """A box of one record."""

        inner: object

    return Rec, Box


PAIRS = [_make(dataclass(frozen=True)), _make(frozen)]


def _observe(Rec, Box) -> list:
    """What a user sees of the two classes, as plain values."""
    out = []
    a, b, c = Rec(Fraction(1, 2), span=3), Rec(Fraction(1, 2), "x", 4), Rec(value=Fraction(2))
    out += [repr(a), repr(c), a == b, a != c, hash(a) == hash(b), hash(a), hash(Box(a)), a.span, b.span]
    out += [a.__eq__(1), Box(a) == Box(b), Rec.__match_args__, Rec.__doc__, Box.__doc__]
    for bad in ((), (1, 2, 3, 4)):
        try:
            Rec(*bad)
            out.append("built")
        except TypeError:
            out.append("TypeError")
    for kwargs in ({"value": 1, "nope": 2}, {"value": 1, "name": "y"}):
        try:
            out.append(repr(Rec(**kwargs)))
        except TypeError:
            out.append("TypeError")
    try:
        Rec(1, value=2)
    except TypeError:
        out.append("TypeError duplicate")
    for action in (lambda: setattr(a, "value", 3), lambda: delattr(a, "name"), lambda: setattr(a, "other", 1)):
        try:
            action()
            out.append("assigned")
        except dataclasses.FrozenInstanceError as e:
            out.append(str(e))
    out += [repr(dataclasses.replace(a, value=Fraction(5))), [f.name for f in dataclasses.fields(a)],
            dataclasses.is_dataclass(a), copy.deepcopy(Box(a)) == Box(a), copy.copy(a) == a]
    match a:
        case Rec(v, n):
            out.append(("match", v, n))
    nan = float("nan")
    out.append(Rec(nan) == Rec(nan))  # distinct NaN objects: unequal, as a tuple comparison says
    x = Rec(nan)
    out.append(x == Rec(x.value))  # the same NaN object: equal (tuples compare identity first)
    return out


def test_frozen_matches_dataclass():
    assert _observe(*PAIRS[0]) == _observe(*PAIRS[1])


@frozen
class _Pickled:
    value: int
    span: object = field(default=None, compare=False, repr=False)


@record
class _PickledPlain:
    value: int
    notes: list = field(default_factory=list)


@frozen
class _PickledSub(_Pickled):
    wrt: str = "a"


def test_frozen_pickles():
    a = _Pickled(3, span=(1, 2))
    b = pickle.loads(pickle.dumps(a))
    assert b == a and b.span == (1, 2) and hash(b) == hash(a) and repr(b) == "_Pickled(value=3)"
    c = _PickledSub(4, wrt="b")
    assert pickle.loads(pickle.dumps(c)) == c and repr(c) == "_PickledSub(value=4, wrt='b')"
    p = _PickledPlain(5, ["n"])
    assert pickle.loads(pickle.dumps(p)) == p and repr(p) == "_PickledPlain(value=5, notes=['n'])"


def test_frozen_refuses_what_it_does_not_support():
    with pytest.raises(TypeError):
        @frozen
        class WithPost:
            a: int

            def __post_init__(self):
                pass


def _make_plain(deco, sub_deco):
    @deco
    class Est:
        """An estimate."""

        value: float
        notes: list = field(default_factory=list)
        memo: dict = field(default_factory=dict, compare=False, repr=False)

    @sub_deco
    class Deriv(Est):
        wrt: str = "a"

    return Est, Deriv


def _observe_plain(Est, Deriv, frozen_: bool) -> list:
    """What a user sees of a record and of a record extending it."""
    out = []
    a, b, d = Est(1.5), Est(1.5, []), Deriv(2.0, ["n"], wrt="b")
    out += [repr(a), repr(d), a == b, a == Est(2.0), d == Deriv(2.0, ["n"], {"m": 1}, "b"), d == Est(2.0, ["n"]),
            Est.__match_args__, Deriv.__match_args__, Est.__doc__, Deriv.__doc__,
            [f.name for f in dataclasses.fields(d)], str(inspect.signature(Deriv)), a.notes is not b.notes]
    try:
        out.append(hash(a) == hash(b) and hash(d) == hash(Deriv(2.0, ["n"], wrt="b")))
    except TypeError as e:
        out.append(str(e))
    for action in (lambda: setattr(a, "value", 3.0), lambda: setattr(d, "wrt", "c"), lambda: setattr(a, "other", 1)):
        try:
            action()
            out.append("assigned")
        except dataclasses.FrozenInstanceError as e:
            out.append(str(e))
    out += [repr(dataclasses.replace(d, wrt="z")), dataclasses.asdict(d) if not frozen_ else None,
            copy.deepcopy(d) == d]
    for bad in ((), (1, [], {}, "w", 5)):
        try:
            Deriv(*bad)
            out.append("built")
        except TypeError:
            out.append("TypeError")
    match d:
        case Deriv(v, n, w):
            out.append(("match", v, n, w))
    return out


_PLAIN = {"plain": (_make_plain(dataclass, dataclass), _make_plain(record, record)),
          "frozen": (_make_plain(dataclass(frozen=True), dataclass(frozen=True)), _make_plain(frozen, frozen))}


@pytest.mark.parametrize("kind", sorted(_PLAIN))
def test_records_with_a_base_match_dataclass(kind):
    theirs, ours = _PLAIN[kind]
    assert _observe_plain(*theirs, kind == "frozen") == _observe_plain(*ours, kind == "frozen")


def _observe_identity(Tape) -> list:
    a, b = Tape((1,)), Tape((1,))
    out = [a == b, a == a, hash(a) == object.__hash__(a), repr(a), Tape.__eq__ is object.__eq__]
    try:
        a.steps = ()
        out.append("assigned")
    except dataclasses.FrozenInstanceError as e:
        out.append(str(e))
    return out


def test_frozen_without_eq_matches_dataclass():
    def make(deco):
        @deco
        class Tape:
            steps: tuple

        return Tape

    assert _observe_identity(make(dataclass(frozen=True, eq=False))) == _observe_identity(make(frozen(eq=False)))


def test_records_refuse_mixed_frozenness():
    @frozen
    class Base:
        a: int

    with pytest.raises(TypeError):
        @record
        class Sub(Base):
            b: int = 0
    with pytest.raises(TypeError):
        @frozen
        class Slotted:
            __slots__ = ("a",)
            a: int


def _frozen_classes():
    for mod in (core.terms, core.programs, surface, modules, primitives, diagnostics):
        for cls in vars(mod).values():
            if isinstance(cls, type) and cls.__module__ == mod.__name__ and dataclasses.is_dataclass(cls) \
                    and "__setattr__" in cls.__dict__ and cls.__setattr__.__module__ in ("langur.records", "langur.core.slots"):
                yield cls


def test_node_classes_are_the_dataclasses_they_were():
    """Each ``@frozen`` class against its ``dataclass(frozen=True)`` twin: the same fields (names,
    defaults, compare, repr) and the same constructor signature where the class has no own
    ``__init__``."""
    classes = list(_frozen_classes())
    assert len(classes) >= 45  # core, surface, modules, primitives, diagnostics
    for cls in classes:
        twin = dataclass(frozen=True)(type(cls.__name__, (), {"__annotations__": dict(cls.__annotations__),
                                                              **{f.name: f for f in _fresh_fields(cls)}}))
        ours = [(f.name, f.default, f.compare, f.repr, f.hash) for f in dataclasses.fields(cls)]
        theirs = [(f.name, f.default, f.compare, f.repr, f.hash) for f in dataclasses.fields(twin)]
        assert ours == theirs, cls
        assert cls.__match_args__ == twin.__match_args__
        if getattr(cls.__init__, "__module__", None) == "langur.records":  # (core's terms: built by __new__)
            assert str(inspect.signature(cls)) == str(inspect.signature(twin)), cls


def _fresh_fields(cls):
    for f in dataclasses.fields(cls):
        kw = {"compare": f.compare, "repr": f.repr, "hash": f.hash}
        if f.default is not dataclasses.MISSING:
            kw["default"] = f.default
        if f.default_factory is not dataclasses.MISSING:
            kw["default_factory"] = f.default_factory
        g = field(**kw)
        g.name = f.name
        yield g


def test_core_nodes_hash_and_print_as_before():
    """Core terms (whose hash and equality the node classes wrap) against tuples of their fields."""
    x, a = core.Var("x"), core.Param("a")
    t = core.Add(core.Mul(core.Const(Fraction(2)), x), a)
    assert hash(x) == hash(("x",)) and hash(core.Const(Fraction(2))) == hash((Fraction(2),))
    assert hash(t) == hash((t.left, t.right))
    assert repr(t) == ("Add(left=Mul(left=Const(value=Fraction(2, 1)), right=Var(name='x')), "
                       "right=Param(name='a'))")
    assert t == core.Add(core.Mul(core.Const(Fraction(2)), core.Var("x", span="elsewhere")), a)


def test_lark_without_regex():
    """lark was imported with ``regex`` hidden (langur.syntax.larkload): the grammar's terminals
    must then need nothing but ``re`` (no Unicode categories ``\\p{…}``), and ``regex`` stays
    importable for anyone else."""
    from langur.syntax import larkload, tables  # noqa: F401  (imports lark as Langur does)

    assert "\\p{" not in tables.grammar_text()
    assert sys.modules.get("regex", "absent") is not None  # not left hidden
    assert larkload.Lark is tables.Lark
