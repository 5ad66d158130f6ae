"""Issue 15 (branch load20): the front end's remaining ``dataclass`` records built without generated
source (``langur.records.frozen`` / ``record``: ~1 ms of every start each), and the same behaviour:
each against a ``dataclass`` twin made from its own fields (``test_records`` compares the decorators
themselves with ``dataclass``), and as the front end uses them."""

from __future__ import annotations

import dataclasses
import inspect
from dataclasses import dataclass
from fractions import Fraction

import pytest
from test_records import _fresh_fields  # (a dataclass twin's fields, made from a record's)

from langur import frontend, modules
from langur.core import Const
from langur.syntax import loops, scope, template, vectors

FROZEN = [scope.DefSig, scope.DiffeoSig, scope.Scope, vectors.Vec, vectors.VecName]
PLAIN = [scope.Env, loops.Budget, template.Record, modules.ElaboratedModule, modules.Loaded,
           frontend.LoadCache]


@pytest.mark.parametrize("cls", FROZEN + PLAIN, ids=lambda c: c.__qualname__)
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
    sc = scope.Scope(variables=("x",), gamma=frozenset({"a"}))
    assert sc.with_index("i", 3).consts == {"i": 3} and sc.consts == {}
    assert sc.with_param("b").gamma == frozenset({"a", "b"})
    assert dataclasses.replace(sc, where="here") == scope.Scope(("x",), frozenset({"a"}), where="here")
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
