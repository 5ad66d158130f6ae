"""Exact folding of the arithmetic the desugarer writes out: no ``x * 1``, ``1 * -a``, ``y * 0``,
``t + 0`` or ``t - 0`` in core terms (fold31).

The sugar of LANGUAGE.md §6 writes arithmetic out: a comparison ``[t >= 0]`` is the condition
``t − 0``, a domain ``[0, 1]`` the indicator ``[x − 0 ≥ 0]``, a loop's copy ``x * i`` at i = 1 is
``x * 1`` (§9), ``dot((x, y, 0), (a, 1, 0))`` is ``x·a + y·1 + 0·0``.  These constructors build the
same sums and products with the identities folded where they are exact for Langur's semantics
(§4, Fig. 7: ⟦t⟧ is a partial function, undefined where a primitive or a negative power is):

* ``t + 0``, ``0 + t``, ``t − 0`` are ``t``; ``0 − t`` is ``−t``; ``−0`` is ``0``, ``−1`` is ``−1``;
* ``−(−s)`` is ``s`` and ``t − (−s)`` is ``t + s``: (−1)·(−1)·v = v wherever v is defined, and ``s``
  is undefined where ``−s`` is (diag32); so are ``−(−1)`` ``1`` and ``t − (−1)`` ``t + 1``;
* ``t · 1``, ``1 · t`` and ``t ^ 1`` are ``t``, ``1 ^ k`` is ``1`` (but ``1 · s ^ −1`` stays: ``1 / s``);
* ``t · 0`` and ``0 · t`` are ``0`` only where ⟦t⟧ is defined everywhere (:func:`defined_everywhere`):
  ``0 · (1/x)`` is undefined at x = 0 and stays as written; so is ``t ^ 0`` ``1``, and ``0 / c`` ``0``
  for a constant ``c ≠ 0``;
* ``t / 1`` is ``t``.

Only a constant written ``0``, ``1`` or ``−1`` (a literal, a loop's index at −1, 0 or 1, a vector's
component) folds, and the one other thing asked of a constant is whether it is 0 (never its sign); no
other constant arithmetic is done, so a loop's copies at any other index have the shape of the first
(``syntax/template.py``: the copies at −1, 0 and 1 are desugared on their own, ``syntax/unrolling.py``).  A ``1 / s`` the user wrote stays ``1 / s`` (``·`` of ``s ^ −1``, the
printer's ``/``).  Spans: a folded node is its kept operand, with that operand's span.
"""

from __future__ import annotations

from fractions import Fraction

from ..core import (
    INT_FRACTIONS,
    MINUS_ONE,
    Add,
    Call,
    Const,
    IfDiffeo,
    ImplicitRoot,
    Mul,
    Pow,
    Prim,
    Term,
    map_children_kept,
    subterms,
)
from ..diagnostics import Span
from ..primitives import REGISTRY

_ZERO, _ONE = INT_FRACTIONS[0], INT_FRACTIONS[1]


def is_zero(t: Term) -> bool:
    """``t`` is the constant 0 (a literal's is ``INT_FRACTIONS[0]``: one identity test)."""
    return type(t) is Const and (t.value is _ZERO or type(t.value) is Fraction and not t.value)


def is_one(t: Term) -> bool:
    """``t`` is the constant 1 (compared with the int 1: Fraction's fast path)."""
    return type(t) is Const and (t.value is _ONE or type(t.value) is Fraction and t.value == 1)


def is_minus_one(t: Term) -> bool:
    """``t`` is the constant −1 (a negation's factor, a literal ``-1``, a loop's index at −1)."""
    return type(t) is Const and (t.value is MINUS_ONE or type(t.value) is Fraction and t.value == -1)


def negand(t: Term) -> Term | None:
    """``s`` when ``t`` is the negation ``−s`` — ``(−1)·s`` or, for ``s = 1``, the constant −1 (as
    :func:`negated` builds them) — else None."""
    if type(t) is Mul and is_minus_one(t.left):
        return t.right
    if is_minus_one(t):
        return Const(_ONE, t.span)
    return None


def defined_everywhere(t: Term) -> bool:
    """⟦t⟧ is defined at every point of ℝⁿ and every parameter value: no negative or fractional
    power, no primitive with a restricted domain (``Domain.everywhere``), no call or implicit root
    (a def's body is not known here; a root is undefined outside its bracket); a conditional's
    condition counts too (its π₀Ψ̂ is evaluated; a diffeo's own terms are no children, so it is
    walked on its own)."""
    for u in subterms(t):
        tu = type(u)
        if tu is Pow:
            k = u.exponent
            if k.denominator != 1 or k < 0 and not nonzero_constant(u.base):
                return False
        elif tu is Prim:
            if not REGISTRY[u.op].domain.everywhere:
                return False
        elif tu is Call or tu is ImplicitRoot:
            return False
        elif tu is IfDiffeo and not defined_everywhere(u.psi.forward[0]):
            return False
    return True


