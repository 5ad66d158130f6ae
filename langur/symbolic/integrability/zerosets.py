"""Where a pole base vanishes on R̄, and the codimension of that set (see the package docstring).

A weight can only blow up on the zero set of a *pole base* ``g`` (:func:`pole_bases`); every zero is
checked, nothing is assumed:

* **the set**: ``g`` is sampled on a grid of R̄ (its faces and corners included).  A sign change
  between neighbouring grid points inside R is a zero set *crossing* R: bisection (50 digits, on
  the segment) finds a point of it, and c = 1.  Otherwise zeros *touching* R̄ are looked for at
  the grid points and local minima of ``g²``, snapped to exact numbers (box bounds, rationals,
  simple surds) and verified with 50 digits; at such a point p, if ``g`` vanishes identically on
  the face of the box through p (``1/x`` on the face x = 0 of [0, 1]²) c is that face's
  codimension, if ``g`` shares its zero set with a condition active at p c = 1, and if ``g`` has
  no other zero on a small sphere around p in R̄ the point is isolated: c = n.  Otherwise the
  set is not known: undecided.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ...precise import DIGITS
from ...precise import real_value as _num
from ...precise import value_at as _value
from .region import Region, Undecidable, compiled

#: Directions tried at a point (the first are the natural ones: axes, inward normals).
DIRECTIONS = 9


def pole_bases(w: sp.Expr, xs: Sequence[sp.Symbol]) -> list[sp.Expr]:
    """The bases g on whose zero sets ``w`` can blow up (see the module docstring)."""
    xs = set(xs)
    out: list[sp.Expr] = []
    for e in sp.preorder_traversal(w):
        g = None
        if isinstance(e, sp.Pow) and e.exp.is_number and e.exp < 0:
            # (|h| vanishes where h does, and h's sign change shows the set crossing R: atan2's
            # derivative y/(|y|·(x² + y²)), the chain rule's |y|/√(x² + y²) for √(1 − x²/(x² + y²)))
            g = e.base.args[0] if isinstance(e.base, sp.Abs) else e.base
        elif isinstance(e, sp.tan):
            g = sp.cos(e.args[0])
        elif isinstance(e, (sp.atanh, sp.acoth)):
            g = 1 - e.args[0] ** 2
        if g is not None and g.free_symbols & xs and g not in out:
            out.append(g)
    return out


@dataclass
class Site:
    """A point of a pole base's zero set on R̄: its shape, the codimension of the set, directions into R̄."""

    point: tuple[sp.Expr, ...]
    shape: str
    codim: int | None
    directions: list[np.ndarray]
    face: tuple[tuple[int, sp.Expr], ...] = ()


def _snap(v: float, bounds: tuple[sp.Expr, sp.Expr], scale: float) -> sp.Expr:
    for b in bounds:
        if abs(v - float(b)) <= 1e-7 * scale:
            return b
    return sp.nsimplify(v, [sp.pi], tolerance=1e-9 * max(1.0, abs(v)), rational=False)


