"""Two wrong answers of the exact engine found by fuzz32 (bench/history/2026-11-29.md#wide32.

* D4, a wrong number: ``∂/∂c ∫∫_{[-1,1]×[0,0.15]} [x² + y² ≥ c + 0.55]·x`` is 0 (the integrand is odd
  in x on a region symmetric in x), but the delta piece's quadrature lost the arc x < 0 and gave
  −0.075, and the engine kept it over the right closed form 0.  Cause: the grid search for the roots
  of ``3/20 − √(0.96 − u²)`` (:func:`langur.symbolic.quadrature.roots._roots`) bisected a grid cell
  holding both its edge of definedness (u = −√0.96) and its root (u = −√0.9375) and kept only the
  first transition.  By hand, per arc: on x ≥ 0 the region at height y is x ∈ [s, 1] with
  s² = c + 0.55 − y², ∫_s^1 x dx = (1 − s²)/2, ∂/∂c = −1/2, over y ∈ [0, 0.15]: −3/40; the arc
  x ≤ 0 gives +3/40 by symmetry.
* D3, a false "undefined": ``[(x − (b + 0.15))/(y + c) ≥ 0]·e^(−(x−3)²)·e^(−y²)`` on
  [0, 10] × [−1000, 1000]; QUADPACK's "probably divergent" fired on an inner integral over y whose
  size (~10⁻¹¹ at x near 10) was the absolute tolerance itself.  By hand: the condition holds on
  x ≥ b + 0.15, y > −c and on x ≤ b + 0.15, y < −c, so the value is
  G(b + 0.15 − 3, 7)·E(−c, 1000) + G(−3, b + 0.15 − 3)·E(−1000, −c) with
  G(p, q) = E(p, q) = √π/2 (erf q − erf p).
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import mpmath
import pytest
import sympy as sp

from langur.ddenote import ddenote_program
from langur.exact import exact_eval
from langur.frontend import load_text
from langur.symbolic.quadrature import UndefinedIntegral
from langur.symbolic.quadrature.adaptive import _quad
from langur.symbolic.quadrature.problem import NumProblem
from langur.symbolic.quadrature.roots import _roots

ROOT = Path(__file__).resolve().parents[1]
CIRCLE = "param c = 0.41\nint ({xs}, [0, 0.15]) [x ^ 2 + y ^ 2 >= c + 0.55] * x d(x, y)\n"
POLE = ("param b = 0.79, c = 0.47\nint ([0, 10], [{ylo}, {yhi}]) [(x - (b + 0.15))/(y + c) >= 0] "
        "* exp(-(x-3)^2) * exp(-y^2) d(x, y)\n")


def _nan_sqrt(v: float) -> float:
    return math.sqrt(v) if v >= 0 else math.nan


def test_a_grid_cell_with_an_edge_and_a_root_gives_both():
    # 3/20 − √(0.96 − u²): undefined beyond ±√0.96, zero at ±√0.9375 — on each side both lie in the
    # grid cell between the nodes ±0.95 and ±1 (step 0.05).  Main found −√0.96 and lost −√0.9375.
    found = sorted(_roots(lambda u: 0.15 - _nan_sqrt(0.96 - u * u), -1.0, 1.0))
    for want in (-math.sqrt(0.96), -math.sqrt(0.9375), math.sqrt(0.9375), math.sqrt(0.96)):
        assert min(abs(r - want) for r in found) < 1e-9, (want, found)
    # and nothing else: the function changes state at these four points only
    assert len(found) == 4


@pytest.mark.parametrize("xs, value", [("[-1, 1]", 0.0), ("[0, 1]", -3 / 40), ("[-1, 0]", 3 / 40)])
def test_each_arc_of_the_circle_counts_in_closed_form_and_quadrature(xs, value):
    loaded = load_text(CIRCLE.format(xs=xs))
    at = loaded.param_values()
    exact = ddenote_program(loaded.program, at, {"c": 1})
    assert exact.inconsistent == ()  # main: "closed form 0.0 disagrees with quadrature -0.075" on [-1, 1]
    assert abs(exact.value - value) < 1e-12
    assert abs(exact.boundary.check - value) < 1e-8  # the delta piece's quadrature: both arcs
    numeric = ddenote_program(loaded.program, at, {"c": 1}, symbolic=False)
    assert abs(numeric.value - value) < 1e-8


def _pole_value(b: float, c: float, ylo: float, yhi: float) -> float:
    mpmath.mp.dps = 30
    e = lambda p, q: mpmath.sqrt(mpmath.pi) / 2 * (mpmath.erf(q) - mpmath.erf(p))  # noqa: E731
    s = mpmath.mpf(b) + mpmath.mpf("0.15")
    return float(e(s - 3, 7) * e(-mpmath.mpf(c), yhi) + e(-3, s - 3) * e(ylo, -mpmath.mpf(c)))


@pytest.mark.parametrize("ylo, yhi", [(-1000, 1000), (-10, 10)])
def test_a_moving_pole_over_a_wide_range_has_its_value(ylo, yhi):
    value = exact_eval(load_text(POLE.format(ylo=ylo, yhi=yhi)).program, {"b": 0.79, "c": 0.47}).value
    assert abs(value - _pole_value(0.79, 0.47, ylo, yhi)) < 1e-8  # 2.3435866 (main: undefined on ±1000)


def test_the_cli_says_neither_engine_finds_it_undefined(tmp_path):
    path = tmp_path / "pole.lgr"
    path.write_text(POLE.format(ylo=-1000, yhi=1000))
    out = subprocess.run([sys.executable, "-m", "langur", "eval", str(path)], capture_output=True, text=True,
                         cwd=ROOT, timeout=120)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "2.34358659" in out.stdout
    assert "undefined" not in out.stdout and "does not exist" not in out.stdout  # main: both said so


def _problem() -> NumProblem:
    return NumProblem([], lambda *_: 0.0, [(0.0, 1.0)], syms=[sp.Symbol("t")])


def test_a_small_integral_is_not_divergent_but_real_divergences_are():
    # 10⁻¹¹·e^(−t²) over [−0.47, 1000]: QUADPACK under ε = 10⁻¹¹ absolute says "probably divergent"
    k = 1.145e-11
    val, err = _quad(lambda t: k * math.exp(-t * t), -0.47, 1000.0, 1e-11, [], _problem(), 0)
    want = k * math.sqrt(math.pi) / 2 * (math.erf(1000.0) + math.erf(0.47))
    assert abs(val - want) <= 1e-11 * want and err < 1e-20
    for h, a, b in ((lambda t: t ** -1.01, 0.0, 1.0), (lambda t: t ** -2.0, 0.0, 1.0),
                    (lambda t: 1e-11 * t ** -2.0, 0.0, 1.0), (lambda t: (t - 0.3) ** -2.0, 0.0, 1.0)):
        with pytest.raises(UndefinedIntegral):
            _quad(h, a, b, 1e-11, [], _problem(), 0)
