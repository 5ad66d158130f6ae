"""Whether an integrand is integrable on its region: an integral that does not exist (LANGUAGE.md §3).

⟦int t d(x⃗)⟧ = ∫ ⟦t⟧ (Fig. 12) exists only when ⟦t⟧ is integrable on the box (Prop. 7.1, Theorem 7.1
assume it: "if ⟦t⟧ is locally integrable").  A principal value is not an integral: ``1/t − 1/(1 − t)``
on [0, 1] diverges at both ends although its symmetric cancellation is 0, and quadrature can
converge to that 0 without a warning; a closed form evaluated at the ends can too (``x/(x²+y²)²`` on
[−1, 1]², odd in x).  This module decides it, once, for the exact engine (:func:`divergence`, which
``langur.denote.require_defined`` asks after integrating) and for the linter's X311–X313
(``langur.lint.singular``, through :func:`piece_blowups` and :func:`blowups`).

One simply decomposable piece ``Π [c ≥ 0] · w`` (Def. 6.2) at given parameter values is integrable
on its closed region R̄ (the box cut by the conditions) unless ``w`` blows up somewhere on R̄. It
can only blow up on the zero set of a *pole base* ``g``: the base of a negative power (``1/x^2`` is
``x^-2``, ``1/sqrt(x)`` is ``x^(-1/2)``), ``cos`` of the argument of a ``tan``, or ``log(b)`` in a
denominator. Near a set S of codimension c in R̄ on which ``|w| ~ dist(·, S)^-α``,

    ∫ |w| < ∞  ⇔  α < c                                    (polar coordinates around S)

so ``1/x`` on [0, 1] (α = 1 on a point of ℝ¹) diverges, ``1/sqrt(x)`` (α = ½) does not,
``1/(x²+y²)`` at the corner of [0, 1]² (α = 2 at a point of ℝ²) diverges, ``1/sqrt(x²+y²)`` does
not, and ``1/(x+y)`` at that corner (α = 1) does not; ``w²`` (the variance of a uniform Monte
Carlo estimate) has 2α.

How the set and the exponent are found (every zero is checked, nothing is assumed):

* **the set**: ``g`` is sampled on a grid of R̄ (its faces and corners included).  A sign change
  between neighbouring grid points inside R is a zero set *crossing* R: bisection (50 digits, on
  the segment) finds a point of it, and c = 1.  Otherwise zeros *touching* R̄ are looked for at
  the grid points and local minima of ``g²``, snapped to exact numbers (box bounds, rationals,
  simple surds) and verified with 50 digits; at such a point p, if ``g`` vanishes identically on
  the face of the box through p (``1/x`` on the face x = 0 of [0, 1]²) c is that face's
  codimension, if ``g`` shares its zero set with a condition active at p c = 1, and if ``g`` has
  no other zero on a small sphere around p in R̄ the point is isolated: c = n.  Otherwise the
  set is not known: undecided.
* **the exponent**: ``|w(p + t·v)|`` at t = ρ, ρ·10⁻², ρ·10⁻⁴ along directions v into R̄ (50-digit
  evaluation of the whole weight, so a numerator that vanishes there counts: ``x/(x²+y²)`` grows
  like r⁻¹, not r⁻²; ``sin(x)/x`` not at all).  Both slopes must agree (within 0.05), else the
  growth is not a power (oscillation, logarithms): undecided.

Verdicts, with α_max the largest and α_typ the median exponent over the directions tried:
integrable when α_max < c − margin; divergent when α_typ ≥ c − margin (margin 0.01, or 0.1 when
a logarithm is singular at p: ``1/(x·log²x)`` measures α ≈ 0.9 but ``1/(x·log x)`` ≈ 0.95 and
diverges, so near c a logarithm leaves it undecided); otherwise undecided.  An anisotropic zero
(``1/(x + y²)`` at the corner: α = 1 almost everywhere, 2 along the y-axis; it is integrable) is
honestly undecided.

The exact engine says "undefined" on a divergent verdict only (never on an undecided one), within
:data:`TIME_LIMIT` CPU seconds per integral; beyond them it claims nothing, and its quadrature's own
diagnostics stand.
"""

from __future__ import annotations

import functools
import itertools
import math
import statistics
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np
import sympy as sp

from ...primitives import REGISTRY
from ...timebox import Deadline
from ..precise import DIGITS
from ..precise import real_value as _num
from ..precise import value_at as _value

