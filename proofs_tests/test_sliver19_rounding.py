"""The quadrature's error bound counts its breakpoints' rounding where the integrand is bounded next
to them, and not a singularity's sampled size (paper §8.2's ⟦p⟧ at a point, §7.3's delta pieces;
the standards: a numeric value carries an error bound, and the bound is true and usable).

Hand values.  The sliver S_k = ∫∫_{[0,1]²} [x ≤ t]·[x − t + y/10^k ≥ 0] d(x, y) is the region
t − y/10^k ≤ x ≤ t (0 ≤ y ≤ 1, inside the box for t = 1/2), of area ∫₀¹ y/10^k dy = 10^-k/2 for
every t near 1/2, so dS_k/dt = 0: the delta of [x ≤ t] gives ∫₀¹ [y/10^k ≥ 0] dy = +1 and the delta
of the other condition −∫∫ δ(x − t + y/10^k)·[x ≤ t] = −1 (solved for y = 10^k(t − x), Jacobian
10^k, over x ∈ [t − 10^-k, t]: the 1-D integral of the constant 10^k over a width 10^-k).
L_k = ∫∫ [10^k·x ≤ 10^k·t + y] = ∫₀¹ min(1, t + y/10^k) dy = t + 10^-k/2, so dL_k/dt = 1.  Monte
Carlo (:mod:`langur.operational`, fixed seeds) agrees within 5 standard errors.

In doubles the sliver's lower end 1/2 − 10^-k is a float a few units in the last place of 1/2 off
(2.4·10⁻¹⁷ for k = 13), i.e. 2.4·10⁻⁴ of the width 10⁻¹³: the quadrature's −0.99976 "± 2e-10" was
not within its bound; the bound now says ±0.09 and the closed form −1 is kept.
"""

import math

import pytest
import sympy as sp
from test_scale18_rounding import _problem  # a NumProblem of polynomial conditions

from langur import operational
from langur.exact import exact_deriv
from langur.frontend import load_text
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.rounding import end_allowance, flat_size

SLIVER = "param t = 0.5\nint ([0, 1], [0, 1]) [x <= t] * [x - t + y / 10^{k} >= 0] d(x, y)\n"
L_FAMILY = "param theta = 0.5\nint ([0, 1], [0, 1]) [10^{k} * x <= 10^{k} * theta + y] d(x, y)\n"
SCALES = [6, 10, 13, 14]

x, y = sp.symbols("x y", real=True)
EPS = 2.0 ** -52


def _cap(k: int) -> float:
    """What a usable bound may be for a value of size 1 carried by a sliver 10^-k wide under the
    weight 10^k: its ends' rounding (a few ε of x = 1/2, ~4·10⁻¹⁵ both) times 10^k, and no less
    than the 10⁻⁶ of an ordinary quadrature's answer."""
    return max(1e-6, 1e-14 * 10.0 ** k)


@pytest.mark.parametrize("k", SCALES)
def test_sliver_delta_piece_is_within_its_bound(k):
    # the delta piece of [x − t + y/10^k ≥ 0] (up to its sign): 10^k over [1/2 − 10^-k, 1/2] = 1
    w = sp.Integer(10) ** k
    p = _problem([w * x - (w / 2 - 1), sp.Rational(1, 2) - x], w, [(0.0, 1.0)], (x,))
    val, err = integrate_problem(p)
    assert abs(val - 1.0) <= err <= _cap(k)


@pytest.mark.parametrize("k", SCALES)
def test_l_family_delta_piece_is_within_its_bound(k):
    # dL_k/dt's delta solved for y: 10^k over x ∈ [1/2, 1/2 + 10^-k] = 1
    w = sp.Integer(10) ** k
    p = _problem([w * x - w / 2, (w / 2 + 1) - w * x], w, [(0.0, 1.0)], (x,))
    val, err = integrate_problem(p)
    assert abs(val - 1.0) <= err <= _cap(k)


@pytest.mark.parametrize("k", [13, 14])
def test_the_bound_is_needed_at_the_smallest_scales(k):
    # the rounding is real: the value is off by far more than the old 2e-10
    w = sp.Integer(10) ** k
    p = _problem([w * x - (w / 2 - 1), sp.Rational(1, 2) - x], w, [(0.0, 1.0)], (x,))
    val, err = integrate_problem(p)
    assert abs(val - 1.0) > 1e-6
    assert abs(val - 1.0) <= err


