"""How one mode computes with the values of a large rational closed form's subtrees (issue 15):
:class:`Arithmetic`, over which :mod:`langur.symbolic.tape`'s walks are written once.

The modes (:mod:`langur.symbolic.rational` uses them): exact reduced integer pairs
(:mod:`langur.symbolic.exactpairs`), fixed-point balls that hold the exact value
(:mod:`langur.symbolic.balls`), values modulo a prime (:mod:`langur.symbolic.residues`).
"""

from __future__ import annotations

from typing import Callable

from langur.symbolic.tape import node_walk


class Arithmetic:
    """How one mode computes with the values of a form's subtrees: the walks (:class:`Tape`,
    :func:`node_walk`) are written once over these operations.

    Declared per mode: ``const(n, d)`` (the rational n/d, d > 0), ``read(z)`` (a point's value of a
    symbol), ``total(values)`` and ``product(values)`` (of a non-empty iterable), ``add(x, y)`` and
    ``mul(x, y)`` (the same of two), ``raise_(x, k)`` (xᵏ for k ≥ 1), ``inverse(x)``, ``sign(x)``
    (−1, 0 or 1), ``neg(x)``, ``scale(x, k)`` (k·x for an integer k; only the slopes use it),
    ``failure`` (the exception the operations raise where the mode cannot decide: a reciprocal or
    a sign at or near 0) and ``points`` (the values of subtrees remembered by point, for
    :func:`point_memo`; a dict of its own unless given).  Derived here, the same for every mode:
    ``power`` (xᵏ for any integer k: undefined at 0 for k < 1), ``magnitude`` (|x|, differentiable
    only away from 0), ``zero`` and ``one``, and the mode's recursive walk ``value_of(e, memo,
    point)`` (:func:`node_walk`)."""

    def __init__(self, name: str, *, const: Callable, read: Callable, total: Callable, product: Callable,
                 add: Callable, mul: Callable, raise_: Callable, inverse: Callable, sign: Callable, neg: Callable,
                 failure: type, scale: Callable | None = None, points: dict | None = None):
        self.name = name
        self.const, self.read, self.total, self.product = const, read, total, product
        self.add, self.mul, self.raise_, self.inverse = add, mul, raise_, inverse
        self.sign, self.neg, self.scale, self.failure = sign, neg, scale, failure
        self.points = {} if points is None else points
        self.zero, self.one = const(0, 1), const(1, 1)
        self.power = power_of(raise_, inverse, self.one)
        self.magnitude = magnitude_of(sign, neg, failure)
        self.value_of = node_walk(self)

    def __repr__(self) -> str:
        return f"Arithmetic({self.name})"


def power_of(raise_, inverse, one):
    """xᵏ for an integer k from xᵏ (k ≥ 1) and 1/x: for k < 1 the reciprocal of x⁻ᵏ (x⁰ = 1), the
    arithmetic's failure where that is (or may be) 0."""
    def power(x, k: int):
        if k >= 1:
            return raise_(x, k)
        y = inverse(raise_(x, -k) if k else x)
        return y if k else one
    return power


def magnitude_of(sign, neg, failure):
    """|x| where it is differentiable (away from 0; the arithmetic's failure at 0)."""
    def magnitude(x):
        s = sign(x)
        if s == 0:
            raise failure()  # (not differentiable there)
        return x if s > 0 else neg(x)
    return magnitude


__all__ = ["Arithmetic", "magnitude_of", "power_of"]
