"""A constant's value as a double (shared by the compiler and the interval enclosures)."""

from __future__ import annotations

import math

from ..core import Const


def const_value(c: Const) -> float:
    v = c.value
    if isinstance(v, str):
        return math.pi
    if isinstance(v, float):
        return v
    try:
        return v.numerator / v.denominator  # = float(Fraction): int / int is correctly rounded
    except OverflowError:  # beyond the doubles (a completion's 1e300·1e300): rounded, that is ±∞,
        return math.inf if v > 0 else -math.inf  # as the doubles of the unfolded term would give
