"""The numbers behind every picture, from the engines' own output (no OpenGL, no matplotlib).

A :class:`Scene` is a program at one parameter point, read through the exact engine:

* ``integrand``: ⟦t⟧ as simply decomposable pieces (Def. 6.2, ``langur.symbolic.decompose``);
* ``regular``: the regular part f of ⦇t⦈ in the normal form of Theorem 7.1 — what standard AD
  integrates (the paper's Dˢ);
* ``deltas``: its delta terms h·δ(Φ), each with Φ's inverse branches (``langur.ddenote``).

From these, :func:`spikes` places each delta of a one-variable program at its roots with its
weight Σ_b h·|dΨ̂_b⁻¹/du₀| (the sifting property), and :func:`ridges` draws each delta of a
two-variable program along its zero set Φ = 0, parametrized by the inverse branches
x = Ψ̂_b⁻¹(0, u₁), with its weight per unit length h·|det DΨ̂_b⁻¹| / |∂x/∂u₁| (so that the
line integral of the density is the delta's integral).  Nothing here is specific to a figure:
any program the engines accept can be drawn.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import sympy as sp

from langur.core import Program
from langur.ddenote import ddenote, ddenote_program
from langur.denote import denote_program, program_box
from langur.symbolic.decompose import Ctx, decompose
from langur.symbolic.pieces import Condition, DeltaPiece, Method, Piece
from langur.sympy_bridge import at_symbols, symbols

#: Points of a curve over the box (split among its pieces).
CURVE_POINTS = 600
#: Tolerance of "on the boundary" tests (a root on a domain bound belongs to it).
TOL = 1e-12


def _numeric(expr: sp.Expr, names: Sequence[sp.Symbol], at: Mapping[sp.Symbol, sp.Expr]):
    """``expr`` with the parameters' values substituted, as a numpy function of ``names``."""
    e = sp.sympify(expr).xreplace(dict(at))
    f = sp.lambdify(list(names), e, modules="numpy")

    def g(*args):
        with np.errstate(all="ignore"):
            out = np.asarray(f(*args), dtype=float)
        return np.broadcast_to(out, np.broadcast(*args).shape) if args else out

    return g


@dataclass
class Field:
    """A sum of Iverson products Σ_i Π_j [Φ_ij ≥ 0]·g_i (regular pieces), evaluated numerically."""

    pieces: list[tuple[list[tuple[object, bool, sp.Expr]], object]]  # ([(Φ function, strict, Φ)], g)
    conditions: list[Condition]  # the distinct conditions, for splitting a domain at the jumps

    def __call__(self, *xs: np.ndarray) -> np.ndarray:
        shape = np.broadcast(*xs).shape
        out = np.zeros(shape)
        for conds, g in self.pieces:
            inside = np.ones(shape, dtype=bool)
            for phi, strict, _ in conds:
                v = phi(*xs)
                inside &= (v > 0) if strict else (v >= 0)
            if inside.any():
                out = out + np.where(inside, g(*xs), 0.0)
        return out

    def on_side(self, signs: dict, *xs: np.ndarray) -> np.ndarray:
        """The field in the region where each distinct condition has the sign ``signs[Φ]`` (True:
        Φ ≥ 0), evaluated by the region, not by the points: exact up to the region's boundary."""
        out = np.zeros(np.broadcast(*xs).shape)
        for conds, g in self.pieces:
            if all(signs[e] if e in signs else not signs[-e] for _, _, e in conds):
                out = out + g(*xs)
        return out


def _field(pieces: Sequence[Piece], xs: Sequence[sp.Symbol], at) -> Field:
    distinct: dict[sp.Expr, Condition] = {}
    for p in pieces:
        for c in p.conditions:
            if c.expr not in distinct and -c.expr not in distinct:
                distinct[c.expr] = c
    return Field([([(_numeric(c.expr, xs, at), c.strict, c.expr) for c in p.conditions], _numeric(p.weight, xs, at))
                  for p in pieces], list(distinct.values()))


@dataclass(frozen=True)
class Spike:
    """A delta of a one-variable program at ``x``: it contributes ``weight`` to the integral."""

    x: float
    weight: float
    term: int  # which delta term of the normal form (1-based, as ``langur show`` numbers them)


@dataclass(frozen=True)
class Ridge:
    """A delta of a two-variable program along a piece of its zero set: ``points`` (n × 2) on the
    curve, ``density`` its weight per unit length there (n values)."""

    points: np.ndarray
    density: np.ndarray
    term: int

    def integral(self) -> float:
        """∫ density ds along the polyline (trapezoids): the delta's contribution."""
        ds = np.linalg.norm(np.diff(self.points, axis=0), axis=1)
        return float(np.sum(ds * (self.density[1:] + self.density[:-1]) / 2))


