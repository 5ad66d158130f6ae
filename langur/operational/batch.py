"""Monte Carlo estimates at many parameter points at once: images (§10.1, Fig. 13).

An image is one integral per pixel, the pixel's position among the parameters.
:func:`estimate_batch` evaluates ⟦p⟧ — and, given a direction γ', ⦇p⦈ split into its regular
part (standard AD, the paper's Dˢ) and its boundary part — at P parameter points with one
compiled program: the points are laid out point-major in flat arrays (P·N samples), so each
compiled closure runs once over all of them (no Python loop per point).  Every point uses the
design that :func:`~.estimate.estimate_value` / :func:`~.estimate.estimate_derivative` draw from
``np.random.default_rng(seed)``, so point i of a batch gives the numbers of the per-point API at
point i with the same seed (``proofs_tests/test_batch.py`` checks it).

The zero-set samplers' boxes (interval enclosures, §9) are found for all points at once; the
mapping of the design onto each zero set, its Jacobians and the integrand are evaluated in one
pass.  A zero set's work depends only on the parameters its condition reads, so it is kept
(:func:`_geometry`) for the next image of the same scene — another colour channel, another
shader — and reused array for array: the numbers are those of computing it again.
"""

from __future__ import annotations

import math
import weakref
from collections import OrderedDict
from dataclasses import field

import numpy as np

from ..core import diffeo_params, free_params, refusals_located
from ..records import frozen
from ..values import ParameterError
from .estimate import LOW_HITS, _inside, prepare
from .link import CACHE, CompileCache, Linked
from .pcg64 import Stream
from .point import DELTA, TANGENT, VALUE, Point, full
from .sample import design, spread, volume_parts

#: At most this many samples (points × samples per point) are evaluated in one pass.
CHUNK = 1_000_000


@frozen
class BatchEstimate:
    """Estimates at P parameter points: arrays of shape (P,).  ``params`` holds each parameter's
    value per point (broadcast); ``value``/``stderr`` estimate ⟦p⟧.  With a direction,
    ``derivative``/``derivative_stderr`` estimate ⦇p⦈ = ``regular`` + ``boundary``; ``regular`` is
    standard AD (deltas dropped).  ``low_hits``: points where a zero set was hit by fewer than
    :data:`~.estimate.LOW_HITS` samples (their boundary standard error is not reliable).

    Every point draws the same design (the per-point API's, for the seed): their errors are
    correlated (common random numbers: an image's noise is smooth across pixels), so the
    standard error of a sum over points is at most the sum of the points' standard errors — not
    the root of the sum of their squares."""

    params: dict[str, np.ndarray]
    value: np.ndarray
    stderr: np.ndarray
    samples: int
    seed: int
    method: str
    direction: dict[str, float] | None = None
    regular: np.ndarray | None = None
    regular_stderr: np.ndarray | None = None
    boundary: np.ndarray | None = None
    boundary_stderr: np.ndarray | None = None
    low_hits: np.ndarray | None = None
    notes: tuple[str, ...] = field(default=())

    @property
    def derivative(self) -> np.ndarray | None:
        return None if self.regular is None else self.regular + self.boundary

    @property
    def derivative_stderr(self) -> np.ndarray | None:
        return None if self.regular is None else np.sqrt(self.regular_stderr ** 2 + self.boundary_stderr ** 2)

    @property
    def standard_ad(self) -> np.ndarray | None:
        return self.regular


