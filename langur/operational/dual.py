"""Dual-number arithmetic of the compiled units (§9): constant powers with their derivatives (NaN
outside the domain, as the primitives of :mod:`langur.primitives`), and sums, products and
selections of derivative parts where ``None`` stands for an exact zero."""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from .point import NAN


def power(a, k: Fraction):
    """a^k for a constant rational k; NaN where undefined (0 to a negative power, fractional
    power of a negative number)."""
    if k == 1:
        return a
    if k == 2:
        return a * a
    if k == 0:
        return np.where(np.isnan(a), NAN, 1.0)
    if k == -1:
        out = 1.0 / np.where(a == 0, NAN, a)
    elif k == Fraction(1, 2):
        out = np.sqrt(a)
    else:
        out = np.power(np.where(a == 0, NAN, a) if k < 0 else a, float(k))
    return out


def power_derivative(a, k: Fraction, v):
    """d/da a^k = k·a^(k−1)."""
    if k == 1:
        return 1.0
    if k == 2:
        return 2.0 * a
    if k == 0:
        return 0.0
    if k == -1:
        return -(v * v)
    return float(k) * power(a, k - 1)


def dadd(da, db):
    if da is None:
        return db
    if db is None:
        return da
    return da + db


def dmul(da, b, db, a):
    """⦇t·s⦈ = ⦇t⦈·⟦s⟧ + ⦇s⦈·⟦t⟧ (Fig. 8, product)."""
    if da is None:
        return None if db is None else db * a
    if db is None:
        return da * b
    return da * b + db * a


def select(c, ds, dr):
    if ds is None and dr is None:
        return None
    return np.where(c, 0.0 if ds is None else ds, 0.0 if dr is None else dr)
