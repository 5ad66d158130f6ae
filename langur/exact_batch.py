"""The exact engine at many parameter points: closed forms evaluated over a whole grid (§10.1).

An image's pixels differ only in their parameters.  Where ⟦p⟧ (and ⦇p⦈) have a closed form in
the parameters, it is derived once and evaluated at every point of its parameter cell at once
(``sympy.lambdify`` to numpy); a point outside every cell found so far gets a derivation of its own
(its cell then covers its neighbours).  A point where the engine finds no closed form is
integrated on its own (quadrature, with its error bound).  So an exact image costs one derivation
per parameter cell the grid meets, and can be checked against the Monte Carlo image
(:func:`langur.operational.batch.estimate_batch`).

A cell's closed form holds where ⟦p⟧ exists: a point of the cell where it is not a finite real
number (``sqrt(x - a)`` on [0, 1], its form ``2/3·((1 − a)^(3/2) − (−a)^(3/2))`` at a > 0, past a
domain end) is asked on its own, and where the integral does not exist the engine's reason is kept
(``undefined``), the value NaN.  Not caught: a closed form that stays finite past the point where
the integral stops existing (``1/(x - a)^2`` on [0, 1] as a enters the box gives
``-1/(1 - a) - 1/a``, a number); a check of every point (``langur.denote.require_defined``) would
cost 0.5–8 ms a point, up to 80 s over Fig. 13's 10⁴ pixels, and is not made.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import sympy as sp

from .core import Program
from .ddenote import ddenote_program
from .denote import denote_program
from .symbolic.pieces import Integral, Method
from .symbolic.quadrature import UndefinedIntegral
from .sympy_bridge import symbol

#: Most derivations one batch may run (each a symbolic integration); past it the remaining points
#: are left out (NaN) and the result says how many.
MAX_DERIVATIONS = 200


@dataclass(frozen=True)
class ExactBatch:
    """⟦p⟧ (``value``) and, with a direction, ⦇p⦈ (``derivative`` = ``regular`` + ``boundary``) at
    P points, arrays (P,); ``error``/``derivative_error``: bounds (0 where a closed form was used);
    ``closed``: which points a closed form gave; ``derivations``: symbolic derivations run;
    ``missing``: points left out (NaN) after :data:`MAX_DERIVATIONS`; ``undefined``: the points
    where the integral does not exist (NaN), by index, with the engine's reason."""

    params: dict[str, np.ndarray]
    value: np.ndarray
    error: np.ndarray
    closed: np.ndarray
    derivations: int
    missing: int = 0
    regular: np.ndarray | None = None
    boundary: np.ndarray | None = None
    derivative_error: np.ndarray | None = None
    undefined: dict[int, str] = field(default_factory=dict)

    @property
    def derivative(self) -> np.ndarray | None:
        return None if self.regular is None else self.regular + self.boundary


def exact_batch(program: Program, params: Mapping[str, object], direction: Mapping[str, object] | None = None,
                *, timeout: float = 60.0) -> ExactBatch:
    """⟦p⟧ (and ⦇p⦈ in ``direction``) at every point of ``params`` (name → number or 1-D array of
    one length P; every parameter of the program must be given)."""
    arrays = {k: np.asarray(v, dtype=float) for k, v in params.items()}
    npts = max([a.shape[0] for a in arrays.values() if a.ndim == 1] or [1])
    grid = {k: np.broadcast_to(a, (npts,)).copy() for k, a in arrays.items()}
    names = sorted(grid)
    syms = [symbol(k) for k in names]
    columns = [grid[k] for k in names]
    out = {k: np.full(npts, np.nan) for k in ("value", "error", "regular", "boundary", "derror")}
    closed = np.zeros(npts, dtype=bool)
    todo = np.ones(npts, dtype=bool)
    undefined: dict[int, str] = {}
    derivations = 0
    while todo.any() and derivations < MAX_DERIVATIONS:
        i = int(np.flatnonzero(todo)[0])
        at = {k: Fraction(repr(float(grid[k][i]))) for k in names}
        derivations += 1
        try:
            den = denote_program(program, at, timeout=timeout)
            parts = [den]
            der = None
            if direction is not None:
                der = ddenote_program(program, at, direction, timeout=timeout)
                parts += [der.regular, der.boundary]
        except UndefinedIntegral as e:  # the integral does not exist here: NaN, and why
            undefined[i] = e.reason
            todo[i] = False
            continue
        if all(p.method == Method.CLOSED_FORM and p.expr is not None and not p.generic for p in parts):
            members = todo & _in_cell(parts, syms, columns)
            members[i] = True
            out["value"][members] = _values(den.expr, syms, columns, members)
            out["error"][members] = 0.0
            if der is not None:
                out["regular"][members] = _values(der.regular.expr, syms, columns, members)
                out["boundary"][members] = _values(der.boundary.expr, syms, columns, members)
                out["derror"][members] = 0.0
            # not a finite real there (past a domain end, module docstring): that point on its own
            past = members & ~np.isfinite(out["value"] if der is None else out["value"] + out["regular"] + out["boundary"])
            past[i] = False
            for k in ("value", "error", "regular", "boundary", "derror"):
                out[k][past] = np.nan
            members &= ~past
            closed |= members
        else:
            members = np.zeros(npts, dtype=bool)
            members[i] = True
            out["value"][i], out["error"][i] = den.value, den.error
            if der is not None:
                out["regular"][i], out["boundary"][i] = der.regular.value, der.boundary.value
                out["derror"][i] = der.error
        todo &= ~members
    extra = {}
    if direction is not None:
        extra = dict(regular=out["regular"], boundary=out["boundary"], derivative_error=out["derror"])
    return ExactBatch(grid, out["value"], out["error"], closed, derivations, int(todo.sum()), **extra,
                      undefined=undefined)


def _in_cell(parts: list[Integral], syms, columns) -> np.ndarray:
    """Which points satisfy every relation of the closed forms' cells."""
    inside = np.ones(len(columns[0]) if columns else 1, dtype=bool)
    for part in parts:
        for rel in part.cell:
            held = sp.lambdify(syms, rel, modules="numpy")(*columns)
            inside &= np.broadcast_to(np.asarray(held, dtype=bool), inside.shape)
    return inside


def _values(expr: sp.Expr, syms, columns, members: np.ndarray) -> np.ndarray:
    f = sp.lambdify(syms, expr, modules="numpy")
    with np.errstate(all="ignore"):
        v = f(*[c[members] for c in columns])
    return np.broadcast_to(np.asarray(v, dtype=float), (int(members.sum()),))
