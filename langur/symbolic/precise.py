"""High-precision evaluation of a sympy expression: the proofs of a numeric fact at an exact point.

Where the exact engine or the linter claims something at a point, a double is not a proof
(``sqrt(2)^2 - 2`` is 4.4e-16 in doubles): the expression is evaluated with :data:`DIGITS`
digits (sympy's ``evalf``, which raises its working precision until that many are right) and
read as a real number.  Used by :mod:`langur.symbolic.definedness` (a point where a primitive's
argument is outside its domain, LANGUAGE.md §1: undefined is said only with a witness) and
:mod:`langur.symbolic.integrability` (zeros of a pole base, growth exponents of a singularity, X311–X313).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Sequence

import sympy as sp

#: Digits of the high-precision evaluations.
DIGITS = 50
#: Largest imaginary part, relative to the real one (at least 1), still read as the rounding of a real value.
IMAGINARY = sp.Float("1e-30")


def real_value(e) -> float:
    """``e``'s real value with :data:`DIGITS` digits as a double (NaN when complex beyond
    :data:`IMAGINARY`, undefined or infinite; a finite value beyond the range of doubles,
    ``10^400 · x``, is clamped to the largest double: it is defined)."""
    try:
        re, im = sp.sympify(e).evalf(DIGITS).as_real_imag()
        if not (re.is_Number and im.is_Number and re.is_finite and im.is_finite):
            return math.nan
        if abs(im) > IMAGINARY * max(1, abs(re)):
            return math.nan
        return max(-sys.float_info.max, min(sys.float_info.max, float(re)))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError, AttributeError):
        return math.nan


def value_at(e: sp.Expr, xs: Sequence[sp.Symbol], p: Sequence) -> float:
    """:func:`real_value` of ``e`` at the point ``xs = p`` (a coordinate that is a double is read
    as a :data:`DIGITS`-digit number; a sympy one exactly)."""
    return real_value(e.xreplace({x: sp.Float(v, DIGITS) if not isinstance(v, sp.Basic) else v
                                  for x, v in zip(xs, p)}))
