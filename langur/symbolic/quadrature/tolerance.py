"""The quadrature's tolerances and thresholds, and the outermost level's loosening (paper §8.2's
⟦p⟧ at a point, Theorem 8.1's finite differences in :mod:`langur.theorem`; issue 13).

Every other module of the package reads these; none is imported here.
"""

from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator

EPSABS = 1e-11  # innermost level; each outer level is 10x looser


#: A sub-interval narrower than this (relative to the variable's range) on which the integrand
#: cannot be evaluated is left out, with a note: there the rounding error of a guard exceeds its
#: value (at a fold of an inverse branch, z = sqrt(r² − x² − y²) near the rim of a disk), not a
#: property of the integral.
NARROW = 1e-8


#: A condition whose value is at most this at a point where a ``folds`` problem's weight is not
#: finite puts that point outside the region or on its boundary within rounding (an implicit root
#: at its piece's turning point, where it cannot be bracketed and 1/|f'| is 1/0): a fold met, not a
#: pole inside the region (there the conditions hold).
BOUNDARY = 1e-9


#: The factor by which the outermost level's tolerance is loosened (:func:`outer_tolerance`).
_OUTER = [1.0]


@contextmanager
def outer_tolerance(factor: float) -> Iterator[None]:
    """Within it, the outermost level of every nested quadrature asks ``quad`` for ``factor``
    times its usual tolerance (absolute and relative); the inner levels keep theirs.  What a
    quadrature reports as its error is the outermost level's error estimate (plus the allowance
    for the inner levels' unpropagated errors, which is still valid because their tolerances are
    unchanged), so the looser tolerance shows in the error bound: a caller that needs a value
    only to an accuracy it can state (Theorem 8.1's finite differences, :mod:`langur.theorem`)
    spends less, and checks the bound it got.  Results computed inside are remembered apart
    (:data:`_DONE`, and :func:`looseness` for the callers' caches)."""
    before = _OUTER[0]
    _OUTER[0] = float(factor)
    try:
        yield
    finally:
        _OUTER[0] = before


def looseness() -> float:
    """The current factor of :func:`outer_tolerance` (1.0 outside it)."""
    return _OUTER[0]

