"""The pieces of an integrand (Def. 6.2), each on its region, and the exact engine's verdict.

The exact engine says "undefined" on a divergent verdict only (never on an undecided one), within
:data:`TIME_LIMIT` CPU seconds per integral; beyond them it claims nothing, and its quadrature's own
diagnostics stand.
"""

from __future__ import annotations

import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass

import sympy as sp

from ...precise import real_value as _num
from ...timebox import Deadline
from .deltas import delta_blowups
from .finite import finite_on_box
from .region import Undecidable
from .verdicts import Blowup, Verdict, blowups_on

#: CPU seconds the exact engine gives the analysis of one integral (beyond: nothing is claimed).
TIME_LIMIT = 5.0


def piece_blowups(pieces, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
                  at: Mapping[sp.Symbol, sp.Expr]) -> Iterator[tuple[sp.Expr, list[Blowup]]]:
    """Each simply decomposable piece's weight (Def. 6.2: ``weight``, ``conditions``) at the parameter
    values ``at`` (``box`` already at them) with its blow-ups on its region, piece by piece.  A piece
    whose weight is constant in the variables or :func:`finite_on_box` is skipped (nothing blows up
    on any region of the box), and so is a region the analysis cannot describe."""
    whole = tuple(tuple(side) for side in box)
    for pc in pieces:
        w = sp.sympify(pc.weight).xreplace(at)
        if not (w.free_symbols & set(xs)) or finite_on_box(w, xs, whole):
            continue
        conds = [sp.sympify(c.expr).xreplace(at) for c in pc.conditions]
        try:
            found = blowups_on(w, xs, box, conds)
        except Undecidable:
            continue
        yield w, found


@dataclass(frozen=True)
class Divergent:
    """``what`` (⟦t⟧, ⦇t⦈'s regular part, or a delta term's weight on its zero set) is not integrable: its
    piece's weight ``weight`` blows up as ``blowup`` says (a divergent verdict), over the variables ``names``."""

    weight: sp.Expr
    blowup: Blowup
    names: tuple[str, ...]
    what: str = "the integrand"

    @property
    def reason(self) -> str:
        b = self.blowup
        pt = ", ".join(_text(v) for v in b.point)
        at = f"({', '.join(self.names)}) = ({pt})" if len(self.names) > 1 else f"{self.names[0]} = {pt}"
        if b.shape == "zero set":  # a delta term in one variable: its weight at the root
            return (f"{self.what} {sp.sstr(self.weight)} is {'not defined' if math.isnan(b.alpha) else 'infinite'} "
                    f"at {at}, where the delta's sifting property evaluates it: the integral does not exist")
        where = f"on the zero set of {sp.sstr(b.base)} (e.g. at {at})" if b.shape == "crossing" else f"at {at}"
        return (f"{self.what} {sp.sstr(self.weight)} is not integrable: it blows up {where} like "
                f"dist^-{b.alpha:.3g} near a set of codimension {b.codim}, and a singularity of order α is "
                "integrable only when α is below that codimension: the integral diverges (a principal value "
                f"or a quadrature that converges to one is not {'⟦p⟧' if self.what == 'the integrand' else '⦇p⦈'})")


def _text(v) -> str:
    f = _num(v)
    return f"{f:.6g}" if math.isfinite(f) else sp.sstr(v)


def divergence(pieces, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
               at: Mapping[sp.Symbol, sp.Expr], what: str = "the integrand") -> Divergent | None:
    """The first blow-up of the ``pieces`` of ``what`` (⟦t⟧'s, or ⦇t⦈'s regular part's, at the
    parameter values ``at``) at which it is not integrable on the box, or None: integrable,
    undecided, or not decided within :data:`TIME_LIMIT` CPU seconds (nothing is claimed then)."""
    ends = [(sp.sympify(lo).xreplace(at), sp.sympify(hi).xreplace(at)) for lo, hi in box]

    def first() -> Divergent | None:
        for w, found in piece_blowups(pieces, tuple(xs), ends, at):
            for b in found:
                if b.verdict is Verdict.DIVERGENT:
                    return Divergent(w, b, tuple(str(x) for x in xs), what)
        return None

    return _within_limit(first)


def delta_divergence(deltas, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
                     at: Mapping[sp.Symbol, sp.Expr]) -> Divergent | None:
    """The first delta term of ⦇t⦈ (``deltas``, at the parameter values ``at``) whose weight is not
    integrable on its zero set (:mod:`.deltas`), or None, as :func:`divergence` decides for pieces."""
    ends = [(sp.sympify(lo).xreplace(at), sp.sympify(hi).xreplace(at)) for lo, hi in box]

    def first() -> Divergent | None:
        for w, _, found in delta_blowups(deltas, tuple(xs), ends, at):
            for b in found:
                if b.verdict is Verdict.DIVERGENT:
                    return Divergent(w, b, tuple(str(x) for x in xs), "the weight of a delta term of ⦇t⦈")
        return None

    return _within_limit(first)


def _within_limit(first) -> Divergent | None:
    """``first()`` within :data:`TIME_LIMIT` CPU seconds; past them, or where the analysis cannot
    evaluate a case, None: nothing is claimed."""
    try:
        return Deadline(TIME_LIMIT).run(first)
    except Exception:  # noqa: BLE001 - time, or a case the analysis cannot evaluate: nothing is claimed
        return None