def _crossings(g, gf, region: Region, pts, vals, inside, k: int) -> list[Site]:
    """Zero sets of g crossing R: neighbouring grid points inside R with opposite signs."""
    n = len(region.xs)
    shape = (k,) * n
    V = vals.reshape(shape)
    I = inside.reshape(shape) & np.isfinite(V)
    P = pts.reshape(shape + (n,))
    found: list[Site] = []
    for axis in range(n):
        a = [slice(None)] * n
        b = [slice(None)] * n
        a[axis], b[axis] = slice(0, -1), slice(1, None)
        flips = I[tuple(a)] & I[tuple(b)] & (np.sign(V[tuple(a)]) * np.sign(V[tuple(b)]) < 0)
        for idx in np.argwhere(flips)[:: max(1, int(np.count_nonzero(flips) // 3) or 1)][:3]:
            i0 = tuple(idx)
            i1 = list(idx)
            i1[axis] += 1
            p = _bisect(g, region.xs, P[i0], P[tuple(i1)], axis)
            if p is None:
                continue
            e = np.zeros(n)
            e[axis] = 1.0
            found.append(Site(p, "crossing", 1, [e, -e]))
        if found:
            break
    return found


def _bisect(g, xs, a: np.ndarray, b: np.ndarray, axis: int):
    """A zero of g on the segment [a, b] along ``axis`` (50 digits), or None (a pole, not a zero)."""
    lo, hi = sp.Float(float(a[axis]), DIGITS), sp.Float(float(b[axis]), DIGITS)
    base = [sp.Float(float(v), DIGITS) for v in a]

    def at(t):
        q = list(base)
        q[axis] = t
        return q

    flo = _value(g, xs, at(lo))
    if not math.isfinite(flo):
        return None
    for _ in range(170):  # 2^-170 ≈ 1e-51 of the grid step
        m = (lo + hi) / 2
        fm = _value(g, xs, at(m))
        if not math.isfinite(fm):
            return None
        if (fm > 0) == (flo > 0):
            lo, flo = m, fm
        else:
            hi = m
    p = at((lo + hi) / 2)
    scale = max(abs(_value(g, xs, at(sp.Float(float(a[axis]), DIGITS)))),
                abs(_value(g, xs, at(sp.Float(float(b[axis]), DIGITS)))), 1e-300)
    return tuple(p) if abs(_value(g, xs, p)) <= 1e-30 * scale else None


def _touchings(g, gf, region: Region, pts, vals, inside) -> list[tuple[sp.Expr, ...]]:
    """Zeros of g on R̄ (not necessarily sign changes): grid zeros and local minima of g²,
    snapped to exact numbers and verified with 50 digits."""
    from scipy import optimize

    ok = inside & np.isfinite(vals)
    if not ok.any():
        return []
    av = np.abs(vals[ok])
    cand = pts[ok][np.argsort(av)[:4]]
    top = float(np.max(av)) or 1.0
    starts = []
    for c in cand:
        if not any(np.linalg.norm(c - s) < 1e-6 * region.scale for s in starts):
            starts.append(c)
    out: list[tuple[sp.Expr, ...]] = []
    near: list[np.ndarray] = []  # where the zeros found so far are (floats)
    bounds = list(zip(region.lo, region.hi))
    for s in sorted(starts, key=lambda q: abs(float(gf(q[None, :])[0]))):
        if any(np.linalg.norm(s - q) < 1e-3 * region.scale for q in near):
            continue
        x0 = s
        if abs(float(gf(s[None, :])[0])) > 1e-14 * top:
            try:
                r = optimize.minimize(lambda q: float(np.nan_to_num(gf(q[None, :])[0], nan=1e300) ** 2), s,
                                      method="L-BFGS-B", bounds=bounds,
                                      options={"ftol": 1e-30, "gtol": 1e-30, "maxiter": 200})
                x0 = r.x
            except (ValueError, ArithmeticError):
                continue
        if abs(float(np.nan_to_num(gf(np.asarray(x0)[None, :])[0], nan=1e300))) > 1e-5 * top:
            continue  # no zero near this start
        x0 = _polish(gf, np.asarray(x0, dtype=float), bounds, region.scale)
        if not region.inside(np.asarray(x0, dtype=float)[None, :], tol=1e-6)[0]:
            continue  # the descent (bounded by the box only) left R̄ for a zero where w is not integrated
        if any(np.linalg.norm(x0 - q) < 1e-3 * region.scale for q in near):
            continue
        p = tuple(_snap(float(v), region.box[i], region.scale) for i, v in enumerate(x0))
        if abs(_value(g, region.xs, p)) > 1e-40 * max(1.0, top) or not region.inside_exact(p):
            raise Undecidable(f"a zero of {g} near {tuple(round(float(v), 6) for v in x0)} that is not an exact "
                              "number the analysis can verify")
        near.append(np.asarray(x0, dtype=float))
        if p not in out:
            out.append(p)
    return out


def _polish(gf, x0: np.ndarray, bounds, scale: float, steps: int = 2) -> np.ndarray:
    """Newton steps towards g = 0 from a minimum of g² (which L-BFGS-B leaves where g² ≈ 1e-18,
    i.e. g ≈ 1e-9: too far for :func:`_snap`'s tolerance; on a condition's line y = 29/100 the
    step lands on it to rounding), kept in the box; a step that does not reduce |g| is not taken."""
    h = 1e-6 * scale
    for _ in range(steps):
        g0 = float(gf(x0[None, :])[0])
        if not math.isfinite(g0) or g0 == 0:
            break
        eye = np.eye(len(x0)) * h
        grad = (gf(x0[None, :] + eye) - gf(x0[None, :] - eye)) / (2 * h)
        norm = float(np.dot(grad, grad))
        if not np.all(np.isfinite(grad)) or norm == 0:
            break
        x1 = np.clip(x0 - g0 * grad / norm, [float(lo) for lo, _ in bounds], [float(hi) for _, hi in bounds])
        if not abs(float(gf(x1[None, :])[0])) < abs(g0):
            break
        x0 = x1
    return x0


def _sphere(n: int, count: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(count, n))
    return v / np.linalg.norm(v, axis=1)[:, None]


def _inward(region: Region, p: Sequence[sp.Expr]) -> tuple[list[tuple[int, sp.Expr, float]], list[int]]:
    """Active box bounds at p (index, bound, inward sign) and active conditions (indices)."""
    active = []
    for i, ((lo, hi), v) in enumerate(zip(region.box, p)):
        if _num(v - lo) == 0 or abs(_num(v - lo)) < 1e-40:
            active.append((i, lo, 1.0))
        elif abs(_num(hi - v)) < 1e-40:
            active.append((i, hi, -1.0))
    sub = dict(zip(region.xs, p))
    conds = [j for j, c in enumerate(region.conds) if abs(_num(c.xreplace(sub))) < 1e-40]
    return active, conds


def _cone(region: Region, p, active, conds, count: int) -> list[np.ndarray]:
    """Unit directions v with p + t·v in R̄ for small t > 0 (checked at t = 1e-6 of the scale)."""
    n = len(region.xs)
    vs = _sphere(n, 8 * count, seed=len(active) + 7 * len(conds))
    for i, _, s in active:
        vs[:, i] = s * np.abs(vs[:, i])
    pf = np.array([float(v) for v in p])
    ok = region.inside(pf[None, :] + 1e-6 * region.scale * vs, tol=0.0)
    return [v for v in vs[ok][:count]]


def _site_at(g, region: Region, p) -> Site:
    """What kind of zero of g the point p ∈ R̄ is (see the module docstring)."""
    n = len(region.xs)
    active, conds = _inward(region, p)
    if n == 1:
        dirs = _cone(region, p, active, conds, 2) or []
        return Site(p, "point", 1, [np.array([1.0]), np.array([-1.0])] if not active else dirs)
    if active:  # does g vanish on the face of the box through p?
        fixed = {region.xs[i]: b for i, b, _ in active}
        gf = g.xreplace(fixed)
        free = [x for x in region.xs if x not in fixed]
        if free and _vanishes_near(gf, free, [p[region.xs.index(x)] for x in free], region):
            normal = np.zeros(n)
            for i, _, s in active:
                normal[i] = s
            dirs = [normal / np.linalg.norm(normal)] + _cone(region, p, active, conds, DIRECTIONS - 1)
            return Site(p, "face", len(active), dirs, tuple((i, b) for i, b, _ in active))
    for j in conds:  # the zero set of a condition active at p, shared with g
        c = region.conds[j]
        try:
            shared = sp.gcd(sp.expand(g), sp.expand(c))
        except (sp.PolynomialError, NotImplementedError, TypeError):
            shared = sp.Integer(1)
        if not shared.is_number:
            grad = np.array([_value(sp.diff(c, x), region.xs, p) for x in region.xs])
            if np.all(np.isfinite(grad)) and np.linalg.norm(grad) > 0:
                return Site(p, "condition", 1, [grad / np.linalg.norm(grad)]
                             + _cone(region, p, active, conds, DIRECTIONS - 1))
    dirs = _cone(region, p, active, conds, 64)
    if not dirs:
        raise Undecidable(f"no direction into the region at {p}")
    pf = np.array([float(v) for v in p])
    rho = 1e-3 * region.scale
    gv = np.array([_value(g, region.xs, tuple(sp.Float(float(c), DIGITS) for c in pf + rho * d)) for d in dirs])
    if not np.all(np.isfinite(gv)):
        return Site(p, "unknown", None, dirs[:DIRECTIONS])
    if np.any(gv > 0) and np.any(gv < 0):  # the zero set passes through p into R: a crossing
        order = np.argsort(-np.abs(gv))
        return Site(p, "crossing", 1, [dirs[i] for i in order[:DIRECTIONS]])
    if np.min(np.abs(gv)) > 1e-12 * max(np.max(np.abs(gv)), 1e-300):
        return Site(p, "point", n, dirs[:DIRECTIONS])
    return Site(p, "unknown", None, dirs[:DIRECTIONS])


def _vanishes_near(gf: sp.Expr, free, at, region: Region) -> bool:
    if sp.expand(gf) == 0:
        return True
    rng = np.random.default_rng(1)
    for _ in range(3):
        q = [sp.Float(float(a) + 1e-3 * region.scale * rng.uniform(-1, 1), DIGITS) for a in at]
        v = _num(gf.xreplace(dict(zip(free, q))))
        if not (math.isfinite(v) and abs(v) < 1e-35):
            return False
    return True


def sites(g: sp.Expr, region: Region) -> list[Site]:
    """Points of the zero set of g on R̄, each with its shape and codimension."""
    pts, k = region.grid()
    gf = compiled(g, region.xs)
    vals = gf(pts)
    inside = region.inside(pts)
    crossing = _crossings(g, gf, region, pts, vals, inside, k)
    if crossing:
        return crossing
    return [_site_at(g, region, p) for p in _touchings(g, gf, region, pts, vals, inside)]

