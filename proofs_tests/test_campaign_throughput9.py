"""A campaign's exact answers with the outermost quadrature level loosened (issue 13, camp9).

``langur fuzz`` computes ⟦p⟧ and ⦇p⦈ with :func:`langur.symbolic.quadrature.outer_tolerance`
(:data:`langur.fuzz.compare.OUTER_LOOSENESS`): the values it compares with Monte Carlo are still
bounded, and Theorem 8.1's finite differences keep their own tolerances.  Expected values by hand,
integrated with scipy's ``quad`` (independent of the engine's nested quadrature).
"""

import math

import pytest
from scipy.integrate import quad

from langur import denote
from langur import theorem as T
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load_text
from langur.fuzz import compare
from langur.symbolic import quadrature
from langur.symbolic.quadrature import nested
from langur.symbolic.quadrature.adaptive import _quad
from langur.symbolic.quadrature.pieceproblems import _DONE
from langur.symbolic.quadrature.tolerance import EPSABS

# ∫_{-1}^{1}∫_{-1}^{1}∫_0^1 [x² + y² ≤ a]·e^{sin z} = πa·∫₀¹ e^{sin z} dz for a ≤ 1 (no elementary
# antiderivative in z: ⟦p⟧ is known by quadrature only), so D_a⟦p⟧ = π·∫₀¹ e^{sin z} dz.
SOURCE = "param a = 0.6\nint ([-1, 1], [-1, 1], [0, 1]) [x ^ 2 + y ^ 2 <= a] * exp(sin(z)) d(x, y, z)\n"
A = 0.6
E_SIN = quad(lambda z: math.exp(math.sin(z)), 0.0, 1.0, epsabs=1e-13, epsrel=1e-13)[0]

# the 2-D program of campaign7's tests: ∫₀^a e^{sin x}(a − x) dx, D_a = ∫₀^a e^{sin x} dx
SOURCE_2D = "param a = 0.7\nint ([0, 1], [0, 1]) [x + y <= a] * exp(sin(x)) d(x, y)\n"


def _forget():
    _DONE.clear()
    denote._remembered.clear()


def test_a_campaigns_answers_are_bounded_at_the_looser_tolerance():
    """The value and the derivative a campaign unit gets (``_exact_answers``, in this process)
    equal the hand values within the error bounds they report; the outermost level asked for
    OUTER_LOOSENESS times its tolerance, the inner ones for theirs."""
    prog = load_text(SOURCE).program
    seen = []
    real = _quad

    def recording(h, a, b, eps, inside, p, level):
        seen.append((len(p.bounds), level, eps))
        return real(h, a, b, eps, inside, p, level)

    _forget()
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(nested, "_quad", recording)
        status, ex, exd, _ = compare._exact_answers(prog, {"a": A}, 20.0)
    assert status == "ok", ex
    value, slope = math.pi * A * E_SIN, math.pi * E_SIN
    assert ex.method != "closed_form" and ex.error is not None
    assert abs(ex.value - value) <= ex.error, (ex.value, value, ex.error)
    d = exd["a"]
    assert abs(d.value - slope) <= (d.error or 0.0) + 1e-9, (d.value, slope, d.error)
    outer = {eps for dim, level, eps in seen if dim == 3 and level == 0}
    usual = EPSABS * 100
    # the campaign's looser outermost level; Theorem 8.1's finite differences keep their own
    # (the loose first pass at LOOSE_OUTER, the usual tolerance)
    assert usual * compare.OUTER_LOOSENESS in outer and outer <= {usual * compare.OUTER_LOOSENESS,
                                                                   usual * T.LOOSE_OUTER, usual}, outer
    assert {eps for dim, level, eps in seen if dim == 3 and level == 1} <= {EPSABS * 10}
    assert quadrature.looseness() == 1.0  # restored after the unit


def test_finite_differences_keep_their_own_tolerance_inside_a_looser_caller(monkeypatch):
    """Theorem 8.1's finite differences at the usual tolerance (the loose first pass switched off)
    inside ``outer_tolerance(OUTER_LOOSENESS)``: every shifted value's outermost level asks for
    the usual tolerance, not the caller's (before camp9 the usual pass took the caller's), and the
    check is the one computed outside the context, agreeing with the hand value."""
    monkeypatch.setattr(T, "LOOSE_OUTER", 1.0)
    prog = load_text(SOURCE_2D).program
    at, direction = {"a": 0.7}, {"a": 1}
    den = denote_program(prog, at, symbolic=False)
    der = ddenote_program(prog, at, direction, symbolic=False)
    _forget()
    outside = T.check_theorem_8_1(prog, at, direction, denotation=den, derivative=der)
    seen = []
    real = _quad

    def recording(h, a, b, eps, inside, p, level):
        seen.append((len(p.bounds), level, eps))
        return real(h, a, b, eps, inside, p, level)

    _forget()
    with pytest.MonkeyPatch.context() as mp, quadrature.outer_tolerance(compare.OUTER_LOOSENESS):
        mp.setattr(nested, "_quad", recording)
        inside = T.check_theorem_8_1(prog, at, direction, denotation=den, derivative=der)
    assert seen and {eps for dim, level, eps in seen if level == 0} == {EPSABS * 10}, seen
    hand = quad(lambda x: math.exp(math.sin(x)), 0.0, 0.7, epsabs=1e-13, epsrel=1e-13)[0]
    assert outside.how == "finite_difference" and outside.holds is True, outside
    assert (inside.holds, inside.d_denotation, inside.error) == (outside.holds, outside.d_denotation, outside.error)
    assert abs(inside.d_denotation - hand) <= inside.error <= T.TIGHT * max(1.0, hand)
