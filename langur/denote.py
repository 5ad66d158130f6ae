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

from . import lazy, observe
from .core import IfDiffeo, IfGe0, Program, refusals_located, subterms
from .memo import remember
from .symbolic import local
from .symbolic.decompose import Ctx, decided_cell, decompose, smooth_value
from .symbolic.pieces import Integral, Method
from .sympy_bridge import at_symbols, denote, symbol, symbols
from .timebox import Deadline
from .values import check_values

#: scipy (0.3 s) only when integrating: read for its :func:`~langur.symbolic.quadrature.looseness`
quadrature = lazy.module("langur.symbolic.quadrature")
#: only when integrating (``langur check`` reads :func:`program_box` here and needs it not)
definedness = lazy.module("langur.symbolic.definedness")
#: only when an integrand applies a primitive or power defined on part of ℝ (none blows up otherwise)
integrability = lazy.module("langur.symbolic.integrability")

__all__ = ["denote", "denote_program", "program_box", "symbol"]


def program_box(program: Program, ctx: Ctx) -> tuple[tuple[sp.Expr, sp.Expr], ...]:
    """The program's bounding box as sympy (lo, hi) pairs in the parameters."""
    return tuple((smooth_value(lo, ctx), smooth_value(hi, ctx)) for lo, hi in program.box)


def point_free(program: Program) -> bool:
    """Whether ``program`` has no variable-free conditional (``ifge0``) anywhere — its body, its
    box, the terms of its diffeomorphisms (components, inverse branches, guards, non-zero terms):
    then neither ⟦t⟧'s decomposition (:func:`~langur.symbolic.decompose.decompose`) nor ⦇t⦈'s
    normal form depends on the evaluation point, which they read only to decide such a
    conditional (``select``).  Remembered by program."""
    hit = _POINT_FREE.get(program)
    if hit is None:
        terms = [program.body] + [t for pair in program.box for t in pair]
        seen: set[int] = set()
        hit = True
        while terms and hit:
            for u in subterms(terms.pop()):
                if id(u) in seen:
                    continue
                seen.add(id(u))
                if isinstance(u, IfGe0):
                    hit = False
                    break
                if isinstance(u, IfDiffeo):
                    psi = u.psi
                    terms += list(psi.forward) + list(psi.nonzero) + [
                        t for b in psi.branches for t in tuple(b.components) + tuple(b.guards)]
        remember(_POINT_FREE, program, hit, 64)
    return hit


#: :func:`point_free`'s answers by program, and the decompositions of point-free programs by
#: the program's identity (with the program).
_POINT_FREE: dict = {}
_DECOMPOSED: dict = {}


def _decomposed(program: Program, ctx: Ctx) -> list:
    """``decompose(program.body, ctx)``, remembered by program when it is :func:`point_free` (the
    same pieces at every point: Theorem 8.1's finite differences decompose the program at four
    shifted points, the check's ⟦p⟧ near the point once more)."""
    if not point_free(program) or observe.watched():
        # (nor while the rules are observed — a campaign's rule coverage counts each application of
        # decompose's — which must see the same ones as without this memo)
        return decompose(program.body, ctx)
    # by identity (the entry keeps the program alive): pieces carry their conditionals' spans,
    # which program equality ignores
    hit = _DECOMPOSED.get(id(program))
    if hit is not None and hit[0] is program:
        return list(hit[1])
    out = decompose(program.body, ctx)
    remember(_DECOMPOSED, id(program), (program, out), 16)
    return list(out)


#: Whether a program applies a primitive defined on part of ℝ only, by program.
_PARTIAL: dict = {}


def _partial(program: Program) -> bool:
    """Whether the integrand applies a primitive or power defined on part of ℝ only (remembered)."""
    partial = _PARTIAL.get(program)
    return remember(_PARTIAL, program, definedness.has_partial(program.body), 64) if partial is None else partial


