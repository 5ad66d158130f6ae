"""Public API: Monte Carlo estimates of ⟦p⟧ and ⦇p⦈ (§9 operational semantics; see the package
docstring for the estimator and why it is unbiased)."""

from __future__ import annotations

import math

import numpy as np

from .. import gcpause
from ..core import Program, refusals_located, tree_size
from ..modules import Loaded
from ..values import ParameterError, check_values
from .link import CACHE, CompileCache, Linked, compile_program, link
from .pcg64 import Stream
from .point import DELTA, TANGENT, VALUE, Point, full
from .results import DerivativeEstimate, Estimate, ValueEstimate
from .sample import design, evaluate_box, spread, volume_parts
from .scaled import root_sum_squares, squares_share

#: Most nodes the program may have written out as a tree: this engine evaluates it path by path
#: (each call of a definition is a linked instance with its own sampling sites, §9), so a
#: program whose definitions share subterms (``f1 = f0 + f0``, ``f2 = f1 + f1``, …) costs its
#: tree's size, which a few lines can make 2⁴⁰.  The exact engine and the linter work on the
#: shared form.
MAX_TREE_NODES = 1_000_000


class TooLarge(ValueError):
    """The program, written out as a tree, is larger than :data:`MAX_TREE_NODES` (T230)."""

    def __init__(self, program: Program, nodes: int):
        self.span, self.nodes = program.span, nodes
        super().__init__(f"the Monte Carlo engine evaluates the program path by path, and written out as a "
                         f"tree it has {nodes:.3g} nodes (at most {MAX_TREE_NODES:,}): its definitions share "
                         "subterms (a definition called twice with the same arguments, a let-bound vector used "
                         "twice); the exact engine and `langur check` work on the shared form")


def prepare(program_or_loaded, params: dict, sites: str = "inlined", direction: dict | None = None,
            cache: CompileCache = CACHE) -> tuple[Linked, dict]:
    """Compile (or fetch from ``cache``) and resolve parameter values to floats; raises
    :class:`~langur.values.ParameterError` for a missing or non-finite value, a value for a
    parameter a Loaded does not declare, or a direction naming a parameter without a value."""
    program = program_or_loaded.program if isinstance(program_or_loaded, Loaded) else program_or_loaded
    if isinstance(program, Program):
        nodes = tree_size(program.body)
        if nodes > MAX_TREE_NODES:
            raise TooLarge(program, nodes)
    if isinstance(program_or_loaded, Loaded):
        unknown = set(params) - set(program_or_loaded.params)
        if unknown:
            raise ParameterError(f"unknown parameter(s) {', '.join(sorted(unknown))} "
                                 f"(declared: {', '.join(program_or_loaded.params) or 'none'})")
        try:
            values = program_or_loaded.param_values({k: v for k, v in params.items()})
        except KeyError as e:
            raise ParameterError(f"no value for parameter(s) {e.args[0]} (it has no default)") from None
        linked = link(program_or_loaded, sites, cache)
        program = program_or_loaded.program
    elif isinstance(program_or_loaded, Program):
        values = dict(params)
        linked = compile_program(program_or_loaded, cache)
        program = program_or_loaded
    else:
        raise TypeError(f"expected a core Program or a Loaded, got {type(program_or_loaded).__name__}")
    check_values(program, values, direction)
    return linked, {k: float(v) for k, v in values.items()}


def _domain(linked: Linked, params: dict, rng, samples: int, method: str):
    """Uniform-design points in Program.box: (points dict, volume, exponent, design), the box's
    volume being volume · 2**exponent (exponent 0 unless it is no double: ``sample.volume_parts``);
    points None if the box is empty or undefined."""
    box = evaluate_box(linked.box_fns, params)
    m = len(linked.variables)
    d = design(rng, m, samples, method)
    if any(math.isnan(lo) or math.isnan(hi) for lo, hi in box):
        return None, math.nan, 0, d  # a bound outside its primitive's domain: the integral is undefined
    if any(not (hi > lo) for lo, hi in box):
        return None, 0.0, 0, d
    lo = np.array([b[0] for b in box])
    width = np.array([b[1] - b[0] for b in box])
    volume, exponent = float(np.prod(width)), 0
    if math.isfinite(volume):
        pts = lo + d.points * width
    else:  # a box beyond the doubles ([−1e308, 1e308]: its width is ∞)
        hi = np.array([b[1] for b in box])
        pts = spread(lo, hi, d.points)
        volume, exponent = (float(v) for v in volume_parts(lo, hi))
    return {x: pts[:, i] for i, x in enumerate(linked.variables)}, volume, int(exponent), d


def _run(linked: Linked, x, params, **point) -> tuple:
    """The linked program run at the :class:`~.point.Point` (``x``, γ, …) under its linking (§9)."""
    return linked.fn(Point(x, params, **point), linked.linking)


