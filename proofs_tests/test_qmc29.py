"""Honest standard errors for ``--method stratified`` and ``qmc`` (branch qmc29; finding F0 of fuzz28).

Before qmc29 a jump at a fixed place cut every replicate's strata (or every scrambled net's
elementary intervals) at the same relative position θ: each replicate's mean took one of two values,
and with θ = 0.97 all 32 replicates agreed 38 % of the time — the printed ± ≈ 0 while the estimate
was off (on main these seeds give |estimate − value| > 5 ± for 22–40 % of them).  Now each replicate
is shifted and tent-transformed (:mod:`langur.operational.replicates`) and the replicates' standard
error widened for its 31 degrees of freedom (:mod:`langur.operational.student`).

Every value below is computed here by hand (or with mpmath's quadrature of a 1-D integral), not by
either engine.  False alarms: with the fix, one comparison exceeds 5 (widened) standard errors with
probability about 5.7e-7 when the replicates' means are close to normal (measured on these programs
over 200 seeds each, bench/history/2026-11-29.md#qmc29: none beyond 3.1); this module makes about 600
comparisons, so a fresh draw would fail with probability below 1e-3 — and the seeds are fixed, so
the module never flakes.  A fix that made the ± useless (huge) fails the second check: the printed
± must stay within a factor of the actual root-mean-square error over the seeds.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys

import numpy as np
import pytest
from test_fuzz28 import QMC_FALSE_ALARM, _qmc_boundary_by_hand

from langur import operational
from langur.frontend import load_text
from langur.operational.pcg64 import Stream
from langur.operational.sample import design
from langur.operational.student import two_sided_tail, widening

SEEDS = range(2000, 2040)
SAMPLES = 20000  # 32 nets of 512 points (qmc), 32 grids of 625 strata (stratified, 1-D)
#: 0.97 of the way through an elementary interval of the 512-point nets (and of a 625-stratum grid: 0.95)
A97 = 0.30072265625  # = (153 + 0.97) / 512

F0 = QMC_FALSE_ALARM  # (test_fuzz28: the delta of sqrt(x + 2) = 2a + 1 over the disc's chord in z)


# (name, program, direction (None: the value), part of the derivative, value by hand)
CASES = [
    ("a jump in one variable", f"param a = {A97}\nint ([0, 1]) [x <= a] * (x + 1) d(x)\n",
     None, None, A97 + A97 ** 2 / 2),  # ∫₀ᵃ (x + 1) dx
    ("a jump along an axis in two variables", f"param a = {A97}\nint ([0, 1], [0, 1]) [x <= a] d(x, y)\n",
     None, None, A97),
    ("a jump on a zero set (a delta in two variables)",
     f"param a = 0.4, b = {A97}\nint ([0, 1], [0, 1]) [x <= a] * [y <= b] d(x, y)\n",
     {"a": 1.0, "b": 0.0}, "boundary", A97),  # ∂/∂a (a·b) = b, all of it on the line x = a
    ("F0: the chord of a disc on a moving curve", F0, {"a": 1.0, "b": 0.0}, "boundary", None),
    ("a smooth integrand", "int ([0, 1], [0, 1]) (x + 1) * (y * y + 1) d(x, y)\n",
     None, None, 1.5 * 4 / 3),  # (∫ x + 1)(∫ y² + 1)
]


def _estimates(text: str, direction, part, method: str) -> tuple[np.ndarray, np.ndarray]:
    loaded = load_text(text, path="qmc29.lgr")
    p = {k: float(v) for k, v in loaded.param_values({}).items()}
    values, ses = [], []
    for seed in SEEDS:
        if direction is None:
            e = operational.estimate_value(loaded, p, samples=SAMPLES, seed=seed, method=method)
        else:
            e = getattr(operational.estimate_derivative(loaded, p, direction, samples=SAMPLES, seed=seed,
                                                        method=method), part)
        values.append(e.value)
        ses.append(e.stderr)
    return np.array(values), np.array(ses)


@pytest.mark.parametrize("method", ["qmc", "stratified", "uniform"])
@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_the_printed_error_covers_the_value_by_hand_on_every_seed(case, method):
    name, text, direction, part, exact = case
    exact = _qmc_boundary_by_hand() if exact is None else exact
    values, ses = _estimates(text, direction, part, method)
    z = np.abs(values - exact) / ses
    assert np.all(ses > 0) and np.all(z <= 5), (name, method, np.max(z), int(np.sum(z > 5)))
    # and the ± is an error, not a bound of no use: within a factor of the actual rms error
    rmse = math.sqrt(float(np.mean((values - exact) ** 2)))
    assert 0.7 <= float(np.mean(ses)) / rmse <= 2.5, (name, method, float(np.mean(ses)), rmse)


def test_the_cli_prints_an_honest_error_where_main_printed_a_hundredth_of_it(tmp_path):
    # on main, `langur eval --method qmc --seed 2` printed 0.34601532 ± 0.00000069 (110 ± off)
    path = tmp_path / "jump.lgr"
    path.write_text(CASES[0][1])
    out = subprocess.run([sys.executable, "-m", "langur", "eval", str(path), "--engine", "mc", "--method", "qmc",
                          "--samples", str(SAMPLES), "--seed", "2"], capture_output=True, text=True, check=True).stdout
    value, se = (float(v) for v in re.search(r"MC\s*:\s*([-0-9.e]+) ± ([-0-9.e]+)", out).groups())
    exact = A97 + A97 ** 2 / 2
    assert abs(value - exact) <= 5 * se
    assert se > 1e-4  # (the actual error of such an estimate: rms 2.6e-4 over 200 seeds)


@pytest.mark.parametrize("method", ["qmc", "stratified"])
def test_replicate_designs_are_uniform_points_in_independent_replicates(method):
    d = design(Stream(7), 3, SAMPLES, method)
    assert d.groups == 32 and d.points.shape[0] % 32 == 0
    assert d.points.min() >= 0.0 and d.points.max() <= 1.0
    # each coordinate uniform: mean 1/2, variance 1/12 (32·512 or 32·216 points: ±0.01 is > 4σ)
    assert np.allclose(d.points.mean(axis=0), 0.5, atol=0.01)
    assert np.allclose(d.points.var(axis=0), 1 / 12, atol=0.01)


def test_student_tail_against_closed_forms_by_hand():
    for t in (0.3, 1.0, 5.0, 40.0):
        assert two_sided_tail(t, 1) == pytest.approx(1 - 2 * math.atan(t) / math.pi, rel=1e-9)  # Cauchy
        assert two_sided_tail(t, 2) == pytest.approx(1 - t / math.sqrt(t * t + 2), rel=1e-9)
        # three degrees of freedom: 1 − (2/π)(θ + sin θ cos θ), θ = atan(t/√3)
        th = math.atan(t / math.sqrt(3))
        assert two_sided_tail(t, 3) == pytest.approx(1 - 2 / math.pi * (th + math.sin(th) * math.cos(th)), rel=1e-9)
    # large ν: the normal tail (t's is heavier by about (z⁴ + 2z² − 1)/(4ν) of it: 0.8 %)
    assert two_sided_tail(5.0, 20001) == pytest.approx(math.erfc(5 / math.sqrt(2)), rel=0.012)


def test_widening_makes_five_errors_the_normal_rate():
    target = math.erfc(5 / math.sqrt(2))  # 5.7e-7: P(|Z| > 5)
    for r in (2, 3, 32, 64):
        w = widening(r)
        assert two_sided_tail(5 * w, r - 1) == pytest.approx(target, rel=1e-6)
    assert widening(2) == pytest.approx(math.tan(math.pi / 2 * (1 - target)) / 5, rel=1e-6)  # Cauchy's quantile
    assert 1.25 < widening(32) < 1.26 and widening(32) > widening(64) > 1.0
