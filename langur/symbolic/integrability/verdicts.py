"""How fast a weight blows up at a point of its singular set, and the verdict (see the package docstring).

* **the exponent**: ``|w(p + t·v)|`` at t = ρ, ρ·10⁻², ρ·10⁻⁴ along directions v into R̄ (50-digit
  evaluation of the whole weight, so a numerator that vanishes there counts: ``x/(x²+y²)`` grows
  like r⁻¹, not r⁻²; ``sin(x)/x`` not at all).  Both slopes must agree (within 0.05), else the
  growth is not a power (oscillation, logarithms): undecided.

Verdicts, with α_max the largest and α_typ the median exponent over the directions tried:
integrable when α_max < c − margin; divergent when α_typ ≥ c − margin (margin 0.01, or 0.1 when
a logarithm is singular at p: ``1/(x·log²x)`` measures α ≈ 0.9 but ``1/(x·log x)`` ≈ 0.95 and
diverges, so near c a logarithm leaves it undecided); otherwise undecided.  An anisotropic zero
(``1/(x + y²)`` at the corner: α = 1 almost everywhere, 2 along the y-axis; it is integrable) is
honestly undecided.
"""

from __future__ import annotations

import math
import statistics
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np
import sympy as sp

from ...memo import remember
from ...precise import DIGITS
from ...precise import value_at as _value
from .region import Region, Undecidable
from .zerosets import Site, pole_bases, sites


class Verdict(Enum):
    INTEGRABLE = "integrable"
    DIVERGENT = "divergent"
    UNDECIDED = "undecided"


@dataclass(frozen=True)
class Blowup:
    """``w`` blows up on a set of codimension ``codim`` in R̄ through ``point`` like dist^-``alpha``."""

    base: sp.Expr  # the pole base g (parameters substituted)
    point: tuple[sp.Expr, ...]  # a point of the singular set (exact numbers, or floats)
    shape: str  # "crossing", "face", "condition", "point" or "unknown"
    codim: int | None
    alpha: float | None  # typical exponent (median over directions)
    alpha_max: float | None
    verdict: Verdict
    square: Verdict  # the same question for w² (a finite variance)
    logarithmic: bool = False
    face: tuple[tuple[int, sp.Expr], ...] = ()  # (variable index, bound) of the face for "face"

def _log_points(w: sp.Expr) -> list[tuple[sp.Expr, float]]:
    """(argument, where it is singular) of each logarithmic function in ``w``: log at 0, atanh at ±1."""
    out = []
    for e in sp.preorder_traversal(w):
        if isinstance(e, sp.log):
            out.append((e.args[0], 0.0))
        elif isinstance(e, (sp.atanh, sp.acoth)):
            out.append((e.args[0], 1.0))
    return out


def growth(w: sp.Expr, xs, p, v: np.ndarray, scale: float) -> float | None:
    """α with |w(p + t·v)| ~ t^-α (None: w vanishes there, or no power law)."""
    logs = []
    for k in (3, 5, 7):
        t = sp.Float(10.0 ** -k * scale, DIGITS)
        q = [pi + t * sp.Float(float(vi), DIGITS) for pi, vi in zip(p, v)]
        val = _value(w, xs, q)
        if not math.isfinite(val):
            return None
        if val == 0:
            return None
        logs.append(math.log10(abs(val)))
    s1, s2 = (logs[1] - logs[0]) / 2, (logs[2] - logs[1]) / 2
    if abs(s1 - s2) > 0.05:
        raise Undecidable("the integrand does not grow like a power there")
    return s2


def _logarithmic(w: sp.Expr, xs, p) -> bool:
    for a, where in _log_points(w):
        v = _value(a, xs, p)
        if not math.isfinite(v) or abs(abs(v) - where) < 1e-30:
            return True
    return False


def decide(alpha_typ: float, alpha_max: float, codim: int, logarithmic: bool) -> Verdict:
    margin = 0.1 if logarithmic else 0.01
    if alpha_max < codim - margin:
        return Verdict.INTEGRABLE
    if alpha_typ >= codim - 0.01 and not (logarithmic and abs(alpha_typ - codim) < 0.1):
        return Verdict.DIVERGENT
    return Verdict.UNDECIDED


def blowups(w: sp.Expr, region: Region) -> list[Blowup]:
    """Every place where ``w`` blows up on R̄, with its verdict."""
    out: list[Blowup] = []
    if region.empty:
        return out
    for g in pole_bases(w, region.xs):
        try:
            found = sites(g, region)
        except Undecidable:
            out.append(Blowup(g, (), "unknown", None, None, None, Verdict.UNDECIDED, Verdict.UNDECIDED))
            continue
        for s in found:
            out.append(_judge(w, g, s, region))
    return out


def _judge(w: sp.Expr, g: sp.Expr, s: Site, region: Region) -> Blowup:
    logarithmic = _logarithmic(w, region.xs, s.point)
    if s.codim is None:
        return Blowup(g, s.point, s.shape, None, None, None, Verdict.UNDECIDED, Verdict.UNDECIDED, logarithmic)
    alphas = []
    try:
        for v in s.directions:
            a = growth(w, region.xs, s.point, v, region.scale)
            if a is not None:
                alphas.append(a)
    except Undecidable:
        return Blowup(g, s.point, s.shape, s.codim, None, None, Verdict.UNDECIDED, Verdict.UNDECIDED,
                      logarithmic, s.face)
    if not alphas:  # w vanishes along every direction tried: no blow-up there
        return Blowup(g, s.point, s.shape, s.codim, 0.0, 0.0, Verdict.INTEGRABLE, Verdict.INTEGRABLE,
                      logarithmic, s.face)
    typ, top = statistics.median(alphas), max(alphas)
    return Blowup(g, s.point, s.shape, s.codim, typ, top, decide(typ, top, s.codim, logarithmic),
                  decide(2 * typ, 2 * top, s.codim, logarithmic), logarithmic, s.face)


#: :func:`blowups_on`'s answers: the linter (X311–X313) and the exact engine (``require_defined``) ask
#: the same questions about a command's program at its point; the second asks this memo.
_FOUND: dict = {}


def blowups_on(w: sp.Expr, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
               conds: Sequence[sp.Expr]) -> list[Blowup]:
    """:func:`blowups` of ``w`` on the region of the box cut by ``conds`` (raises
    :class:`~.region.Undecidable` where the region cannot be described), remembered by its arguments:
    the analysis is deterministic (its random directions are seeded), an interrupted one is not kept."""
    key = (w, tuple(xs), tuple(tuple(side) for side in box), tuple(conds))
    hit = _FOUND.get(key)
    if hit is None:
        hit = remember(_FOUND, key, tuple(blowups(w, Region(xs, box, conds))), 64)
    return list(hit)
