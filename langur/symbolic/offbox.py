"""A piece as it is on the box at the evaluation point: its conditions' signs proved there (§6.3, §7.3).

A piece ``Π [cᵢ ≥ 0] · w`` (Def. 6.2) or ``δ(π₀Ψ̂) · Π [cᵢ ≥ 0] · w`` (Theorem 7.1) is integrated over
the program's box.  Where a condition is strictly positive on the whole closed box at the evaluation
point it is 1 there; where it is strictly negative the piece is 0 there; where π₀Ψ̂ has no zero in
the box the delta is 0 there.  :func:`reduced` gives each piece so: None for 0, else without the
conditions that are 1.  The quadrature at the point (:mod:`langur.symbolic.quadrature`, the
cross-check of every closed form and the value where there is none) integrates these: it would find
the same value, but only after following every kink of the conditions over the box (the ray
tracer's pixel: a tenth of a second per piece, bench/history/2026-11-29.md#split32.  The closed forms are
still sought for the pieces as they are (:mod:`langur.symbolic.regions`: in the parameters, for all
parameter values where it can), and checked against these values.

This is what a split into factors' signs (:mod:`langur.syntax.poles`) adds to a program whose moving
pole does not reach the box at the point: raytrace/scene.lgr's depth shader ``[zth − k/(n·d) ≥ 0]`` is
``[n·d ≥ 0] ⊕ [zth·n·d − k ≥ 0]``, and on its pixel ``n·d > 0``: the ``n·d < 0`` branch and the pole's
deltas are 0 there, the condition ``n·d ≥ 0`` is 1.

The decision is a proof: the sign comes from an interval enclosure of the condition over the box,
the parameters at their values (:func:`langur.enclosures.enclose`, outward rounding); a condition it
does not enclose (a primitive it has no interval rule for, a pole in the box, a value off the reals)
is kept as it is.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import mpmath
import sympy as sp

from ..enclosures import enclose
from .pieces import DeltaPiece, Piece


def box_at(boxd: Mapping[sp.Symbol, tuple], at: Mapping) -> dict[sp.Symbol, tuple] | None:
    """The box's ends at the evaluation point (symbol → sympy number) as real numbers, or None (an
    end that is not one: it moves with an outer variable, or a parameter has no value).  The box may
    be empty (an end past the other); each caller decides what that means: nothing decided here,
    an integral of 0 for :func:`langur.symbolic.quadrature.enclosed.enclose_integral`."""
    out = {}
    for v, (lo, hi) in boxd.items():
        lo, hi = sp.sympify(lo).subs(at), sp.sympify(hi).subs(at)
        if not (lo.is_number and hi.is_number and lo.is_real and hi.is_real):
            return None
        out[v] = (lo, hi)
    return out


def sign_on_box(expr: sp.Expr, box: Mapping[sp.Symbol, tuple], at: Mapping) -> int:
    """1 when ``expr > 0`` on the whole closed box at the point ``at`` (symbol → value), −1 when
    ``expr < 0`` there, 0 when not proved either (an enclosure that holds 0, is not finite, or none)."""
    whole = dict(box)
    for s in expr.free_symbols:
        if s not in whole:
            if s not in at:
                return 0
            whole[s] = (at[s], at[s])
    try:
        iv = enclose(expr, whole)
    except (ValueError, TypeError, ZeroDivisionError, OverflowError):
        return 0
    if iv is None or not (mpmath.isfinite(iv.a) and mpmath.isfinite(iv.b)):
        return 0
    return 1 if iv.a > 0 else -1 if iv.b < 0 else 0


def reduced(pieces: Sequence, boxd: Mapping[sp.Symbol, tuple], at: Mapping) -> list:
    """Each of ``pieces`` (regular or delta) as it is on the box near ``at``: None where it is 0
    there, else without its conditions that are 1 there (module doc)."""
    box = box_at(boxd, at)
    if box is None or not all(bool(lo <= hi) for lo, hi in box.values()):
        return list(pieces)  # (not numbers, or an empty box: nothing decided)
    signs: dict[sp.Expr, int] = {}

    def sign(expr) -> int:
        if expr not in signs:
            signs[expr] = sign_on_box(expr, box, at)
        return signs[expr]

    out = []
    for pc in pieces:
        if isinstance(pc, DeltaPiece) and sign(pc.psi.forward[0]) != 0:
            out.append(None)  # π₀Ψ̂ has no zero in the box: the delta is 0 there
            continue
        kept = tuple(c for c in pc.conditions if sign(c.expr) != 1)
        if any(sign(c.expr) == -1 for c in kept):
            out.append(None)  # a condition negative on the whole box: the piece is 0 there
        elif len(kept) < len(pc.conditions):
            out.append(DeltaPiece(pc.psi, kept, pc.weight) if isinstance(pc, DeltaPiece) else Piece(kept, pc.weight))
        else:
            out.append(pc)
    return out


__all__ = ["box_at", "reduced", "sign_on_box"]
