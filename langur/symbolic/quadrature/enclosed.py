"""A proof of where a piece's integral lies: ``∫_box Π[cᵢ ≥ 0]·w`` enclosed by outward-rounded
interval arithmetic (paper §8.2's ⟦p⟧ at a point; branch exact32, bench/RESULTS.md).

``quad`` samples an interval at 21 abscissae and estimates its error from two rules that agree:
a peak between the abscissae (``exp(-1e8*(x - 0.3)^2)`` on [0, 1], width 10⁻⁴) is never seen,
both rules say 0, and the exact engine printed ``0 (quadrature, error ≤ 1e-10)`` — an estimate
nothing backs.  What is proved here instead: the box is cut into cells, and on each cell

* a condition whose interval enclosure (:func:`langur.enclosures.enclose`) lies above 0 holds on
  the whole cell, one below 0 on none of it; otherwise the cell is *uncertain*;
* an uncertain cell contributes ``vol · hull(W, 0)``, W the weight's enclosure over the cell;
* a certain cell (every condition holds) contributes the product midpoint rule with its error
  term: ``vol·w(m) + vol/24 · Σᵢ hᵢ² · ∂ᵢ²w(ξᵢ)`` (the one-dimensional rule's remainder
  ``h³/24·w''(ξ)`` applied variable by variable, each ξᵢ somewhere in the cell, so each ∂ᵢ²w is
  replaced by its enclosure over the cell), intersected with ``vol · W``; where a second
  derivative is not enclosed (``Abs``' derivative ``sign``: not enclosed) or not finite, ``vol · W``
  alone.

Every contribution is an interval that contains the cell's integral, so their sum contains the
integral: a proof, whatever the weight does between samples.  The widest contribution is halved
(along the cell's side longest relative to the box) until the enclosure is as narrow as asked or
:data:`CELLS` cells have been enclosed — a count, not a time, so the answer is the same on every
machine.  Nothing is assumed about the integrand: a weight, condition or box end outside
:func:`~langur.enclosures.enclose`'s arithmetic (an implicit root, a ``Piecewise``, ``erfc``…) gives
no proof (None), and neither does one whose enclosure stays infinite (a pole, an integrable
singularity: the enclosure never becomes finite).

Used by :mod:`langur.symbolic.integrate`: a quadrature's error is printed as a bound only when
such a proof backs it, and a closed form that disagrees with its quadrature is kept when the
enclosure holds it and excludes the quadrature.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from typing import Sequence

import mpmath
import sympy as sp

from langur.enclosures import enclose, interval_function
from langur.symbolic.walks import free_symbols

#: Cells enclosed to back a quadrature's error estimate, before the enclosure is given as it is
#: (a count, the same on every machine: about a tenth of a CPU second for a one-variable weight).
CELLS = 300

#: Cells enclosed where a quadrature is in doubt (outside its enclosure, or disagreeing with a
#: closed form): about a CPU second.
CELLS_REFUTED = 3000

#: CPU seconds a proof of ``cells`` cells may take: ``max(1, cells/1000)`` (a cell takes well under a
#: millisecond, but mpmath's interval ``exp`` of a hugely negative interval takes seconds — ``exp(-cosh
#: x)`` on [−10⁶, 10⁶] has ``exp(-e^(10⁶)/2)`` in its first cell, 30 s — and a proof is never worth that:
#: past it there is no proof, and the error is printed as an estimate).
def seconds(cells: int) -> float:
    return max(1.0, cells / 1000)


#: The relative width below which an enclosure of :data:`CELLS` cells is not narrowed further.
CONFIRMS = 1e-2

#: The weight's operation count beyond which no second derivative is taken (their enclosures would
#: cost more than the cells they save); the cells then use ``vol · W`` alone.
SECOND_DERIVATIVE_OPS = 200

_IV = mpmath.iv


@dataclass(frozen=True)
class Enclosed:
    """``lo ≤ ∫ ≤ hi``, proved; ``cells``: how many cells were enclosed."""

    lo: float
    hi: float
    cells: int
    #: the width of the first enclosure, over the whole box at once: the integral's scale
    scale: float = math.inf
    #: the number of variables integrated
    dimensions: int = 1

    def holds(self, value: float, slack: float = 0.0) -> bool:
        """Whether ``value`` is within ``slack`` of the enclosure."""
        return self.lo - slack <= value <= self.hi + slack

    def confirms(self, value: float, slack: float = 0.0) -> bool:
        """Whether ``value`` is within ``slack`` of the enclosure and the enclosure is narrower than
        :data:`CONFIRMS` of its :attr:`scale` (else a narrower one may be worth its cells: ``[0, 8.6]``
        of a scale of 100 holds a quadrature's 0 that missed 31 peaks of
        ``exp(-1e4*sin(x - 37.3)^2)`` on [0, 100])."""
        return self.holds(value, slack) and self.hi - self.lo <= max(slack, CONFIRMS * self.scale)

    def distance(self, value: float) -> float:
        """The largest |value − t| over t in the enclosure: a proved bound on ``value``'s error."""
        return max(value - self.lo, self.hi - value)


