"""``@frozen`` and ``@record``: ``@dataclass(frozen=True)`` and ``@dataclass`` without generated
source (issue 15, start-up).

``dataclasses.dataclass`` writes each method it adds as Python source and compiles it with
``exec`` when the class is created: six compilations per frozen class (``__init__``, ``__repr__``,
``__eq__``, ``__hash__``, ``__setattr__``, ``__delattr__``), three per plain one, about a
millisecond of CPU per class.  The core and surface syntax declare some fifty node classes, so
every process that reads a program paid ~50 ms of compiling before its first line was parsed: a
sixth of a one-shot ``langur eval``; the engines' results, the catalogue of codes and the
commands' records some sixty compilations more.

:func:`frozen` and :func:`record` collect the fields themselves, as ``dataclass(init=False,
repr=False, eq=False)`` would (``dataclasses.Field`` objects in ``__dataclass_fields__``, so
``dataclasses.fields``, ``replace``, ``is_dataclass`` and ``match`` work as before; calling
``dataclass`` for that cost ~0.1 M instructions a class, resolving each string annotation against
the module), and attach the same methods as closures over the field names, compiling nothing.
They behave as ``dataclass``'s do: ``__init__`` takes the fields positionally or by name with their
defaults (a class's own ``__init__`` is kept; ``inspect.signature`` of the class is dataclass's,
made when asked), ``__eq__`` compares the tuples of the fields with ``compare=True`` when the
classes are the same (``NotImplemented`` otherwise), ``__repr__`` writes the fields with
``repr=True`` (``...`` on recursion).  A frozen record's ``__hash__`` hashes that tuple (so hashes,
and the order of sets and dicts keyed by nodes, are unchanged), and assigning or deleting a field
raises ``dataclasses.FrozenInstanceError``; a plain record with ``eq`` is unhashable, as a plain
dataclass is.  ``eq=False`` (``@frozen(eq=False)``) keeps identity's equality and hash.  A record
may extend a record (its fields after the base's, as ``dataclass`` orders them).
``@frozen(slots=True)`` is ``dataclass(frozen=True, slots=True)`` for a class that writes its own
``__init__`` (the Monte Carlo engine's evaluation point, built at every call of a def).
``proofs_tests/test_records.py`` and ``test_oneshot22.py`` compare them with ``dataclass``'s on
the same classes.

Only the features Langur's records use are supported (fields with a default or a
``default_factory``; no ``ClassVar``, ``InitVar``, ``KW_ONLY`` or ``__post_init__``; slots only
frozen, with an own ``__init__``): anything else is refused when the class is created.
"""

from __future__ import annotations

import abc
import dataclasses
import inspect
from _thread import get_ident
from dataclasses import KW_ONLY, Field, InitVar, field
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


def frozen(cls=None, *, eq: bool = True, slots: bool = False):
    """``@dataclass(frozen=True)`` (or ``@frozen(eq=False)``: ``dataclass(frozen=True, eq=False)``;
    ``@frozen(slots=True)``: ``dataclass(frozen=True, slots=True)``, whose class must then write its
    own ``__init__``, setting each field with ``object.__setattr__``) for ``cls``, without
    compiling generated source (see above)."""
    if cls is None:
        return lambda c: _make(c, frozen=True, eq=eq, slots=slots)
    return _make(cls, frozen=True, eq=eq, slots=slots)


def record(cls=None, *, eq: bool = True):
    """``@dataclass`` (or ``@record(eq=False)``: ``dataclass(eq=False)``) for ``cls``, without
    compiling generated source (see above)."""
    if cls is None:
        return lambda c: _make(c, frozen=False, eq=eq)
    return _make(cls, frozen=False, eq=eq)