#: One sample carrying more than this share of the sum of squares: the variance estimate rests on
#: a single point (a heavy tail), so the standard error says nothing.
DOMINANT = 0.5
#: Fewer nonzero scores than this on a zero set: too few to estimate its variance ("low hits").
LOW_HITS = 30


def all_zero_note(n: int, derivative: bool = False) -> str:
    """The note of an estimate whose every sample was 0 (its standard error is then 0): true
    whether the integral is 0 (an empty pixel of ``examples/raytrace/scene.lgr``) or has mass no
    sample met (``exp(-1e8*(x - 0.3)^2)`` on [0, 1]); bench/history/2026-11-29.md#exact32."""
    where = "in the box and on the discontinuities " if derivative else ""
    return (f"every one of the {n} samples {where}was 0, so the standard error is 0: it bounds nothing — "
            "mass where no sample fell (a region or a peak narrower than the samples' spacing) is not seen, "
            "and the integral may be 0 or not")


def _not_finite(f: np.ndarray, where: str = "samples", overflows=None) -> list[str]:
    """The note on ``f``'s samples that are not finite, if any; ``overflows(bad)``: whether this
    engine's arithmetic overflows where it computes the samples ``bad`` (a mask), when it can tell."""
    bad = ~np.isfinite(f)
    count = int(np.count_nonzero(bad))
    if not count:
        return []
    if overflows is not None and overflows(bad):
        return [f"{count} of {len(f)} {where} are not finite: this engine's floating-point arithmetic overflowed "
                "computing them (a value beyond ±1.8e308 is inf, and inf·0 or inf − inf is NaN); the integrand "
                "itself may be finite there"]
    return [f"{count} of {len(f)} {where} are not finite: the integrand is undefined, infinite or too large "
            "for a float there"]


def _overflows(linked: Linked, x: dict, p: dict, bad: np.ndarray, **point) -> bool:
    """Does the integrand's evaluation overflow (numpy's overflow flag: a result beyond ±1.8e308) at
    the points ``bad`` of ``x``?  They are evaluated again, alone (the arithmetic is point by point:
    the same operations on them as in the run over all points), only when some samples are not
    finite; nothing of the estimate changes."""
    seen: list[str] = []
    with np.errstate(over="call", call=lambda kind, flag: seen.append(kind)):
        _run(linked, {v: a[bad] for v, a in x.items()}, p, **point)
    return bool(seen)


def tail_notes(f: np.ndarray, overflows=None) -> list[str]:
    """What the samples themselves say about the estimate's variance (where they can tell);
    ``overflows``: as :func:`_not_finite`'s."""
    n = len(f)
    bad = _not_finite(f, overflows=overflows)
    if bad:
        return bad
    top, total = squares_share(f.astype(float))
    if n >= 100 and total > 0 and math.isfinite(total) and top > DOMINANT * total:
        return [f"one sample carries {top / total:.0%} of the sum of squares: the samples have a "
                "heavy tail, the variance may be infinite and the standard error is not reliable"]
    return []


def _variance(notes: list[str], infinite_variance: str | None) -> dict:
    """``finite_variance`` and ``notes`` of a result (the caller's reason first)."""
    if infinite_variance:
        notes = [f"no finite variance: {infinite_variance}; the standard error means nothing"] + notes
    return {"finite_variance": not infinite_variance, "notes": tuple(notes)}


@refusals_located
def estimate_value(program_or_loaded, params: dict, *, samples: int = 10000, seed: int = 0,
                   method: str = "uniform", sites: str = "inlined", infinite_variance: str | None = None,
                   cache: CompileCache = CACHE) -> ValueEstimate:
    """⟦int t d(x⃗)⟧(γ) ≈ vol(box)·mean ⟦t⟧(ρᵢ, γ) over a design in Program.box.

    ``infinite_variance``: why the integrand is known not to be square-integrable (the caller's
    analysis; the result's ``finite_variance`` is then False).  The result's ``notes`` also say
    what the samples show: non-finite values, or one sample dominating the sum of squares.
    ``cache``: where compiled units and linked programs are kept (§9)."""
    with gcpause.paused():  # (the samples' arrays and the points hold no cycles)
        linked, p = prepare(program_or_loaded, params, sites, cache=cache)
        rng = Stream(seed)  # numpy's default_rng(seed), its draws without numpy.random
        notes: list[str] = []
        with np.errstate(all="ignore"):
            value, se, n, seen = _over_domain(linked, p, rng, samples, method, 0, notes, mode=VALUE)
        if not seen:
            notes.append(all_zero_note(n))
    return ValueEstimate(value, se, n, seed, method, **_variance(notes, infinite_variance), all_zero=not seen)


