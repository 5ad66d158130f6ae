"""Theorem 8.1's finite differences with the accuracy their bound needs (issue 13, campaign7).

The shifted values of ⟦p⟧ are first computed with the outermost quadrature level's tolerance
loosened (:func:`langur.symbolic.quadrature.outer_tolerance`); that answer stands only when it
holds with a tight bound of which the quadrature's share is small, else the step is computed again
at the usual tolerance (:func:`langur.theorem._finite_difference`).  Expected values by hand,
integrated with scipy's ``quad`` (independent of the engine's nested quadrature).
"""

import math

import pytest
import sympy as sp
from scipy.integrate import quad

from langur import denote
from langur import theorem as T
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load_text
from langur.symbolic import quadrature
from langur.symbolic.quadrature import kinks, nested
from langur.symbolic.quadrature.adaptive import _quad
from langur.symbolic.quadrature.kinks import _critical_points
from langur.symbolic.quadrature.pieceproblems import _DONE
from langur.symbolic.quadrature.tolerance import EPSABS

# ∫₀¹∫₀¹ [x + y ≤ a]·e^{sin x} = ∫₀^a e^{sin x}(a − x) dx for a ≤ 1 (no elementary antiderivative:
# ⟦p⟧ is known by quadrature only), so D_a⟦p⟧ = ∫₀^a e^{sin x} dx.
SOURCE = "param a = 0.7\nint ([0, 1], [0, 1]) [x + y <= a] * exp(sin(x)) d(x, y)\n"
A = 0.7


def _program():
    return load_text(SOURCE).program


def _answers(prog):
    """⟦p⟧ and ⦇p⦈ at a = A by quadrature (what the check gets when sympy finds no closed form for
    ⟦p⟧; the closed-form search itself is not what is tested here, and costs seconds)."""
    return (denote_program(prog, {"a": A}, symbolic=False),
            ddenote_program(prog, {"a": A}, {"a": 1}, symbolic=False))


def _forget():
    _DONE.clear()
    denote._remembered.clear()


def test_loose_finite_difference_decides_the_hand_value():
    prog = _program()
    den, der = _answers(prog)
    th = T.check_theorem_8_1(prog, {"a": A}, {"a": 1}, denotation=den, derivative=der)
    hand = quad(lambda x: math.exp(math.sin(x)), 0.0, A, epsabs=1e-13, epsrel=1e-13)[0]
    assert th.how == "finite_difference" and th.holds is True, th
    assert any("usual tolerance" in n for n in th.notes), th.notes  # the loose pass decided
    assert abs(th.d_denotation - hand) <= th.error
    assert th.error <= T.TIGHT * max(1.0, abs(hand))
    assert abs(th.derivative_denotation - hand) < 1e-8  # ⦇p⦈: the delta on x + y = a, by hand


def test_loose_values_equal_the_usual_ones_within_their_bounds():
    prog = _program()
    seen = []
    real = _quad

    def recording(h, a, b, eps, inside, p, level):
        seen.append((level, eps))
        return real(h, a, b, eps, inside, p, level)

    q = {"a": A + 1e-3}
    _forget()
    usual = denote_program(prog, q, symbolic=False)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(nested, "_quad", recording)
        _forget()  # (else the usual value, remembered, serves the looser request too)
        with quadrature.outer_tolerance(T.LOOSE_OUTER):
            loose = denote_program(prog, q, symbolic=False)
    assert seen and {eps for level, eps in seen if level == 0} == {EPSABS * 10 * T.LOOSE_OUTER}
    assert {eps for level, eps in seen if level == 1} <= {EPSABS}  # inner level unchanged
    assert abs(loose.value - usual.value) <= loose.error + usual.error
    hand = quad(lambda x: math.exp(math.sin(x)) * (q["a"] - x), 0.0, q["a"], epsabs=1e-13, epsrel=1e-13)[0]
    assert abs(loose.value - hand) <= loose.error and abs(usual.value - hand) <= usual.error
    # the loose value is remembered apart: the usual tolerance never gets it back
    again = denote_program(prog, q, symbolic=False)
    assert (again.value, again.error) == (usual.value, usual.error)
    assert quadrature.looseness() == 1.0


def test_without_room_in_the_bound_the_usual_computation_decides(monkeypatch):
    # no share of the bound allowed to the loose quadrature: the answer is exactly the usual
    # tolerance's central difference at the first step (the computation before this change)
    prog = _program()
    den, der = _answers(prog)
    monkeypatch.setattr(T, "QUADRATURE_SHARE", 0.0)
    th = T.check_theorem_8_1(prog, {"a": A}, {"a": 1}, denotation=den, derivative=der)
    usual = T._difference_at(prog, {"a": A}, {"a": 1}, der, den, 20.0, "x", T.FD_STEPS[0])
    assert th.holds is True and not any("usual tolerance" in n for n in th.notes)
    assert (th.d_denotation, th.error) == (usual.d_denotation, usual.error)


def test_a_genuine_failure_is_never_taken_from_the_loose_pass():
    # [x ≥ a] twice counts the jump twice: ⦇p⦈ = −2e^{sin a}, D⟦p⟧ = −e^{sin a}; the loose pass
    # does not hold, so the usual computation gives the failure (as before)
    prog = load_text("param a = 0.5\nint ([0, 1], [0, 1]) [x >= a] * [x >= a] * exp(sin(x)) d(x, y)\n").program
    th = T.check_theorem_8_1(prog, {"a": 0.5}, {"a": 1}, denotation=denote_program(prog, {"a": 0.5}, symbolic=False),
                             derivative=ddenote_program(prog, {"a": 0.5}, {"a": 1}, symbolic=False))
    assert th.holds is False and th.how == "finite_difference"
    assert th.d_denotation == pytest.approx(-math.exp(math.sin(0.5)), rel=1e-6)
    assert not any("usual tolerance" in n for n in th.notes)


def test_critical_points_solved_once_per_expression(monkeypatch):
    # tanh(z − 0.53) − 0.1 (late programs of seed 1): sympy's solve on its derivative comes back at
    # every outer level of every piece and point it is a factor of; the answer is remembered, and is
    # the one sympy gives (none real: tanh is monotone), while a quadratic's vertex is by hand
    z, y = sp.symbols("z y")
    e = sp.tanh(z - sp.Float(0.53)) - sp.Float(0.1)
    calls = []
    real = sp.solve

    def counting(*args, **kwargs):
        calls.append(args)
        return real(*args, **kwargs)

    monkeypatch.setattr(kinks, "_CRITICAL", {})
    monkeypatch.setattr(kinks, "CRITICAL_SECONDS", 60.0)  # (not the time limit's answer)
    monkeypatch.setattr(sp, "solve", counting)
    first = _critical_points(e, z)
    assert _critical_points(e, z) == first and len(calls) == 1
    assert all(not r.is_real for r in first) or first == []
    assert [float(r) for r in _critical_points(z**2 + y**2 - 0.3 - 2 * z, z)] == [1.0]
    # a time limit's empty answer is not kept: asked again
    monkeypatch.setattr(kinks, "run_with_timeout", lambda fn, s, **kw: (_ for _ in ()).throw(TimeoutError()))
    w = sp.sin(z * y) - sp.Float(0.2)
    assert _critical_points(w, z) == [] and (w, z) not in kinks._CRITICAL
