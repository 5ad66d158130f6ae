"""One-shot start-up, second round (issue 15, branch oneshot22): records without a ``dataclass()`` call
per class, slotted frozen records, the Monte Carlo engine's ``Point`` and ``Linking`` as such
records, and ``langur.timebox`` without the ``signal`` module's enums.

What a user of a class can observe is compared with a ``dataclass`` twin built from the same
declaration (construction, equality, hashes, ``repr``, frozenness, ``__slots__``, pickling,
``dataclasses.fields``/``replace``, ``match``); the start-up facts are checked in a fresh
interpreter.
"""

from __future__ import annotations

import copy
import dataclasses
import inspect
import os
import pickle
import subprocess
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from test_records import _fresh_fields  # (a dataclass twin's fields, made from a record's)

from langur import records
from langur.operational import point
from langur.records import FACTORY, frozen, record

ROOT = Path(__file__).resolve().parents[1]


@dataclass(frozen=True, slots=True)
class PtTheirs:
    vars: dict
    mode: int = 0
    sites: frozenset = frozenset()
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    def moved(self):
        return type(self)(self.vars, self.mode + 1)


@frozen(slots=True)
class PtOurs:
    vars: dict
    mode: int = 0
    sites: frozenset = frozenset()
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    def __init__(self, vars, mode=0, sites=frozenset(), memo=FACTORY):  # noqa: A002, B008
        object.__setattr__(self, "vars", vars)
        object.__setattr__(self, "mode", mode)
        object.__setattr__(self, "sites", sites)
        object.__setattr__(self, "memo", {} if memo is FACTORY else memo)

    def moved(self):
        return type(self)(self.vars, self.mode + 1)


def _observe_slotted(Pt) -> list:
    a, b, c = Pt({"x": 1}), Pt({"x": 1}, 0, frozenset(), {"m": 2}), Pt(vars={"x": 2}, mode=1)
    name = Pt.__name__
    out = [repr(a).replace(name, "Pt"), repr(c).replace(name, "Pt"), a == b, a == c, a.memo == {} and a.memo is not Pt({}).memo, Pt.__slots__,
           hasattr(a, "__dict__"), Pt.__match_args__, [f.name for f in dataclasses.fields(Pt)],
           repr(dataclasses.replace(c, mode=5)).replace(name, "Pt"), repr(a.moved()).replace(name, "Pt"),
           dataclasses.is_dataclass(a)]
    # (not a new attribute: Python 3.11's slotted frozen dataclass raises TypeError from its
    # __setattr__'s super(), which names the class from before slots=True made it again; a record
    # raises FrozenInstanceError, below)
    for action in (lambda: setattr(a, "mode", 3), lambda: delattr(a, "vars")):
        try:
            action()
            out.append("assigned")
        except (dataclasses.FrozenInstanceError, AttributeError, TypeError) as e:
            out.append((type(e).__name__, str(e).replace(name, "Pt")))
    try:
        hash(a)
        out.append("hashed")
    except TypeError as e:  # (a dict field)
        out.append(str(e))
    h = Pt(frozenset({1}))  # hashable fields: the tuple of the compared fields' hash
    out += [hash(h) == hash((frozenset({1}), 0, frozenset())), hash(h) == hash(Pt(frozenset({1}), memo={"z": 1}))]
    back = pickle.loads(pickle.dumps(c))
    out += [back == c, repr(back).replace(name, "Pt"), copy.deepcopy(c) == c, copy.copy(c) == c]
    match c:
        case Pt(v, m):
            out.append(("match", v, m))
    return out


def test_frozen_slotted_record_matches_dataclass():
    assert "__eq__" in PtOurs.__dict__ and PtOurs.__eq__.__module__ == "langur.records"
    assert _observe_slotted(PtTheirs) == _observe_slotted(PtOurs)
    with pytest.raises(dataclasses.FrozenInstanceError):
        PtOurs({}).other = 1


def test_a_slotted_record_writes_its_own_init():
    with pytest.raises(TypeError):
        @frozen(slots=True)
        class NoInit:
            a: int


