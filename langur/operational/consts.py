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
    return v.numerator / v.denominator  # = float(Fraction): int / int is correctly rounded
