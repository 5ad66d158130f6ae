"""Pieces of a condition split at its kinks whose variables cancel (issue 18; LANGUAGE.md §6).

The desugarer splits a condition with ``abs``, ``min`` or ``max`` over the variables at each kink
(``Desugarer.conditional``, in :mod:`langur.syntax.conditionals`).  On a piece the variables may
cancel: ``[abs(x) + abs(x - 1) <= a]``
between its kinks 0 and 1 is ``[x + (1 - x) <= a]``, i.e. ``[1 <= a]``, the flat bottom of the
function.  Such a piece is no diffeomorphic condition (nothing can be solved for), but it is a
plain conditional on the parameters (Fig. 6, conditional): :func:`cancelled` writes it without the
variables, so that it is desugared to ``ifge0`` like any condition over the parameters.  Only
affine pieces with rational coefficients are recognised (:func:`langur.syntax.affine.linear`, no
sympy), which is what splitting affine arguments of ``abs``/``min``/``max`` gives.

Also here, :func:`lattice`: a bracket on a ``min``, ``max`` or ``abs`` as a product or a disjunction
of two simpler brackets, for conditions too large to split at their kinks.
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

from ..core import Const, Mul, Param, Term, free_vars
from . import affine
from .folding import plus
from .printer import print_core
from .surface import Apply, BinOp, Iverson, Logic, Neg, Num, STerm


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
    for (_, name), c in sorted(coeffs.items()):  # parameters only: the variables cancelled (0 + a is a)
        out = plus(out, Param(name) if c == 1 else Mul(Const(c), Param(name)))
    return replace(out, span=getattr(cond, "span", None))


#: The words of the desugarer's refusal of a condition too large to split at its kinks (T207).
TOO_LARGE = "written out it has more than"


def lattice(st: Iverson) -> STerm | None:
    """``[max(A, B) <= s]`` as ``[A <= s & B <= s]``, and alike (or None): a bracket comparing a
    ``min``, ``max`` or ``abs`` with a term, as the conjunction or disjunction of two brackets.

    Pointwise ``max(A, B) ≤ s ⇔ A ≤ s ∧ B ≤ s``, ``min(A, B) ≤ s ⇔ A ≤ s ∨ B ≤ s`` (and ``≥``
    dually), ``abs(t) = max(t, −t)``: ⟦p⟧ is unchanged, and no conditional on the kink's own sign is
    left (the split of ``Desugarer.conditional`` doubles the written-out condition at each nested
    kink: the 4-cube ``[max(max(abs(x), abs(y)), max(abs(z), abs(w))) <= a]`` is a product of 8
    affine conditions instead).  Strict and non-strict comparisons alike (they differ on null sets)."""
    if len(st.ops) != 1:
        return None
    left, right = st.terms
    op = st.ops[0]
    flipped = {"<=": ">=", "<": ">", ">=": "<=", ">": "<", "≤": "≥", "≥": "≤"}
    for side, other, o in ((left, right, op), (right, left, flipped.get(op, op))):
        # a min/max/abs under sums, differences and minus signs is brought alone to one side:
        # [abs(t) - 0.1 <= 0.05] is [abs(t) <= 0.05 + 0.1]
        while _arguments(side) is None:
            if isinstance(side, Neg):
                side, other, o = side.arg, Neg(other, span=other.span), flipped.get(o, o)
            elif isinstance(side, BinOp) and side.op in ("+", "-") and _reaches(side.left):
                side, other = side.left, BinOp("-" if side.op == "+" else "+", other, side.right, span=other.span)
            elif isinstance(side, BinOp) and side.op == "+" and _reaches(side.right):
                side, other = side.right, BinOp("-", other, side.left, span=other.span)
            elif isinstance(side, BinOp) and side.op == "-" and _reaches(side.right):
                side, other, o = side.right, BinOp("-", side.left, other, span=other.span), flipped.get(o, o)
            elif (k := _scaled(side)) is not None:  # 2 * abs(t) <= s is abs(t) <= s / 2
                c, side = k
                other, o = BinOp("/", other, Num(c, span=other.span), span=other.span), o if c > 0 else flipped.get(o, o)
            else:
                break
        parts = _arguments(side)
        if parts is None:
            continue
        name, a, b = parts
        upper = o in ("<=", "<", "≤")  # side ≤ other
        # max ≤ s and min ≥ s are conjunctions; max ≥ s and min ≤ s disjunctions
        both = (name == "max") == upper
        brackets = tuple(Iverson((u, other), (o,), span=st.span) for u in (a, b))
        return Logic("and" if both else "or", brackets, span=st.span)
    return None


def _reaches(t: STerm) -> bool:
    """Does a min/max/abs stand in ``t`` under sums, differences, minus signs and nonzero
    constant factors only?"""
    if _arguments(t) is not None:
        return True
    if isinstance(t, Neg):
        return _reaches(t.arg)
    if (k := _scaled(t)) is not None:
        return _reaches(k[1])
    return isinstance(t, BinOp) and t.op in ("+", "-") and (_reaches(t.left) or _reaches(t.right))


def _scaled(t: STerm) -> tuple[Fraction, STerm] | None:
    """``(c, u)`` for ``c * u``, ``u * c`` or ``u / c`` with a nonzero number ``c``."""
    if isinstance(t, BinOp) and t.op == "*" and isinstance(t.left, Num) and t.left.value:
        return Fraction(t.left.value), t.right
    if isinstance(t, BinOp) and t.op == "*" and isinstance(t.right, Num) and t.right.value:
        return Fraction(t.right.value), t.left
    if isinstance(t, BinOp) and t.op == "/" and isinstance(t.right, Num) and t.right.value:
        return 1 / Fraction(t.right.value), t.left
    return None


def _arguments(t: STerm) -> tuple[str, STerm, STerm] | None:
    """``("max", A, B)`` for ``max(A, B)`` and ``abs(A)`` (``max(A, −A)``), ``("min", A, B)``."""
    if isinstance(t, Apply) and t.name in ("min", "max") and len(t.args) == 2:
        return t.name, t.args[0], t.args[1]
    if isinstance(t, Apply) and t.name == "abs" and len(t.args) == 1:
        return "max", t.args[0], Neg(t.args[0], span=t.span)
    return None


def on_piece(why: str, sides: list[tuple[Term, bool]]) -> str:
    """The reason a piece of a split condition cannot be completed, saying which piece it is."""
    if not sides:
        return why
    where = " and ".join(f"{print_core(c)} {'>=' if holds else '<'} 0" for c, holds in sides)
    return (f"on its piece where {where} (abs, min and max split the condition at their kinks, and "
            f"each piece must be completed on its own): {why}")
