"""Samplers: points in a box (the domain) and on the zero set of a condition (a delta's support).

* :func:`design` draws points in the unit cube [0,1]^m — ``"uniform"`` (i.i.d.), ``"stratified"``
  or ``"qmc"`` (independent replicates of jittered grids or scrambled Sobol' nets, each shifted and
  tent-transformed so that a jump cannot make them err alike: :mod:`.replicates`) — and knows how
  to turn values at those points into an estimate of the mean with a standard error.
* :class:`SiteSampler` samples the zero set {π₀Ψ̂ = 0} of one diffeomorphic conditional (a *site*)
  through every branch of Ψ̂⁻¹ and weighs each point by |det DΨ̂_b⁻¹(0, u')| computed by the
  engine's own forward mode (see the package docstring for the estimator).
* interval enclosures (:mod:`.interval`) bound the coordinates u' of the zero set when Ψ̂'s
  other components are not plain variables, and find the part of them the box can meet.
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from .. import lazy
from ..core import Diffeo, Var
from ..records import record
from .compile import compile_pure
from .pcg64 import Stream
from .point import TANGENT, UNLINKED, VALUE, Point, full
from .scaled import homogeneous

# Interval enclosures of a zero set's other coordinates, imported when a site's condition is not
# completed by variables alone (start-up of a one-shot ``langur eval`` on an affine program, issue 15).
interval = lazy.module("langur.operational.interval")
# The replicate designs (stratified, qmc) and their standard error, imported when first drawn: the
# default uniform design never needs them (start-up of a one-shot ``langur eval``, issue 15).
replicates = lazy.module("langur.operational.replicates")

METHODS = ("uniform", "stratified", "qmc")


# -- designs in the unit cube ---------------------------------------------------------------------

@record
class Design:
    """``points`` (N, m) in [0,1]^m and the estimator of the mean of f over the cube."""

    points: np.ndarray
    method: str
    groups: int = 0  # stratified, qmc: the number of independent randomizations (replicates)

    def mean(self, f: np.ndarray) -> tuple[float, float]:
        """Estimate of ∫_{[0,1]^m} f and its standard error (finite for finite samples, however
        large: :func:`.scaled.homogeneous`)."""
        return homogeneous(self._mean, np.asarray(f))

    def _mean(self, f: np.ndarray) -> tuple[float, float]:
        n = len(f)
        if n == 0:
            return 0.0, 0.0
        if self.method == "exact" or n == 1 and self.method == "uniform" and self.points.shape[1] == 0:
            return float(f[0]) if n == 1 else float(np.mean(f)), 0.0
        if self.method in ("stratified", "qmc"):  # the replicates' means are i.i.d. unbiased estimates
            return replicates.mean(f, self.groups)
        est = float(np.mean(f))
        se = float(np.std(f, ddof=1)) / math.sqrt(n) if n > 1 else float("inf")
        return est, se


def design(rng: Stream | np.random.Generator, m: int, samples: int, method: str) -> Design:
    """``samples`` points (or the nearest count the method supports) in [0,1]^m."""
    if method not in METHODS:
        raise ValueError(f"unknown Monte Carlo method {method!r} (one of {', '.join(METHODS)})")
    if int(samples) < 2:
        raise ValueError(f"samples must be at least 2 (a standard error needs two), got {samples}")
    if m == 0:  # a point: the zero set of a condition in one variable is a set of roots
        return Design(np.zeros((1, 0)), "exact")
    samples = int(samples)
    if method == "uniform":
        return Design(rng.random((samples, m)), "uniform")
    points, groups = (replicates.stratified if method == "stratified" else replicates.qmc)(rng, m, samples)
    return Design(points, method, groups)


# -- boxes beyond the doubles ---------------------------------------------------------------------
# A box of doubles can be wider than any double: [−1e308, 1e308] is 2e308 long, so hi − lo is ∞,
# lo + u·∞ is ∞ or NaN (u = 0), and vol · mean is ∞·0 = NaN where the integral is 0
# (bench/history/2026-11-29.md#hostile32.  Both are computed differently only there: an ordinary box keeps
# its very points and volume.

def spread(lo: np.ndarray, hi: np.ndarray, unit: np.ndarray) -> np.ndarray:
    """The points lo·(1 − u) + hi·u of the box [lo, hi] for the unit-cube points ``unit`` (arrays
    that broadcast): where hi − lo is a double, :func:`design`'s callers' ``lo + u·(hi − lo)``;
    the form here where it is not."""
    return lo * (1 - unit) + hi * unit


def volume_parts(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The volumes Π (hi − lo) along the last axis as ``mantissa · 2**exponent`` (numpy's frexp of
    each side, whose halves are doubles: hi/2 − lo/2), for boxes whose volume is no double; an
    estimate vol · mean is then ``np.ldexp(mantissa · mean, exponent)``, ±∞ only when it is."""
    f, e = np.frexp(hi / 2 - lo / 2)
    return np.prod(f, axis=-1), np.sum(e + 1, axis=-1)