def test_records_are_made_without_calling_dataclass(monkeypatch):
    """The fields are collected by ``records`` itself (``dataclass`` resolved every string annotation
    against the module); the result is what ``dataclasses`` reads of a dataclass."""

    def refused(*args, **kwargs):
        raise AssertionError("dataclasses.dataclass called")

    monkeypatch.setattr(records.dataclasses, "dataclass", refused)

    @frozen
    class Base:
        """A base."""

        value: int
        span: object = field(default=None, compare=False, repr=False)

    @frozen
    class Sub(Base):
        name: str = "x"
        notes: tuple = ()

    @record
    class Plain:
        items: list = field(default_factory=list)

    monkeypatch.undo()

    @dataclass
    class Twin(Plain):  # a dataclass extending a record reads its fields and parameters
        more: int = 0

    s = Sub(1, name="y")
    assert [f.name for f in dataclasses.fields(Sub)] == ["value", "span", "name", "notes"]
    assert [f.name for f in dataclasses.fields(Twin)] == ["items", "more"] and Twin([1], 2).items == [1]
    assert Sub.__match_args__ == ("value", "span", "name", "notes") and Sub.span is None and Sub.name == "x"
    assert repr(s).endswith(".Sub(value=1, name='y', notes=())") and s == Sub(1, 5, "y")
    assert dataclasses.replace(s, value=2) == Sub(2, None, "y")
    assert Plain().items == [] and Plain().items is not Plain().items and "items" not in Plain.__dict__
    assert str(inspect.signature(Sub)) == "(value: 'int', span: 'object' = None, name: 'str' = 'x', notes: 'tuple' = ()) -> None"
    assert Sub.__doc__.startswith("Sub(value: 'int'") and Base.__doc__ == "A base."


def test_records_refuse_what_dataclass_would_read_otherwise():
    for annotation in ("ClassVar[int]", "InitVar[int]", "KW_ONLY"):
        with pytest.raises(TypeError):
            frozen(type("Bad", (), {"__annotations__": {"a": annotation}, "__module__": __name__}))
    with pytest.raises(ValueError):  # a mutable default, as dataclass refuses it
        record(type("Mutable", (), {"__annotations__": {"a": "list"}, "a": [], "__module__": __name__}))
    with pytest.raises(TypeError):  # a field() without an annotation
        record(type("Stray", (), {"__annotations__": {}, "a": field(default=1), "__module__": __name__}))


def test_a_subclass_with_its_own_init_has_its_own_signature():
    @record
    class Base:
        a: int
        b: int = 2

    class Sub(Base):
        def __init__(self, c: int):
            super().__init__(c, c)

    assert str(inspect.signature(Base)) == "(a: 'int', b: 'int' = 2) -> None"
    assert str(inspect.signature(Sub)) == "(c: 'int')"
    assert Sub(3) == Base(3, 3) or Sub(3).a == 3


def test_point_and_linking_are_their_dataclasses():
    """The Monte Carlo engine's evaluation point and linking, against ``dataclass(frozen=True,
    slots=True)`` twins of the same declarations."""
    for cls in (point.Point, point.Linking):
        assert cls.__eq__.__module__ == "langur.records" and "__dict__" not in cls.__dict__
        twin = dataclass(frozen=True, slots=True)(
            type(cls.__name__, (), {"__annotations__": dict(cls.__annotations__),
                                    **{f.name: f for f in _fresh_fields(cls)}}))
        assert cls.__slots__ == twin.__slots__ and cls.__match_args__ == twin.__match_args__
        assert [(f.name, f.default, f.default_factory, f.compare, f.repr) for f in dataclasses.fields(cls)] == \
            [(f.name, f.default, f.default_factory, f.compare, f.repr) for f in dataclasses.fields(twin)]
    x = np.linspace(0.0, 1.0, 5)
    args = ({"x": x}, {"a": 0.5})
    ours, theirs = point.Point(*args), _twin(point.Point)(*args)
    assert repr(ours).replace("Point", "T") == repr(theirs).replace("Point", "T")
    assert ours.dvars == {} and ours.memo == {} and ours.memo is not point.Point(*args).memo
    lk = point.Linking(3, [0, 1])
    assert repr(lk) == repr(_twin(point.Linking)(3, [0, 1])) and lk == point.Linking(3, [0, 1])
    assert hash(point.UNLINKED) == hash(_twin(point.Linking)())
    with pytest.raises(dataclasses.FrozenInstanceError):
        ours.mode = 2
    bound = ours.bind("z", 1.0, None)
    assert bound.params == {"a": 0.5, "z": 1.0} and bound.root == ({"a": 0.5}, {}) and ours.values() is ours


def _twin(cls):
    return dataclass(frozen=True, slots=True)(
        type(cls.__name__, (), {"__annotations__": dict(cls.__annotations__),
                                **{f.name: f for f in _fresh_fields(cls)}}))


def test_timebox_needs_no_signal_enums():
    """``langur.timebox`` works through ``_signal`` (the C module ``signal`` wraps): importing it
    builds none of ``signal``'s enums."""
    code = "import sys, langur.timebox as t; print('signal' in sys.modules, t.run_with_timeout(lambda: 7, 1.0))"
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT,
                         timeout=60, check=True).stdout.split()
    assert out == ["False", "7"]
