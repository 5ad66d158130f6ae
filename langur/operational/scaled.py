"""Means and standard errors of samples near the top of the doubles (§9's estimator, computed
without overflow; bench/history/2026-11-29.md#overflow33.

A standard error squares its samples' deviations: samples of 1e200 are finite, their squares
(1e400) are not, so the plain formula says ``± inf`` of a finite estimate.  Both the estimate and
its standard error are homogeneous of degree 1 in the samples, so they are computed again on the
samples divided by a power of two near their largest magnitude (exact: only the exponents change)
and multiplied back — only when the plain result is not finite while every sample is, so that
every ordinary result stays bit-for-bit what the plain formula gives."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np


def _scale(f: np.ndarray) -> float:
    """A power of two near max |f| (1.0 for an all-zero ``f``)."""
    top = float(np.max(np.abs(f))) if f.size else 0.0
    return math.ldexp(1.0, math.frexp(top)[1]) if top > 0 else 1.0


def homogeneous(reduce: Callable[[np.ndarray], tuple[float, ...]], f: np.ndarray) -> tuple[float, ...]:
    """``reduce(f)`` — a tuple of floats each homogeneous of degree 1 in ``f`` (a mean, a standard
    error) — computed on ``f`` scaled when the plain computation overflowed although ``f`` is finite."""
    out = reduce(f)
    if all(math.isfinite(v) for v in out) or not np.all(np.isfinite(f)):
        return out
    s = _scale(f)
    return tuple(v * s for v in reduce(f / s))


def root_sum_squares(plain: float, terms: Sequence[float]) -> float:
    """``plain`` = √(Σ tᵢ²) as the caller computed it, unless that overflowed where every ``tᵢ`` is
    finite: then ``math.hypot`` of the terms (which scales them)."""
    if math.isfinite(plain) or not all(math.isfinite(t) for t in terms):
        return plain
    return math.hypot(*terms)


def squares_share(f: np.ndarray) -> tuple[float, float]:
    """(max fᵢ², Σ fᵢ²) of ``f`` scaled by one power of two when Σ fᵢ² overflowed although ``f`` is
    finite: their ratio (a sample's share of the sum of squares) is what is wanted, and it does not
    change with the scale."""
    with np.errstate(over="ignore"):
        sq = np.square(f)
        total = float(np.sum(sq))
    if not math.isfinite(total) and np.all(np.isfinite(f)):
        sq = np.square(f / _scale(f))
        total = float(np.sum(sq))
    return float(np.max(sq)) if sq.size else 0.0, total
