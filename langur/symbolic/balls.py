"""Fixed-point balls that hold the exact value of a large rational closed form (issue 15): its
double or its sign with less work than the exact pairs (:mod:`langur.symbolic.exactpairs`), for
Theorem 8.1's check (:mod:`langur.symbolic.rational`'s ``float_value``, ``sign_value``,
``dual_derivative_float``).

Balls: the same values, bounded with less work.  Theorem 8.1's check reads of these exact
values only their signs and their doubles, and near the parameters (floats, dyadic rationals of
~55 bits) their numerators and denominators carry hundreds of digits: most of the exact
arithmetic is reducing them (gcds).  A ball ``(m, r)`` stands for the interval
[(m − r)·2⁻ᴾ, (m + r)·2⁻ᴾ] (P = :data:`BALL_BITS`, m and r ≥ 0 integers); every operation
below returns a ball holding every result of its operation on the points of its operands'
balls, so the exact value is inside the final ball.  Rounding is monotone, so when both ends
of that ball round to the same double the exact value rounds to it too: ``float`` of the exact
Fraction, the same double.  Where a ball cannot decide (it holds 0 where a sign or a quotient is
needed, or its ends round apart) the exact pairs are computed instead.
"""

from __future__ import annotations

import math

from langur.symbolic.arithmetic import Arithmetic
from langur.symbolic.exactpairs import rational_pair

#: Bits after the binary point of a ball's integers.
BALL_BITS = 192
_P = BALL_BITS
_MASK = (1 << _P) - 1
_SCALE = 1 << _P


class Uncertain(Exception):
    """A ball cannot decide: the exact arithmetic is computed instead."""


def _bconst(n: int, d: int):
    """The ball of the rational n/d (d > 0): ⌊n·2ᴾ/d⌋, radius 1 unless exact."""
    m, rem = divmod(n << _P, d)
    return m, (1 if rem else 0)


def _bsum(xs):
    """A ball holding every sum of points of the balls ``xs``: the centres' and the radii's sums."""
    m = r = 0
    for a, s in xs:
        m += a
        r += s
    return m, r


def _bmul(x, y):
    """A ball holding every product of points of balls ``x`` and ``y``: the centres' product
    ab·2⁻²ᴾ is within |a|s + |b|r + rs (in 2⁻²ᴾ) of each, and shifting it down by P floors
    (< 1 in 2⁻ᴾ)."""
    a, r = x
    b, s = y
    p = a * b
    if r or s:
        return p >> _P, ((abs(a) * s + abs(b) * r + r * s) >> _P) + 2
    return p >> _P, (1 if p & _MASK else 0)


def _bprod(xs):
    it = iter(xs)
    v = next(it)
    for y in it:
        v = _bmul(v, y)
    return v


def _bpow(x, k: int):
    """A ball holding xᵏ for every point x of ball ``x`` (k ≥ 1 an integer): |(a + δ)ᵏ − aᵏ| ≤
    (|a| + |δ|)ᵏ − |a|ᵏ.  (A power below 1 is the reciprocal, :func:`_binv`, of one above:
    :class:`Arithmetic`'s ``power``.)"""
    if k == 1:
        return x
    a, r = x
    c = a ** k  # (in 2⁻ᵏᴾ)
    shift = (k - 1) * _P
    if r:
        big = abs(a)
        return c >> shift, (((big + r) ** k - big ** k) >> shift) + 2
    return c >> shift, (1 if c & ((1 << shift) - 1) else 0)


def _binv(x):
    """A ball holding 1/x for every point x of ball ``x`` (:class:`Uncertain` when it holds 0):
    in 2⁻ᴾ, 2²ᴾ/t for t within r of a, which is within 2²ᴾ·r/(|a|(|a| − r)) of 2²ᴾ/a."""
    a, r = x
    big = abs(a)
    if big <= r:
        raise Uncertain()
    m, rem = divmod(1 << (2 * _P), a)
    if r:
        return m, ((r << (2 * _P)) // (big * (big - r))) + 2
    return m, (1 if rem else 0)


def double(ball) -> float:
    """The double of the exact value inside ``ball``, when both its ends round to the same one
    (:class:`Uncertain` otherwise, or when it is beyond a double's range)."""
    m, r = ball
    try:
        lo, hi = (m - r) / _SCALE, (m + r) / _SCALE  # (int / int rounds correctly)
    except OverflowError:
        raise Uncertain() from None
    if lo != hi or math.isinf(lo):
        raise Uncertain()
    return lo


def sign(ball) -> int:
    """The sign of every point of ``ball`` (:class:`Uncertain` when they differ)."""
    m, r = ball
    if m > r:
        return 1
    if m < -r:
        return -1
    if m == r == 0:
        return 0
    raise Uncertain()


#: Balls of subtrees by evaluation point, as :data:`~langur.symbolic.exactpairs.VALUES`.
BALL_VALUES: dict = {}

BALLS = Arithmetic(
    "balls", const=_bconst, read=lambda z: _bconst(*rational_pair(z)), total=_bsum, product=_bprod,
    add=lambda x, y: (x[0] + y[0], x[1] + y[1]), mul=_bmul, raise_=_bpow,
    inverse=_binv, sign=sign, neg=lambda x: (-x[0], x[1]), scale=lambda x, k: (k * x[0], abs(k) * x[1]),
    failure=Uncertain, points=BALL_VALUES)


__all__ = ["BALLS", "BALL_BITS", "BALL_VALUES", "Uncertain", "double", "sign"]
