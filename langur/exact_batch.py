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
(``undefined``), the value NaN.  A form can also stay finite past the point where the integral stops
existing (``1/(x - a)^2`` on [0, 1] as a enters the box: ``-1/(1 - a) - 1/a``, a number): the integral
can only stop existing where a *pole base* of the integrand (or of its derivative in the direction;
:func:`langur.symbolic.integrability.pole_bases`) vanishes on the closed box.  So the grid's points are
sorted once per batch (:func:`maybe_singular`, vectorized: each base sampled on a grid of the box at
every point): where no base can vanish, the integrand is bounded and the cell's form is used; at the
few points where one may, the exact engine's own check (``langur.denote.require_defined``, with
⦇t⦈'s pieces for a derivative: the same verdict as a derivation of that point) decides before the
cell's form is used there, and an undefined point is NaN with its reason.
"""

from __future__ import annotations

import itertools
from collections.abc import Mapping
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import sympy as sp

from .core import Program
from .ddenote import ddenote_program, normal_form
from .denote import denote_program, require_defined
from .symbolic.decompose import Ctx
from .symbolic.definedness import has_partial
from .symbolic.integrability import pole_bases
from .symbolic.pieces import Integral, Method
from .symbolic.quadrature import UndefinedIntegral
from .sympy_bridge import at_symbols, denote, symbol, symbols

#: Most derivations one batch may run (each a symbolic integration); past it the remaining points
#: are left out (NaN) and the result says how many.
MAX_DERIVATIONS = 200
#: Grid points per dimension of the box on which :func:`maybe_singular` samples each pole base.
SINGULAR_GRID = {1: 101, 2: 21, 3: 9}
#: A pole base whose smallest |value| on that grid is below this fraction of its largest may vanish
#: between grid points (``(x − a)² + y²`` at (a, 0), a between two nodes: a ratio of about 6·10⁻⁴).
TOUCHING = 1e-2
#: Points sampled at once (memory: points × grid values).
CHUNK = 512


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
    singular = maybe_singular(program, direction, names, columns, npts)
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
            # where a pole base may vanish on the box, the integral may not exist: the engine's check first
            for j in np.flatnonzero(members & singular):
                why = None if j == i else _undefined_at(program, {k: Fraction(repr(float(grid[k][j]))) for k in names},
                                                         direction)
                if why is not None:
                    undefined[int(j)] = why
                    members[j] = todo[j] = False
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
    """The closed form at the ``members``: in real arithmetic, and where that is NaN in complex
    arithmetic, kept where the imaginary parts cancel (``log(a) − log(a − Max(0, Min(1, a)))`` at a < 0:
    log(−1) = iπ twice, which real numpy reads as NaN)."""
    f = sp.lambdify(syms, expr, modules="numpy")
    args = [c[members] for c in columns]
    with np.errstate(all="ignore"):
        v = np.array(np.broadcast_to(np.asarray(f(*args), dtype=float), (int(members.sum()),)))
        nan = np.isnan(v)
        if nan.any():
            try:
                z = np.broadcast_to(np.asarray(f(*[a[nan].astype(complex) for a in args]), dtype=complex),
                                    (int(nan.sum()),))
            except (TypeError, ValueError):
                return v
            v[nan] = np.where(np.abs(z.imag) <= 1e-12 * np.maximum(1.0, np.abs(z.real)), z.real, np.nan)
    return v


def maybe_singular(program: Program, direction: Mapping[str, object] | None, names: list[str],
                   columns: list[np.ndarray], npts: int) -> np.ndarray:
    """Per point (parameter values ``columns``, by ``names``): may a pole base of ⟦t⟧, or of its derivative
    in ``direction``, vanish on the closed box there?  Each base is sampled on a grid of the box
    (:data:`SINGULAR_GRID`, faces and corners included) at every point at once: a sign change, a value
    not a finite real number, or a smallest |value| below :data:`TOUCHING` of the largest says it may
    (conservative where a zero touches between nodes); a base affine in the variables is sampled at the
    box's corners only, where its extremes are (exact: a zero on the closed box iff min ≤ 0 ≤ max).  False: the integrand is bounded on the
    box there (it can blow up only on a pole base's zero set), so the integral exists where its
    closed form is a finite number.  Where the bases cannot be found, True everywhere."""
    if not has_partial(program.body):  # no primitive or power defined on part of ℝ: nothing blows up
        return np.zeros(npts, dtype=bool)
    xs = list(symbols(program.variables))
    params = [symbol(k) for k in names]
    try:
        bases = _bases(denote(program.body), xs, [symbol(k) for k, v in (direction or {}).items() if v])
        ends = [sp.lambdify(params, sp.Matrix([denote(lo), denote(hi)]), modules="numpy") for lo, hi in program.box]
        fs = [(sp.lambdify(xs + params, g, modules="numpy"), _affine(g, xs)) for g in bases]
    except Exception:  # noqa: BLE001 - a base or box sympy cannot compile: every point is checked on its own
        return np.ones(npts, dtype=bool)
    if not fs:
        return np.zeros(npts, dtype=bool)
    n = len(xs)
    k = SINGULAR_GRID.get(n, 5)
    grid = np.array(list(itertools.product(np.linspace(0.0, 1.0, k), repeat=n)))  # (G, n)
    corners = np.array(list(itertools.product((0.0, 1.0), repeat=n)))  # an affine base's extremes
    out = np.zeros(npts, dtype=bool)
    with np.errstate(all="ignore"):
        for start in range(0, npts, CHUNK):
            part = [c[start:start + CHUNK] for c in columns]
            m = len(part[0]) if part else min(CHUNK, npts - start)
            box = np.stack([np.broadcast_to(np.asarray(f(*part), dtype=float).reshape(2, -1), (2, m))
                            for f in ends], axis=-1)  # (2, m, n)
            lo, width = box[0][:, None, :], (box[1] - box[0])[:, None, :]
            for f, affine in fs:
                unit = corners if affine else grid
                pts = lo + unit[None, :, :] * width  # (m, G, n)
                try:
                    v = np.asarray(f(*[pts[..., d] for d in range(n)], *[c[:, None] for c in part]))
                except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                    out[start:start + m] = True
                    continue
                if np.iscomplexobj(v):
                    v = np.where(np.abs(v.imag) <= 1e-12 * np.maximum(1.0, np.abs(v.real)), v.real, np.nan)
                v = np.broadcast_to(v.astype(float), (m, unit.shape[0]))
                a = np.abs(v)
                zero = (np.min(v, axis=1) <= 0) & (np.max(v, axis=1) >= 0) if affine else \
                    ((np.min(v, axis=1) < 0) & (np.max(v, axis=1) > 0)) | (np.min(a, axis=1) <= TOUCHING * np.max(a, axis=1))
                out[start:start + m] |= ~np.all(np.isfinite(v), axis=1) | zero
    return out


def _bases(w: sp.Expr, xs: list[sp.Symbol], moving: list[sp.Symbol]) -> list[sp.Expr]:
    """The pole bases of ⟦t⟧ = ``w`` and of its derivatives in the ``moving`` parameters: those of ``w``,
    and those of the derivative of each power that is not a natural number's and each function applied
    (the chain rule makes a derivative's poles only there: ``log(x − a)`` gives ``1/(x − a)``); each
    small subterm is differentiated, not ``w``."""
    out = dict.fromkeys(pole_bases(w, xs))
    for e in sp.preorder_traversal(w) if moving else ():
        partial = (e.is_Pow and not (e.exp.is_Integer and e.exp >= 0)) or \
            (isinstance(e, sp.Function) and not isinstance(e, sp.Piecewise))
        if partial and e.free_symbols & set(xs) and e.free_symbols & set(moving):
            out.update(dict.fromkeys(g for p in moving for g in pole_bases(sp.diff(e, p), xs)))
    return list(out)


def _affine(g: sp.Expr, xs: list[sp.Symbol]) -> bool:
    """Is ``g`` affine in the variables (its extremes on the box at its corners)?"""
    try:
        return sp.Poly(g, *xs).total_degree() <= 1
    except sp.PolynomialError:
        return False


def _undefined_at(program: Program, at: Mapping[str, Fraction], direction: Mapping[str, object] | None) -> str | None:
    """The exact engine's reason why ⟦p⟧ (with ``direction``: or ⦇p⦈) does not exist at ``at``, or None:
    ``langur.denote.require_defined``, which a derivation of that point asks after integrating."""
    ctx = Ctx(at=at_symbols(at), variables=tuple(program.variables))
    nf = normal_form(program, direction, at) if direction is not None else None
    try:
        require_defined(program, ctx, nf.regular if nf else None, nf.deltas if nf else None)
    except UndefinedIntegral as e:
        return e.reason
    return None