#: Grid points per dimension (the grid has at most a few thousand points).
GRID = {1: 401, 2: 41, 3: 15}
#: Directions tried at a point (the first are the natural ones: axes, inward normals).
DIRECTIONS = 9


class Verdict(Enum):
    INTEGRABLE = "integrable"
    DIVERGENT = "divergent"
    UNDECIDED = "undecided"


@dataclass(frozen=True)
class Blowup:
    """``w`` blows up on a set of codimension ``codim`` in R̄ through ``point`` like dist^-``alpha``."""

    base: sp.Expr  # the pole base g (parameters substituted)
    point: tuple[sp.Expr, ...]  # a point of the singular set (exact numbers, or floats)
    shape: str  # "crossing", "face", "condition", "point" or "unknown"
    codim: int | None
    alpha: float | None  # typical exponent (median over directions)
    alpha_max: float | None
    verdict: Verdict
    square: Verdict  # the same question for w² (a finite variance)
    logarithmic: bool = False
    face: tuple[tuple[int, sp.Expr], ...] = ()  # (variable index, bound) of the face for "face"


class Undecidable(Exception):
    """The analysis cannot be carried out (no numeric value, time, shape)."""


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


def _log_points(w: sp.Expr) -> list[tuple[sp.Expr, float]]:
    """(argument, where it is singular) of each logarithmic function in ``w``: log at 0, atanh at ±1."""
    out = []
    for e in sp.preorder_traversal(w):
        if isinstance(e, sp.log):
            out.append((e.args[0], 0.0))
        elif isinstance(e, (sp.atanh, sp.acoth)):
            out.append((e.args[0], 1.0))
    return out


class Region:
    """R̄: the box (numbers) cut by conditions ``c ≥ 0`` (sympy, parameters substituted)."""

    def __init__(self, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]], conds: Sequence[sp.Expr]):
        self.xs = tuple(xs)
        self.box = [(sp.nsimplify(lo), sp.nsimplify(hi)) for lo, hi in box]
        self.lo = np.array([float(lo) for lo, _ in self.box])
        self.hi = np.array([float(hi) for _, hi in self.box])
        if not (np.all(np.isfinite(self.lo)) and np.all(np.isfinite(self.hi)) and np.all(self.hi > self.lo)):
            raise Undecidable("the box is empty or unbounded")
        self.scale = float(np.max(self.hi - self.lo))
        self.conds = [c for c in conds if c.free_symbols & set(self.xs)]
        # a condition constant on the box (a guard of an inverse branch that does not apply at
        # these parameters) that is negative empties the region: nothing there can blow up
        self.empty = any(_num(c) < 0 for c in conds if not c.free_symbols & set(self.xs))
        self._cfs = [_numpy(c, self.xs) for c in self.conds]

    def grid(self) -> np.ndarray:
        n = len(self.xs)
        k = GRID.get(n, 7)
        axes = [np.linspace(lo, hi, k) for lo, hi in zip(self.lo, self.hi)]
        return np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, n), k

    def inside(self, pts: np.ndarray, tol: float = 1e-12) -> np.ndarray:
        ok = np.all((pts >= self.lo - tol * self.scale) & (pts <= self.hi + tol * self.scale), axis=1)
        for f in self._cfs:
            with np.errstate(all="ignore"):
                v = f(pts)
            ok &= np.nan_to_num(v, nan=-1.0) >= -tol * self.scale
        return ok

    def inside_exact(self, p: Sequence[sp.Expr]) -> bool:
        for (lo, hi), v in zip(self.box, p):
            if not (_num(v - lo) >= -1e-40 and _num(hi - v) >= -1e-40):
                return False
        sub = dict(zip(self.xs, p))
        return all(_num(c.xreplace(sub)) >= -1e-40 for c in self.conds)


@functools.lru_cache(maxsize=4096)  # one condition bounds many regions
def _lambdified(e: sp.Expr, xs: tuple):
    """``e`` compiled for numpy over ``xs``, or False where sympy cannot print it (zoo, nan…)."""
    try:
        return sp.lambdify(list(xs), e, modules="numpy")
    except Exception:  # noqa: BLE001 - sympy cannot print zoo, nan… for numpy: nowhere a number
        return False