def _make(cls, frozen: bool, eq: bool, slots: bool = False):
    own_doc = cls.__dict__.get("__doc__")
    if "__slots__" in cls.__dict__:
        raise TypeError(f"{cls.__name__}: records support plain fields only (no slots)")
    fields, names, compared, shown = _collect(cls, frozen)
    if slots:
        cls = _slotted(cls, names)
    key = _getter(compared)

    if "__init__" not in cls.__dict__:
        cls.__init__ = _init(cls.__qualname__, fields)
        cls.__signature__ = _Signature(cls.__init__, fields)

    def __eq__(self, other):
        if other.__class__ is self.__class__:
            return key(self) == key(other)
        return NotImplemented

    def __hash__(self):
        return hash(key(self))

    running = set()

    def __repr__(self):  # (``...`` on recursion, as reprlib.recursive_repr, without its wrapper per class)
        mark = id(self), get_ident()
        if mark in running:
            return "..."
        running.add(mark)
        try:
            return self.__class__.__qualname__ + "(" + ", ".join(f"{n}={getattr(self, n)!r}" for n in shown) + ")"
        finally:
            running.discard(mark)

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
    if frozen and slots:  # (as dataclass: a frozen slotted instance is unpickled field by field)
        def __getstate__(self):
            return [getattr(self, n) for n in names]

        def __setstate__(self, state):
            for n, v in zip(names, state):
                object.__setattr__(self, n, v)

        methods += [__getstate__, __setstate__]
    prefix = cls.__qualname__ + "."
    for fn in methods:
        fn.__qualname__ = prefix + fn.__name__
        setattr(cls, fn.__name__, fn)
    if own_doc is None:  # dataclass's default docstring: the class's name and signature, when read
        cls.__doc__ = _Doc(cls)
    return cls


def _slotted(cls, names: tuple[str, ...]):
    """``cls`` made again with ``__slots__`` for its fields, as ``dataclass(slots=True)`` makes it:
    the fields' class attributes (their defaults) dropped, as they would clash with the slots."""
    if "__init__" not in cls.__dict__:
        raise TypeError(f"{cls.__name__}: a slotted record writes its own __init__")
    namespace = {k: v for k, v in cls.__dict__.items() if k not in names and k not in ("__dict__", "__weakref__")}
    namespace["__slots__"] = tuple(n for n in names if n not in _slot_names(cls.__mro__[1:]))
    new = type(cls)(cls.__name__, cls.__bases__, namespace)
    new.__qualname__ = cls.__qualname__
    return new


def _slot_names(bases) -> set:
    return {n for b in bases for n in b.__dict__.get("__slots__", ())}


class _Signature:
    """``inspect.signature`` of a record whose ``__init__`` is :func:`_init`'s, made when asked
    (``inspect`` reads a class's ``__signature__`` first): dataclass's signature, the fields with
    their defaults and annotations (a factory shown as dataclass shows it).  Building it for every
    record at start-up cost ~3 M instructions of a one-shot ``langur eval``.  A subclass with an
    ``__init__`` of its own is not described by it (None: ``inspect`` looks further)."""

    def __init__(self, init, fields):
        self.init, self.fields, self.made = init, fields, None

    def __get__(self, instance, owner):
        if instance is not None or owner.__init__ is not self.init:
            return None
        if self.made is None:
            params = []  # (the class's signature: without ``self``)
            for f in self.fields:
                if not f.init:
                    continue
                default = f.default if f.default is not _MISSING else \
                    _FACTORY if f.default_factory is not _MISSING else inspect.Parameter.empty
                params.append(inspect.Parameter(f.name, inspect.Parameter.POSITIONAL_OR_KEYWORD, annotation=f.type,
                                                default=default))
            self.made = inspect.Signature(params, return_annotation=None)
        return self.made


class _Doc:
    """dataclass's default docstring of a record that has none (its name and signature), written
    when read (``type.__doc__`` calls a descriptor found in the class's own namespace)."""

    def __init__(self, cls):
        self.cls, self.text = cls, None

    def __get__(self, instance, owner):
        if self.text is None:
            self.text = self.cls.__name__ + str(inspect.signature(self.cls)).replace(" -> None", "")
        return self.text


#: What ``dataclass(cls, init=False, repr=False, eq=False)`` gives every record: its parameters
#: (``__dataclass_params__``, shared: they are the same for all) and the marker of a real field
#: (``Field._field_type``), read off one such dataclass instead of named from dataclasses' internals.
_PROBE = dataclasses.dataclass(init=False, repr=False, eq=False)(
    type("_Probe", (), {"__annotations__": {"x": "int"}, "__doc__": "A probe."}))
