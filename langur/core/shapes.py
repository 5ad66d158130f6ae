"""Nodes built from a node of the same shape (issue 15): a loop's copies, and the affine completion
of a condition of the same shape as one completed before (:func:`langur.syntax.affine.completed`).

Such a node's attributes that depend on its shape only (:mod:`langur.core.attributes`: its
classes, names, primitives, exponents and diffeos, the tuple ``shape``) are those of the node it
copies, the same tuple; only those that depend on the values of its constants are computed.  Each function's node is equal, attributes
included, to the one the constructor builds.
"""

from __future__ import annotations

import operator

from .attributes import _LEAF_SHAPE, FP, FV, _binary_value, _small_power, int_fraction
from .terms import Add, Const, IfDiffeo, Mul, Pow, Prim, Term

#: What a shape (:func:`shape_with_span`) gives a node: its attributes of the shape, and its span.
_shape_span = operator.itemgetter("shape", "span")
#: All that a constant keeps (:func:`like_leaf` copies it).
_LEAF_COPY = ("value", "span", "shape", "small", "small_all", "_hash", "typed", "memo")
_leaf_copy = operator.attrgetter(*_LEAF_COPY)


def same_shape(t: "Term", s: "Term") -> bool:
    """``t`` and ``s`` have the same attributes but those that depend on their constants' values
    (then a node above one of them may be built by :func:`like` from a node above the other)."""
    return t.shape == s.shape


def shape_of(t: "Term") -> dict:
    """What :func:`like` keeps of ``t`` (an ``Add``, ``Mul``, ``Pow``, ``Prim`` or ``IfDiffeo``):
    the attributes of its shape, and its exponent or primitive."""
    d = {"shape": t.shape}
    if type(t) is Pow:
        d["exponent"] = t.exponent
    elif type(t) is Prim:
        d["op"] = t.op
    elif type(t) is not Add and type(t) is not Mul and type(t) is not IfDiffeo:
        raise TypeError(f"shape_of: not an Add, Mul, Pow, Prim or IfDiffeo: {t!r}")
    return d


def shape_with_span(t: "Term") -> dict:
    """:func:`shape_of` ``t`` with its span: what :func:`like_binary` and :func:`like_power` copy
    (an ``Add`` or ``Mul``, the most frequent, read in one call)."""
    tt = type(t)
    if tt is Add or tt is Mul:
        return {"shape": t.shape, "span": t.span}
    d = shape_of(t)
    d["span"] = t.span
    return d


def like(cls: type, shape: dict, kids: tuple, span) -> "Term":
    """The node of class ``cls`` with children ``kids`` (in the order of :func:`children`) and
    ``span`` whose other fields and attributes of its shape are ``shape`` (:func:`shape_of` of a
    node whose children had the :func:`same_shape` as ``kids``): only the attributes that depend on
    its constants' values are computed (a loop's copies, issue 15).  Equal, attributes included,
    to the node the constructor builds.

    For an ``IfDiffeo``, ``kids`` is ``(psi, then, orelse)`` and ``psi`` must have what Ψ̂ gives the
    node (``_diffeo_summary``) in common with the Ψ̂ of the node ``shape`` was taken from: the same
    variables and the same shapes of its terms, whatever their constants (an affine completion of
    a condition of the same shape, :func:`langur.syntax.affine.completed`)."""
    new = _new(cls.__base__)
    new.shape = shape["shape"]
    new.span, new._hash, new.typed, new.memo = span, None, None, None
    if cls is Add or cls is Mul:
        a, b = kids
        new.left, new.right = a, b
        _binary_value(new, a, b, cls is Mul)
        new.__class__ = cls  # (_built, written out)
        return new
    if cls is IfDiffeo:
        psi, a, b = kids
        new.psi, new.then, new.orelse = psi, a, b
        v = new.small = False if not new.shape[FV] and not new.shape[FP] else None
        new.small_all = v is not False and a.small_all and b.small_all
        new.__class__ = cls  # (_built, written out)
        return new
    (a,) = kids
    if cls is Pow:
        new.base = a
        new.exponent = shape["exponent"]
        new.small = v = _small_power(a.small, shape["exponent"])
    else:
        new.arg = a
        new.op = shape["op"]
        new.small = v = False if a.small is not None else None
    new.small_all = v is not False and a.small_all
    new.__class__ = cls  # (_built, written out)
    return new