def _numpy(e: sp.Expr, xs) -> callable:
    f = _lambdified(e, tuple(xs))
    if f is False:
        return lambda pts: np.full(pts.shape[0], np.nan)

    def call(pts: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            try:
                v = np.asarray(f(*[pts[:, i] for i in range(pts.shape[1])]), dtype=complex)
            except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                return np.full(pts.shape[0], np.nan)
        v = np.broadcast_to(v, (pts.shape[0],))
        return np.where(np.abs(v.imag) <= 1e-12 * np.maximum(1.0, np.abs(v.real)), v.real, np.nan)

    return call


# ----------------------------------------------------------------------------------------------
# The singular set


@dataclass
class _Site:
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


def _crossings(g, gf, region: Region, pts, vals, inside, k: int) -> list[_Site]:
    """Zero sets of g crossing R: neighbouring grid points inside R with opposite signs."""
    n = len(region.xs)
    shape = (k,) * n
    V = vals.reshape(shape)
    I = inside.reshape(shape) & np.isfinite(V)
    P = pts.reshape(shape + (n,))
    found: list[_Site] = []
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
            found.append(_Site(p, "crossing", 1, [e, -e]))
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


def _site_at(g, region: Region, p) -> _Site:
    """What kind of zero of g the point p ∈ R̄ is (see the module docstring)."""
    n = len(region.xs)
    active, conds = _inward(region, p)
    if n == 1:
        dirs = _cone(region, p, active, conds, 2) or []
        return _Site(p, "point", 1, [np.array([1.0]), np.array([-1.0])] if not active else dirs)
    if active:  # does g vanish on the face of the box through p?
        fixed = {region.xs[i]: b for i, b, _ in active}
        gf = g.xreplace(fixed)
        free = [x for x in region.xs if x not in fixed]
        if free and _vanishes_near(gf, free, [p[region.xs.index(x)] for x in free], region):
            normal = np.zeros(n)
            for i, _, s in active:
                normal[i] = s
            dirs = [normal / np.linalg.norm(normal)] + _cone(region, p, active, conds, DIRECTIONS - 1)
            return _Site(p, "face", len(active), dirs, tuple((i, b) for i, b, _ in active))
    for j in conds:  # the zero set of a condition active at p, shared with g
        c = region.conds[j]
        try:
            shared = sp.gcd(sp.expand(g), sp.expand(c))
        except (sp.PolynomialError, NotImplementedError, TypeError):
            shared = sp.Integer(1)
        if not shared.is_number:
            grad = np.array([_value(sp.diff(c, x), region.xs, p) for x in region.xs])
            if np.all(np.isfinite(grad)) and np.linalg.norm(grad) > 0:
                return _Site(p, "condition", 1, [grad / np.linalg.norm(grad)]
                             + _cone(region, p, active, conds, DIRECTIONS - 1))
    dirs = _cone(region, p, active, conds, 64)
    if not dirs:
        raise Undecidable(f"no direction into the region at {p}")
    pf = np.array([float(v) for v in p])
    rho = 1e-3 * region.scale
    gv = np.array([_value(g, region.xs, tuple(sp.Float(float(c), DIGITS) for c in pf + rho * d)) for d in dirs])
    if not np.all(np.isfinite(gv)):
        return _Site(p, "unknown", None, dirs[:DIRECTIONS])
    if np.any(gv > 0) and np.any(gv < 0):  # the zero set passes through p into R: a crossing
        order = np.argsort(-np.abs(gv))
        return _Site(p, "crossing", 1, [dirs[i] for i in order[:DIRECTIONS]])
    if np.min(np.abs(gv)) > 1e-12 * max(np.max(np.abs(gv)), 1e-300):
        return _Site(p, "point", n, dirs[:DIRECTIONS])
    return _Site(p, "unknown", None, dirs[:DIRECTIONS])


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


def sites(g: sp.Expr, region: Region) -> list[_Site]:
    """Points of the zero set of g on R̄, each with its shape and codimension."""
    pts, k = region.grid()
    gf = _numpy(g, region.xs)
    vals = gf(pts)
    inside = region.inside(pts)
    crossing = _crossings(g, gf, region, pts, vals, inside, k)
    if crossing:
        return crossing
    return [_site_at(g, region, p) for p in _touchings(g, gf, region, pts, vals, inside)]


# ----------------------------------------------------------------------------------------------
# Growth exponents and verdicts


def growth(w: sp.Expr, xs, p, v: np.ndarray, scale: float) -> float | None:
    """α with |w(p + t·v)| ~ t^-α (None: w vanishes there, or no power law)."""
    logs = []
    for k in (3, 5, 7):
        t = sp.Float(10.0 ** -k * scale, DIGITS)
        q = [pi + t * sp.Float(float(vi), DIGITS) for pi, vi in zip(p, v)]
        val = _value(w, xs, q)
        if not math.isfinite(val):
            return None
        if val == 0:
            return None
        logs.append(math.log10(abs(val)))
    s1, s2 = (logs[1] - logs[0]) / 2, (logs[2] - logs[1]) / 2
    if abs(s1 - s2) > 0.05:
        raise Undecidable("the integrand does not grow like a power there")
    return s2


def _logarithmic(w: sp.Expr, xs, p) -> bool:
    for a, where in _log_points(w):
        v = _value(a, xs, p)
        if not math.isfinite(v) or abs(abs(v) - where) < 1e-30:
            return True
    return False


def decide(alpha_typ: float, alpha_max: float, codim: int, logarithmic: bool) -> Verdict:
    margin = 0.1 if logarithmic else 0.01
    if alpha_max < codim - margin:
        return Verdict.INTEGRABLE
    if alpha_typ >= codim - 0.01 and not (logarithmic and abs(alpha_typ - codim) < 0.1):
        return Verdict.DIVERGENT
    return Verdict.UNDECIDED


#: The sympy functions of the primitives defined and finite on all of ℝ (exp, sin, cos, tanh, atan, erf).
_EVERYWHERE = tuple(getattr(sp, p.sympy) for p in REGISTRY.values()
                    if isinstance(getattr(sp, p.sympy, None), type) and p.domain.everywhere)

#: Largest degree of a pole base whose real roots :func:`_zero_free` counts exactly.
ZERO_FREE_DEGREE = 20


def finite_on_box(w: sp.Expr, xs: Sequence[sp.Symbol], box: tuple[tuple[sp.Expr, sp.Expr], ...]) -> bool:
    """Is ``w`` certainly defined and finite on the whole closed box?  Built of the variables,
    finite real numbers, +, ·, integer powers and the primitives defined on all of ℝ, with every
    negative power's base free of zeros on the box (:func:`_zero_free`, exact).  Then
    :func:`blowups` has nothing to find on any region inside the box (no pole base vanishes
    there, no partial primitive is applied): a caller need not build the regions of a sum of 10⁴
    pieces ``[x ≥ c_k] / (x + 1)``.  False says nothing."""
    xs = tuple(xs)
    for n in sp.preorder_traversal(w):
        if n.is_Symbol:
            if n not in xs:
                return False
        elif n.is_Number:
            if n.is_finite is not True:
                return False
        elif n.is_Pow:
            if not n.exp.is_Integer or (n.exp < 0 and not _zero_free(n.base, xs, box)):
                return False
        elif not (n.is_Add or n.is_Mul or n.is_NumberSymbol or isinstance(n, _EVERYWHERE)):
            return False
    return True


@functools.lru_cache(maxsize=4096)  # one pole base, many regions
def _zero_free(g: sp.Expr, xs: tuple, box: tuple) -> bool:
    """Has ``g`` no zero on the closed box?  Decided exactly for a polynomial in one variable with
    rational coefficients, of degree at most :data:`ZERO_FREE_DEGREE`, on a side with rational
    ends (Sturm's count of its real roots there: 0); a nonzero finite number has none; anything
    else: False (not known)."""
    free = g.free_symbols
    if not free:
        return bool(g.is_Number and g.is_finite and g != 0)
    if len(free) != 1 or not free <= set(xs):
        return False
    (x,) = free
    lo, hi = box[xs.index(x)]
    if not (lo.is_Rational and hi.is_Rational and lo <= hi):
        return False
    try:
        p = sp.Poly(g, x)
    except sp.PolynomialError:
        return False
    if p.domain not in (sp.ZZ, sp.QQ) or p.degree() > ZERO_FREE_DEGREE:
        return False
    return p.count_roots(lo, hi) == 0


def blowups(w: sp.Expr, region: Region) -> list[Blowup]:
    """Every place where ``w`` blows up on R̄, with its verdict."""
    out: list[Blowup] = []
    if region.empty:
        return out
    for g in pole_bases(w, region.xs):
        try:
            found = sites(g, region)
        except Undecidable:
            out.append(Blowup(g, (), "unknown", None, None, None, Verdict.UNDECIDED, Verdict.UNDECIDED))
            continue
        for s in found:
            out.append(_judge(w, g, s, region))
    return out


def _judge(w: sp.Expr, g: sp.Expr, s: _Site, region: Region) -> Blowup:
    logarithmic = _logarithmic(w, region.xs, s.point)
    if s.codim is None:
        return Blowup(g, s.point, s.shape, None, None, None, Verdict.UNDECIDED, Verdict.UNDECIDED, logarithmic)
    alphas = []
    try:
        for v in s.directions:
            a = growth(w, region.xs, s.point, v, region.scale)
            if a is not None:
                alphas.append(a)
    except Undecidable:
        return Blowup(g, s.point, s.shape, s.codim, None, None, Verdict.UNDECIDED, Verdict.UNDECIDED,
                      logarithmic, s.face)
    if not alphas:  # w vanishes along every direction tried: no blow-up there
        return Blowup(g, s.point, s.shape, s.codim, 0.0, 0.0, Verdict.INTEGRABLE, Verdict.INTEGRABLE,
                      logarithmic, s.face)
    typ, top = statistics.median(alphas), max(alphas)
    return Blowup(g, s.point, s.shape, s.codim, typ, top, decide(typ, top, s.codim, logarithmic),
                  decide(2 * typ, 2 * top, s.codim, logarithmic), logarithmic, s.face)


# ----------------------------------------------------------------------------------------------
# The pieces of an integrand, and the exact engine's verdict

#: CPU seconds the exact engine gives the analysis of one integral (beyond: nothing is claimed).
TIME_LIMIT = 5.0


def piece_blowups(pieces, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
                  at: Mapping[sp.Symbol, sp.Expr]) -> Iterator[tuple[sp.Expr, list[Blowup]]]:
    """Each simply decomposable piece's weight (Def. 6.2: ``weight``, ``conditions``) at the parameter
    values ``at`` (``box`` already at them) with its blow-ups on its region, piece by piece.  A piece
    whose weight is constant in the variables or :func:`finite_on_box` is skipped (nothing blows up
    on any region of the box), and so is a region the analysis cannot describe."""
    whole = tuple(tuple(side) for side in box)
    for pc in pieces:
        w = sp.sympify(pc.weight).xreplace(at)
        if not (w.free_symbols & set(xs)) or finite_on_box(w, xs, whole):
            continue
        conds = [sp.sympify(c.expr).xreplace(at) for c in pc.conditions]
        try:
            region = Region(xs, box, conds)
        except Undecidable:
            continue
        yield w, blowups(w, region)


@dataclass(frozen=True)
class Divergent:
    """``what`` (⟦t⟧, or ⦇t⦈'s regular part) is not integrable: its piece's weight ``weight`` blows up
    as ``blowup`` says (a divergent verdict), over the variables ``names``."""

    weight: sp.Expr
    blowup: Blowup
    names: tuple[str, ...]
    what: str = "the integrand"

    @property
    def reason(self) -> str:
        b = self.blowup
        pt = ", ".join(_text(v) for v in b.point)
        at = f"({', '.join(self.names)}) = ({pt})" if len(self.names) > 1 else f"{self.names[0]} = {pt}"
        where = f"on the zero set of {sp.sstr(b.base)} (e.g. at {at})" if b.shape == "crossing" else f"at {at}"
        return (f"{self.what} {sp.sstr(self.weight)} is not integrable: it blows up {where} like "
                f"dist^-{b.alpha:.3g} near a set of codimension {b.codim}, and a singularity of order α is "
                "integrable only when α is below that codimension: the integral diverges (a principal value "
                "or a quadrature that converges to one is not ⟦p⟧)")


def _text(v) -> str:
    f = _num(v)
    return f"{f:.6g}" if math.isfinite(f) else sp.sstr(v)


def divergence(pieces, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]],
               at: Mapping[sp.Symbol, sp.Expr], what: str = "the integrand") -> Divergent | None:
    """The first blow-up of the ``pieces`` of ``what`` (⟦t⟧'s, or ⦇t⦈'s regular part's, at the
    parameter values ``at``) at which it is not integrable on the box, or None: integrable,
    undecided, or not decided within :data:`TIME_LIMIT` CPU seconds (nothing is claimed then)."""
    ends = [(sp.sympify(lo).xreplace(at), sp.sympify(hi).xreplace(at)) for lo, hi in box]

    def first() -> Divergent | None:
        for w, found in piece_blowups(pieces, tuple(xs), ends, at):
            for b in found:
                if b.verdict is Verdict.DIVERGENT:
                    return Divergent(w, b, tuple(str(x) for x in xs), what)
        return None

    try:
        return Deadline(TIME_LIMIT).run(first)
    except Exception:  # noqa: BLE001 - time, or a case the analysis cannot evaluate: nothing is claimed
        return None
