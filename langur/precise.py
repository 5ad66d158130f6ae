"""High-precision evaluation of a sympy expression: the proofs of a numeric fact at an exact point.

Where the exact engine or the linter claims something at a point, a double is not a proof
(``sqrt(2)^2 - 2`` is 4.4e-16 in doubles): the expression is evaluated with :data:`DIGITS`
digits (sympy's ``evalf``, which raises its working precision until that many are right) and
read as a real number.  Used by :mod:`langur.symbolic.definedness` (a point where a primitive's
argument is outside its domain, LANGUAGE.md §1: undefined is said only with a witness),
:mod:`langur.symbolic.integrability` and :mod:`langur.lint.singular` (zeros of a pole base, growth
exponents of a singularity, X311–X313), :mod:`langur.symbolic.readable` (which branch of a
``Min``/``Max``/``Piecewise`` a closed form takes between two breakpoints) and the quadrature
(:mod:`langur.symbolic.quadrature`: the ends of the box and of an implicit root's bracket at the
parameters' values, paper §8.2).  Each of these had its own evaluation (30 digits; a complex value
read as its real part, raised, or NaN), now this one.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence

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


class NotReal(TypeError):
    """:func:`real_number`'s refusal: the expression has no real value there (a ``TypeError``, as
    ``float`` of a complex number raises)."""


def real_number(e) -> float:
    """:func:`real_value`, except that ±∞ (sympy's ``oo``, ``-oo``: an unbounded end) is ±inf, and
    raising :class:`NotReal` where it is NaN otherwise (complex or undefined): for a caller that must
    not go on with a number that is not one (a branch of a ``Min`` chosen by comparing NaN, a bound
    of integration)."""
    v = real_value(e)
    if math.isnan(v):
        s = sp.sympify(e)
        if s is sp.oo or s is sp.S.NegativeInfinity:
            return float(s)
        raise NotReal("not a real number")
    return v


def real_number_at(e, at: Mapping) -> float:
    """:func:`real_number` of ``e`` at the point ``at`` (symbol → value), each value read as a
    double: the values the quadrature's compiled functions are called with
    (:mod:`langur.symbolic.quadrature.compiling`), so that a bound computed here and the integrand
    there see the same point."""
    return real_number(sp.sympify(e).xreplace({k: sp.Float(float(v), DIGITS) for k, v in at.items()}))
