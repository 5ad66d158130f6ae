"""Where a condition is in force: the conditionals it is nested in (paper Fig. 8, nesting; Def. 7.2).

A condition written in a branch of ``ifge0 ⌊Ψ_k⌋ then s else r`` is multiplied by ``[π₀Ψ̂_k ≥ 0]``
(in ``s``) or ``[π₀Ψ̂_k < 0]`` (in ``r``): its delta, and its meetings with other zero sets, only
matter where those outer conditions select its branch.  The kink split of ``abs``/``min``/``max``
(``langur.syntax.desugar``) makes this the common case: ``[abs(x) + abs(y - a) <= 0.5]`` has the
piece ``y - x ≥ 0`` in force only where ``x ≥ 0``, so that the line ``y = x`` passing through the
box's corner (−1, −1) is no meeting of zero sets of the program at all.

:func:`ancestry` maps each occurrence to the sides of the conditionals around it (every path to it,
for a subterm shared after inlining); :func:`in_force` says whether an occurrence can be in force at
a point: ``False`` only when, on every path, some enclosing condition is strictly on the other side.
"""

from __future__ import annotations

from collections.abc import Mapping

import sympy as sp

from ..core import IfDiffeo, Term, children
from .collect import Occurrence
from .geometry import num

#: Paths recorded per conditional (a term shared after inlining has one per use); past it: unknown.
MAX_PATHS = 16
#: Nodes visited in all; past it the analysis gives up (every condition is taken to be in force).
MAX_VISITS = 100_000

#: For each occurrence index, the paths to it: each a tuple of (enclosing occurrence index, +1 in
#: its then-branch / −1 in its else-branch); ``None`` when unknown (in force everywhere).
Ancestry = dict[int, list[tuple[tuple[int, int], ...]] | None]


def ancestry(body: Term, occurrences: list[Occurrence]) -> Ancestry:
    """The enclosing conditionals of each occurrence of ``body`` (see the module docstring)."""
    by_node: dict[int, list[int]] = {}
    for o in occurrences:
        if o.node is not None:
            by_node.setdefault(id(o.node), []).append(o.index)
    paths: dict[int, list[tuple[tuple[int, int], ...]] | None] = {}
    visits = [0]

    def walk(t: Term, stack: tuple[tuple[int, int], ...]) -> None:
        visits[0] += 1
        if visits[0] > MAX_VISITS:
            raise RecursionError
        if isinstance(t, IfDiffeo):
            seen = paths.setdefault(id(t), [])
            if seen is not None:
                if len(seen) >= MAX_PATHS:
                    paths[id(t)] = None
                elif stack not in seen:
                    seen.append(stack)
            ids = by_node.get(id(t), [])
            # a node read in several let contexts is several occurrences: its side is not one thing
            me = ids[0] if len(ids) == 1 else None
            walk(t.psi.forward[0], stack)
            walk(t.then, stack + (((me, 1),) if me is not None else ()))
            walk(t.orelse, stack + (((me, -1),) if me is not None else ()))
            return
        for ch in children(t):
            walk(ch, stack)

    try:
        walk(body, ())
    except RecursionError:
        return {o.index: None for o in occurrences}
    out: Ancestry = {}
    for o in occurrences:
        out[o.index] = paths.get(id(o.node)) if o.node is not None else None
    return out


def in_force(occ: Occurrence, xsol: Mapping[sp.Symbol, sp.Expr], point: Mapping | None,
             occurrences: list[Occurrence], anc: Ancestry) -> bool:
    """Can ``occ`` be in force at the point ``xsol`` (values of the variables, possibly over the
    parameters) at the parameter values ``point``?  False only when on every path to it some
    enclosing condition is strictly on the side that does not select it (a tolerance of 1e-9)."""
    if point is None:
        return True
    found = anc.get(occ.index)
    if not found:  # unknown, or at the top level
        return True
    for path in found:
        if all(_may_select(occurrences[i], side, xsol, point) for i, side in path):
            return True
    return False


def _may_select(h: Occurrence, side: int, xsol, point) -> bool:
    try:
        v = num(h.f.subs(xsol).subs(point))
    except (TypeError, ValueError, AttributeError):
        return True
    if v is None:
        return True
    return v > -1e-9 if side > 0 else v < 1e-9