# (program, its parameter, the derivative by hand, the Monte Carlo seed): the sliver's two deltas
# cancel (0); the L family's one delta has weight 1
FAMILIES = {"sliver": (SLIVER, "t", 0.0, 7), "l_family": (L_FAMILY, "theta", 1.0, 11)}


@pytest.mark.parametrize("k", SCALES)
@pytest.mark.parametrize("family", FAMILIES)
def test_derivative_is_exact_and_agrees_with_monte_carlo(family, k):
    text, param, want, seed = FAMILIES[family]
    loaded = load_text(text.format(k=k), f"{family}.lgr")
    at = loaded.param_values({})
    d = exact_deriv(loaded.program, at, {param: 1})
    err = d.error or 0.0
    assert abs(d.value - want) <= err + 1e-12 and err <= 1e-6
    assert not any("internal error" in n or "disagrees" in n for n in d.notes)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds is True
    mc = operational.estimate_derivative(loaded, at, {param: 1.0}, samples=20000, seed=seed)
    assert abs(mc.value - want) <= 5 * mc.stderr + 1e-9


def test_a_bounded_end_counts_twice_its_rounding_times_the_integrand():
    # a constant 10¹³ next to both ends: 2δ·10¹³ per end, read from samples next to the end
    got = end_allowance((1e-15, 3e-15), 0.4, 0.5, (0.0, 1.0), 1e13, 1e-11, lambda ts: [1e13] * len(ts))
    assert got == pytest.approx(2 * (1e-15 + 3e-15) * 1e13, rel=1e-12)
    # a weight vanishing at the end (x − 0.4 near 0.4) is bounded: the largest of its samples
    got = end_allowance((1e-3, 0.0), 0.4, 0.5, (0.0, 1.0), 1e9, 1e-11, lambda ts: [1e9 * (t - 0.4) for t in ts])
    assert 0 < got <= 2 * 1e-3 * 1e9 * 0.064 * 1.000001


def test_the_samples_stay_inside_the_range():
    # a breakpoint at 0.9 known to ±0.01 under a weight 1 defined only on the box [0, 1]: 16δ = 0.16 would
    # sample outside the box (NaN: a bounded end taken for a singular one); inside, the end counts 2δ·1
    def h(ts):
        return [1.0 if 0.0 <= t <= 1.0 else math.nan for t in ts]

    assert end_allowance((0.01, 0.0), 0.9, 0.95, (0.0, 1.0), 1.0, 1e-11, h) == pytest.approx(0.02, rel=1e-12)


def test_a_singular_end_does_not_multiply_the_singularity():
    # 1/√(t − a) at the end a (the island's 1/(6√R) at R's root): no allowance from that end, and the
    # largest sample (4.5e15 next to the end) does not count; the other end (bounded) still does
    a, b = 0.3, 0.5

    def h(ts):
        return [1 / math.sqrt(t - a) if t > a else math.nan for t in ts]

    got = end_allowance((1e-13, 1e-16), a, b, (0.0, 1.0), 4.5e15, 1e-11, h)
    assert got == pytest.approx(2 * 1e-16 * max(abs(v) for v in h([b - 16e-16, b - 32e-16, b - 64e-16])), rel=1e-9)
    # a pole (grows like 1/s) likewise
    got = end_allowance((1e-13, 0.0), a, b, (0.0, 1.0), 1e20, 1e-11, lambda ts: [1 / (t - a) for t in ts])
    assert got == 0.0


def test_an_ordinary_bound_is_taken_unsampled():
    # below QUIET·eps the rough estimate is the allowance and the integrand is not asked again
    def never(ts):
        raise AssertionError("sampled")

    assert end_allowance((1e-16, 1e-16), 0.0, 1.0, (0.0, 1.0), 2.0, 1e-11, never) == pytest.approx(8e-16)


def test_flat_size():
    assert flat_size([2.0, 2.0, 2.1]) == 2.1
    assert flat_size([1.0, 3.0, 1.0]) is None  # a peak: not bounded at this scale
    assert flat_size([1.0, math.nan, 1.0]) is None