def nonzero_constant(t: Term) -> bool:
    """``t`` is a rational constant other than 0 (its negative integer powers are defined: ``a / 4``).
    (Not its sign: a loop's copies at indices of both signs share the first copy's shape.)"""
    return type(t) is Const and type(t.value) is Fraction and t.value != 0


def plus(t: Term, s: Term, span: Span | None = None) -> Term:
    """``t + s``; ``t + 0`` and ``0 + s`` fold."""
    if type(s) is Const and is_zero(s):  # (the class first: most operands are no constant)
        return t
    if type(t) is Const and is_zero(t):
        return s
    return Add(t, s, span)


def negated(t: Term, span: Span | None = None) -> Term:
    """``−t``, i.e. ``(−1)·t``; ``−0`` is ``0``, ``−1`` the constant −1 (as ``(−1)·1`` would fold) and
    ``−(−s)`` is ``s``."""
    if is_zero(t):
        return t
    if is_one(t):
        return Const(MINUS_ONE, span)
    s = negand(t)
    if s is not None:
        return s
    return Mul(Const(MINUS_ONE), t, span)


def minus(t: Term, s: Term, span: Span | None = None) -> Term:
    """``t − s``, i.e. ``t + (−1)·s``; ``t − 0`` is ``t``, ``0 − s`` is ``−s``, ``t − (−r)`` is ``t + r``."""
    if type(s) is Const and is_zero(s):
        return t
    if type(t) is Const and is_zero(t):
        return negated(s, span)
    r = negand(s)
    if r is not None:
        return Add(t, r, span)
    return Add(t, Mul(Const(MINUS_ONE), s), span)


def times(t: Term, s: Term, span: Span | None = None) -> Term:
    """``t · s``; a factor 1 folds (but in ``1 · s ^ −1``, which prints as ``1 / s``), a factor 0 absorbs
    the other where that one is defined everywhere, and ``(−1) · (−r)`` is ``r``."""
    if type(s) is Const or type(t) is Const:
        if is_minus_one(t) and negand(s) is not None:
            return negand(s)
        if is_one(s):
            return t
        if is_one(t) and not (type(s) is Pow and s.exponent == -1):
            return s
        if is_zero(s) and defined_everywhere(t):
            return s
        if is_zero(t) and defined_everywhere(s):
            return t
    return Mul(t, s, span)


def divided(t: Term, s: Term, span: Span | None = None) -> Term:
    """``t / s``, i.e. ``t · s ^ −1``; ``t / 1`` is ``t``, ``0 / c`` is ``0`` for a constant ``c ≠ 0``
    (``1 / s`` stays: the printer's ``/``)."""
    if type(s) is Const and (is_one(s) or is_zero(t) and nonzero_constant(s)):
        return t
    return Mul(t, Pow(s, MINUS_ONE, span), span)


def power(t: Term, k: Fraction, span: Span | None = None) -> Term:
    """``t ^ k``; ``t ^ 1`` is ``t``, ``1 ^ k`` is ``1`` (so ``t · 1 ^ −1``, printed ``t / 1``, is ``t``);
    ``t ^ 0`` is ``1`` where ``t`` is defined everywhere (``0 ^ 0`` is 1, as both engines compute it:
    sympy's ``0**0`` and numpy's ``0.0 ** 0``)."""
    if k == 1 or is_one(t):
        return t
    if not k and defined_everywhere(t):
        return Const(_ONE, span)
    return Pow(t, k, span)


def refolded(t: Term) -> Term:
    """``t`` with its sums, products and powers folded as the constructors above build them, for a term
    made by substitution (a declared diffeo's parameter ``k`` given ``1`` in ``k * x - c``); ``t``
    itself, node for node, where nothing folds."""
    done: dict[int, Term] = {}

    def go(u: Term) -> Term:
        found = done.get(id(u))
        if found is not None:
            return found
        tu = type(u)
        if tu is Add or tu is Mul:
            a, b = go(u.left), go(u.right)
            out = plus(a, b, u.span) if tu is Add else times(a, b, u.span)
            if a is u.left and b is u.right and type(out) is tu:
                out = u  # (nothing folded here)
        elif tu is Pow:
            a = go(u.base)
            out = power(a, u.exponent, u.span)
            if a is u.base and type(out) is Pow:
                out = u
        else:
            out = map_children_kept(u, go)
        done[id(u)] = out
        return out

    return go(t)


__all__ = ["defined_everywhere", "divided", "is_minus_one", "is_one", "is_zero", "minus", "negand", "negated",
           "nonzero_constant", "plus", "power", "refolded", "times"]
