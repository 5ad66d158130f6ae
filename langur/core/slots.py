"""Term nodes stored in slots, without a ``__dict__`` per node (issue 15, loading at small n).

A node of a frozen record keeps its fields and the attributes it computes when it is built
(:mod:`langur.core.attributes`) in its ``__dict__``: one more object per node for Python to make,
fill entry by entry and collect.  Term nodes keep them in slots instead: :func:`_slotted` makes the
record classes again over a few *layouts*, classes that only declare the slots — every field of the
classes of a group (leaves, sums and products, unary nodes, the others), and the attributes every
term keeps (:data:`_KEPT`: the tuple ``shape`` and the small value; :data:`_MEMOS`).  A slot a class has no field for stays empty (reading it
is an ``AttributeError``, as for an attribute it does not have).

A frozen record refuses assignment by its own ``__setattr__``, which every assignment then calls;
the layout has Python's own, so a node is filled as an instance of the layout (one store per slot,
the interpreter's cheapest, when the code that fills the nodes meets one type: a layout per group of
classes that share that code) and then given its class (:func:`_built`).  Its ``_hash``, typing memo
(``typed``) and engines' memos (``memo``, a dict made when one is kept) start at ``None`` and are
written later by :data:`_keep_hash`, :data:`keep_typed` and :data:`keep_memo` (the node is frozen:
an attribute that is not a field is still written only by these).  ``typed`` and ``memo`` are
public (read in place by the type system and the engines, :mod:`langur.core`); ``_hash`` is
read only here (:mod:`.sharing`).
"""

from __future__ import annotations

import dataclasses

from .attributes import _KEPT

#: What a term keeps besides its fields and :data:`_KEPT`, written after it is built: its hash
#: (:mod:`langur.core.sharing`), the contexts it was typed in (``langur.typesys``) and a dict of
#: the engines' derived facts (``None`` until one is kept).
_MEMOS = ("_hash", "typed", "memo")


class _Kept:
    """The slots every term has: the attributes of :mod:`langur.core.attributes` and :data:`_MEMOS`
    (the layout of :func:`_slotted` adds the fields)."""

    __slots__ = _KEPT + _MEMOS


#: ``_keep_hash(t, h)``: write a built node's ``_hash`` (and so ``keep_typed``, ``keep_memo``).
_keep_hash = _Kept._hash.__set__
keep_typed = _Kept.typed.__set__
keep_memo = _Kept.memo.__set__


def _built(t, cls: type):
    """``t``, a filled instance of the layout of ``cls`` (``cls.__base__``, :func:`_slotted`), made a
    node of ``cls`` (frozen from now on)."""
    t.__class__ = cls
    return t


def _refuse_set(self, name, value):
    raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")


def _refuse_delete(self, name):
    raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")


def _reduce(self):  # pickled and copied as its constructor's call (which recomputes what it keeps)
    return self.__class__, tuple(getattr(self, f.name) for f in dataclasses.fields(self))


def _slotted(*groups: tuple[type, ...]) -> tuple[type, ...]:
    """The frozen record classes of ``groups`` (``records.frozen``, each with its own ``__new__`` that
    fills an instance of ``cls.__base__`` and returns it :func:`_built`) made again, each group over
    one layout (a :class:`_Kept` with a slot per field of any class of the group): the same names,
    fields (``dataclasses.fields``, ``replace``, ``match``), equality, hash and ``repr``, frozen,
    pickled and copied by their constructor."""
    out = []
    for classes in groups:
        fields = {f.name: None for cls in classes for f in dataclasses.fields(cls)}
        layout = type("TermSlots", (_Kept,), {"__slots__": tuple(fields), "__module__": classes[0].__module__})
        out.extend(_remade(cls, layout) for cls in classes)
    return tuple(out)


def _remade(cls: type, layout: type) -> type:
    names = {f.name for f in dataclasses.fields(cls)}
    skip = {"__dict__", "__weakref__", "__init__", "__signature__", "__setattr__", "__delattr__", *names}
    namespace = {k: v for k, v in cls.__dict__.items() if k not in skip}
    namespace.update(__slots__=(), __setattr__=_refuse_set, __delattr__=_refuse_delete, __reduce__=_reduce)
    new = type(cls)(cls.__name__, (layout,), namespace)
    new.__qualname__ = cls.__qualname__
    return new