# -- sampling the zero set of one condition -------------------------------------------------------

#: Cells per coordinate of the grid over the u'-box that :meth:`SiteSampler.shrink` encloses
#: (for one, two, three or more coordinates).
SHRINK_CELLS = (64, 16, 6)
#: Most cells of that grid, per parameter point: with more coordinates each gets fewer cells (6 per
#: coordinate were 6⁴⁰ cells for a zero set in 41 variables, an out-of-memory:
#: bench/history/2026-11-29.md#hostile32 — down to one, the u'-box itself, which still finds a zero set
#: missing the box.
SHRINK_MOST = 6 ** 5
#: Rounds of shrinking, while a round still removes more than 1 − SHRINK_ENOUGH of the volume.
SHRINK_ROUNDS, SHRINK_ENOUGH = 8, 0.8
#: The narrower box replaces the u'-box only when its volume is at most this fraction of it.
SHRINK_WORTH = 0.25


class SiteSampler:
    """Points on {π₀Ψ̂ = 0} for one site, with weights, compiled once per canonical Ψ̂.

    ``psi`` is in the program's variables (all of them, in order) with every parameter a program
    parameter (lets and call arguments substituted: see link.py).  The coordinates u' are Ψ̂'s
    components 1..n−1; they are ordered canonically (identity components in the program's
    variable order first, then the others in Ψ̂'s order) so that the inlined and the linked
    program draw identical points.
    """

    def __init__(self, psi: Diffeo, variables: tuple[str, ...]):
        self.psi = psi
        self.variables = variables
        self._condition = None
        self._branches = None
        self._enclosures = None
        self._nonzero = None
        self.on_numbers = False
        self.has_guards = any(b.guards for b in psi.branches)
        coords = []
        for i in range(1, len(psi.forward)):
            f = psi.forward[i]
            if isinstance(f, Var) and f.name in variables:
                coords.append(((0, variables.index(f.name)), psi.inputs[i], f.name, None))
            else:
                coords.append(((1, i), psi.inputs[i], None, f))
        coords.sort(key=lambda c: c[0])
        self.coords = [(u, var, term) for _, u, var, term in coords]

    @property
    def condition(self):
        """π₀Ψ̂ compiled (on first use: a site the direction does not move is never compiled)."""
        if self._condition is None:
            self._compile()
        return self._condition

    @property
    def numbers(self) -> bool:
        """Whether π₀Ψ̂ and every inverse branch's components and guards give the same doubles run on
        Python floats as on arrays (:attr:`~.sharing.Sharing.numbers`): a zero set's point in one
        variable is then found on numbers, without numpy's cost per call on arrays of one element."""
        if self._branches is None:
            self._compile()
        return self.on_numbers

    @property
    def branches(self):
        """Each inverse branch's components and guards, compiled on first use."""
        if self._branches is None:
            self._compile()
        return self._branches

    def _compile(self) -> None:
        """π₀Ψ̂ and every inverse branch's components and guards, compiled together (a site whose
        zero set is sampled needs both: its points and D_γ π₀Ψ̂·γ' there)."""
        branches = self.psi.branches
        terms = [self.psi.forward[0], *(t for b in branches for t in (*b.components, *b.guards))]
        fns, self.on_numbers = compile_pure(terms)
        fns = iter(fns)
        self._condition = next(fns)
        self._branches = [([next(fns) for _ in b.components], [next(fns) for _ in b.guards]) for b in branches]

    def vanishing(self, params: dict):
        """Where one of Ψ̂'s ``nonzero`` coefficients (``Diffeo.nonzero``: what the completion
        divides by, such as ``a`` in ``a*x - 1/2``) is exactly 0 at ``params`` (numbers, or arrays
        of P points): Ψ̂ is no diffeomorphism there and ⦇p⦈ is not defined (its inverse divides by
        zero).  A bool, or a bool array of the parameters' shape."""
        if not self.psi.nonzero:
            return False
        if self._nonzero is None:
            self._nonzero = compile_pure(self.psi.nonzero)[0]
        env = Point({}, params, mode=VALUE)
        out = False
        for fn in self._nonzero:
            out = out | (np.asarray(fn(env, UNLINKED)[0], dtype=float) == 0.0)
        return out

    def region(self, box: dict[str, tuple[float, float]], params: dict) -> list[tuple[float, float]]:
        """The u'-box: a variable's own interval, or an interval enclosure of Ψ̂'s component."""
        lo, hi = self.region_many(_column(box), params)
        return [(float(a), float(b)) for a, b in zip(lo[0], hi[0])]

    def region_many(self, box: dict, params: dict) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`region` at P points: ``box`` maps each variable to (lo, hi) arrays of shape (P,
        1); ``params`` values are numbers or (P, 1) arrays.  Returns (lo, hi), shape (P, m)."""
        npts = next(iter(box.values()))[0].shape[0]
        los, his = [], []
        for _, var, term in self.coords:
            lo, hi = box[var] if var is not None else interval.enclose(term, box, params)
            los.append(np.broadcast_to(lo, (npts, 1)))
            his.append(np.broadcast_to(hi, (npts, 1)))
        if not los:
            return np.zeros((npts, 0)), np.zeros((npts, 0))
        return np.concatenate(los, axis=1).astype(float), np.concatenate(his, axis=1).astype(float)

    def shrink(self, region, box: dict[str, tuple[float, float]], params: dict) -> list[tuple[float, float]]:
        """The part of the u'-box whose points can lie on the zero set *inside the program's box*
        (see :meth:`shrink_many`); an empty result (every interval of zero width) means the zero
        set misses the box."""
        if not region:
            return region
        lo = np.array([[a for a, _ in region]], dtype=float)
        hi = np.array([[b for _, b in region]], dtype=float)
        lo, hi = self.shrink_many(lo, hi, _column(box), params)
        return [(float(a), float(b)) for a, b in zip(lo[0], hi[0])]

    def shrink_many(self, lo: np.ndarray, hi: np.ndarray, box: dict, params: dict):
        """The hull of the cells of a grid over each u'-box (``lo``, ``hi``: shape (P, m)) where
        some inverse branch's enclosure meets the program's box (``box``: variable → (P, 1)
        arrays) and its guards can hold.  Interval enclosures are conservative, so no point of
        the zero set inside the box is cut away (the estimate stays unbiased); a zero set that
        crosses a small part of a wide box is then sampled where it is, not missed.  Rounds
        repeat on the narrower hull while a round still removes much; the narrower box is kept
        only when it is much narrower (else the design over the full box is kept)."""
        original = (lo, hi)
        npts = lo.shape[0]
        active = np.ones(npts, dtype=bool)
        empty = np.zeros(npts, dtype=bool)
        lo, hi = lo.copy(), hi.copy()
        for _ in range(SHRINK_ROUNDS):  # a narrower hull, gridded again, may shrink further
            idx = np.flatnonzero(active)
            if not len(idx):
                break
            sub_box = {v: (a[idx], b[idx]) for v, (a, b) in box.items()}
            sub_params = {k: (v[idx] if np.ndim(v) == 2 else v) for k, v in params.items()}
            slo, shi = self._shrink_once(lo[idx], hi[idx], sub_box, sub_params)
            gone = np.any(shi <= slo, axis=1)
            done = np.prod(shi - slo, axis=1) > SHRINK_ENOUGH * np.prod(hi[idx] - lo[idx], axis=1)
            lo[idx], hi[idx] = slo, shi
            empty[idx[gone]] = True
            active[idx[gone | done]] = False
        # sample the narrower box only when it is much narrower: the design (and a fold's change of
        # variables) over the full box is kept where the zero set already fills most of it
        keep = ~empty & (np.prod(hi - lo, axis=1) > SHRINK_WORTH * np.prod(original[1] - original[0], axis=1))
        return np.where(keep[:, None], original[0], lo), np.where(keep[:, None], original[1], hi)

    def _shrink_once(self, lo, hi, box, params):
        npts, m = lo.shape
        k = SHRINK_CELLS[min(m, len(SHRINK_CELLS)) - 1]
        while k > 1 and k ** m > SHRINK_MOST:
            k -= 1
        edges = np.linspace(lo, hi, k + 1, axis=2)  # (P, m, k + 1)
        cells = np.array(list(itertools.product(range(k), repeat=m)))  # (K, m)
        cell = {self.psi.inputs[0]: (np.zeros((1, 1)), np.zeros((1, 1)))}
        for j, (u, _, _) in enumerate(self.coords):
            cell[u] = (edges[:, j, cells[:, j]], edges[:, j, cells[:, j] + 1])  # (P, K)
        meets = np.zeros((npts, len(cells)), dtype=bool)
        found = iter(interval.enclose_all(self.enclosures, cell, params))  # every branch's terms: one tape
        for b in self.psi.branches:
            meets |= self._meets(b, found, box)
        any_cell = meets.any(axis=1)
        out_lo = np.stack([np.where(meets, cell[u][0], np.inf).min(axis=1) for u, _, _ in self.coords], axis=1)
        out_hi = np.stack([np.where(meets, cell[u][1], -np.inf).max(axis=1) for u, _, _ in self.coords], axis=1)
        # no cell meets the box: the zero set misses it (zero-width intervals)
        return np.where(any_cell[:, None], out_lo, lo), np.where(any_cell[:, None], out_hi, lo)

    @property
    def enclosures(self):
        """One enclosure tape of every branch's components and guards, in order (they share most
        of their subterms: the conic of Fig. 14's four terms have 403 distinct ones of 1,313)."""
        if self._enclosures is None:
            self._enclosures = interval.tape_of(t for b in self.psi.branches for t in (*b.components, *b.guards))
        return self._enclosures

    def _meets(self, branch, found, box) -> np.ndarray:
        """The cells where ``branch`` can meet the box: ``found`` yields the enclosures of its
        components, then of its guards."""
        ok = None
        for var, _ in zip(self.psi.variables, branch.components):
            clo, chi = next(found)
            blo, bhi = box[var]
            here = ~((chi < blo) | (clo > bhi))
            ok = here if ok is None else ok & here
        for _ in branch.guards:
            ok = ok & ~(next(found)[1] < 0)  # NaN: keep the cell
        return ok

    def points(self, unit: np.ndarray, region, params: dict):
        """Map unit-cube points to the zero set through every branch.

        Returns ``volume`` and, per branch, ``(x: dict var -> array, weight, valid)`` with
        weight = |det DΨ̂_b⁻¹(0, u')| (forward mode, one pass per input) and valid = all guards ≥ 0.
        """
        n = unit.shape[0]
        if not region and not self.coords:  # one variable: the zero set is points, u' has no coordinate
            # (on the number 0 where the branches give the same doubles on numbers as on arrays)
            zero = 0.0 if n == 1 and self.numbers else np.zeros(n)
            return 1.0, self.branch_points({self.psi.inputs[0]: zero}, n, params, None)
        lo = np.array([[r[0] for r in region]], dtype=float).reshape(1, len(region))
        hi = np.array([[r[1] for r in region]], dtype=float).reshape(1, len(region))
        if len(self.coords) == 1 and self.has_guards:
            inputs = {self.psi.inputs[0]: np.zeros(n)}
            inputs[self.coords[0][0]], factor = self.fold_map(unit[:, 0], lo[0, 0], hi[0, 0], params)
            volume = float(hi[0, 0] - lo[0, 0])
            return volume, self.branch_points(inputs, n, params, factor)
        volume, out = self.points_many(unit, lo, hi, params)
        return float(volume[0]), out

    @property
    def folds(self) -> bool:
        """One coordinate u' and guards: the design goes through :meth:`fold_map`."""
        return len(self.coords) == 1 and self.has_guards

    def points_many(self, unit: np.ndarray, lo: np.ndarray, hi: np.ndarray, params: dict, point_params=None):
        """:meth:`points` for P parameter points at once: ``lo``, ``hi`` are the u'-boxes, shape
        (P, m); ``params`` values are scalars or arrays of P·N values (point-major, N = ``unit``'s
        rows), ``point_params`` the same per point (P values; needed where the design folds).
        Returns the volumes (P,) and, per branch, arrays of P·N values."""
        n = unit.shape[0]
        width = hi - lo
        volume = np.prod(width, axis=1) if width.shape[1] else np.ones(width.shape[0])
        size = width.shape[0] * n
        inputs = {self.psi.inputs[0]: np.zeros(size)}
        factor = None
        if self.folds:
            u, factor = self.fold_map_many(unit[:, 0], lo[:, 0], hi[:, 0], point_params)
            inputs[self.coords[0][0]], factor = u.reshape(size), factor.reshape(size)
            return volume, self.branch_points(inputs, size, params, factor)
        for j, (u, _, _) in enumerate(self.coords):
            inputs[u] = (lo[:, j, None] + unit[None, :, j] * width[:, j, None]).reshape(size)
        return volume, self.branch_points(inputs, size, params, None)

    def branch_points(self, inputs: dict, n: int, params: dict, factor):
        """Each branch's points Ψ̂_b⁻¹(0, u'), weights |det DΨ̂_b⁻¹| (times a fold map's
        ``factor``) and guards, at the u' points ``inputs``."""
        out = []
        order = self.psi.inputs
        if len(order) == 1:  # one variable: x = Ψ̂⁻¹(0) and dx/du0 from one forward-mode pass
            tenv = Point(inputs, params, dvars={order[0]: 1.0}, mode=TANGENT)
            for comps, guards in self.branches:
                valid = np.empty(n, dtype=bool)  # (np.ones without its Python frame)
                valid.fill(True)
                for g in guards:
                    valid &= np.asarray(g(tenv, UNLINKED)[0]) >= 0
                v, d = comps[0](tenv, UNLINKED)
                # |dx/du0|: of a number, the number's abs (the same double as np.abs: the sign bit cleared)
                weight = full(abs(d), n) if type(d) is float else np.abs(full(d, n))
                out.append(({self.variables[0]: full(v, n)}, weight, valid))
            return out
        for comps, guards in self.branches:
            env = Point(inputs, params)
            valid = np.ones(n, dtype=bool)
            for g in guards:
                valid &= np.asarray(g(env, UNLINKED)[0]) >= 0
            jac = np.empty((n, len(comps), len(order)))
            x = {}
            for i, u in enumerate(order):  # one forward-mode pass per input: column i of DΨ̂_b⁻¹
                tenv = Point(inputs, params, dvars={u: 1.0}, mode=TANGENT)
                for j, c in enumerate(comps):
                    v, d = c(tenv, UNLINKED)
                    jac[:, j, i] = 0.0 if d is None else d
                    if i == 0:
                        x[self.variables[j]] = full(v, n)
            weight = np.abs(jac[:, 0, 0]) if len(order) == 1 else np.abs(np.linalg.det(jac))
            if factor is not None:
                weight = np.where(factor > 0, weight * factor, 0.0)
            out.append((x, weight, valid))
        return out

    def fold_map(self, s: np.ndarray, lo: float, hi: float, params: dict, grid: int = 257):
        """Where branches fold, |det DΨ̂_b⁻¹| ~ 1/√(distance to the guard's root): integrable, not
        square-integrable.  For a 1-dimensional u' this maps the design through a change of
        variables u = T(s) that vanishes like s² at each root: [lo, hi] is cut at the guards'
        roots (found on a grid, refined by bisection), and each piece [p, q] is run through
        u = p + (q − p)(1 − cos πt)/2, so f(T(s))·T'(s) is bounded.  The design's points s stay
        uniform on [0, 1] with vol = hi − lo, so the returned factor is T'(s)/(hi − lo).  Any cut
        points give an exact change of variables (unbiased); good ones only lower the variance.
        Without a root on [lo, hi] (nor at its ends) the map is the identity."""
        u, factor = self.fold_map_many(s, np.array([lo], dtype=float), np.array([hi], dtype=float), params, grid)
        return u[0], factor[0]

    def fold_map_many(self, s: np.ndarray, lo: np.ndarray, hi: np.ndarray, params: dict, grid: int = 257):
        """:meth:`fold_map` for P parameter points at once: ``lo``, ``hi`` shape (P,), ``params``
        values numbers or arrays (P,); the guards are evaluated on every point's grid, and their
        roots bisected, in one pass each.  Returns u and the factor, shape (P, N)."""
        npts = lo.shape[0]
        u_name = self.coords[0][0]
        zero = self.psi.inputs[0]
        cuts: list[list[float]] = [[float(lo[i]), float(hi[i])] for i in range(npts)]
        xs = np.linspace(lo, hi, grid, axis=1)  # (P, grid)
        at_ends = np.zeros(npts, dtype=bool)

        def rows(idx):  # the parameters of the points ``idx`` (one per value to evaluate)
            return {k: (np.asarray(v)[idx] if np.ndim(v) else v) for k, v in params.items()}

        for _, guards in self.branches:
            for g in guards:
                def value(u, idx, g=g):
                    v = g(Point({zero: np.zeros(len(u)), u_name: u}, rows(idx)), UNLINKED)[0]
                    return np.broadcast_to(np.asarray(v, dtype=float), u.shape)

                owner = np.repeat(np.arange(npts), grid)
                vals = value(xs.reshape(-1), owner).reshape(npts, grid)
                with np.errstate(all="ignore"):
                    scale = 1e-9 * (1.0 + np.nanmax(np.abs(vals), axis=1))
                at_ends |= np.any(np.abs(vals[:, [0, -1]]) <= scale[:, None], axis=1)
                sg = vals >= 0
                p, k = np.nonzero(sg[:, 1:] != sg[:, :-1])
                a, b, sa = xs[p, k], xs[p, k + 1], sg[p, k]
                for _ in range(60 if len(k) else 0):
                    m = 0.5 * (a + b)
                    same = (value(m, p) >= 0) == sa
                    a, b = np.where(same, m, a), np.where(same, b, m)
                for i, c in zip(p.tolist(), (0.5 * (a + b)).tolist()):
                    cuts[i].append(c)
        n = s.shape[0]
        u, factor = np.empty((npts, n)), np.empty((npts, n))
        for i in range(npts):  # each point's cuts: a piecewise map of its own
            lo_i, hi_i = float(lo[i]), float(hi[i])
            if len(cuts[i]) == 2 and not at_ends[i] or not hi_i > lo_i:  # no fold: the plain uniform map
                u[i], factor[i] = lo_i + s * (hi_i - lo_i), 1.0
                continue
            pts = np.array(sorted({c for c in cuts[i] if lo_i <= c <= hi_i}))
            frac = (pts - lo_i) / (hi_i - lo_i)
            j = np.clip(np.searchsorted(frac, s, side="right") - 1, 0, len(pts) - 2)
            t = (s - frac[j]) / (frac[j + 1] - frac[j])
            u[i] = pts[j] + (pts[j + 1] - pts[j]) * (1.0 - np.cos(np.pi * t)) / 2.0
            factor[i] = (np.pi / 2.0) * np.sin(np.pi * t)
        return u, factor

    def dpsi(self, x: dict, params: dict, dparams: dict):
        """D_γ π₀Ψ̂ · γ' at the points ``x`` (forward mode in the parameters); at one point on
        numbers where π₀Ψ̂ gives the same doubles on numbers as on arrays (:attr:`numbers`)."""
        if self.numbers and all(type(v) is np.ndarray and v.shape == (1,) for v in x.values()):
            x = {k: float(v[0]) for k, v in x.items()}
        d = self.condition(Point(x, params, dparams=dparams, mode=TANGENT), UNLINKED)[1]
        return 0.0 if d is None else d


def _column(box: dict[str, tuple[float, float]]) -> dict:
    """A box of numbers as the (1, 1) arrays :meth:`SiteSampler.region_many` reads."""
    return {v: (np.array([[float(a)]]), np.array([[float(b)]])) for v, (a, b) in box.items()}


def evaluate_box(box_fns, params: dict) -> list[tuple[float, float]]:
    """Program.box at the parameters (box terms are variable-free)."""
    env = Point({}, params, mode=VALUE)
    return [(float(lo(env, UNLINKED)[0]), float(hi(env, UNLINKED)[0])) for lo, hi in box_fns]