def undefined_where(program: Program, ctx: Ctx) -> definedness.Undefined | None:
    """A primitive of the integrand evaluated outside its domain on a set of positive measure of the
    box at ``ctx.at`` (LANGUAGE.md §1, §3: ``[x >= 0] * log(x)`` on [−1, 1]), which the
    decomposition's pieces cannot show (:mod:`langur.symbolic.definedness`), or None."""
    return definedness.undefined_part(program.body, ctx, program.variables, program_box(program, ctx)) \
        if _partial(program) else None


def divergent_where(program: Program, ctx: Ctx, pieces: list | None = None,
                    what: str = "the integrand") -> integrability.Divergent | None:
    """Where ⟦t⟧ (or the ``pieces`` of ``what``: ⦇t⦈'s regular part) blows up at ``ctx.at`` too fast to
    be integrable on the box (a principal value such as ∫₀¹ 1/t − 1/(1 − t) is no integral;
    :mod:`langur.symbolic.integrability`), or None; only a primitive or power defined on part of ℝ
    can blow up, and only a derivative of one."""
    if not _partial(program):
        return None
    return integrability.divergence(_decomposed(program, ctx) if pieces is None else pieces, symbols(program.variables),
                                    program_box(program, ctx), ctx.at or {}, what)


def divergent_delta(program: Program, ctx: Ctx, deltas: list) -> integrability.Divergent | None:
    """The first of ⦇t⦈'s delta terms (``deltas``, Theorem 7.1) whose weight is not integrable on its zero
    set at ``ctx.at`` (:mod:`langur.symbolic.integrability.deltas`), or None; gated as :func:`divergent_where`."""
    if not _partial(program):
        return None
    return integrability.delta_divergence(deltas, symbols(program.variables), program_box(program, ctx), ctx.at or {})


def require_defined(program: Program, ctx: Ctx, regular: list | None = None, deltas: list | None = None) -> None:
    """Raise :class:`~langur.symbolic.quadrature.UndefinedIntegral` where :func:`undefined_where`
    finds a part of the box on which the integrand is undefined, or :func:`divergent_where` a
    blow-up it is not integrable at: ⟦p⟧ does not exist, nor does ⦇p⦈; with ``regular`` (⦇t⦈'s
    regular part, Theorem 7.1), also where that is not integrable, and with ``deltas`` (its delta
    terms) where one's weight is not integrable on its zero set: ⦇p⦈ does not exist."""
    bad = undefined_where(program, ctx) or divergent_where(program, ctx) or \
        (divergent_where(program, ctx, regular, "the regular part of ⦇t⦈") if regular else None) or \
        (divergent_delta(program, ctx, deltas) if deltas else None)
    if bad is not None:
        raise quadrature.UndefinedIntegral(bad.reason)


def zero_integral() -> Integral:
    return Integral(sp.Integer(0), 0.0, Method.CLOSED_FORM, 0.0, 0.0)


#: The last few results of :func:`denote_program` by (program, point, symbolic), with the time
#: they had: ⟦p⟧ at the parameters is asked for by ``langur eval`` and again by each partial
#: derivative's Theorem 8.1 check in the same process (``langur deriv``, ``langur fuzz``).
REMEMBERED = 16
_remembered: dict = {}


@refusals_located
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
    pieces = _decomposed(program, ctx)
    if not pieces:
        require_defined(program, ctx)
        return zero_integral()
    with local.cell_forms() if near else nullcontext():
        out = integrate_pieces(pieces, symbols(program.variables), program_box(program, ctx), point,
                               timeout=timeout, cell=decided_cell(program.body, ctx), symbolic=symbolic,
                               proofs=not near)  # (Theorem 8.1's check wants the form, not a proof of the value)
    require_defined(program, ctx)  # (after: where the pieces show it, the integrator's words)
    remember(_remembered, key, (replace(out, notes=list(out.notes)), time_left), REMEMBERED)
    return out