@refusals_located
def estimate_batch(program_or_loaded, params: dict, *, direction: dict | None = None, samples: int = 10000,
                   seed: int = 0, method: str = "uniform", sites: str = "inlined",
                   cache: CompileCache = CACHE) -> BatchEstimate:
    """⟦p⟧ (and ⦇p⦈ in ``direction``) at every point of ``params``: each value a number or a 1-D
    array, the arrays of one length P (the points); parameters left out take their defaults
    (for a Loaded).  Raises :class:`~langur.values.ParameterError` as the per-point API does."""
    arrays = {k: np.asarray(v, dtype=float) for k, v in params.items()}
    sizes = {a.shape[0] for a in arrays.values() if a.ndim == 1}
    if len(sizes) > 1 or any(a.ndim > 1 for a in arrays.values()):
        raise ValueError("every parameter's values must be a number or a 1-D array, all of one length")
    npts = sizes.pop() if sizes else 1
    if npts == 0:
        raise ValueError("no parameter points")
    first = {k: float(a[0]) if a.ndim else float(a) for k, a in arrays.items()}
    linked, p0 = prepare(program_or_loaded, first, sites, direction, cache)
    bad = [k for k, a in arrays.items() if not np.all(np.isfinite(a))]
    if bad:
        raise ParameterError(f"parameter(s) {', '.join(sorted(bad))} have non-finite values")
    grid = {k: (np.broadcast_to(arrays[k], (npts,)) if k in arrays else np.full(npts, v)) for k, v in p0.items()}
    dp = {k: float(v) for k, v in (direction or {}).items() if float(v) != 0.0}
    per = max(1, CHUNK // max(1, int(samples)))
    parts = [_chunk(linked, {k: v[i:i + per] for k, v in grid.items()}, dp if direction is not None else None,
                    samples, seed, method) for i in range(0, npts, per)]
    cat = {name: np.concatenate([part[name] for part in parts]) for name in parts[0]}
    extra = {}
    if direction is not None:
        extra = dict(direction=dp, regular=cat["reg"], regular_stderr=cat["reg_se"], boundary=cat["bnd"],
                     boundary_stderr=cat["bnd_se"], low_hits=cat["low"])
    notes = ()
    if direction is not None and np.any(cat["low"]):
        notes = (f"low hits: at {int(np.count_nonzero(cat['low']))} of {npts} points a zero set was hit by fewer "
                 f"than {LOW_HITS} samples; their standard errors are not reliable (give more samples)",)
    if direction is not None and np.any(cat["degenerate"]):
        notes += (f"⦇p⦈ is not defined at {int(np.count_nonzero(cat['degenerate']))} of {npts} points: the "
                  "completion of a condition divides by a parameter coefficient that is 0 there (no "
                  "diffeomorphism); the derivative is NaN there",)
    return BatchEstimate({k: np.array(v) for k, v in grid.items()}, cat["value"], cat["se"], int(samples), seed,
                         method, notes=notes, **extra)


def _run(linked: Linked, x, params, **point) -> tuple:
    return linked.fn(Point(x, params, **point), linked.linking)


def _rows_mean(d, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The design's estimate of the mean and its standard error, row by row of ``f`` (P, N)."""
    if d.method == "uniform" and f.shape[1] > 1:
        n = f.shape[1]
        return np.mean(f, axis=1), np.std(f, axis=1, ddof=1) / math.sqrt(n)
    rows = [d.mean(row) for row in f]
    return np.array([r[0] for r in rows]), np.array([r[1] for r in rows])


def _box(linked: Linked, grid: dict, npts: int) -> tuple[np.ndarray, np.ndarray]:
    """Program.box at each point: lower and upper ends, shape (P, m)."""
    env = Point({}, grid, mode=VALUE)
    lo = [np.broadcast_to(np.asarray(f(env, linked.linking)[0], dtype=float), (npts,)) for f, _ in linked.box_fns]
    hi = [np.broadcast_to(np.asarray(g(env, linked.linking)[0], dtype=float), (npts,)) for _, g in linked.box_fns]
    return np.stack(lo, axis=1), np.stack(hi, axis=1)


def _chunk(linked: Linked, grid: dict, dp: dict | None, samples: int, seed: int, method: str) -> dict:
    npts = len(next(iter(grid.values())))
    rng = Stream(seed)  # numpy's default_rng(seed), its draws without numpy.random
    m = len(linked.variables)
    d = design(rng, m, samples, method)
    n = d.points.shape[0]
    lo, hi = _box(linked, grid, npts)
    with np.errstate(over="ignore"):  # (a box beyond the doubles: handled below)
        width = hi - lo
    undefined = np.any(np.isnan(lo) | np.isnan(hi), axis=1)
    empty = ~undefined & np.any(~(hi > lo), axis=1)
    volume = np.prod(np.where(empty[:, None], 1.0, width), axis=1)
    pts = lo[:, None, :] + d.points[None, :, :] * width[:, None, :]
    wide = ~np.isfinite(volume) & ~undefined & ~empty  # boxes beyond the doubles ([−1e308, 1e308])
    if np.any(wide):
        pts[wide] = spread(lo[wide, None, :], hi[wide, None, :], d.points[None, :, :])
        mantissa, exponent = volume_parts(lo[wide], hi[wide])
        volume = volume.copy()
        volume[wide] = mantissa
    else:
        exponent = None
    x = {v: pts[:, :, i].reshape(npts * n) for i, v in enumerate(linked.variables)}
    rep = {k: np.repeat(v, n) for k, v in grid.items()}
    out = {}
    with np.errstate(all="ignore"):
        f = full(_run(linked, x, rep, mode=VALUE)[0], npts * n).reshape(npts, n)
        mean, se = _rows_mean(d, f)
        out["value"], out["se"] = _finish(*_times(volume, exponent, wide, mean, se), empty, undefined)
        if dp is None:
            return out
        g = full(_run(linked, x, rep, dparams=dp, mode=TANGENT)[1], npts * n).reshape(npts, n)
        mean, se = _rows_mean(d, g)
        out["reg"], out["reg_se"] = _finish(*_times(volume, exponent, wide, mean, se), empty, undefined)
        bnd, var, low, degenerate = _boundary(linked, grid, dp, rng, samples, method, lo, hi, npts)
        out["bnd"], out["bnd_se"] = _finish(bnd, np.sqrt(var), empty, undefined)
        out["low"], out["degenerate"] = low, degenerate & ~empty
    return out


def _times(volume: np.ndarray, exponent, wide: np.ndarray, mean: np.ndarray, se: np.ndarray):
    """volume · mean and volume · se, where the rows ``wide`` hold their volume as mantissa · 2**exponent
    (``sample.volume_parts``; ``exponent`` None: no such row)."""
    est, err = volume * mean, volume * se
    if exponent is not None:
        est[wide], err[wide] = np.ldexp(est[wide], exponent), np.ldexp(err[wide], exponent)
    return est, err


def _finish(est: np.ndarray, se: np.ndarray, empty: np.ndarray, undefined: np.ndarray):
    """An empty box integrates to 0 exactly; a box outside a primitive's domain to NaN."""
    est = np.where(empty, 0.0, np.where(undefined, math.nan, est))
    se = np.where(empty, 0.0, np.where(undefined, math.nan, se))
    return est, se


def _boundary(linked: Linked, grid: dict, dp: dict, rng, samples: int, method: str, lo, hi, npts: int):
    """Σ_k ∫ E_k δ_k at every point (see :func:`.estimate._boundary`): each site's u'-boxes for all
    points at once, then every site's points at the parameter points whose box it meets, scored in
    one DELTA pass."""
    live = set(dp)
    m = len(linked.variables) - 1
    total, var = np.zeros(npts), np.zeros(npts)
    low = np.zeros(npts, dtype=bool)
    degenerate = np.zeros(npts, dtype=bool)  # Ψ̂ no diffeomorphism: ⦇p⦈ not defined (NaN)
    plan = []  # (site id, design, its points, their volumes, branches [(x, weight, valid, dpsi)], params)
    for k, site in enumerate(linked.sites):
        if not (site.deps & live):
            continue
        degenerate |= np.broadcast_to(site.sampler.vanishing(grid), (npts,))
        des = design(rng, m, samples, method)
        unbounded, idx, volumes, branches = _geometry(site.sampler, des, grid, dp, lo, hi, npts, m)
        total[unbounded] = var[unbounded] = math.nan  # no finite box encloses the zero set here
        if not len(idx):
            continue
        rep = {name: np.repeat(v[idx], des.points.shape[0]) for name, v in grid.items()}
        plan.append((k, des, idx, volumes, branches, rep))
    total[degenerate] = var[degenerate] = math.nan
    if not plan:
        return total, var, low, degenerate
    # every (site, branch) block of its points × N samples one after the other, in one DELTA pass
    ids, xs, ws, oks, dps, reps, boxes, counts = [], {v: [] for v in linked.variables}, [], [], [], [], [], []
    for k, des, idx, _, branches, rep in plan:
        size = len(idx) * des.points.shape[0]
        counts.append(size * len(branches))
        for xb, w, ok, dpsi in branches:
            ids.append(np.full(size, k))
            for v in linked.variables:
                xs[v].append(xb[v])
            ws.append(w)
            oks.append(ok)
            dps.append(full(dpsi, size))
            reps.append(rep)
            boxes.append(np.repeat(idx, des.points.shape[0]))
    site_ids = np.concatenate(ids)
    x = {v: np.concatenate(a) for v, a in xs.items()}
    params = {name: np.concatenate([r[name] for r in reps]) for name in grid}
    _, g = _run(linked, x, params, mode=DELTA, site=site_ids, sites=frozenset(k for k, *_ in plan))
    owner = np.concatenate(boxes)
    inside = _inside(x, {v: (lo[owner, j], hi[owner, j]) for j, v in enumerate(linked.variables)})
    score = np.where(np.concatenate(oks) & inside, np.concatenate(dps) * full(g, len(site_ids)) * np.concatenate(ws), 0.0)
    at = 0
    for (_k, des, idx, volumes, branches, _), c in zip(plan, counts):
        nb = des.points.shape[0]
        f = score[at:at + c].reshape(len(branches), len(idx), nb).sum(axis=0)
        at += c
        if des.method == "exact":
            total[idx] += f.sum(axis=1) if nb > 1 else f[:, 0]
            continue
        hits = np.count_nonzero(f, axis=1)
        low[idx] |= (hits > 0) & (hits < LOW_HITS)
        mean, se = _rows_mean(des, f)
        total[idx] += volumes * mean
        var[idx] += (volumes * se) ** 2
    return total, var, low, degenerate


#: Recent sites' zero-set work (:func:`_geometry`), most recent last, at most GEOMETRY_BYTES of arrays.
_GEOMETRY: OrderedDict = OrderedDict()
GEOMETRY_BYTES = 96 * 2 ** 20


def _geometry(sampler, des, grid: dict, dp: dict, lo, hi, npts: int, m: int):
    """One site's zero set at every point: where no finite box encloses it (``unbounded``), the
    points whose box it meets (``idx``), and there the volumes of their u'-boxes and each
    branch's points, weights, guards and D_γ π₀Ψ̂ · γ' (:meth:`SiteSampler.points_many`).

    All of it depends only on the design, the program's boxes, γ' and the parameters Ψ̂ reads —
    not on the integrand's other parameters — so it is kept (:data:`_GEOMETRY`) and reused,
    array for array, when the same zero set is asked again: another colour channel of an image,
    another shader over the same scene (§10.2: the geometry is the shader's argument)."""
    psi = sampler.psi
    reads = diffeo_params(psi).union(*(free_params(t) for b in psi.branches for t in (*b.components, *b.guards)))
    key = (id(sampler), des.method, des.points.tobytes(), lo.tobytes(), hi.tobytes(), tuple(sorted(dp.items())),
           tuple((name, grid[name].tobytes()) for name in sorted(reads) if name in grid))
    hit = _GEOMETRY.get(key)
    if hit is not None and hit[0]() is sampler:
        _GEOMETRY.move_to_end(key)
        return hit[1]
    skip = np.zeros(npts, dtype=bool)
    unbounded = np.zeros(npts, dtype=bool)
    ulo, uhi = np.zeros((npts, m)), np.zeros((npts, m))
    if m:
        col = {name: v[:, None] for name, v in grid.items()}
        box = {v: (lo[:, j, None], hi[:, j, None]) for j, v in enumerate(sampler.variables)}
        ulo, uhi = sampler.region_many(box, col)
        unbounded = np.any(~np.isfinite(ulo) | ~np.isfinite(uhi), axis=1)
        skip |= unbounded
        fine = np.flatnonzero(~unbounded)
        if len(fine):
            sub = {v: (a[fine], b[fine]) for v, (a, b) in box.items()}
            slo, shi = sampler.shrink_many(ulo[fine], uhi[fine], sub, {k: v[fine] for k, v in col.items()})
            ulo[fine], uhi[fine] = slo, shi
            skip[fine[np.any(~(shi > slo), axis=1)]] = True
    idx = np.flatnonzero(~skip)  # the points whose box this zero set meets
    volumes, branches = None, []
    if len(idx):
        sub = {name: v[idx] for name, v in grid.items()}
        rep = {name: np.repeat(v, des.points.shape[0]) for name, v in sub.items()}
        volumes, branches = sampler.points_many(des.points, ulo[idx], uhi[idx], rep, point_params=sub)
        branches = [(xb, w, ok, sampler.dpsi(xb, rep, dp)) for xb, w, ok in branches]
    out = (unbounded, idx, volumes, branches)
    size = sum(a.nbytes for xb, w, ok, d in branches for a in (*xb.values(), w, ok, np.asarray(d)))
    if size <= GEOMETRY_BYTES:
        _GEOMETRY[key] = (weakref.ref(sampler), out, size)
        while sum(v[2] for v in _GEOMETRY.values()) > GEOMETRY_BYTES:
            _GEOMETRY.popitem(last=False)
    return out
