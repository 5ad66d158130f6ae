"""A weight certainly finite on the whole closed box: nothing for :mod:`.zerosets` to look for on any region
of it (the integral of such a piece exists, Prop. 7.1's "locally integrable" holds)."""

from __future__ import annotations

import functools
from collections.abc import Sequence

import sympy as sp

from ...sympy_bridge import DOMAINS

#: The sympy functions of the primitives defined and finite on all of ℝ (exp, sin, cos, tanh, atan, erf).
_EVERYWHERE = tuple(f for f, dom in DOMAINS.items() if dom.everywhere)

#: Largest degree of a pole base whose real roots :func:`_zero_free` counts exactly.
ZERO_FREE_DEGREE = 20


def finite_on_box(w: sp.Expr, xs: Sequence[sp.Symbol], box: tuple[tuple[sp.Expr, sp.Expr], ...]) -> bool:
    """Is ``w`` certainly defined and finite on the whole closed box?  Built of the variables,
    finite real numbers, +, ·, integer powers and the primitives defined on all of ℝ, with every
    negative power's base free of zeros on the box (:func:`_zero_free`, exact).  Then
    :func:`blowups` has nothing to find on any region inside the box (no pole base vanishes
    there, no partial primitive is applied): a caller need not build the regions of a sum of 10⁴
    pieces ``[x ≥ c_k] / (x + 1)``.  False says nothing.

    Not :func:`langur.enclosures.enclose`'s whitelist (``_enclosable``), although both walk "built of
    the variables, finite numbers, +, · and powers": that one says interval arithmetic is *sound* for
    an expression, not that the expression is finite — ``1/x`` and ``log(x)`` are enclosed, their
    enclosures over [0, 1] infinite — and an enclosure can be too wide to prove a pole base free of
    zeros (``x² − 2x + 1.0001`` over [0, 2] encloses [−2.9999, 5.0001] ∋ 0), which Sturm's count here
    decides exactly.  Finite on a box is a property of ``w``; enclosable, of the arithmetic."""
    xs = tuple(xs)
    for n in sp.preorder_traversal(w):
        if n.is_Symbol:
            if n not in xs:
                return False
        elif n.is_Number:
            if n.is_finite is not True:
                return False
        elif n.is_Pow:
            if not n.exp.is_Integer or (n.exp < 0 and not _zero_free(n.base, xs, box)):
                return False
        elif not (n.is_Add or n.is_Mul or n.is_NumberSymbol or isinstance(n, _EVERYWHERE)):
            return False
    return True


@functools.lru_cache(maxsize=4096)  # one pole base, many regions
def _zero_free(g: sp.Expr, xs: tuple, box: tuple) -> bool:
    """Has ``g`` no zero on the closed box?  Decided exactly for a polynomial in one variable with
    rational coefficients, of degree at most :data:`ZERO_FREE_DEGREE`, on a side with rational
    ends (Sturm's count of its real roots there: 0); a nonzero finite number has none; anything
    else: False (not known)."""
    free = g.free_symbols
    if not free:
        return bool(g.is_Number and g.is_finite and g != 0)
    if len(free) != 1 or not free <= set(xs):
        return False
    (x,) = free
    lo, hi = box[xs.index(x)]
    if not (lo.is_Rational and hi.is_Rational and lo <= hi):
        return False
    try:
        p = sp.Poly(g, x)
    except sp.PolynomialError:
        return False
    if p.domain not in (sp.ZZ, sp.QQ) or p.degree() > ZERO_FREE_DEGREE:
        return False
    return p.count_roots(lo, hi) == 0

