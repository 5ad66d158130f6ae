"""Issue 15 (branch load20): the front end's remaining ``dataclass`` records built without generated
source (``langur.records.frozen`` / ``mutable``: ~1 ms of every start each), and the same behaviour.

``mutable`` is compared with ``dataclass`` (eq, not frozen) on the same class, as ``test_records``
compares ``frozen`` with ``dataclass(frozen=True)``: what a user of the class can observe.  Then the
front end's records, each against a ``dataclass`` twin made from its own fields.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import pickle
from dataclasses import dataclass, field
from fractions import Fraction

import pytest

from langur import frontend, modules
from langur.core import Const
from langur.records import mutable
from langur.syntax import desugar, loops, template, vectors


def _make(deco):
    @deco
    class Rec:
        value: Fraction
        name: str = "x"
        items: list = field(default_factory=list)
        span: object = field(default=None, compare=False, repr=False)

    @deco
    class Box:
        """A box of one record."""

        inner: object

    return Rec, Box


def _observe(Rec, Box) -> list:
    """What a user sees of the two classes, as plain values."""
    out = []
    a, b, c = Rec(Fraction(1, 2), span=3), Rec(Fraction(1, 2), "x", [], 4), Rec(value=Fraction(2))
    out += [repr(a), repr(c), a == b, a != c, a.span, b.span, a.items is not b.items, Rec.__hash__, Box.__hash__]
    for x in (a, Box(a)):
        try:
            hash(x)
            out.append("hashable")
        except TypeError as e:
            out.append(str(e))
    out += [a.__eq__(1), Box(a) == Box(b), Rec.__match_args__, Rec.__doc__, Box.__doc__]
    for bad in ((), (1, 2, 3, 4, 5)):
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
    a.value = Fraction(7)  # mutable: fields assignable, new attributes too
    a.other = 1
    del a.other
    a.items.append(1)
    out += [repr(a), a == b, str(inspect.signature(Rec))]
    out += [repr(dataclasses.replace(a, value=Fraction(5))), [f.name for f in dataclasses.fields(a)],
            dataclasses.is_dataclass(a), copy.deepcopy(Box(a)) == Box(a), copy.copy(a) == a]
    match a:
        case Rec(v, n, items):
            out.append(("match", v, n, items))
    box = Box(None)
    box.inner = box  # recursion in repr
    out.append(repr(box))
    nan = float("nan")
    out.append(Rec(nan) == Rec(nan))
    x = Rec(nan)
    out.append(x == Rec(x.value))
    return out


def test_mutable_matches_dataclass():
    assert _observe(*_make(dataclass)) == _observe(*_make(mutable))


@mutable
class _Pickled:
    value: int
    span: object = field(default=None, compare=False, repr=False)


def test_mutable_pickles():
    a = _Pickled(3, span=(1, 2))
    b = pickle.loads(pickle.dumps(a))
    assert b == a and b.span == (1, 2) and repr(b) == "_Pickled(value=3)"


def test_mutable_refuses_what_it_does_not_support():
    with pytest.raises(TypeError):
        @mutable
        class WithPost:
            a: int

            def __post_init__(self):
                pass
    with pytest.raises(TypeError):
        @mutable
        class WithHash:
            a: int

            def __hash__(self):
                return 0


FROZEN = [desugar.DefSig, desugar.DiffeoSig, desugar.Scope, vectors.Vec, vectors.VecName]
MUTABLE = [desugar.Env, loops.Budget, template.Record, modules.ElaboratedModule, modules.Loaded,
           frontend.LoadCache]


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


@pytest.mark.parametrize("cls", FROZEN + MUTABLE, ids=lambda c: c.__qualname__)
def test_front_end_records_are_the_dataclasses_they_were(cls):
    """Each record against a ``dataclass`` twin (frozen or not, as it was): the same fields (names,
    defaults, compare, repr), ``match`` arguments, constructor signature and hashability; and it was
    built without dataclass's generated source (its methods are ``langur.records``' closures: fails
    on the code before, where each was a ``dataclass``)."""
    is_frozen = cls in FROZEN
    twin = dataclass(frozen=is_frozen)(type(cls.__name__, (), {"__annotations__": dict(cls.__annotations__),
                                                               **{f.name: f for f in _fresh_fields(cls)}}))
    ours = [(f.name, f.default, f.default_factory, f.compare, f.repr, f.hash) for f in dataclasses.fields(cls)]
    theirs = [(f.name, f.default, f.default_factory, f.compare, f.repr, f.hash) for f in dataclasses.fields(twin)]
    assert ours == theirs
    assert cls.__match_args__ == twin.__match_args__
    ours, theirs = inspect.signature(cls).parameters.values(), inspect.signature(twin).parameters.values()
    assert [(p.name, p.kind, p.default) for p in ours] == [(p.name, p.kind, p.default) for p in theirs]
    assert (cls.__hash__ is None) == (twin.__hash__ is None) == (not is_frozen)
    assert cls.__eq__.__module__ == cls.__repr__.__module__ == "langur.records"
    # built alike: required fields only (positionally, by name), then every field given
    fields = dataclasses.fields(cls)
    required = [object() for f in fields if f.default is dataclasses.MISSING
                and f.default_factory is dataclasses.MISSING]
    names = [f.name for f in fields]
    given = [object() for _ in fields]
    for args, kwargs in ((required, {}), ((), dict(zip(names, required))), (given, {}),
                         ((), dict(zip(names, given))), (given[:1], dict(zip(names[1:], given[1:])))):
        a, b = cls(*args, **kwargs), twin(*args, **kwargs)
        assert [getattr(a, n) for n in names] == [getattr(b, n) for n in names]
        assert repr(a) == repr(b).replace(twin.__qualname__, cls.__qualname__, 1)
    one, two = cls(*required), cls(*required)  # a default factory's value is fresh per instance
    for f in fields:
        if f.default_factory is not dataclasses.MISSING:
            assert getattr(one, f.name) is not getattr(two, f.name)
    with pytest.raises(TypeError):
        cls(*given, object())
    if fields and required:
        with pytest.raises(TypeError):
            cls(*required[:-1])
    if is_frozen:
        with pytest.raises(dataclasses.FrozenInstanceError):
            setattr(one, names[0], 1)


def test_records_in_use_behave_as_before():
    """The records as the front end uses them: a Scope copied by ``with_index`` / ``with_param`` /
    ``replace`` compares and hashes by its fields; frozen ones refuse assignment; a Loaded compares
    equal to a second load of the same text (fields compared), and is unhashable."""
    sc = desugar.Scope(variables=("x",), gamma=frozenset({"a"}))
    assert sc.with_index("i", 3).consts == {"i": 3} and sc.consts == {}
    assert sc.with_param("b").gamma == frozenset({"a", "b"})
    assert dataclasses.replace(sc, where="here") == desugar.Scope(("x",), frozenset({"a"}), where="here")
    with pytest.raises(dataclasses.FrozenInstanceError):
        sc.where = "there"
    v = vectors.Vec((Const(Fraction(1)),))
    assert hash(v) == hash(vectors.Vec((Const(Fraction(1)),))) and vectors.VecName.of(v).params == frozenset()
    text = "param a = 1\nint ([0, 1]) [x - a / 2 >= 0] * x d(x)\n"
    frontend.clear_load_cache()
    one = frontend.load_text(text)
    frontend.clear_load_cache()
    two = frontend.load_text(text)
    assert one == two and one is not two and one.main == two.main
    with pytest.raises(TypeError):
        hash(one)
    budget = loops.Budget()
    assert budget.charge(2, 3) is None and budget == loops.Budget(2, 6, False)