def _over_domain(linked: Linked, p: dict, rng, samples: int, method: str, part: int,
                 notes: list[str] | None = None, **point):
    """vol(box) · mean over a design in Program.box of ``linked.fn``'s value (``part`` 0) or tangent
    (``part`` 1), with its standard error, the number of points and whether a sample was not 0 (an
    empty box, whose integral is 0 exactly, counts as seen): ``(estimate, stderr, n, seen)``;
    :func:`tail_notes` of the samples are appended to ``notes``."""
    x, volume, exponent, d = _domain(linked, p, rng, samples, method)
    n = d.points.shape[0]
    if x is None:  # an empty or undefined box
        return (0.0, 0.0, n, True) if volume == 0.0 else (math.nan, math.nan, n, True)
    f = full(_run(linked, x, p, **point)[part], n)
    if notes is not None:
        notes += tail_notes(np.asarray(f), lambda bad: _overflows(linked, x, p, bad, **point))
    mean, se = d.mean(f)
    seen = mean != 0 or se != 0 or bool(np.any(f))  # (any: only for 0 ± 0)
    if exponent:  # ± ∞ only where the estimate itself is no double
        return float(np.ldexp(volume * mean, exponent)), float(np.ldexp(volume * se, exponent)), n, seen
    return volume * mean, volume * se, n, seen


@refusals_located
def estimate_derivative(program_or_loaded, params: dict, direction: dict, *, samples: int = 10000,
                        seed: int = 0, method: str = "uniform", sites: str = "inlined",
                        infinite_variance: str | None = None, cache: CompileCache = CACHE) -> DerivativeEstimate:
    """⦇int t d(x⃗)⦈(γ, γ') ≈ regular part (standard AD) + one zero-set estimate per site.

    ``sites`` (for a Loaded only): where the zero-set samplers come from, see :func:`.link.link`;
    ``infinite_variance`` and ``notes``: as :func:`estimate_value` (for the regular part)."""
    with gcpause.paused():  # (the samples' arrays and the points hold no cycles)
        linked, p = prepare(program_or_loaded, params, sites, direction, cache)
        dp = {k: float(v) for k, v in direction.items() if float(v) != 0.0}
        rng = Stream(seed)  # numpy's default_rng(seed), its draws without numpy.random
        with np.errstate(all="ignore"):
            # regular part: the tangent with every delta dropped (Dˢ), over the domain design
            notes: list[str] = []
            reg, reg_se, n, seen = _over_domain(linked, p, rng, samples, method, 1, notes, dparams=dp, mode=TANGENT)
            bnd, bnd_ses, hit = _boundary(linked, p, dp, rng, samples, method, notes)
        if not (seen or hit):
            notes.append(all_zero_note(n, derivative=True))
    bnd_var = 0.0
    for s in bnd_ses:  # the sites' variances summed in order, as ever (s·s: the correctly rounded square,
        bnd_var += s * s  # as s ** 2 was, but ∞ where a Python float's ** 2 raised OverflowError)
    bnd_se = root_sum_squares(math.sqrt(bnd_var), bnd_ses)
    return DerivativeEstimate(reg + bnd, root_sum_squares(math.sqrt(reg_se * reg_se + bnd_var), (reg_se, *bnd_ses)),
                              n, seed, method,
                              **_variance(notes, infinite_variance), all_zero=not (seen or hit),
                              regular=Estimate(reg, reg_se), boundary=Estimate(bnd, bnd_se))


def _inside(x: dict, box: dict) -> np.ndarray:
    """Which points lie in the closed box B (widened by 1e-9 of each side's scale); the ends may be
    numbers or, one per point, arrays (the batch)."""
    inside = None
    for v, (lo, hi) in box.items():
        tol = 1e-9 * np.maximum(1.0, np.maximum(np.abs(lo), np.abs(hi)))
        ok = (x[v] >= lo - tol) & (x[v] <= hi + tol)
        inside = ok if inside is None else inside & ok
    return inside


#: The note of a result where a condition's completion divides by a coefficient that is 0 (the
#: sampler's Ψ̂ is canonical, shared by programs: it has no place in a source to point to).
VANISHING_NOTE = ("⦇p⦈ is not defined: the completion of a condition divides by a parameter coefficient that "
                  "is 0 here (no diffeomorphism); the result is NaN (`langur deriv` completes such a "
                  "condition by another variable where one does not degenerate)")


