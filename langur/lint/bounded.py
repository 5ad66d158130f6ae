"""A bounded integrand: the integral exists, with nothing for the integrability analysis to find.

``langur.lint.singular`` (X311, X312, with sympy) looks for the points where the integrand blows
up.  A term built from constants, variables, parameters (at finite values), sums, products,
non-negative integer powers, powers of nonzero rational constants (``1/i``), primitives defined and continuous on all of ℝ (``exp``, ``sin``,
``atan`` …: ``Domain.everywhere``), conditionals and ``let`` is bounded on the program's compact box
(a continuous function is bounded on a compact set, and a conditional picks one of two bounded
branches): it blows up nowhere, so ⟦p⟧ and the square of its integrand are integrable.  The
analysis would find no blow-up; the commands skip it, and sympy, for such programs (the Monte
Carlo path's start-up, issue 15).  Sympy-free and conservative: anything else answers ``False``.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction

from ..core import Add, Const, IfDiffeo, IfGe0, Let, Mul, Param, Pow, Prim, Program, Term, Var, subterms
from ..primitives import REGISTRY
from ..syntax.affine import rational_value


def bounded(t: Term) -> bool:
    """``t`` is built from bounded pieces only (module docstring); conditions included."""
    for u in subterms(t):
        match u:
            case Const() | Var() | Param() | Add() | Mul() | IfGe0() | Let():
                continue
            case Pow(_, k) if k >= 0 and k.denominator == 1:
                continue
            case Pow(b, k) if _constant_power(b, k):
                continue
            case Prim(op, _) if op in REGISTRY and REGISTRY[op].domain.everywhere:
                continue
            case IfDiffeo(psi, _, _) if all(bounded(f) for f in psi.forward):
                continue
        return False
    return True


def _constant_power(base: Term, k) -> bool:
    """``base ^ k`` is a finite real constant: a rational base, nonzero for an integer ``k < 0``,
    positive for a fractional ``k`` (microbenchmark 1's ``1/i``)."""
    v = rational_value(base)
    return v is not None and (v > 0 or (v != 0 and k.denominator == 1))


def nothing_to_find(program: Program, point: Mapping[str, object]) -> bool:
    """⟦p⟧ exists at ``point`` with a bounded integrand on a rational, non-empty box: the
    integrability analysis (X311/X312) and the empty-domain check (X314) would report nothing."""
    if any(not isinstance(v, (int, float, Fraction)) or v != v or v in (float("inf"), float("-inf"))
           for v in point.values()):
        return False
    for lo, hi in program.box:
        a, b = rational_value(lo), rational_value(hi)
        if a is None or b is None or a > b:
            return False
    return bounded(program.body)
