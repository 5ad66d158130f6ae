"""Another completion where a condition's completion degenerates (paper §5.2, Def. 3.4; LANGUAGE.md §6).

A condition over variables is completed to Ψ̂ = (t, the other variables) by isolating one variable
``v`` (:mod:`langur.syntax.diffeo`).  When ``t`` is affine in ``v`` with a coefficient over the
parameters — a triangle's edge function ``(cx − bx)·(y − by) − (cy − by)·(x − bx)`` solved for
``y`` — Ψ̂ is a diffeomorphism only where that coefficient does not vanish (``Diffeo.nonzero``).
Where it vanishes the *condition* need not degenerate: its zero set is still a hypersurface when
``t`` depends on another variable there (at ``bx = cx`` the edge is the vertical line ``x = bx``).
⟦p⟧ does not depend on the variable a completion isolates, and the ⦇p⦈ of two completions agree
wherever both are diffeomorphisms in a neighbourhood of the parameter values (Theorem 8.1 for
each), so at such values the engines are given the completion solved for another variable
(:func:`at_values`).  Only where every completion degenerates is the derivative undefined: that set
is what X306 reports (:func:`degenerate_set`), and X305 at values in it (:func:`alternative` is None).

The alternative completions are tried in a chain: isolate any variable but ``v``, then any but
``v`` and the one that completion isolated, …, as long as the chain's completions degenerate.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import sympy as sp

from ..core import Diffeo, IfDiffeo, Program, Term, free_params, map_children
from ..diagnostics import Span
from ..sympy_bridge import symbol, to_sympy
from ..syntax.completion import complete, diffeo
from ..syntax.support import numeric_box
from .algebra import exact
from .geometry import num


@dataclass(frozen=True)
class Recompleted:
    """One condition given another completion at the parameter values."""

    span: Span | None
    was: str  # the variable its completion isolated
    now: str  # the variable the alternative isolates
    vanishing: str  # the coefficient that vanishes at the values (printed)

    def note(self) -> str:
        where = f"{self.span.line}:{self.span.col}: " if self.span is not None else ""
        return (f"{where}the condition's completion solved for {self.was} divides by {self.vanishing}, "
                f"which vanishes here; it is completed by {self.now} instead (same ⟦p⟧, a diffeomorphism "
                "near these values)")


def vanishing(psi: Diffeo, point: dict[sp.Symbol, sp.Expr]) -> list[sp.Expr]:
    """The terms of ``psi.nonzero`` that vanish at ``point`` (exact parameter values by symbol)."""
    out = []
    for t in psi.nonzero:
        e = to_sympy(t)
        if e.free_symbols <= set(point) and num(e.subs(point)) == 0:
            out.append(e)
    return out


def _chain(psi: Diffeo, box):
    """The alternative completions of ``psi``'s condition, each avoiding the variables isolated
    before it (stops when no variable is left or a completion fails)."""
    if psi.name is not None or psi.solved_for is None:
        return  # a declared diffeo is the user's: it is not replaced
    avoid = {psi.solved_for}
    while True:
        try:
            alt = complete(psi.condition, psi.variables, box, frozenset(avoid))
        except diffeo.CompletionError:
            return
        yield alt
        if alt.solved_for is None or alt.solved_for in avoid:
            return
        avoid.add(alt.solved_for)


def alternative(psi: Diffeo, point: dict[sp.Symbol, sp.Expr], box=()) -> Diffeo | None:
    """A completion of ``psi``'s condition that is a diffeomorphism at ``point`` when ``psi`` is
    not there (a coefficient in ``psi.nonzero`` vanishes), else ``None`` (``psi`` is fine, or every
    completion degenerates at ``point``)."""
    if not vanishing(psi, point):
        return None
    for alt in _chain(psi, box):
        if not vanishing(alt, point):
            return replace(alt, span=psi.span)
    return None


def degenerate_set(psi: Diffeo, box=()) -> list[sp.Expr]:
    """Expressions over the parameters whose common zeros are where every completion of ``psi``'s
    condition in the chain degenerates: one product of ``nonzero`` terms per completion, ``psi``'s
    first.  Empty when some completion never degenerates (no ``nonzero`` terms)."""
    out = [sp.Mul(*(to_sympy(t) for t in psi.nonzero))] if psi.nonzero else []
    if not out:
        return []
    for alt in _chain(psi, box):
        if not alt.nonzero:
            return []
        out.append(sp.Mul(*(to_sympy(t) for t in alt.nonzero)))
    return out


def at_values(program: Program, values) -> tuple[Program, tuple[Recompleted, ...]]:
    """``program`` with each completed condition that degenerates at ``values`` (parameter name →
    number) given a completion that does not, when one exists; and what was replaced."""
    point = {symbol(k): exact(v) for k, v in values.items()}
    box = numeric_box(program.variables, program.box)
    done: dict[int, Term] = {}
    changes: list[Recompleted] = []

    def go(t: Term) -> Term:
        key = id(t)
        if key in done:
            return done[key]
        u = map_children(t, go)
        if isinstance(u, IfDiffeo) and u.psi.nonzero and free_params(u.psi.condition) <= values.keys():
            alt = alternative(u.psi, point, box)
            if alt is not None:
                coefficient = " · ".join(sp.sstr(e) for e in vanishing(u.psi, point))
                changes.append(Recompleted(u.psi.span, u.psi.solved_for, alt.solved_for, coefficient))
                u = replace(u, psi=alt)
        done[key] = u
        return u

    integrand = go(program.integrand)
    if not changes:
        return program, ()
    return replace(program, integrand=integrand), tuple(changes)
