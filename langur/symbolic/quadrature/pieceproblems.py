"""The pieces' front (Def. 6.2's pieces, paper §8.2): each piece ``[conditions] · weight`` as a
:class:`NumProblem` at the evaluation point (Psi's inverse branches as root hints) and its
integral; a piece's result is remembered by the values of the parameters it depends on, so
Theorem 8.1's shifted points reuse it (issue 13).
"""

from __future__ import annotations

from typing import Sequence

import sympy as sp

from langur.memo import remember
from langur.precise import real_number_at
from langur.symbolic.pieces import NOT_FINITE, Piece, Psi
from langur.symbolic.quadrature.compiling import (
    OnFirstCall,
    _lambdify,
    _vectorize,
    substituted,
)
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.problem import NumCond, NumProblem, _level, _parametric
from langur.symbolic.quadrature.tolerance import _OUTER
from langur.symbolic.quadrature.wide import centres, spread
from langur.symbolic.walks import free_symbols, has_any, rational_form


def _psi_hints(psi: Psi | None, v: sp.Symbol, variables, level: int, at: dict):
    """Roots of the condition in ``v`` from Psi's inverse branches (completed Psi only), and
    whether they depend on the outer variables."""
    if psi is None or psi.solved_for != v or not psi.branches:
        return None, True
    others = [x for x in psi.variables if x != v]
    if any(x not in variables[:level] for x in others):
        return None, True
    sub = {psi.inputs[0]: 0}
    sub.update({u: x for u, x in zip(psi.inputs[1:], others)})
    fns = []
    outer = set(variables[:level])
    vary = False
    for b in psi.branches:
        comp = dict(b.inverse)[v].xreplace(sub)
        guards = [g.xreplace(sub) for g in b.guards]
        if any(has_any(sp.sympify(e), NOT_FINITE) for e in [comp, *guards]):
            continue  # no root: Ψ̂⁻¹ is infinite at u₀ = 0 (``(x − a)/(y + 1/2)`` solved for y)
        vary = vary or any(free_symbols(sp.sympify(e)) & outer for e in [comp, *guards])
        fns.append((_lambdify(variables[:level], comp, at), [_lambdify(variables[:level], g, at) for g in guards]))

    def hints(*prefix):
        out = []
        for f, gs in fns:
            for g in gs:
                if not g(*prefix) >= 0:  # (_holds: NaN >= 0 is false)
                    break
            else:
                r = f(*prefix)
                if r == r:  # (not NaN)
                    out.append(r)
        return out

    return hints, vary


def piece_problem(piece: Piece, variables, box, at: dict) -> NumProblem:
    variables = list(variables)
    conds = []
    for c in piece.conditions:
        lv = _level(c.expr, variables)
        hints, vary = _psi_hints(c.psi, variables[lv], variables, lv, at) if lv >= 0 else (None, True)
        expr = sp.sympify(c.expr)
        conds.append(NumCond(_lambdify(variables[: lv + 1], expr, at), lv, hints, substituted(expr, at),
                             sym=_parametric(expr), hints_vary=vary))
    bounds = [(real_number_at(lo, at), real_number_at(hi, at)) for lo, hi in box]
    vweight = _vectorize(variables, piece.weight, at) if variables else None
    if vweight is not None and rational_form(sp.sympify(piece.weight)):
        # compiled at its first call: with the vectorized weight on every innermost interval it is
        # never called (a rational form prints and compiles for math without fail, so nothing is
        # raised later that would have been raised here; the point's values are copied now)
        point = dict(at)
        weight = OnFirstCall(lambda: _lambdify(variables, piece.weight, point))
    else:
        weight = _lambdify(variables, piece.weight, at)
    w = substituted(sp.sympify(piece.weight), at)
    wide = {level: spread(lo, hi, centres(w, v)) for level, (v, (lo, hi)) in enumerate(zip(variables, bounds))}
    return NumProblem(conds, weight, bounds, syms=variables, vweight=vweight,
                      at=dict(at), sbounds=[(sp.sympify(lo), sp.sympify(hi)) for lo, hi in box], spread=wide)


#: Each piece's quadrature ``(value, error, problem)`` by the piece, the variables, the box and the
#: values of the parameters the piece and the box depend on (at most :data:`DONE` kept).  Theorem
#: 8.1's finite differences evaluate ⟦p⟧ at points shifted along one parameter: the pieces that do
#: not depend on it are the same integrals there, and the same deterministic computation would
#: give the same numbers, so they are taken from here instead of being integrated again.
DONE = 256


_DONE: dict = {}


def _symbols_of(obj) -> set:
    """The free symbols of a piece (its conditions, their diffeomorphisms' forward and inverse
    maps and guards, its weight), of a box, or of any tuple of those."""
    if isinstance(obj, sp.Basic):
        return free_symbols(obj)  # (each distinct subtree once: sympy walks the repeats)
    if isinstance(obj, (tuple, list)):
        return set().union(*[_symbols_of(o) for o in obj]) if obj else set()
    if hasattr(obj, "__dataclass_fields__"):
        return set().union(*[_symbols_of(getattr(obj, f)) for f in obj.__dataclass_fields__ if f != "origin"])
    return set()


def _piece_key(piece: Piece, variables, box, at: dict):
    box = tuple((sp.sympify(lo), sp.sympify(hi)) for lo, hi in box)
    used = (_symbols_of(piece) | _symbols_of(box)) - set(variables)
    return (piece, tuple(variables), box,
            tuple(sorted(((str(k), at[k]) for k in at if k in used), key=lambda kv: kv[0])))


def quad_pieces(pieces: Sequence[Piece], variables, box, at: dict,
                notes: list[str] | None = None, problems: list[NumProblem] | None = None) -> tuple[float, float]:
    """Σ ∫_box piece at ``at``: (value, error estimate).  scipy's warnings that did not stop the
    result are appended to ``notes``, the problems integrated to ``problems`` (whether each
    converged); :class:`UndefinedIntegral` when the integral does not exist.  A piece already
    integrated with the same values of the parameters it depends on is not integrated again
    (:data:`DONE`)."""
    val = err = 0.0
    for pc in pieces:
        try:
            key = _piece_key(pc, variables, box, at)
            hit = _DONE.get(key)  # (a value at the usual tolerance serves a looser request too)
            if _OUTER[0] != 1.0:
                key = (key, _OUTER[0])  # a looser value never serves a request at the usual tolerance
                hit = hit or _DONE.get(key)
        except TypeError:  # something unhashable: integrated, not remembered
            key, hit = None, None
        if hit is None:
            prob = piece_problem(pc, variables, box, at)
            v, e = integrate_problem(prob)
            if key is not None:
                remember(_DONE, key, (v, e, prob), DONE)
        else:
            v, e, prob = hit
        val += v
        err += e
        if notes is not None:
            notes.extend(prob.notes)
        if problems is not None:
            problems.append(prob)
    return val, err