def _boundary(linked: Linked, p: dict, dp: dict, rng, samples: int, method: str,
              notes: list[str] | None = None) -> tuple[float, list[float], bool]:
    """Σ_k ∫ E_k δ_k: every live site's zero set sampled through every inverse branch, all sites'
    points scored in ONE vectorized pass of the integrand in DELTA mode.  A site whose zero set
    was hit (scored nonzero) by fewer than :data:`LOW_HITS` points says so in ``notes``: its
    standard error is not backed by enough samples.  ``(estimate, each site's standard error, whether a score was not 0)``
    (no site sampled: nothing to see, so False)."""
    live = set(dp)
    box = dict(zip(linked.variables, evaluate_box(linked.box_fns, p)))
    m = len(linked.variables) - 1
    plan = []  # (site id, design, volume, [(x, weight, valid, dpsi)])
    point = design(rng, m, samples, method) if m == 0 else None  # (one variable: one point, no draw)
    for k, site in enumerate(linked.sites):
        if site.deps.isdisjoint(live):
            continue  # D_γ π₀Ψ̂·γ' ≡ 0: the delta's coefficient vanishes identically
        sampler = site.sampler
        if sampler.vanishing(p):  # Ψ̂ is no diffeomorphism here: ⦇p⦈ is not defined
            if notes is not None:
                notes.append(VANISHING_NOTE)
            return math.nan, [math.nan], True
        des = point if point is not None else design(rng, m, samples, method)
        region = sampler.region(box, p) if m else ()
        if region:  # (one variable: no u'-box to enclose nor shrink)
            if any(math.isinf(a) or math.isinf(b) or math.isnan(a) or math.isnan(b) for a, b in region):
                # no finite box encloses this zero set's coordinates (a pole of Ψ̂'s other components
                # over the domain): no uniform design can sample it, so the estimate is undefined
                return math.nan, [math.nan], True
            region = sampler.shrink(region, box, p)
            if region and any(not (b > a) for a, b in region):
                continue
        volume, branches = sampler.points(des.points, region, p)
        plan.append((k, des, volume, [(xb, w, ok, sampler.dpsi(xb, p, dp)) for xb, w, ok in branches]))
    if not plan:
        return 0.0, [], False
    # lay out every (site, branch) block of points one after the other: site ids, points, weights
    ids, xs, ws, oks, dps, counts = [], {v: [] for v in linked.variables}, [], [], [], []
    for k, des, _, branches in plan:
        nb = des.points.shape[0]
        counts.append(nb * len(branches))
        for xb, w, ok, dpsi in branches:
            ids.append(k)
            for v in linked.variables:
                xs[v].append(xb[v])
            ws.append(w)
            oks.append(ok)
            dps.append(full(dpsi, nb))
    # each block's site id repeated over its points (one call, not an array per block)
    site = np.repeat(np.array(ids, dtype=int), [des.points.shape[0] for _, des, _, branches in plan for _ in branches])
    x = {v: np.concatenate(a) for v, a in xs.items()}
    _, g = _run(linked, x, p, mode=DELTA, site=site, sites=frozenset(k for k, *_ in plan))
    # score = [guards ≥ 0] · (D_γπ₀Ψ̂·γ') · G_k · |det DΨ̂_b⁻¹|, all blocks at once.  A point of a
    # zero set outside the box B scores 0: the domain's indicators vanish there, even where the
    # integrand itself is undefined (0·NaN would be NaN: sqrt(x) at the root −√a of [x² ≤ a] on
    # [0, 1]).  The box is closed and slightly widened, so points on its faces (the zero sets of
    # parametric bounds, found up to rounding) are still decided by the indicators themselves.
    inside = _inside(x, box)
    score = np.where(np.concatenate(oks) & inside,
                     np.concatenate(dps) * full(g, len(site)) * np.concatenate(ws), 0.0)
    starts = np.concatenate(([0], np.cumsum(counts)[:-1]))
    if notes is not None:  # (a delta's score too large for a float: the estimate is not a number)
        notes += _not_finite(score, "samples on the discontinuities")
    if all(des.method == "exact" for _, des, _, _ in plan):  # one variable: every root once, exactly
        total = float(np.sum(np.add.reduceat(score, starts)))
        return total, [], total != 0 or bool(np.any(score))  # (any: only for an exact 0)
    total, ses = 0.0, []
    for (_k, des, volume, branches), at, c in zip(plan, starts, counts):
        # per u'-point, the sum over branches; then the design's mean and standard error
        f = score[at:at + c].reshape(len(branches), des.points.shape[0]).sum(axis=0)
        hits = int(np.count_nonzero(f))
        if notes is not None and 0 < hits < LOW_HITS:
            notes.append(f"low hits: the zero set of delta site {_k} was hit by {hits} of {len(f)} samples; "
                         "its standard error is not reliable (give more --samples)")
        mean, se = des.mean(f)
        total += volume * mean
        ses.append(volume * se)
    return total, ses, total != 0 or any(s != 0 for s in ses) or bool(np.any(score))