@dataclass
class Scene:
    """A program at a parameter point in a direction γ', with the exact engine's answers."""

    program: Program
    params: dict[str, float]
    direction: dict[str, float]
    box: list[tuple[float, float]]
    integrand: Field
    regular: Field
    deltas: list[DeltaPiece]
    value: float
    derivative: float
    standard_ad: float
    boundary: float
    notes: list[str] = field(default_factory=list)

    @property
    def variables(self) -> tuple[str, ...]:
        return tuple(self.program.variables)

    @property
    def at(self) -> dict:
        return at_symbols(self.params)


def scene(program: Program, params: Mapping[str, float], direction: Mapping[str, float], *,
          timeout: float = 20.0) -> Scene:
    """Read ``program`` at ``params`` in the direction ``direction`` through the exact engine."""
    params = {k: float(v) for k, v in params.items()}
    direction = {k: float(v) for k, v in direction.items()}
    at = at_symbols(params)
    xs = symbols(program.variables)
    ctx = Ctx(at=at, variables=tuple(program.variables))
    nf = ddenote(program.body, direction, at=params, variables=tuple(program.variables))
    box = [(float(_numeric(lo, [], at)()), float(_numeric(hi, [], at)())) for lo, hi in program_box(program, ctx)]
    value = denote_program(program, params, timeout=timeout)
    der = ddenote_program(program, params, direction, timeout=timeout)
    notes = [] if value.method == der.method == Method.CLOSED_FORM else ["values by quadrature"]
    return Scene(program, params, direction, box, _field(decompose(program.body, ctx), xs, at),
                 _field(nf.regular, xs, at), list(nf.deltas), value.value, der.value, der.regular.value,
                 der.boundary.value, notes)


# ----------------------------------------------------------------------------------------------
# One variable


def _inside(conditions: Sequence[Condition], xs, at, point: Sequence[float]) -> bool:
    for c in conditions:
        v = float(_numeric(c.expr, xs, at)(*point))
        if not (v > 0 if c.strict else v >= -1e-12):
            return False
    return True


def breakpoints(s: Scene, f: Field) -> list[float]:
    """The roots of ``f``'s conditions inside the box (where it may jump), sorted."""
    (lo, hi), = s.box
    out = {lo, hi}
    for c in f.conditions:
        for r in _roots_1d(c.psi, s.at):
            if lo < r < hi:
                out.add(r)
    for d in s.deltas:
        for r in _roots_1d(d.psi, s.at):
            if lo < r < hi:
                out.add(r)
    return sorted(out)


def _roots_1d(psi, at) -> list[float]:
    if psi is None:
        return []
    out = []
    u0 = psi.inputs[0]
    for b in psi.branches:
        point = {u0: 0, **dict(at)}
        if any(float(sp.N(g.xreplace(point))) < 0 for g in b.guards):
            continue
        (_, x_expr), = b.inverse
        v = complex(sp.N(x_expr.xreplace(point)))
        if abs(v.imag) < 1e-12 and math.isfinite(v.real):
            out.append(v.real)
    return out


def curve(s: Scene, f: Field, points: int = CURVE_POINTS) -> list[tuple[np.ndarray, np.ndarray]]:
    """``f`` on the box, one ``(x, y)`` array pair per interval between jumps (never a cliff)."""
    cuts = breakpoints(s, f)
    out = []
    for a, b in zip(cuts, cuts[1:]):
        eps = 1e-9 * max(1.0, abs(b - a))
        x = np.linspace(a + eps, b - eps, max(8, int(points * (b - a) / (cuts[-1] - cuts[0]))))
        out.append((x, f(x)))
    return out


def spikes(s: Scene) -> list[Spike]:
    """Each delta of a one-variable program at its roots: weight h(x_b)·|dΨ̂_b⁻¹/du₀(0)| (the
    sifting property ∫ h δ(Φ) dx = Σ_b h(x_b)/|Φ'(x_b)|), where the delta's conditions hold."""
    if len(s.variables) != 1:
        raise ValueError("spikes are for one-variable programs")
    (x,) = symbols(s.variables)
    (lo, hi), = s.box
    out = []
    for k, d in enumerate(s.deltas, 1):
        u0 = d.psi.inputs[0]
        for b in d.psi.branches:
            point = {u0: sp.Integer(0), **dict(s.at)}
            if any(float(sp.N(g.xreplace(point))) < 0 for g in b.guards):
                continue
            (_, x_expr), = b.inverse
            root = float(sp.N(x_expr.xreplace(point)))
            if not lo - 1e-12 <= root <= hi + 1e-12 or not _inside(d.conditions, [x], s.at, [root]):
                continue
            jac = abs(float(sp.N(sp.diff(x_expr, u0).xreplace(point))))
            w = float(_numeric(d.weight, [x], s.at)(np.float64(root))) * jac
            out.append(Spike(root, w, k))
    return out


# ----------------------------------------------------------------------------------------------
# Two variables