def enclose_integral(conditions: Sequence[sp.Expr], weight, variables: Sequence[sp.Symbol], box, at: dict, *,
                     target: float = 0.0, cells: int = CELLS) -> Enclosed | None:
    """An enclosure of ``∫_box Π[c ≥ 0]·weight`` (``c`` in ``conditions``; strict or not makes no
    difference to the integral) at the parameter values ``at`` (symbol → sympy number), narrowed
    until its width is at most ``target`` or ``cells`` cells were enclosed; None when there is no
    proof (module docstring)."""
    variables = tuple(variables)
    try:
        w = sp.sympify(weight).xreplace(at)
        conds = [sp.sympify(c).xreplace(at) for c in conditions]
        ends = [(sp.sympify(lo).xreplace(at), sp.sympify(hi).xreplace(at)) for lo, hi in box]
    except (sp.SympifyError, TypeError, AttributeError):
        return None
    if not variables or any(free_symbols(e) - set(variables) for e in [w, *conds]) or any(
            interval_function(variables[0], e, variables[1:]).refused for e in [w, *conds]):
        return None  # (a symbol without a value; an implicit root, a Piecewise: never enclosed)
    outer = []
    for v, (lo, hi) in zip(variables, ends):
        if free_symbols(lo) | free_symbols(hi):
            return None  # (an end that moves with an outer variable: not a box)
        a, b = _constant(lo), _constant(hi)
        if a is None or b is None or not (mpmath.isfinite(a.a) and mpmath.isfinite(b.b)):
            return None
        if a.b != a.a:
            conds.append(v - lo)  # an end known to an interval: the sliver is uncertain
        if b.b != b.a:
            conds.append(hi - v)
        if not a.a < b.b:
            return Enclosed(0.0, 0.0, 0, 0.0, len(variables))
        outer.append((_down(a.a), _up(b.b)))
    second = ([sp.diff(w, v, 2) for v in variables]
              if sp.count_ops(w) <= SECOND_DERIVATIVE_OPS else None)
    return _refine(conds, w, second, variables, outer, target, cells)


_NONE = sp.Dummy("none")


def _constant(e: sp.Expr):
    """An interval holding the number ``e`` (:func:`~langur.enclosures.enclose` over a box of one
    unused variable: it wants one), or None."""
    return enclose(e, {_NONE: (0.0, 0.0)})


def _refine(conds, w, second, variables, outer, target: float, budget: int) -> Enclosed | None:
    sides = [b - a for a, b in outer]
    heap: list = []
    final: list = []  # contributions of cells that cannot be halved
    count = 0
    total_width = 0.0

    def push(cell):
        nonlocal count, total_width
        count += 1
        part = _cell(conds, w, second, variables, cell)
        if part is None:
            return False
        width = _up(part.b) - _down(part.a)
        total_width += width
        heapq.heappush(heap, (-width, count, cell, part))
        return True

    if not push(tuple(outer)):
        return None
    scale = total_width
    while count < budget and heap and not total_width <= target:
        neg, _, cell, part = heapq.heappop(heap)
        i = max(range(len(cell)), key=lambda k: (cell[k][1] - cell[k][0]) / sides[k])
        a, b = cell[i]
        m = a + (b - a) / 2
        if not a < m < b:  # as narrow as floats go (the sliver of an end 1/3): kept as it is
            final.append(part)
            continue
        total_width += neg
        if not math.isfinite(total_width):  # (recounted: inf − inf)
            total_width = sum(-h[0] for h in heap) + sum(_up(p.b) - _down(p.a) for p in final)
        for half in ((a, m), (m, b)):
            if not push(cell[:i] + (half,) + cell[i + 1:]):
                return None
    total = sum((h[3] for h in heap), sum(final, _IV.mpf(0)))
    if not (mpmath.isfinite(total.a) and mpmath.isfinite(total.b)):
        return None  # (a pole, an integrable singularity: never finite)
    return Enclosed(_down(total.a), _up(total.b), count, scale, len(outer))


def _down(end) -> float:
    """A double at most the interval end ``end`` (mpmath's ends are doubles at its 53 bits, but
    for exponents beyond a double's: one step down covers the conversion's rounding)."""
    return math.nextafter(float(end), -math.inf)


def _up(end) -> float:
    """A double at least ``end`` (:func:`_down`)."""
    return math.nextafter(float(end), math.inf)


def _cell(conds, w, second, variables, cell):
    """An interval holding the cell's integral, or None (the weight not enclosed at all)."""
    box = dict(zip(variables, cell))
    certain = True
    for c in conds:
        z = enclose(c, box)
        if z is None:
            certain = False
        elif z.b < 0:
            return _IV.mpf(0)
        elif not z.a > 0:
            certain = False
    W = enclose(w, box)
    if W is None:
        return None
    vol = _IV.mpf(1)
    for a, b in cell:
        vol *= _IV.mpf(b) - _IV.mpf(a)
    if not certain:
        return vol * _IV.mpf([min(W.a, 0), max(W.b, 0)])
    whole = vol * W
    if second is None or not (mpmath.isfinite(W.a) and mpmath.isfinite(W.b)):
        return whole
    mid = {v: (a + (b - a) / 2,) * 2 for v, (a, b) in box.items()}
    fm = enclose(w, mid)
    rest = _IV.mpf(0)
    for (a, b), d2 in zip(cell, second):
        D = enclose(d2, box)
        if fm is None or D is None or not (mpmath.isfinite(D.a) and mpmath.isfinite(D.b)):
            return whole
        h = _IV.mpf(b) - _IV.mpf(a)
        rest += h * h * D
    rule = vol * fm + vol * rest / 24
    lo, hi = max(rule.a, whole.a), min(rule.b, whole.b)
    return _IV.mpf([lo, hi]) if lo <= hi else whole