_PARAMS = _PROBE.__dataclass_params__
_FIELD = dataclasses.fields(_PROBE)[0]._field_type


def _collect(cls, frozen: bool) -> tuple:
    """What ``dataclass(cls, init=False, repr=False, eq=False)`` does to ``cls``, done directly
    (issue 15, start-up: ``dataclass`` resolves each string annotation against the module to rule
    out ``ClassVar``/``InitVar``/``KW_ONLY``, ~0.1 M instructions a class; records refuse those
    outright): the fields, the bases' first (a record's base is a record frozen as it is), each a
    ``dataclasses.Field`` named, typed and marked as ``dataclass`` marks it; a field's class
    attribute its default (none for a factory); ``__dataclass_fields__``, ``__dataclass_params__``
    and ``__match_args__`` set, so ``dataclasses.fields``, ``replace``, ``is_dataclass`` and
    ``match`` work as on a dataclass.  Returns the fields in order, and the names of all, of those
    compared and of those shown (``repr``).  A class with ``__post_init__`` is refused."""
    fields = {}
    abstract = False
    for base in cls.__mro__[-1:0:-1]:
        namespace = base.__dict__
        if "__post_init__" in namespace:
            raise TypeError(f"{cls.__name__}: records support plain fields only (no __post_init__)")
        abstract = abstract or "__abstractmethods__" in namespace
        base_fields = namespace.get("__dataclass_fields__")
        if base_fields is None:
            continue
        if namespace.get("_record_frozen", base.__dataclass_params__.frozen) is not frozen:
            raise TypeError(f"{cls.__name__}: a record extends only records frozen as it is "
                            f"({base.__name__} is {'not ' if frozen else ''}frozen)")
        fields.update(base_fields)
    namespace = cls.__dict__
    if "__post_init__" in namespace:
        raise TypeError(f"{cls.__name__}: records support plain fields only (no __post_init__)")
    annotations = namespace.get("__annotations__", {})
    for name, kind in annotations.items():
        text = kind if kind.__class__ is str else getattr(kind, "__name__", "") or repr(kind)
        if "ClassVar" in text or "InitVar" in text or "KW_ONLY" in text or kind is KW_ONLY or \
                isinstance(kind, InitVar):  # (not plain fields to dataclass: refused)
            raise TypeError(f"{cls.__name__}.{name}: records support plain fields only (no {text})")
        default = namespace.get(name, _MISSING)
        if isinstance(default, Field):
            f = default
            if f.default is _MISSING:
                delattr(cls, name)
            else:
                setattr(cls, name, f.default)
        else:
            f = field(default=default)
        if f.default_factory is _MISSING and f.default.__class__.__hash__ is None:
            raise ValueError(f"mutable default {type(f.default)} for field {name} is not allowed: use default_factory")
        f.name, f.type, f._field_type = name, kind, _FIELD
        if f.kw_only is _MISSING:
            f.kw_only = False
        fields[name] = f
    for name, value in namespace.items():
        if isinstance(value, Field) and name not in annotations:
            raise TypeError(f"{name!r} is a field but has no type annotation")
    cls.__dataclass_fields__ = fields
    cls.__dataclass_params__ = _PARAMS
    cls._record_frozen = frozen
    out = tuple(fields.values())
    names, compared, shown, positional = [], [], [], []
    for f in out:
        names.append(f.name)
        if f.compare:
            compared.append(f.name)
        if f.repr:
            shown.append(f.name)
        if f.init and not f.kw_only:
            positional.append(f.name)
    if "__match_args__" not in namespace:
        cls.__match_args__ = tuple(positional)
    if abstract or "__abstractmethods__" in namespace:
        abc.update_abstractmethods(cls)
    return out, tuple(names), tuple(compared), tuple(shown)


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

    __init__.__qualname__ = f"{qualname}.__init__"
    return __init__


__all__ = ["FACTORY", "frozen", "record"]
