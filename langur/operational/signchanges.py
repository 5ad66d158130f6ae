"""Certified sign changes of a smooth function of one variable, vectorized (issue 18).

A condition whose turning points move with the parameters is split at the k-th sign change of
``g = ∂f/∂x`` (an indexed :class:`~langur.core.ImplicitRoot`, :mod:`langur.syntax.turning`).
Counting them on a grid of points misses two sign changes in one cell.  Here every cell of a
:data:`GRID`-cell grid of ``[lo, hi]`` is *certified*: an interval enclosure of ``g − target``
over the cell that excludes 0 says it has no zero there; one of ``g' = ∂g/∂x`` (the root's
``slope``) that excludes 0 says ``g`` is strictly monotone there, so it has at most one zero,
which exists iff ``g − target`` changes sign between the cell's ends.  A cell certified by
neither is halved, at most :data:`DEPTH` times; a piece still uncertified then (``g`` and ``g'``
both vanish there: a degenerate turning point, or an enclosure too wide) is refused with
:class:`~langur.core.TooManyRoots`, located at the condition and at the piece.

Every enclosure is that of a *certified* tape of :mod:`langur.operational.interval` (ends rounded
outward, tight ``sin``/``cos``), so "excludes 0" is a proof, and so is the sign of ``g − target``
at a cell's end: it is read from the enclosure of ``g`` at that point, not from ``g`` evaluated
in doubles.  Where that point enclosure contains 0 (a sign change within rounding of the point),
the sign is unknown: the cells on its two sides are monotone (neither excludes 0), and when ``g``
rises (or falls) on both they are one monotone piece, whose sign change is decided by its outer
ends; when it rises on one and falls on the other (``g`` has an extremum there that is 0 within
rounding: a degenerate turning point) the piece is refused.  At the ends of ``[lo, hi]`` an
unknown sign is ``g``'s double value's (a sign change within rounding of an end of the domain
cuts off a piece of that width, which no integral sees).  The exact engine certifies the same way
on its own, with mpmath's interval arithmetic (:mod:`langur.enclosures`).
"""

from __future__ import annotations

import numpy as np

from ..codes import turning_points_uncertified
from ..core import TooManyRoots
from .interval import enclose_all

#: Cells of the grid of ``[lo, hi]`` each certified (the same as the exact engine's).
GRID = 16
#: Halvings of a cell that neither enclosure certifies before the term is refused.
DEPTH = 30


def certified_brackets(value, tape, x: str, target: np.ndarray, lo: np.ndarray, hi: np.ndarray, params: dict,
                       root=None, what: str = "g", others: dict | None = None, lenient: bool = False):
    """The brackets ``(row, a, b)`` (arrays, sorted by row then ``a``) each holding exactly one
    sign change of ``g − target`` for the parameter point ``row``, all of them on ``[lo, hi]``.

    ``value(at, rows)``: ``g`` at the points ``at`` for the parameter rows ``rows`` (1-D arrays);
    ``tape``: ``tape_of([g, g'], certified=True)``; ``target``, ``lo``, ``hi``: one value per row;
    ``params``: name → number or one value per row; a row whose ``hi`` ≤ ``lo`` has none.
    ``others``: the other variables ``g`` mentions (name → one value per row: a condition split
    along ``x`` whose turning points move with them), enclosed as points.

    ``lenient``: a cell still uncertified after :data:`DEPTH` halvings (narrower than 2⁻³⁰ of a
    grid cell) is decided by the signs of ``g − target`` at its ends (doubles) instead of refused.
    That is for turning points that move with the *integration* variables (``others``): two of
    them merge (``3x² − y`` at ``y = 0``) only on a null set of the zero set, which no integral
    sees, and refusing there would refuse every sample that lands on it (a quadrature node, a
    grid's midpoint)."""
    ok = np.flatnonzero(hi > lo)  # an empty interval (a moving end past the other) has none
    rows = np.repeat(ok, GRID)
    cell = np.tile(np.arange(GRID), len(ok))
    width = hi - lo
    a = lo[rows] + width[rows] * (cell / GRID)
    b = np.where(cell == GRID - 1, hi[rows], lo[rows] + width[rows] * ((cell + 1) / GRID))
    kept: list[tuple] = []  # certified cells: (row, a, b, direction) with direction 0 = no zero in it
    others = others or {}
    for depth in range(DEPTH + 1):
        at = _at_rows(params, rows)
        t = target[rows]
        box = {x: (a, b), **{k: (p, p) for k, p in _at_rows(others, rows).items()}}
        with np.errstate(all="ignore"):
            (gl, gh), (dl, dh) = enclose_all(tape, box, at)
            gl, gh, dl, dh = (np.broadcast_to(v, a.shape) for v in (gl, gh, dl, dh))
            free = (gl > t) | (gh < t)  # no zero in the cell (ends rounded outward: a proof)
            rising, falling = ~free & (dl > 0), ~free & ~(dl > 0) & (dh < 0)  # at most one
        done = free | rising | falling
        kept.append((rows[done], a[done], b[done], np.where(rising, 1, np.where(falling, -1, 0))[done]))
        rest = ~done
        if not rest.any():
            break
        if depth == DEPTH:
            if lenient:  # a null set of the other variables: the ends' signs decide (see above)
                kept.append((rows[rest], a[rest], b[rest], np.full(int(rest.sum()), LOOSE)))
                break
            k = int(np.argmax(rest))
            raise _uncertified(what, x, a[k], b[k], root)
        rows, a, b = rows[rest], a[rest], b[rest]
        mid = 0.5 * (a + b)
        rows, a, b = np.concatenate([rows, rows]), np.concatenate([a, mid]), np.concatenate([mid, b])
    r, ca, cb, direction = (np.concatenate(c) for c in zip(*kept))
    order = np.lexsort((ca, r))
    r, ca, cb, direction = r[order], ca[order], cb[order], direction[order]
    return _sign_changes(value, tape, x, target, params, r, ca, cb, direction, root, what, others, lenient)


