"""Exact values and directional derivatives of large rational closed forms (issue 15): a closed
form of rationals, symbols, +, ·, integer powers and ``Abs`` evaluated at a rational point with
integer pairs (Henrici's reduced additions) instead of sympy's nodes, and differentiated along a line
by dual numbers over the rationals.  Theorem 8.1's check (:mod:`langur.theorem`) differentiates the
closed form of ⟦p⟧ that :mod:`langur.symbolic.local` builds for large problems (the stylization
kernel's triangle, §10.3.1; the ray-traced triangle, §10.2), decides the relations of its parameter
cell at the point with :func:`sign_value`, and :mod:`langur.symbolic.context` takes such a form's
value at the point with :func:`float_value`.

Such a form is walked in two ways (:mod:`langur.symbolic.tape`): flattened once into a list of
operations (:class:`~langur.symbolic.tape.Tape`, for the values at a point and the slope along a
tangent) or recursively over its distinct subtrees (:func:`~langur.symbolic.tape.node_walk`).  Each
walk is written once, over an :class:`~langur.symbolic.arithmetic.Arithmetic`: the operations a mode
computes with and the failure it raises where it cannot go on.  The modes are three arithmetics:

* :data:`~langur.symbolic.exactpairs.EXACT`: reduced integer pairs (the exact values: :func:`rational_value`,
  :func:`dual_derivative`);
* :data:`~langur.symbolic.balls.BALLS`: fixed-point intervals that hold the exact value, for its double or its sign with
  less work (:func:`float_value`, :func:`sign_value`, :func:`dual_derivative_float`; the exact
  pairs where a ball cannot decide);
* :func:`~langur.symbolic.residues.residues`: values modulo a prime, which tell sympy expressions apart
  (``local._near_form``'s size certificate, :func:`residue`).
"""

from __future__ import annotations

from fractions import Fraction

import sympy as sp

from langur.symbolic.arithmetic import Arithmetic
from langur.symbolic.balls import BALLS, Uncertain, double, sign
from langur.symbolic.exactpairs import EXACT
from langur.symbolic.residues import NoResidue, residues
from langur.symbolic.tape import NotRational, Tape, point_memo


def rational_value(expr, point: dict):
    """``expr`` at ``point`` (symbols → Rationals) as an exact Fraction, for forms built from
    rationals, symbols, +, ·, integer powers and ``Abs``; None otherwise (or on a division by 0).
    The values of subtrees are remembered per point (:func:`~langur.symbolic.tape.point_memo`): a closed form, the
    relations of its cell and the closed forms of the other partial derivatives share their
    subtrees."""
    try:
        n, d = _value_at(EXACT, expr, point)
        return Fraction(n, d)
    except (NotRational, ZeroDivisionError):
        return None


def dual_derivative(expr, point: dict, tangent: dict):
    """``d/ds expr(point + s·tangent)`` at s = 0 as an exact Fraction, by dual numbers over the
    rationals (one pass over the distinct subtrees): for closed forms built from rationals,
    symbols, +, ·, integer powers and ``Abs`` (away from 0); None otherwise (or where it is not
    differentiable: a division by 0, ``Abs`` at 0).  The form is flattened once into a list of
    operations (:class:`~langur.symbolic.tape.Tape`) and its values at a point computed once (every partial
    derivative's Theorem 8.1 check differentiates the same closed form of ⟦p⟧ at the same
    points); a subtree whose derivative along the line is 0 costs no arithmetic."""
    try:
        n, d = _slope_at(EXACT, expr, point, tangent)
        return Fraction(n, d)
    except (NotRational, ZeroDivisionError):
        return None


def dual_derivative_float(expr, point: dict, tangent: dict) -> float | None:
    """``float(dual_derivative(expr, point, tangent))`` (the same double; None where that is
    None), from balls when they decide it, else from the exact value."""
    return _decided(lambda: double(_slope_at(BALLS, expr, point, tangent)),
                    lambda: dual_derivative(expr, point, tangent), float)


def float_value(expr, point: dict) -> float | None:
    """``float(rational_value(expr, point))`` (the same double; None where that is None), from
    balls when they decide it, else from the exact value."""
    return _decided(lambda: double(_value_at(BALLS, expr, point)), lambda: rational_value(expr, point), float)


def sign_value(expr, point: dict) -> int | None:
    """The sign (−1, 0, 1) of ``rational_value(expr, point)`` (None where that is None), from
    balls when they decide it, else from the exact value."""
    return _decided(lambda: sign(_value_at(BALLS, expr, point)), lambda: rational_value(expr, point),
                    lambda q: (q > 0) - (q < 0))


def residue(e, point: dict, memo: dict, prime: int):
    """``e``'s value at the point modulo ``prime`` (``point``: the symbols' residues; ``memo``: the
    residues of subtrees already walked, the caller's) for a form of rationals, symbols, +, · and
    integer powers; None for anything else, a symbol without a residue, or where a denominator is
    divisible by the prime.  Equal expressions have equal residues (a ring homomorphism)."""
    try:
        return residues(prime).value_of(e, memo, point)
    except (NotRational, NoResidue):
        return None


def _decided(by_balls, exact, of_exact):
    """``by_balls()`` when the balls decide it; None for a form that is not rational; else
    ``of_exact`` of the exact value ``exact()`` (None where that is None)."""
    try:
        return by_balls()
    except NotRational:
        return None
    except Uncertain:
        pass
    value = exact()
    return None if value is None else of_exact(value)


def _value_at(arith: Arithmetic, expr, point: dict):
    """``expr`` at ``point`` in ``arith`` (the values of subtrees remembered per point)."""
    return arith.value_of(sp.sympify(expr), point_memo(arith, point), point)


def _slope_at(arith: Arithmetic, expr, point: dict, tangent: dict):
    """The derivative of ``expr`` along ``tangent`` at ``point`` in ``arith`` (:meth:`Tape.slope`)."""
    tape = Tape.of(sp.sympify(expr))
    return tape.slope(tape.values(point, arith), tangent, arith)


__all__ = ["dual_derivative", "dual_derivative_float", "float_value", "rational_value", "residue", "sign_value"]
