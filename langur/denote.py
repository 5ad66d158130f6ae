"""The denotational semantics ⟦p⟧ (paper §6 Fig. 7, §8 Fig. 12) with sympy.

⟦t⟧ itself (Fig. 7) is :func:`langur.sympy_bridge.denote`, the one translation of core terms to
sympy, re-exported here.  ``denote_program(p, at)`` is ⟦int t d(x⃗)⟧(γ) = ∫ ⟦t⟧(ρ, γ) dρ
(Fig. 12) at the parameters ``at``: ⟦t⟧ is decomposed into simply decomposable pieces (Def. 6.2,
``langur.symbolic.decompose``, whose smooth weights are ``denote``'s) and integrated piece by piece
by ``langur.symbolic.integrate`` (never sympy's integrate of a Piecewise), which returns the closed
form in the parameters when it finds one, else quadrature.
"""

from __future__ import annotations

from collections.abc import Mapping
from contextlib import nullcontext
from dataclasses import replace

import sympy as sp

from . import lazy
from .core import Program
from .symbolic import local
from .symbolic.decompose import Ctx, decided_cell, decompose, smooth_value
from .symbolic.pieces import Integral, Method
from .sympy_bridge import at_symbols, denote, symbol, symbols
from .timebox import Deadline
from .values import check_values

#: scipy (0.3 s) only when integrating: read for its :func:`~langur.symbolic.quadrature.looseness`
quadrature = lazy.module("langur.symbolic.quadrature")

__all__ = ["denote", "denote_program", "program_box", "symbol"]


def program_box(program: Program, ctx: Ctx) -> tuple[tuple[sp.Expr, sp.Expr], ...]:
    """The program's bounding box as sympy (lo, hi) pairs in the parameters."""
    return tuple((smooth_value(lo, ctx), smooth_value(hi, ctx)) for lo, hi in program.box)


def zero_integral() -> Integral:
    return Integral(sp.Integer(0), 0.0, Method.CLOSED_FORM, 0.0, 0.0)


#: The last few results of :func:`denote_program` by (program, point, symbolic), with the time
#: they had: ⟦p⟧ at the parameters is asked for by ``langur eval`` and again by each partial
#: derivative's Theorem 8.1 check in the same process (``langur deriv``, ``langur fuzz``).
REMEMBERED = 16
_remembered: dict = {}


def denote_program(program: Program, at: Mapping[str, object] | None = None, *,
                   timeout: float = 20.0, symbolic: bool = True, near: bool = False) -> Integral:
    """⟦int t d(x⃗)⟧(γ) (Fig. 12) at the parameter values ``at`` (name → number; exact decimals
    are read as rationals).  The result's ``expr`` is the closed form in the parameters, valid
    near ``at``, when one was found.  Without ``symbolic`` only the value is wanted: quadrature,
    with its error bound (no closed form sought where it converged).  With ``near`` a closed form
    valid in the parameter cell of ``at`` is enough (2-D affine regions: the polygon decided at
    the point, :func:`langur.symbolic.local.cell_forms`; what Theorem 8.1's check needs).  Raises
    :class:`~langur.values.ParameterError` when ``at`` does not give every parameter of the
    program a finite value."""
    from .symbolic.integrate import integrate_pieces  # scipy: 0.3 s, only when integrating

    check_values(program, at)
    point = at_symbols(at)
    # (a value computed with a looser quadrature, Theorem 8.1's finite differences, kept apart)
    key = (program, frozenset(point.items()), symbolic, near, quadrature.looseness())
    time_left = Deadline(timeout).remaining()  # within an enclosing budget(), perhaps less than timeout
    known, had = _remembered.get(key, (None, 0.0))
    # a closed form is final; a fallback to quadrature is reused only by a call with no more time
    if known is not None and (known.method == Method.CLOSED_FORM or time_left <= had):
        return replace(known, notes=list(known.notes))
    ctx = Ctx(at=point, variables=tuple(program.variables))
    pieces = decompose(program.body, ctx)
    if not pieces:
        return zero_integral()
    with local.cell_forms() if near else nullcontext():
        out = integrate_pieces(pieces, symbols(program.variables), program_box(program, ctx), point,
                               timeout=timeout, cell=decided_cell(program.body, ctx), symbolic=symbolic)
    if len(_remembered) >= REMEMBERED:
        _remembered.pop(next(iter(_remembered)))
    _remembered[key] = (replace(out, notes=list(out.notes)), time_left)
    return out
