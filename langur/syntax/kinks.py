"""Pieces of a condition split at its kinks whose variables cancel (issue 18; LANGUAGE.md §6).

The desugarer splits a condition with ``abs``, ``min`` or ``max`` over the variables at each kink
(``Desugarer.conditional``).  On a piece the variables may cancel: ``[abs(x) + abs(x - 1) <= a]``
between its kinks 0 and 1 is ``[x + (1 - x) <= a]``, i.e. ``[1 <= a]``, the flat bottom of the
function.  Such a piece is no diffeomorphic condition (nothing can be solved for), but it is a
plain conditional on the parameters (Fig. 6, conditional): :func:`cancelled` writes it without the
variables, so that it is desugared to ``ifge0`` like any condition over the parameters.  Only
affine pieces with rational coefficients are recognised (:func:`langur.syntax.affine.linear`, no
sympy), which is what splitting affine arguments of ``abs``/``min``/``max`` gives.
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

from ..core import Add, Const, Mul, Param, Term, free_vars
from . import affine


def cancelled(cond: Term) -> Term:
    """``cond`` written over the parameters alone when its variables cancel (an affine form whose
    variable coefficients are all 0), else ``cond`` itself."""
    if not free_vars(cond):
        return cond
    form = affine.linear(cond)
    if form is None or any(kind == "v" for kind, _ in form[0]):
        return cond
    coeffs, constant = form
    out: Term = Const(Fraction(constant))
    for (_, name), c in sorted(coeffs.items()):  # parameters only: the variables cancelled
        out = Add(out, Param(name) if c == 1 else Mul(Const(c), Param(name)))
    return replace(out, span=getattr(cond, "span", None))