def ridges(s: Scene, points: int = CURVE_POINTS) -> list[Ridge]:
    """Each delta of a two-variable program along its zero set, as pieces of polyline with the
    weight per unit length h·|det DΨ̂_b⁻¹(0, u₁)| / |∂x/∂u₁| (the line integral of the density is
    the delta's integral), kept where its guards and conditions hold and inside the box."""
    if len(s.variables) != 2:
        raise ValueError("ridges are for two-variable programs")
    xs = symbols(s.variables)
    (x0, x1), (y0, y1) = s.box
    out = []
    for k, d in enumerate(s.deltas, 1):
        u0, u1 = d.psi.inputs[0], d.psi.inputs[1]
        lo, hi = _range(d.psi.forward[1], xs, s)
        weight = _numeric(d.weight, xs, s.at)
        for b in d.psi.branches:
            comps = dict(b.inverse)
            px, py = (sp.sympify(comps[v]).xreplace({u0: 0}) for v in xs)
            full = [sp.sympify(comps[v]) for v in xs]
            det = _numeric(sp.Matrix([[sp.diff(c, w) for w in (u0, u1)] for c in full]).det().xreplace({u0: 0}),
                           [u1], s.at)
            fx, fy = _numeric(px, [u1], s.at), _numeric(py, [u1], s.at)
            dfx, dfy = _numeric(sp.diff(px, u1), [u1], s.at), _numeric(sp.diff(py, u1), [u1], s.at)
            guards = [_numeric(sp.sympify(g).xreplace({u0: 0}), [u1], s.at) for g in b.guards]
            conds = [(_numeric(c.expr, xs, s.at), c.strict) for c in d.conditions]

            def keep(u, fx=fx, fy=fy, guards=guards, conds=conds):
                X, Y = fx(u), fy(u)
                ok = np.isfinite(X) & np.isfinite(Y) & (X >= x0 - TOL) & (X <= x1 + TOL) \
                    & (Y >= y0 - TOL) & (Y <= y1 + TOL)
                for g in guards:
                    ok &= g(u) >= -TOL
                for phi, strict in conds:
                    v = phi(X, Y)
                    ok &= (v > 0) if strict else (v >= -TOL)
                return ok

            u = np.linspace(lo, hi, points)
            for run in _runs(keep(u)):
                uu = _refine_ends(u, run, keep)
                X, Y, speed = fx(uu), fy(uu), np.hypot(dfx(uu), dfy(uu))
                with np.errstate(all="ignore"):  # ∞/∞ at a fold: continued below
                    dens = _continue(weight(X, Y) * np.abs(det(uu)) / np.where(speed > 0, speed, np.nan))
                if len(uu) >= 2:
                    out.append(Ridge(np.column_stack([X, Y]), dens, k))
    return out


def _continue(density: np.ndarray) -> np.ndarray:
    """At a fold of Ψ̂⁻¹ (where the curve turns back, |∂x/∂u₁| and |det DΨ̂⁻¹| are both infinite)
    the density is their finite limit along the curve: the nearest finite value stands in."""
    ok = np.isfinite(density)
    if ok.all() or not ok.any():
        return density
    idx = np.arange(len(density))
    nearest = np.interp(idx, idx[ok], idx[ok]).round().astype(int)
    return np.where(ok, density, density[nearest])


def _range(f: sp.Expr, xs, s: Scene) -> tuple[float, float]:
    """The range of Ψ̂'s second component over the box (dense sampling, widened a little)."""
    (x0, x1), (y0, y1) = s.box
    gx, gy = np.meshgrid(np.linspace(x0, x1, 201), np.linspace(y0, y1, 201))
    v = _numeric(f, xs, s.at)(gx, gy)
    v = v[np.isfinite(v)]
    return float(v.min()), float(v.max())


def _refine_ends(u: np.ndarray, run: np.ndarray, keep) -> np.ndarray:
    """The run's parameters, extended at each end to where ``keep`` stops holding (bisection
    between the last point kept and the first point not kept), so no piece of curve is lost."""
    pts = u[run]
    i, j = run[0], run[-1]
    ends = []
    for inside, outside in ((u[i], u[i - 1] if i > 0 else None), (u[j], u[j + 1] if j + 1 < len(u) else None)):
        if outside is None:
            ends.append(None)
            continue
        a, b = inside, outside
        for _ in range(50):
            m = (a + b) / 2
            if keep(np.array([m]))[0]:
                a = m
            else:
                b = m
        ends.append(a)
    if ends[0] is not None:
        pts = np.concatenate([[ends[0]], pts])
    if ends[1] is not None:
        pts = np.concatenate([pts, [ends[1]]])
    return pts


def _runs(mask: np.ndarray) -> list[np.ndarray]:
    """Index arrays of the maximal runs where ``mask`` holds."""
    idx = np.flatnonzero(mask)
    if idx.size == 0:
        return []
    splits = np.flatnonzero(np.diff(idx) > 1) + 1
    return np.split(idx, splits)
