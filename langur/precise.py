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
parameters' values, paper §8.2), and the checks that compare a value at a point: the Theorem 8.1
check (:mod:`langur.theorem`), the linter's tangencies and turning points (:mod:`langur.lint.tangent`)
and the front end's turning points (:mod:`langur.syntax.turning`: the sign of ∂f/∂x between its
zeros, a turning point without a closed form bracketed around its value).  Each of these had its own
evaluation (20, 30 or 40 digits; a complex value read as its real part, raised, or NaN), now this one.
"""

from __future__ import annotations

import math
import sys
from collections.abc import Mapping, Sequence

import sympy as sp

#: Digits of the high-precision evaluations.
DIGITS = 50
#: Digits of the Theorem 8.1 check's evaluations of whole closed forms (:mod:`langur.theorem`): two
#: doubles are compared, and a large form holding implicit roots costs a tenth of a second per
#: evaluation at more (turning.lgr).
FORM_DIGITS = 20
#: Largest imaginary part, relative to the real one (at least 1), still read as the rounding of a real value.
IMAGINARY = sp.Float("1e-30")


def evaluated(e, digits: int = DIGITS) -> sp.Expr:
    """``e`` evaluated by sympy with ``digits`` digits (the one call of ``evalf`` here): a Float, a
    complex number, or what is left where it is not a number; to be put in a larger form once
    (an implicit root, which evalf would otherwise solve again at every precision it tries)."""
    return sp.sympify(e).evalf(digits)


def _real(e) -> sp.Expr | None:
    """``e``'s real value with :data:`DIGITS` digits as a sympy number, or None when it is complex
    beyond :data:`IMAGINARY`, undefined or infinite (the one reading of every function here)."""
    try:
        re, im = evaluated(e).as_real_imag()
        if not (re.is_Number and im.is_Number and re.is_finite and im.is_finite):
            return None
        return None if abs(im) > IMAGINARY * max(1, abs(re)) else re
    except (TypeError, ValueError, ZeroDivisionError, OverflowError, AttributeError):
        return None


def real_value(e) -> float:
    """``e``'s real value with :data:`DIGITS` digits as a double (NaN when complex beyond
    :data:`IMAGINARY`, undefined or infinite; a finite value beyond the range of doubles,
    ``10^400 · x``, is clamped to the largest double: it is defined)."""
    re = _real(e)
    if re is None:
        return math.nan
    try:
        return max(-sys.float_info.max, min(sys.float_info.max, float(re)))
    except (TypeError, ValueError, OverflowError):
        return math.nan


def complex_value(e, digits: int = DIGITS) -> complex:
    """``e``'s value with ``digits`` digits as a complex double (a ``TypeError`` where it is not a
    number: a symbol left, ``zoo``; ``nan`` stays nan): for a caller that reads a modulus, or a real
    part up to its own noise (:func:`langur.symbolic.context.nearly_real`)."""
    return complex(evaluated(e, digits))


def number(e) -> sp.Expr:
    """``e``'s real value as a sympy Float of :data:`DIGITS` digits (not rounded to a double: exact
    comparisons of points, a bracket around a value), ±∞ (``oo``: an unbounded end) as it is, raising
    :class:`NotReal` where :func:`real_value` is NaN otherwise."""
    s = sp.sympify(e)
    if s is sp.oo or s is sp.S.NegativeInfinity:
        return s
    re = _real(s)
    if re is None:
        raise NotReal("not a real number")
    return sp.Float(re, DIGITS)


def sign(e) -> int:
    """The sign (−1, 0, 1) of ``e``'s finite real value with :data:`DIGITS` digits, not rounded to a
    double (10⁻⁴⁰⁰ is positive); :class:`NotReal` where :func:`real_value` is NaN (complex,
    undefined or infinite)."""
    re = _real(e)
    if re is None:
        raise NotReal("not a real number")
    return 1 if re > 0 else -1 if re < 0 else 0


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
