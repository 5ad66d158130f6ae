"""False "undefined" from one level's quadrature (bug hunt F2 and F6, bench/history/2026-11-29.md#fuzz28; LANGUAGE.md's
undefined integrals; paper §8.2's ⟦p⟧ at a point).

* **F2**: QUADPACK's "probably divergent" (ier = 5) fired on a convergent integral whose integrand
  changes sign and whose value is small against ∫|h| (a sphere's delta, 1/√ at its fold, a jump
  that changes sign).  ``_quad`` now integrates the two one-signed parts apart when it fires: the
  integral exists exactly when both do, and a part that diverges or does not converge leaves the
  verdict "probably divergent".
* **F6**: an interval ending at a cylinder's fold, a root computed in doubles one unit in the last
  place outside the square root's domain, was sampled by ``quad`` at that end (a sub-interval of
  a few units in the last place: its nodes round to the end) and read as "NaN at ever more
  points".  A NaN within rounding of an end now counts 0.

The values are by hand (∫₀¹ t^(−1/2) = 2, ∫₀¹ log t = −1); the ones that failed on main (facc4ad)
are marked.  The whole programs F2 and F6 take 40–120 CPU s in the exact engine: their check
against the Monte Carlo engine is in bench/history/2026-11-29.md#fold28, not here.
"""

from __future__ import annotations

import math

import pytest
import sympy as sp

from langur.symbolic.quadrature.adaptive import _Finite, _quad
from langur.symbolic.quadrature.problem import NumProblem, UndefinedIntegral

EPS = 1e-11  # the innermost tolerance (tolerance.EPSABS)


def _problem() -> NumProblem:
    return NumProblem([], lambda t: 0.0, [(0.0, 1.0)], syms=[sp.Symbol("t")], at={}, sbounds=[(0, 1)])


def _q(h, a: float = 0.0, b: float = 1.0) -> tuple[float, float]:
    return _quad(h, a, b, EPS, [], _problem(), 0)


# ----------------------------------------------------------------------------------------------
# Convergent, sign-changing, small against ∫|h|: QUADPACK says "probably divergent" (failed on main)


@pytest.mark.parametrize("h, exact", [
    (lambda t: 1.0 / math.sqrt(t) - 1.99, 0.01),   # 2 − 1.99 (F2's shape: 1/√ at an end)
    (lambda t: 1.0 / math.sqrt(t) - 1.9, 0.1),
    (lambda t: math.log(t) + 0.99, -0.01),         # −1 + 0.99
])
def test_a_convergent_integral_with_cancellation_has_its_value(h, exact):
    val, err = _q(h)
    assert val == pytest.approx(exact, abs=1e-9)
    assert err < 1e-8


def test_scipy_alone_calls_the_first_one_divergent():
    """The premise: the warning these tests are about is QUADPACK's, on this integrand."""
    import warnings

    from scipy import integrate as si
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", si.IntegrationWarning)
        si.quad(lambda t: 1.0 / math.sqrt(t) - 1.99, 0.0, 1.0, epsabs=EPS, epsrel=EPS, limit=100)
    assert any("probably divergent" in str(w.message) for w in caught)


# ----------------------------------------------------------------------------------------------
# Divergent integrals stay undefined (passed on main; the parts must not hide them)


@pytest.mark.parametrize("h", [
    lambda t: 1.0 / (t - 0.3),               # a pole inside, both signs (its "principal value" is finite)
    lambda t: 1.0 / t,                       # one-signed, 1/t at an end
    lambda t: 1.0 / t - 3.0,                 # sign-changing, 1/t at an end
    lambda t: math.sin(1.0 / t) / t,         # ∫|h| = ∫ |sin u|/u du = ∞ (only conditionally convergent)
])
def test_a_divergent_integral_is_still_undefined(h):
    with pytest.raises(UndefinedIntegral):
        _q(h)


def test_a_pole_across_is_not_given_the_sum_of_its_parts():
    """1/(t − 0.3) on [0, 1]: the positive part alone diverges; the error a non-converged quad
    returns for it (≈ 3.6, value ≈ 10.5) must not become an answer."""
    with pytest.raises(UndefinedIntegral, match="divergent"):
        _q(lambda t: 1.0 / (t - 0.3))


# ----------------------------------------------------------------------------------------------
# A NaN at an end within rounding (F6) counts 0; a NaN inside is still recorded (failed on main)


A = 0.61
FOLD = A + math.sqrt(0.3)  # 1.1577225575051662: F6's fold, a unit in the last place past the root


def _weight(t: float) -> float:
    """F6's 1/√ weight as the engine computes it (the square root's argument expanded)."""
    v = -10 * A**2 + 20 * A * t - 10 * t**2 + 3
    return 1.0 / math.sqrt(v) if v > 0 else (math.inf if v == 0 else math.nan)


def test_the_fold_lies_outside_the_domain_in_doubles():
    assert math.isnan(_weight(FOLD))


def test_a_nan_at_an_end_counts_zero_and_inside_it_is_bad():
    g = _Finite(_weight, (FOLD - 1e-7, FOLD))
    assert g(FOLD) == 0.0 and not g.bad and not g.undefined
    assert g(FOLD + 1e-9) == 0.0 and g.bad == [FOLD + 1e-9] and g.undefined  # beyond rounding: recorded


def test_an_interval_ending_at_the_fold_integrates():
    """∫ over [F − w, F] of 1/√(3 − 10(t − a)²) = ∫ 1/√(20√0.3·s − 10s²) ds, s = F − t: by
    hand, (1/√10)·(π/2 − asin(1 − w/√0.3)) (the antiderivative of 1/√(2rs − s²) is asin((s − r)/r))."""
    r = math.sqrt(0.3)
    for w in (1e-5, 1e-7, 3e-8):
        val, _ = _q(_weight, FOLD - w, FOLD)
        exact = (math.pi / 2 - math.asin(1 - w / r)) / math.sqrt(10)
        assert val == pytest.approx(exact, rel=1e-5)


def test_a_nan_on_a_set_of_positive_measure_is_still_undefined():
    """NaN on [0.5, 1] (outside the domain on half the interval): undefined, not 0."""
    with pytest.raises(UndefinedIntegral):
        _q(lambda t: math.sqrt(0.5 - t) if t <= 0.5 else math.nan)
