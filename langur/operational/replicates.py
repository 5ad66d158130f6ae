"""Designs of independent replicates: ``--method stratified`` and ``qmc`` (the points of
:func:`.sample.design`), and their estimate of the mean with an honest standard error.

``stratified``: R independent jittered grids (one uniform point per stratum); ``qmc``: R
independently scrambled Sobol' nets (randomized quasi-Monte Carlo, scipy.stats.qmc).  Both estimate
the variance from independent randomizations (the spread of the replicates' means), never from
points within one randomization: a stratum or net that puts a jump's points deterministically
cannot make it 0 while the estimate is off (issue 13).

That spread is honest only if the replicates' means are close to normal.  A grid's strata and a
net's elementary intervals lie at the same places in every replicate (scrambling permutes digits; it
never moves the intervals), so a jump at a fixed place cuts them at the same relative position θ in
every replicate: a replicate's count of points before the jump is ⌊nθ'⌋ or ⌊nθ'⌋ + 1 with
probability θ — a two-point law — and with θ = 0.97 all 32 replicates agree 38 % of the time: the
spread is then ≈ 0 while the estimate is off (bench/history/2026-11-29.md#qmc29: before this, the
printed ± was exceeded fivefold on 22–40 % of seeds for a jump in a 1-D value or on the zero set of
a program in two variables; finding F0 of branch fuzz28).

So each replicate is also moved by its own uniform random shift modulo 1 (Cranley & Patterson
1976; applied to low-discrepancy point sets by Tuffin 1996) followed by the tent (baker's) transform
x ↦ 1 − |2x − 1| (Hickernell 2002 for shifted lattices; Cristea, Dick, Leobacher & Pillichshammer
2007 for digital nets), coordinate by coordinate.  The shift puts a jump at a uniformly random
relative place in each replicate's strata or intervals (the two-point law becomes a continuous one,
for a single jump in one variable a triangular law); the tent keeps a smooth integrand continuous
across the shift's wrap at 0 ≡ 1 (the shift alone makes every face a jump: 20–40× the error on a
smooth integrand, measured).  Every point stays uniform on [0, 1]^m and the replicates stay i.i.d.,
so the estimate and the replicates' variance estimate stay unbiased.  The price is accuracy on
smooth integrands: the tent doubles derivatives, 2–3× the error at the same number of samples
(in 1–3 variables still 60–200× below uniform sampling's for qmc, 4–300× for stratified: measured
in bench/history/2026-11-29.md#qmc29).

The replicates' spread has R − 1 degrees of freedom, so their standard error is widened by
:func:`.student.widening` (1.254 for R = 32): 5 of them are Student's t quantile at the normal 5σ
rule's false-alarm rate (5.7e-7), where 5 unwidened ones would be exceeded 2.1e-5 of the time.
"""

from __future__ import annotations

import math

import numpy as np

from .pcg64 import numpy_generator
from .student import widening

#: Independent randomizations of a qmc design (each a scrambled, shifted, tent-transformed net).
QMC_RANDOMIZATIONS = 32
#: Independent replicates of a stratified design (each a jittered grid, one point per stratum).
STRATIFIED_REPLICATES = 32


def stratified(rng, m: int, samples: int) -> tuple[np.ndarray, int]:
    """The points (R·strata, m) of R jittered grids, each shifted and tent-transformed; and R."""
    reps = STRATIFIED_REPLICATES if samples >= 2 * STRATIFIED_REPLICATES else 2
    per_axis = max(1, math.floor((samples / reps) ** (1.0 / m) + 1e-9))
    strata = per_axis ** m
    grid = np.stack(np.meshgrid(*([np.arange(per_axis)] * m), indexing="ij"), axis=-1).reshape(strata, m)
    jitter = rng.random((reps, strata, m))
    return shifted_tent(rng, (grid[None, :, :] + jitter) / per_axis), reps


def qmc(rng, m: int, samples: int) -> tuple[np.ndarray, int]:
    """The points (K·2^level, m) of K scrambled Sobol' nets, each shifted and tent-transformed; and K."""
    from scipy.stats import qmc as scipy_qmc  # (half a second to import: only for this method)

    k = QMC_RANDOMIZATIONS if samples >= 2 * QMC_RANDOMIZATIONS else 2
    level = max(0, math.floor(math.log2(samples / k)))
    blocks = [scipy_qmc.Sobol(m, scramble=True, seed=numpy_generator(rng), bits=64).random_base2(level) for _ in range(k)]
    return shifted_tent(rng, np.stack(blocks)), k


def shifted_tent(rng, replicates: np.ndarray) -> np.ndarray:
    """Each replicate (``replicates``: shape (R, n, m), points in [0, 1)^m) shifted by its own
    uniform vector modulo 1, then x ↦ 1 − |2x − 1| in every coordinate: the (R·n, m) points,
    replicate by replicate (see the module docstring)."""
    reps, _, m = replicates.shape
    moved = (replicates + rng.random((reps, 1, m))) % 1.0
    return (1.0 - np.abs(2.0 * moved - 1.0)).reshape(-1, m)


def mean(f: np.ndarray, replicates: int) -> tuple[float, float]:
    """The mean of the replicates' means of ``f`` (R blocks of equal length, in order) and its
    standard error: their spread, widened by :func:`.student.widening` (infinite with one)."""
    per = f.reshape(replicates, -1).mean(axis=1)
    est = float(np.mean(per))
    if replicates < 2:
        return est, math.inf
    return est, widening(replicates) * float(np.std(per, ddof=1)) / math.sqrt(replicates)
