"""``@frozen`` and ``@record``: ``@dataclass(frozen=True)`` and ``@dataclass`` without generated
source (issue 15, start-up).

``dataclasses.dataclass`` writes each method it adds as Python source and compiles it with
``exec`` when the class is created: six compilations per frozen class (``__init__``, ``__repr__``,
``__eq__``, ``__hash__``, ``__setattr__``, ``__delattr__``), three per plain one, about a
millisecond of CPU per class.  The core and surface syntax declare some fifty node classes, so
every process that reads a program paid ~50 ms of compiling before its first line was parsed: a
sixth of a one-shot ``langur eval``; the engines' results, the catalogue of codes and the
commands' records some sixty compilations more.

:func:`frozen` and :func:`record` let ``dataclass`` collect the fields (so ``dataclasses.fields``,
``replace``, ``is_dataclass`` and ``match`` work as before) but ask it for no method, and attach
the same methods as closures over the field names, compiling nothing.  They behave as
``dataclass``'s do: ``__init__`` takes the fields positionally or by name with their defaults (a
class's own ``__init__`` is kept), ``__eq__`` compares the tuples of the fields with
``compare=True`` when the classes are the same (``NotImplemented`` otherwise), ``__repr__`` writes
the fields with ``repr=True`` (``...`` on recursion).  A frozen record's ``__hash__`` hashes that
tuple (so hashes, and the order of sets and dicts keyed by nodes, are unchanged), and assigning or
deleting a field raises ``dataclasses.FrozenInstanceError``; a plain record with ``eq`` is
unhashable, as a plain dataclass is.  ``eq=False`` (``@frozen(eq=False)``) keeps identity's
equality and hash.  A record may extend a record (its fields after the base's, as ``dataclass``
orders them).  ``proofs_tests/test_records.py`` compares them with ``dataclass``'s on the same
classes.

Only the features Langur's records use are supported (fields with a default or a
``default_factory``; no ``InitVar``, ``KW_ONLY``, ``__post_init__`` or slots): anything else is
refused when the class is created.
"""

from __future__ import annotations

import dataclasses
import inspect
import reprlib
from operator import attrgetter

_MISSING = dataclasses.MISSING


class _Factory:
    def __repr__(self) -> str:
        return "<factory>"


#: How dataclass's signatures show a default factory, and the default of such a field in a record's
#: written-out ``__init__`` (dataclass's own marker): ``def __init__(self, xs=FACTORY)`` then
#: ``xs = [] if xs is FACTORY else xs``, as dataclass's generated ``__init__`` does.
FACTORY = getattr(dataclasses, "_HAS_DEFAULT_FACTORY", None) or _Factory()
_FACTORY = FACTORY


def frozen(cls=None, *, eq: bool = True):
    """``@dataclass(frozen=True)`` (or ``@frozen(eq=False)``: ``dataclass(frozen=True, eq=False)``)
    for ``cls``, without compiling generated source (see above)."""
    if cls is None:
        return lambda c: _make(c, frozen=True, eq=eq)
    return _make(cls, frozen=True, eq=eq)


def record(cls=None, *, eq: bool = True):
    """``@dataclass`` (or ``@record(eq=False)``: ``dataclass(eq=False)``) for ``cls``, without
    compiling generated source (see above)."""
    if cls is None:
        return lambda c: _make(c, frozen=False, eq=eq)
    return _make(cls, frozen=False, eq=eq)