def like_binary(cls: type, shape: dict, a: "Term", b: "Term") -> "Term":
    """``like(cls, shape, (a, b), span)`` for an ``Add`` or a ``Mul`` whose ``shape`` also holds its
    ``span`` (``dict(shape_of(t), span=…)``): a loop's copies build most of their nodes so, one call
    each (issue 15)."""
    new = _new(cls.__base__)
    new.shape, new.span = _shape_span(shape)
    new.left, new.right, new._hash, new.typed, new.memo = a, b, None, None, None
    x, y = a.small, b.small
    if (x is None or y is None) and x is not False and y is not False:
        # (_binary_value's first case, written out: a copy's nodes over a variable or parameter)
        new.small = None
        new.small_all = a.small_all and b.small_all
    else:
        _binary_value(new, a, b, cls is Mul)
    new.__class__ = cls  # (_built, written out)
    return new


def like_binary_many(cls: type, shape: dict, lefts: list, rights: list) -> list:
    """``[like_binary(cls, shape, a, b) for a, b in zip(lefts, rights)]`` in one loop (the same node
    of all of a loop's copies at once, issue 15)."""
    out = []
    append = out.append
    mul = cls is Mul
    _layout = cls.__base__
    kept, span = _shape_span(shape)
    for a, b in zip(lefts, rights):
        new = _new(_layout)
        new.shape = kept
        new.span = span
        new.left = a
        new.right = b
        new._hash = new.typed = new.memo = None
        x, y = a.small, b.small
        if (x is None or y is None) and x is not False and y is not False:
            new.small = None
            new.small_all = a.small_all and b.small_all
        else:
            _binary_value(new, a, b, mul)
        new.__class__ = cls  # (_built, written out: t is an Add or a Mul)
        append(new)
    return out


def like_power(shape: dict, a: "Term", small) -> "Term":
    """``like(Pow, shape, (a,), span)`` whose ``shape`` also holds its ``span``, with the small value
    of ``a ^ k`` given (``small_power(small_value(a), k)``, which a copy may have computed already)."""
    new = _new(_POW)
    new.shape, new.span = _shape_span(shape)
    new.base, new.exponent, new._hash, new.typed, new.memo = a, shape["exponent"], None, None, None
    new.small = small
    new.small_all = small is not False and a.small_all
    new.__class__ = Pow  # (_built, written out)
    return new


def like_leaf(c: Const, span) -> Const:
    """``Const(c.value, span=span)``, its attributes copied from ``c`` (a loop's copy reads its
    index at several places: one number, issue 15)."""
    new = _new(_CONST)
    (new.value, new.span, new.shape, new.small, new.small_all, new._hash, new.typed,
     new.memo) = _leaf_copy(c)
    new.span = span
    new.__class__ = Const  # (_built, written out)
    return new


_new = object.__new__
_POW = Pow.__base__
_CONST = Const.__base__


def index_const(value: int, span=None) -> Const:
    """``Const(Fraction(value), span=span)`` for an int ``value`` (a loop's index in one of its
    copies, issue 15): an integer of fewer than 1000 bits is its own small value, so its attributes
    are written without the constructor's tests.  Equal, attributes included, to the constructor's."""
    number = int_fraction(value)
    if value.bit_length() >= 1000:
        return Const(number, span=span)
    new = _new(_CONST)
    new.value, new.span, new._hash, new.typed, new.memo = number, span, None, None, None
    new.shape, new.small, new.small_all = _LEAF_SHAPE, number, True  # (a leaf's attributes: its shape, no small value but a constant's)
    new.__class__ = Const  # (_built, written out)
    return new
