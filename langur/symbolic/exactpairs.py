"""Exact values of a large rational closed form (issue 15): reduced integer pairs
``(numerator, denominator > 0)`` added by Henrici's algorithm and multiplied crosswise, the
:class:`~langur.symbolic.arithmetic.Arithmetic` :data:`EXACT` of :mod:`langur.symbolic.rational`'s
exact values and dual-number derivatives over the rationals (Theorem 8.1's check of large closed
forms, §10.2, §10.3.1).
"""

from __future__ import annotations

import math

import sympy as sp

from langur.symbolic.arithmetic import Arithmetic
from langur.symbolic.tape import NotRational


def qadd(x, y):
    """``x + y`` for reduced integer pairs ``(numerator, denominator > 0)``, reduced (Henrici's
    algorithm, as CPython's ``Fraction``: the gcds are taken of the operands' denominators, not of
    the sum's far larger numerator and denominator; a gcd of two large integers was most of the
    time of evaluating a large closed form exactly)."""
    a, b = x[1], y[1]
    if a == b:
        n = x[0] + y[0]
        g = _gcd(n, a)
        return (n, a) if g == 1 else (n // g, a // g)
    g = _gcd(a, b)
    if g == 1:  # (then the sum of reduced fractions is reduced)
        return x[0] * b + y[0] * a, a * b
    s = a // g
    t = x[0] * (b // g) + y[0] * s
    g2 = _gcd(t, g)  # (a common factor of t and the denominator s·b divides g)
    return (t, s * b) if g2 == 1 else (t // g2, s * (b // g2))


def qmul(x, y):
    """``x · y`` for reduced integer pairs, reduced (each numerator against the other denominator)."""
    n1, d1 = x
    n2, d2 = y
    g1 = _gcd(n1, d2)
    if g1 != 1:
        n1, d2 = n1 // g1, d2 // g1
    g2 = _gcd(n2, d1)
    if g2 != 1:
        n2, d1 = n2 // g2, d1 // g2
    return n1 * n2, d1 * d2


_gcd = math.gcd
_ZERO, _ONE = (0, 1), (1, 1)


def qsum(xs):
    v = _ZERO
    for x in xs:
        v = qadd(v, x)
    return v


def qprod(xs):
    v = _ONE
    for x in xs:
        v = qmul(v, x)
    return v


def qinv(x):
    n, d = x
    if n == 0:
        raise NotRational()
    return (-d, -n) if n < 0 else (d, n)


def rational_pair(z) -> tuple[int, int]:
    z = sp.sympify(z)
    if not isinstance(z, sp.Rational):
        raise NotRational()
    return int(z.p), int(z.q)


#: Exact values of subtrees (reduced integer pairs, :func:`qadd`) by evaluation point.
VALUES: dict = {}

EXACT = Arithmetic(
    "exact", const=lambda n, d: (n, d), read=rational_pair, total=qsum, product=qprod, add=qadd, mul=qmul,
    raise_=lambda x, k: (x[0] ** k, x[1] ** k), inverse=qinv, sign=lambda x: (x[0] > 0) - (x[0] < 0),
    neg=lambda x: (-x[0], x[1]), scale=lambda x, k: qmul((k, 1), x), failure=NotRational, points=VALUES)


__all__ = ["EXACT", "VALUES", "qadd", "qinv", "qmul", "qprod", "qsum", "rational_pair"]