def _make(cls, frozen: bool, eq: bool):
    own_doc = cls.__dict__.get("__doc__")
    if own_doc is None:  # (dataclass would write one from object's signature, tokenizing it: later)
        cls.__doc__ = "?"
    if hasattr(cls, "__post_init__") or "__slots__" in cls.__dict__:
        raise TypeError(f"{cls.__name__}: records support plain fields only (no __post_init__, no slots)")
    for base in cls.__mro__[1:-1]:
        if dataclasses.is_dataclass(base) and \
                base.__dict__.get("_record_frozen", base.__dataclass_params__.frozen) is not frozen:
            raise TypeError(f"{cls.__name__}: a record extends only records frozen as it is "
                            f"({base.__name__} is {'not ' if frozen else ''}frozen)")
    cls = dataclasses.dataclass(cls, init=False, repr=False, eq=False)
    cls._record_frozen = frozen
    fields = dataclasses.fields(cls)
    names = tuple(f.name for f in fields)
    compared = tuple(f.name for f in fields if f.compare)
    key = _getter(compared)
    shown = tuple(f.name for f in fields if f.repr)

    if "__init__" not in cls.__dict__:
        cls.__init__ = _init(cls.__qualname__, fields)

    def __eq__(self, other):
        if other.__class__ is self.__class__:
            return key(self) == key(other)
        return NotImplemented

    def __hash__(self):
        return hash(key(self))

    @reprlib.recursive_repr()
    def __repr__(self):
        return self.__class__.__qualname__ + "(" + ", ".join(f"{n}={getattr(self, n)!r}" for n in shown) + ")"

    field_names = frozenset(names)

    def __setattr__(self, name, value):
        if type(self) is cls or name in field_names:
            raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    def __delattr__(self, name):
        if type(self) is cls or name in field_names:
            raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    methods = [__repr__]
    if eq:
        methods.append(__eq__)
        if frozen:
            methods.append(__hash__)
        elif "__hash__" not in cls.__dict__:  # (dataclass's rule: eq without frozen, unhashable)
            cls.__hash__ = None
    if frozen:
        methods += [__setattr__, __delattr__]
    for fn in methods:
        fn.__qualname__ = f"{cls.__qualname__}.{fn.__name__}"
        setattr(cls, fn.__name__, fn)
    if own_doc is None:  # dataclass's default docstring: the class's name and signature
        cls.__doc__ = cls.__name__ + str(inspect.signature(cls)).replace(" -> None", "")
    return cls


def _getter(names: tuple[str, ...]):
    """The tuple of the fields ``names`` of a record (always a tuple, as dataclass compares)."""
    if len(names) >= 2:
        return attrgetter(*names)
    if len(names) == 1:
        one = attrgetter(names[0])
        return lambda obj: (one(obj),)
    return lambda obj: ()


def _init(qualname: str, fields) -> object:
    """``__init__(self, f1, f2=default, …)``: fields by position or by name, defaults filled in."""
    names = tuple(f.name for f in fields if f.init)
    defaults = {}
    for f in fields:
        if f.default is not _MISSING:
            defaults[f.name] = (False, f.default)
        elif f.default_factory is not _MISSING:
            defaults[f.name] = (True, f.default_factory)
        elif not f.init:
            raise TypeError(f"{qualname}: field {f.name} has init=False and no default")
    hidden = tuple(f.name for f in fields if not f.init)
    types = {f.name: f.type for f in fields}
    n = len(names)

    def __init__(self, *args, **kwargs):
        if len(args) > n:
            raise TypeError(f"{qualname}.__init__() takes {n + 1} positional arguments but {len(args) + 1} were given")
        d = self.__dict__
        for name, v in zip(names, args):
            d[name] = v
        if kwargs or len(args) < n:
            for name in names[len(args):]:
                if name in kwargs:
                    d[name] = kwargs.pop(name)
                elif name in defaults:
                    factory, v = defaults[name]
                    d[name] = v() if factory else v
                else:
                    raise TypeError(f"{qualname}.__init__() missing required argument: {name!r}")
            if kwargs:
                name = next(iter(kwargs))
                if name in names:
                    raise TypeError(f"{qualname}.__init__() got multiple values for argument {name!r}")
                raise TypeError(f"{qualname}.__init__() got an unexpected keyword argument {name!r}")
        for name in hidden:
            factory, v = defaults[name]
            d[name] = v() if factory else v

    params = [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD)]
    for name in names:
        default = defaults.get(name)
        params.append(inspect.Parameter(name, inspect.Parameter.POSITIONAL_OR_KEYWORD, annotation=types[name],
                                        default=inspect.Parameter.empty if default is None
                                        else (_FACTORY if default[0] else default[1])))
    __init__.__signature__ = inspect.Signature(params, return_annotation=None)
    __init__.__qualname__ = f"{qualname}.__init__"
    return __init__


__all__ = ["FACTORY", "frozen", "record"]
