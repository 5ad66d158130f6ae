"""The substitution at tangency kinks, one level (issue 13, tang13:
:func:`langur.symbolic.quadrature.nested._tangent_quad`).  Integrands with a half-power end,
values by hand: ∫_{−1}^{1} √(1 − t²) dt = π/2, ∫_0^1 t^{-1/2} dt = 2, ∫_0^1 √t·cos t dt against
scipy's QAWS (which weights by (t − 0)^{1/2} itself, an independent method); a pole at a tangency
end stays undefined, as :func:`_quad` decides it.
"""

from __future__ import annotations

import math

import pytest
from scipy.integrate import quad

from langur.symbolic.quadrature.adaptive import _quad
from langur.symbolic.quadrature.nested import _tangent_quad
from langur.symbolic.quadrature.problem import NumProblem, UndefinedIntegral

EPS = 1e-10  # the middle level's tolerance in 3-D


def _problem():
    return NumProblem(conds=[], weight=lambda t: 0.0, bounds=[(-1.0, 1.0), (-1.0, 1.0)])


class _Counted:
    def __init__(self, f):
        self.f, self.n = f, 0

    def __call__(self, t):
        self.n += 1
        return self.f(t)


def test_a_half_disc_both_ends_tangent():
    """√(1 − t²) on [−1, 1] with tangency kinks at both ends: π/2 within the bound, with fewer
    evaluations than ``quad`` on the untransformed integrand needs."""
    p = _problem()
    h = _Counted(lambda t: math.sqrt(max(0.0, 1.0 - t * t)))
    val, err = _tangent_quad(h, -1.0, 1.0, EPS, [], {-1.0, 1.0}, p, 1)
    assert abs(val - math.pi / 2) <= err + 1e-15 and err <= EPS * 10, (val, err)
    plain = _Counted(h.f)
    pval, perr = _quad(plain, -1.0, 1.0, EPS, [], p, 1)
    assert abs(pval - math.pi / 2) <= perr + 1e-15
    assert p.converged and h.n < plain.n / 3, (h.n, plain.n)


def test_a_tangency_kink_inside_and_other_kinks_kept():
    """A tangency kink at 0 inside [−1, 1] (√|t| on both sides) and an ordinary kink at 0.5
    (|t − 0.5|): the interval is cut at 0, the kink at 0.5 passed on in u; the value by hand:
    ∫_{−1}^{1} √|t| dt + ∫_{−1}^{1} |t − 0.5| dt = 4/3 + 1.25."""
    p = _problem()
    val, err = _tangent_quad(lambda t: math.sqrt(abs(t)) + abs(t - 0.5), -1.0, 1.0, EPS, [0.0, 0.5], {0.0}, p, 1)
    assert abs(val - (4 / 3 + 1.25)) <= err + 1e-14, (val, err)


def test_an_integrable_inverse_square_root_end():
    """t^{-1/2} on [0, 1] with a tangency kink at 0 (the transformed integrand is the constant 2)."""
    p = _problem()
    val, err = _tangent_quad(lambda t: 1.0 / math.sqrt(t), 0.0, 1.0, EPS, [], {0.0}, p, 1)
    assert abs(val - 2.0) <= err + 1e-14, (val, err)


def test_against_qaws():
    """√t·cos t on [0, 0.9] with a tangency kink at 0, and the mirror image ending at a tangency
    kink: scipy's algebraic-weight quadrature (QAWS, the √t as its weight) as the reference."""
    ref = quad(math.cos, 0.0, 0.9, weight="alg", wvar=(0.5, 0.0), epsabs=1e-14, epsrel=1e-14)[0]
    p = _problem()
    val, err = _tangent_quad(lambda t: math.sqrt(t) * math.cos(t), 0.0, 0.9, EPS, [], {0.0}, p, 1)
    assert abs(val - ref) <= err + 1e-14, (val, ref, err)
    val, err = _tangent_quad(lambda t: math.sqrt(-t) * math.cos(-t), -0.9, 0.0, EPS, [], {0.0}, p, 1)
    assert abs(val - ref) <= err + 1e-14, (val, ref, err)


def test_a_pole_at_a_tangency_end_stays_undefined():
    """1/t on (0, 1]: the substituted integrand 2/u still grows like 1/u, and the integral is
    still found not to exist (as ``quad`` on the original finds)."""
    p = _problem()
    with pytest.raises(UndefinedIntegral):
        _quad(lambda t: 1.0 / t, 0.0, 1.0, EPS, [], p, 1)
    with pytest.raises(UndefinedIntegral):
        _tangent_quad(lambda t: 1.0 / t, 0.0, 1.0, EPS, [], {0.0}, p, 1)
