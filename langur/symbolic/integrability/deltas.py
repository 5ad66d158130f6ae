"""⦇t⦈'s delta terms on their zero sets: where a delta term's weight is not integrable (X313's delta half).

⦇p⦈ = ∫ ⦇t⦈ (Fig. 8, Theorem 7.1) exists only when every delta term δ(π₀Ψ̂)·h has a weight h that is
integrable on the zero set of π₀Ψ̂: the delta's sifting property integrates h over that set (LANGUAGE.md
§4, the change of variables through Ψ̂⁻¹).  ``if x >= a then 1 / sqrt(abs(x - 1/2)) else 0`` puts
δ(x − a) on a weight that is infinite at x = a = 1/2; on [0, 1]², ``[y ≥ x + a]`` times
``1/|(x, y)| − 1/|(1 − x, 1 − y)|`` (integrable in ℝ², α = 1 < 2) puts δ on ``1/(√2·x) − 1/(√2·(1 − x))``
along the diagonal at a = 0, a principal value (α = 1 at both ends of a set of dimension 1): no integral.

A delta term is pulled back to its zero set through the inverse branch ``x = Ψ̂_b⁻¹(0, u′)`` when Ψ̂ was
completed by solving for one variable (then u′ are the other variables, their box is the box's, and
the region is cut by the term's conditions, the branch's guards and the box pulled back); in one
variable the weight is evaluated at the root.  The Jacobian ``|det DΨ̂_b⁻¹|`` is left out (its folds,
``1/sqrt`` at the rim of a disk, are integrable) unless it is a polynomial that may vanish and cancel a
pole of the weight (:func:`_vanishing_jacobian`); a declared Ψ̂ in several variables is not analysed.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator, Mapping, Sequence

import sympy as sp

from ...precise import DIGITS
from ...precise import real_value as _num
from .finite import finite_on_box
from .region import Undecidable
from .verdicts import Blowup, Verdict, blowups_on


def delta_blowups(deltas, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
                  at: Mapping[sp.Symbol, sp.Expr]
                  ) -> Iterator[tuple[sp.Expr, tuple[sp.Symbol, ...], list[Blowup]]]:
    """Each delta term's (``DeltaPiece``: ``psi``, ``conditions``, ``weight``) weight at the parameter
    values ``at`` (``box`` already at them), per inverse branch: (the weight, the variables u′ of its zero
    set, its blow-ups there, each at a point of the box in all the variables ``xs``; their codimension
    is the singular set's in the zero set).  In one variable a weight infinite or undefined at the root (inside the box
    and the conditions) is one DIVERGENT blow-up of shape "zero set" (α = ∞, or NaN where undefined)."""
    xs = tuple(xs)
    for d in deltas:
        psi = d.psi
        if psi.solved_for is None and len(xs) > 1:
            continue  # a declared Ψ̂: its other coordinates are not the variables
        for br in psi.branches:
            sub = {psi.inputs[0]: sp.Integer(0)}
            others = [x for x in psi.variables if x != psi.solved_for]
            sub.update(dict(zip(psi.inputs[1:], others)))
            inv = {x: e.xreplace(sub).xreplace(at) for x, e in br.inverse}
            w0 = sp.sympify(d.weight).xreplace(at)
            w = w0.xreplace(inv) * _vanishing_jacobian(psi, br, sub, at, xs)
            conds = [sp.sympify(c.expr).xreplace(at).xreplace(inv) for c in d.conditions]
            conds += [g.xreplace(sub).xreplace(at) for g in br.guards]
            for i, x in enumerate(xs):  # the box, pulled back
                conds += [inv.get(x, x) - box[i][0], box[i][1] - inv.get(x, x)]
            if len(xs) == 1:
                v = _at_root(w)
                if all(_num(c) >= 0 for c in conds) and not math.isfinite(v):
                    yield w0, xs, [Blowup(w0, tuple(inv.values()), "zero set", 0, v, None,
                                          Verdict.DIVERGENT, Verdict.DIVERGENT)]
                continue
            uxs = tuple(x for x in xs if x != psi.solved_for)
            ubox = [box[xs.index(x)] for x in uxs]
            if finite_on_box(w, uxs, tuple(tuple(side) for side in ubox)):
                continue  # nothing blows up on any region of u′'s box
            try:
                found = blowups_on(w, uxs, ubox, conds)
            except Undecidable:
                continue
            yield w, uxs, [_lifted(b, inv, uxs, xs) for b in found]


def _lifted(b: Blowup, inv: Mapping[sp.Symbol, sp.Expr], uxs: tuple, xs: tuple) -> Blowup:
    """A blow-up found in the zero set's variables u′ as a point of the box, in all the variables
    ``xs`` (``x = Ψ̂_b⁻¹(0, u′)``; a face named by its variable's index in ``xs``): what the linter and
    the engine print, ``(x, y) = (1, 1)``, not the u′ coordinates alone under every variable's name."""
    at = {u: sp.sympify(v) for u, v in zip(uxs, b.point)}
    point = tuple(inv.get(x, x).xreplace(at) for x in xs) if len(b.point) == len(uxs) else b.point
    return dataclasses.replace(b, point=point, face=tuple((xs.index(uxs[i]), v) for i, v in b.face))


def _vanishing_jacobian(psi, br, sub: dict, at: Mapping, xs: Sequence[sp.Symbol]) -> sp.Expr:
    """det DΨ̂_b⁻¹ = ∂x_b/∂u₀ on the zero set when it is a nonconstant polynomial in u′ there, else 1.
    A pole of the condition across which it changes sign (``(x − a)/(y + ½)`` solved for ``x``:
    ``x = a + u₀·(y + ½)``) puts a weight ``1/(y + ½)`` on the zero set that the Jacobian ``y + ½``
    cancels: left out, the weight would look non-integrable (a false X313).  Integrability sees
    only the modulus, so the sign does not matter; an unbounded Jacobian (a fold) is left out as before."""
    if psi.solved_for is None or len(xs) == 1:
        return sp.Integer(1)
    comp = dict(br.inverse).get(psi.solved_for)
    if comp is None:
        return sp.Integer(1)
    jac = sp.diff(comp, psi.inputs[0]).xreplace(sub).xreplace(at)
    uxs = tuple(x for x in xs if x != psi.solved_for)
    if not (jac.free_symbols & set(uxs)) or not jac.is_polynomial(*uxs):
        return sp.Integer(1)  # constant (affine completions: nothing changes), or possibly unbounded
    return jac


def _at_root(w: sp.Expr) -> float:
    """The weight's value at the root: a real number, ±∞ (``oo``) where it is infinite, else NaN (0/0,
    ``zoo``, outside a primitive's domain)."""
    v = _num(w)
    if math.isnan(v) and sp.sympify(w).evalf(DIGITS) in (sp.oo, -sp.oo):
        return math.inf
    return v
