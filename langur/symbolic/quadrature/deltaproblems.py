"""The delta pieces' front (paper §7.3, Theorem 7.1; LANGUAGE.md §4): ``∫ h δ(π₀Ψ̂)`` over the box
as one problem over ``u'`` per inverse branch of Ψ̂, with the forward map's Jacobian
``1/|det DΨ̂(x)|`` at ``x = Ψ̂_b⁻¹(0, u')`` (independent of the inverse-map Jacobian the closed form
uses); a branch through an implicit root is a ``folds`` problem.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.memo import remember
from langur.precise import real_number_at, real_value
from langur.symbolic.pieces import DeltaPiece
from langur.symbolic.quadrature.brackets import _implied_by_bracket
from langur.symbolic.quadrature.compiling import COMPILED, _lambdify, substituted
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.problem import NumCond, NumProblem, _level, _parametric
from langur.symbolic.quadrature.wide import spread
from langur.symbolic.walks import free_symbols
from langur.sympy_bridge import magnitude


def _vanishes(expr, syms, bounds, at) -> bool:
    """Numerically zero at a few pseudo-random points of the u' box: each value rounding against
    the size of the terms it is made of (:func:`~langur.sympy_bridge.magnitude`; ``y/10**13`` is a
    condition, not 0)."""
    expr = sp.sympify(expr)
    if expr.is_number:
        return abs(real_value(expr)) < 1e-300
    f = _lambdify(syms, expr, at)
    rng = np.random.default_rng(12345)
    points = [[rng.uniform(lo, hi) for lo, hi in bounds] for _ in range(5)]
    values = [f(*u) for u in points]
    if any(math.isnan(v) or abs(v) > 1e-6 for v in values):
        return False  # (the common answer, without the magnitude's compilation: rounding that large
        # needs terms of size 10¹⁰, and then the condition is taken for nonzero, as it always was)
    scale = _lambdify(syms, magnitude(expr), at)
    return all(abs(v) <= 1e-12 * scale(*u) for v, u in zip(values, points))


def cofactor_det(m: sp.Matrix) -> sp.Expr:
    """det ``m`` by cofactor expansion (:func:`_expansion`), nothing expanded, cancelled or
    simplified."""
    if m.rows != m.cols:
        raise ValueError(f"det of a {m.rows}x{m.cols} matrix")
    return _expansion(lambda i, j: m[i, j], lambda i, j: m[i, j] == 0, list(range(m.rows)), list(range(m.cols)))


def jacobian_det(fs: Sequence, xs: Sequence) -> sp.Expr:
    """det (∂f_i/∂x_j) by cofactor expansion (:func:`_expansion`), an entry known to be 0 where
    ``x_j`` is not in ``f_i``, and only the entries the expansion multiplies differentiated: for
    Ψ̂ = (f, x) that is ∂f/∂y alone.  The forward Jacobian det DΨ̂ is only ever evaluated in floats
    at the quadrature's nodes, so sympy's ``Matrix.det`` (which expands and cancels the products: a
    third of a second for the ray tracer's shader condition) buys nothing here."""
    fs = [sp.sympify(f) for f in fs]
    if len(fs) != len(xs):
        raise ValueError(f"det of a {len(fs)}x{len(xs)} Jacobian")
    free = [free_symbols(f) for f in fs]
    known: dict = {}

    def entry(i, j):
        if (i, j) not in known:
            known[i, j] = sp.diff(fs[i], xs[j])
        return known[i, j]

    return _expansion(entry, lambda i, j: xs[j] not in free[i], list(range(len(fs))), list(range(len(xs))))


def _expansion(entry, zero, rows: list, cols: list) -> sp.Expr:
    """det of the minor (``rows``, ``cols``), expanded along its row with the most entries ``zero``
    says are 0 (the first such row); ``entry(i, j)`` is asked only for the entries multiplied."""
    if len(rows) == 1:
        return entry(rows[0], cols[0])
    k = max(range(len(rows)), key=lambda r: sum(zero(rows[r], j) for j in cols))
    i = rows[k]
    rest = rows[:k] + rows[k + 1:]
    return sp.Add(*[(-1) ** (k + c) * entry(i, j) * _expansion(entry, zero, rest, cols[:c] + cols[c + 1:])
                    for c, j in enumerate(cols) if not zero(i, j)])


#: det DΨ̂ by (forward map, variables): the same Ψ̂ comes back for other partial derivatives.
_FORWARD_DETS: dict = {}


def delta_problems(piece: DeltaPiece, variables, box, at: dict, ubox) -> list[NumProblem]:
    """One problem over ``u'`` per inverse branch (forward-Jacobian form, see module doc).

    ``ubox``: the (lo, hi) bounds of ``u'`` (shared with the closed form: it is only an
    enclosure; the box conditions added here cut it to the right region)."""
    psi = piece.psi
    variables = list(variables)
    missing = [x for x in variables if x not in psi.variables]
    uprime = list(psi.inputs[1:]) + missing
    bounds = [(real_number_at(lo, at), real_number_at(hi, at)) for lo, hi in ubox]
    problems = []
    for b in psi.branches:
        sub = {psi.inputs[0]: sp.Integer(0)}
        inv = {x: e.xreplace(sub) for x, e in b.inverse}
        xs = [inv.get(x, x) for x in variables]
        conds = []
        exprs = [c.expr for c in piece.conditions] + [g.xreplace(sub) for g in b.guards]
        guards_start = len(piece.conditions)
        for i, (lo, hi) in enumerate(box):
            exprs += [variables[i] - lo, hi - variables[i]]
        empty = False
        for k, e in enumerate(exprs):
            if len(uprime) >= 2 and k not in range(guards_start, guards_start + len(b.guards)) \
                    and _implied_by_bracket(e, variables, xs, at):  # (fold section)
                continue
            se = e if guards_start <= k < guards_start + len(b.guards) else e.xreplace(dict(zip(variables, xs)))
            if _vanishes(se, uprime, bounds, at):
                if k < guards_start and piece.conditions[k].strict:
                    empty = True  # [0 > 0] is FALSE: the piece is 0 on this branch of the zero set
                    break
                continue  # vanishes identically on the zero set: 0 >= 0 is TRUE (paper convention)
            lv = _level(se, uprime)
            conds.append(NumCond(_lambdify(uprime[: lv + 1], se, at), lv, None, substituted(se, at), sym=_parametric(se)))
        if empty:
            continue
        problems.append(NumProblem(conds, _Weight(piece, variables, uprime, xs, at), bounds, syms=uprime, at=dict(at),
                                   sbounds=[(sp.sympify(lo), sp.sympify(hi)) for lo, hi in ubox],
                                   folds=any(e.has(ImplicitRootFn) for e in xs),
                                   spread={lv: spread(lo, hi) for lv, (lo, hi) in enumerate(bounds)}))
    return problems


def _forward_det(psi):
    """det DΨ̂ (:func:`jacobian_det`), remembered by (forward map, variables)."""
    jac = _FORWARD_DETS.get((psi.forward, psi.variables))
    if jac is None:  # (only evaluated numerically: the cofactor formula, not sympy's simplifying det)
        jac = jacobian_det(psi.forward, psi.variables)
        remember(_FORWARD_DETS, (psi.forward, psi.variables), jac, COMPILED)
    return jac


class _Weight:
    """A branch's weight ``h(x)/|det DΨ̂(x)|`` at ``x = Ψ̂_b⁻¹(0, u')``, as a function of ``u'``;
    det DΨ̂ and the compiled functions made at its first call: a region the quadrature finds empty
    never calls it (the shader's Ψ̂ of the ray tracer: its derivative and compilation were a
    twentieth of ∂/∂t)."""

    __slots__ = ("piece", "variables", "uprime", "xs", "at", "_fns")

    def __init__(self, piece: DeltaPiece, variables: list, uprime: list, xs: list, at: dict):
        self.piece, self.variables, self.uprime, self.xs, self.at = piece, variables, uprime, xs, at
        self._fns = None

    def __call__(self, *u):
        if self._fns is None:
            self._fns = ([_lambdify(self.uprime, e, self.at) for e in self.xs],
                         _lambdify(self.variables, _forward_det(self.piece.psi), self.at),
                         _lambdify(self.variables, self.piece.weight, self.at))
        x_fns, jac_f, w_f = self._fns
        x = [f(*u) for f in x_fns]
        d = jac_f(*x)
        return w_f(*x) / abs(d) if d != 0 else math.nan  # degenerate: Ψ̂ not invertible here


def quad_delta_pieces(pieces: Sequence[DeltaPiece], variables, box, at: dict, uboxes,
                      notes: list[str] | None = None, problems: list[NumProblem] | None = None
                      ) -> tuple[float, float]:
    """Σ ∫ h δ(π₀Ψ̂) at ``at`` over the box; ``uboxes[i]`` is piece i's ``u'`` box (``notes`` and
    errors as :func:`quad_pieces`)."""
    val = err = 0.0
    for pc, ub in zip(pieces, uboxes):
        for prob in delta_problems(pc, variables, box, at, ub):
            v, e = integrate_problem(prob)
            val += v
            err += e
            if notes is not None:
                notes.extend(prob.notes)
            if problems is not None:
                problems.append(prob)
    return val, err

