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

Enclosures are those of :mod:`langur.operational.interval` (tight ``sin``/``cos``), in doubles:
certified up to the rounding of ``+`` and ``×`` (not directed), which the enclosures of monotone
primitives already widen by two units in the last place.  The exact engine certifies the same
way on its own, with mpmath's interval arithmetic (:mod:`langur.implicit`).
"""

from __future__ import annotations

import numpy as np

from ..core import TooManyRoots
from .interval import enclose_all

#: Cells of the grid of ``[lo, hi]`` each certified (the same as the exact engine's).
GRID = 16
#: Halvings of a cell that neither enclosure certifies before the term is refused.
DEPTH = 30


def certified_brackets(value, tape, x: str, target: np.ndarray, lo: np.ndarray, hi: np.ndarray, params: dict,
                       span=None, what: str = "g"):
    """The brackets ``(row, a, b)`` (arrays, sorted by row then ``a``) each holding exactly one
    sign change of ``g − target`` for the parameter point ``row``, all of them on ``[lo, hi]``.

    ``value(at, rows)``: ``g`` at the points ``at`` for the parameter rows ``rows`` (1-D arrays);
    ``tape``: ``tape_of([g, g'], tight=True)``; ``target``, ``lo``, ``hi``: one value per row;
    ``params``: name → number or one value per row."""
    m = np.size(target)
    rows = np.repeat(np.arange(m), GRID)
    cell = np.tile(np.arange(GRID), m)
    width = hi - lo
    a = lo[rows] + width[rows] * (cell / GRID)
    b = np.where(cell == GRID - 1, hi[rows], lo[rows] + width[rows] * ((cell + 1) / GRID))
    found: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for depth in range(DEPTH + 1):
        at = {k: (np.asarray(v, dtype=float)[rows] if np.ndim(v) else v) for k, v in params.items()}
        t = target[rows]
        with np.errstate(all="ignore"):
            (gl, gh), (dl, dh) = enclose_all(tape, {x: (a, b)}, at)
            gl, gh, dl, dh = (np.broadcast_to(v, a.shape) for v in (gl, gh, dl, dh))
            free = (gl - t > 0) | (gh - t < 0)  # no zero in the cell
            monotone = ~free & ((dl > 0) | (dh < 0))  # at most one
        if monotone.any():
            r, ca, cb, tm = rows[monotone], a[monotone], b[monotone], t[monotone]
            ga, gb = value(ca, r) - tm, value(cb, r) - tm
            change = ((ga >= 0) != (gb >= 0)) & ~np.isnan(ga) & ~np.isnan(gb)
            found.append((r[change], ca[change], cb[change]))
        rest = ~free & ~monotone
        if not rest.any():
            break
        if depth == DEPTH:
            k = int(np.argmax(rest))
            raise TooManyRoots(
                f"cannot certify the turning points (sign changes of {what}) near {x} in "
                f"[{a[k]:.12g}, {b[k]:.12g}] at these parameter values: there {what} and its derivative both "
                f"vanish (a degenerate turning point) or their interval enclosures stay too wide; Langur "
                f"refuses rather than miss one", span)
        rows, a, b = rows[rest], a[rest], b[rest]
        mid = 0.5 * (a + b)
        rows, a, b = np.concatenate([rows, rows]), np.concatenate([a, mid]), np.concatenate([mid, b])
    if not found:
        empty = np.zeros(0)
        return empty.astype(int), empty, empty
    r, ca, cb = (np.concatenate(c) for c in zip(*found))
    order = np.lexsort((ca, r))
    return r[order], ca[order], cb[order]