#: The direction of a cell left uncertified in lenient mode (its ends' signs decide).
LOOSE = 2


def _at_rows(params: dict, rows: np.ndarray) -> dict:
    return {k: (np.asarray(v, dtype=float)[rows] if np.ndim(v) else v) for k, v in params.items()}


def _uncertified(what, x, a, b, root) -> TooManyRoots:
    return TooManyRoots(turning_points_uncertified(what, x, a, b), root)


def _sign_changes(value, tape, x, target, params, r, a, b, direction, root, what, others, lenient):
    """The brackets of the sign changes over the certified cells (sorted by row, then ``a``; they
    tile each row's ``[lo, hi]``): the sign of ``g − target`` at each cell's start and at each
    row's end, from point enclosures; a point of unknown sign joins the monotone cells on its two
    sides (the same direction, else refused); a bracket runs between consecutive points of known
    sign that differ."""
    n = len(r)
    if n == 0:
        empty = np.zeros(0)
        return empty.astype(int), empty, empty
    last = np.r_[r[1:] != r[:-1], True]  # the last cell of its row
    pts = np.concatenate([a, b[last]])  # every cell's start, then each row's end
    prow = np.concatenate([r, r[last]])
    t = target[prow]
    with np.errstate(all="ignore"):
        box = {x: (pts, pts), **{k: (p, p) for k, p in _at_rows(others, prow).items()}}
        (pl, ph), _ = enclose_all(tape, box, _at_rows(params, prow))
        pl, ph = np.broadcast_to(pl, pts.shape), np.broadcast_to(ph, pts.shape)
        sign = np.where(pl > t, 1, np.where(ph < t, -1, 0))
    # the order along each row: the cells' starts, the row's end after its last cell
    where_end = np.flatnonzero(last)
    order = np.concatenate([np.arange(n), where_end + 0.5])
    seq = np.argsort(order, kind="stable")
    pts, prow, sign = pts[seq], prow[seq], sign[seq]
    ends = np.r_[True, prow[1:] != prow[:-1]] | np.r_[prow[1:] != prow[:-1], True]  # lo and hi of a row
    unknown_end = ends & (sign == 0)
    if (direction == LOOSE).any():  # lenient: a point of unknown sign next to a loose cell, its double's sign
        loose = np.r_[direction == LOOSE, np.zeros(len(where_end), dtype=bool)][seq]
        unknown_end |= (sign == 0) & (loose | np.r_[False, loose[:-1]])
    if unknown_end.any():  # within rounding of the domain's end: the double value's sign
        with np.errstate(all="ignore"):
            v = value(pts[unknown_end], prow[unknown_end]) - target[prow[unknown_end]]
        sign[unknown_end] = np.where(v >= 0, 1, -1)
    inner = (sign == 0)  # an interior point: its cells (before, after) are monotone the same way
    if inner.any():
        k = np.flatnonzero(inner)  # in ``seq`` order; point k starts cell k (cells come first)
        before, after = direction[seq[k] - 1], direction[seq[k]]
        bad = (before == 0) | (before != after)
        if bad.any() and lenient:  # an extremum of g − target that is 0 within rounding: a null set
            j = k[bad]
            with np.errstate(all="ignore"):
                sign[j] = np.where(value(pts[j], prow[j]) - target[prow[j]] >= 0, 1, -1)
            inner[j] = False
        elif bad.any():
            j = k[int(np.argmax(bad))]
            raise _uncertified(what, x, pts[j - 1], pts[j + 1], root)
    known = ~inner
    pts, prow, sign = pts[known], prow[known], sign[known]
    change = (prow[1:] == prow[:-1]) & (sign[1:] != sign[:-1])
    return prow[:-1][change], pts[:-1][change], pts[1:][change]
