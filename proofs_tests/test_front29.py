"""Conditions a user writes that the front end refused (T207) or completed badly (branch front29;
bench/history/2026-11-29.md#front29, "Conditions the front end refused …").

* ``erf`` under a division, a root, a ``log`` or a fractional power (``[1/(erf(x) + 2) <= a]``,
  ``[sqrt(erf(x) + 2) >= a + 1]``) was refused: sympy's ``continuous_domain`` does not know ``erf``
  and the registry's completion of it took polynomials in ``erf`` only.  Now such a condition is
  continuous on the whole domain when interval enclosures prove every operation that can be
  discontinuous finite there (:mod:`langur.syntax.continuity`), and it has no turning point when
  enclosures prove its derivative of one sign (:mod:`langur.syntax.monotone`): one implicit-root
  branch, not the eight pieces between moving turning points that an unsolved derivative got.
* ``exp(2x - 1)`` under a factor (``[exp(2*x - 1) <= a + 0.5]``, ``[exp(x + y) <= a + 1]``) was
  completed by an implicit root although it has a closed-form inverse: the factor beside
  ``exp(…)`` was computed as ``a / exp(…)``, which sympy leaves as ``exp(1 - 2x)·exp(2x - 1)``, still
  in ``x`` (:func:`langur.syntax.diffeo._peel`).
* A condition in two variables proved monotone only with ``erf`` in its derivative
  (``[x + y + erf(x + y) <= a]``) was split along a variable into eight pieces; now one branch.

* ``asin``, ``acos``, ``atanh`` had no inverse in the registry (:mod:`langur.primitives`): a condition
  on them was completed by an implicit root, and ``[asin(x*y) <= a]`` or an angular sector
  ``[atan2(y, x) <= a]`` (``atan2`` is ``acos`` of ``x/sqrt(x^2 + y^2)`` on each side of its cut) was
  refused; their inverses ``sin``, ``cos``, ``tanh`` (with the guards of the branch they invert on)
  give closed forms.

Every expected value is computed here independently with mpmath (roots by bisection, areas by
hand), never read from an engine.
"""

import mpmath as mp
import pytest
from test_front28 import _both_engines as front28_both_engines

from langur.cli import main
from langur.core import IfDiffeo, ImplicitRoot, Pow, Prim, subterms
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load_text
from langur.operational import estimate_derivative, estimate_value

mp.mp.dps = 30


def _program(text):
    return load_text(text, "case.lgr").program


def _condition(program, variable):
    """The Diffeo of the program's one condition that is not a bound of the box (those are affine:
    no primitive, no power), solved for ``variable``."""
    found = [t.psi for t in subterms(program.body) if isinstance(t, IfDiffeo)
             and any(isinstance(s, Prim | Pow) for s in subterms(t.psi.condition))]
    assert len(found) == 1, found
    assert found[0].solved_for == variable
    return found[0]


def _has_root(psi):
    return any(isinstance(r, ImplicitRoot) for b in psi.branches for c in (*b.components, *b.guards) for r in subterms(c))


def _both_engines(text, a, value, slope):
    front28_both_engines(text, a, value, slope, slope_tol=1e-8, samples=4000, seed=3)


# ---------------------------------------------------------------------------------------------
# erf under a division, a root, a log, a fractional power: g(erf(x)) ≤ a with g monotone

#: (condition, h(x, a) with the set {x : h(x, a) ≤ 0}, the parameter value): h is g(erf(x)) − level
#: with g monotone, so one root in [-1, 1].
ERF_SHAPES = [
    ("1/(erf(x) + 2) <= a", lambda x, a: 1 / (mp.erf(x) + 2) - a, 0.4),
    ("sqrt(erf(x) + 2) >= a + 1", lambda x, a: a + 1 - mp.sqrt(mp.erf(x) + 2), 0.3),
    ("log(erf(x) + 2) <= a + 0.5", lambda x, a: mp.log(mp.erf(x) + 2) - a - mp.mpf("0.5"), 0.3),
    ("erf(x)/(erf(x) + 2) <= a", lambda x, a: mp.erf(x) / (mp.erf(x) + 2) - a, 0.2),
    ("1/(erf(x) + 2)^2 <= a", lambda x, a: 1 / (mp.erf(x) + 2) ** 2 - a, 0.2),
    ("(erf(x) + 2)^(1/3) <= a + 1", lambda x, a: mp.cbrt(mp.erf(x) + 2) - a - 1, 0.3),
]


@pytest.mark.parametrize("cond, h, a", ERF_SHAPES, ids=[c for c, _, _ in ERF_SHAPES])
def test_erf_under_a_division_or_a_root_is_completed_by_one_branch(cond, h, a):
    text = f"param a = {a}\nint ([-1, 1]) [{cond}] d(x)\n"
    psi = _condition(_program(text), "x")
    assert len(psi.branches) == 1 and _has_root(psi)  # one monotone piece: no moving turning points
    A = mp.mpf(str(a))
    r = mp.findroot(lambda x: h(x, A), (mp.mpf(-1), mp.mpf(1)), solver="bisect")
    assert -1 < r < 1
    # the set is [-1, r] or [r, 1], whichever side h is ≤ 0 on; the root moves by −(∂h/∂a)/(∂h/∂x)
    left = h(mp.mpf(-1), A) < 0
    value = r + 1 if left else 1 - r
    dr = -mp.diff(lambda t: h(r, t), A) / mp.diff(lambda x: h(x, A), r)
    _both_engines(text, a, value, dr if left else -dr)


def test_the_first_reported_case_by_hand():
    # 1/(erf(x) + 2) ≤ a ⟺ erf(x) ≥ 1/a − 2 ⟺ x ≥ r = erfinv(1/a − 2): value 1 − r, and
    # dr/da = −(1/a²)·(√π/2)·exp(r²), so the derivative is (√π/2)·exp(r²)/a²
    a = mp.mpf("0.4")
    r = mp.erfinv(1 / a - 2)
    _both_engines("param a = 0.4\nint ([-1, 1]) [1/(erf(x) + 2) <= a] d(x)\n", 0.4, 1 - r,
                  mp.sqrt(mp.pi) / 2 * mp.exp(r * r) / a**2)


@pytest.mark.parametrize("cond", ["1/erf(x) <= a", "sqrt(erf(x)) <= a"])
def test_a_pole_or_a_root_of_a_negative_number_in_the_box_stays_refused(cond, tmp_path, capsys):
    # 1/erf(x): a pole at 0 (that does not move: no split, pole31); sqrt(erf(x)): undefined on
    # [-1, 0) (not continuous on the whole domain)
    path = tmp_path / "refused.lgr"
    path.write_text(f"param a = 0.3\nint ([-1, 1]) [{cond}] d(x)\n")
    assert main(["check", str(path)]) == 1
    out = capsys.readouterr()
    assert "T207" in out.out and "internal error" not in out.out + out.err


def test_a_moving_pole_of_erf_is_split_at_it():
    # 1/(erf(x) + a) ≤ ½ (refused here before pole31: a pole wherever erf(x) = −a): a quotient, split
    # at its moving pole (langur.syntax.poles).  With a = 0.3, erf(x) + a > 0 would need erf(x) + a ≥ 2,
    # impossible; erf(x) + a < 0 makes it true: the set is x < −erfinv(a), value 1 − erfinv(a),
    # d/da = −(√π/2)·exp(erfinv(a)²) (the pole's end moves; there is no root)
    a = mp.mpf("0.3")
    _both_engines("param a = 0.3\nint ([-1, 1]) [1/(erf(x) + a) <= 0.5] d(x)\n", 0.3, 1 - mp.erfinv(a),
                  -mp.sqrt(mp.pi) / 2 * mp.exp(mp.erfinv(a) ** 2))


# ---------------------------------------------------------------------------------------------
# exp(…) beside a factor: a closed form, not an implicit root


def test_exp_of_an_affine_argument_is_inverted_in_closed_form():
    # exp(2x − 1) ≤ a + ½ ⟺ x ≤ x* = (log(a + ½) + 1)/2; ∫_{-1}^{x*} (1 + x) dx = (x* + 1)²/2,
    # derivative (x* + 1)·dx*/da = (x* + 1)/(2(a + ½))
    text = "param a = 0.3\nint ([-1, 1]) [exp(2*x - 1) <= a + 0.5] * (1 + x) d(x)\n"
    psi = _condition(_program(text), "x")
    assert not _has_root(psi)
    a = mp.mpf("0.3")
    xs = (mp.log(a + mp.mpf("0.5")) + 1) / 2
    _both_engines(text, 0.3, (xs + 1) ** 2 / 2, (xs + 1) / (2 * (a + mp.mpf("0.5"))))


def test_exp_of_a_sum_of_variables_is_inverted_in_closed_form():
    # exp(x + y) ≤ a + 1 ⟺ x + y ≤ c = log(a + 1) ∈ [0, 2]: area 4 − (2 − c)²/2, derivative (2 − c)/(a + 1)
    text = "param a = 0.3\nint ([-1, 1], [-1, 1]) [exp(x + y) <= a + 1] d(x, y)\n"
    psi = _condition(_program(text), "y")
    assert not _has_root(psi)
    a = mp.mpf("0.3")
    c = mp.log(a + 1)
    _both_engines(text, 0.3, 4 - (2 - c) ** 2 / 2, (2 - c) / (a + 1))


# ---------------------------------------------------------------------------------------------
# two variables, monotone proved with erf in the derivative


def test_a_sum_under_erf_in_two_variables_is_one_implicit_branch():
    # s = x + y: s + erf(s) ≤ a ⟺ s ≤ s* (s + erf(s) increasing); area of {x + y ≤ s*} in [-1, 1]²
    # is 4 − (2 − s*)²/2 for s* ∈ [0, 2], derivative (2 − s*)·ds*/da = (2 − s*)/(1 + erf'(s*))
    text = "param a = 0.3\nint ([-1, 1], [-1, 1]) [x + y + erf(x + y) <= a] d(x, y)\n"
    psi = _condition(_program(text), "y")
    assert len(psi.branches) == 1 and _has_root(psi)  # before: split along y into 8 pieces
    a = mp.mpf("0.3")
    s = mp.findroot(lambda t: t + mp.erf(t) - a, (mp.mpf(0), mp.mpf(2)), solver="bisect")
    assert 0 < s < 2
    program = _program(text)
    exact_v = denote_program(program, {"a": 0.3})
    area = 4 - (2 - s) ** 2 / 2
    assert abs(float(exact_v.value) - float(area)) <= 1e-7 + float(exact_v.error or 0)
    exact_d = ddenote_program(program, {"a": 0.3}, {"a": 1})
    slope = (2 - s) / (1 + 2 / mp.sqrt(mp.pi) * mp.exp(-s * s))
    assert abs(exact_d.value - float(slope)) <= 1e-6 + exact_d.error
    mc_d = estimate_derivative(program, {"a": 0.3}, {"a": 1}, samples=4000, seed=3)
    assert abs(mc_d.value - float(slope)) <= 5 * mc_d.stderr + 1e-8


# ---------------------------------------------------------------------------------------------
# asin, acos, atanh inverted (the registry's inverses: sin, cos, tanh), so atan2 and asin(x·y) complete


@pytest.mark.parametrize("cond, value, slope", [
    # acos(x) ≤ a + 1 ⟺ x ≥ cos(a + 1): value 1 − cos(a + 1), derivative sin(a + 1)
    ("acos(x) <= a + 1", lambda a: 1 - mp.cos(a + 1), lambda a: mp.sin(a + 1)),
    # asin(x) ≤ a ⟺ x ≤ sin(a): value sin(a) + 1, derivative cos(a)
    ("asin(x) <= a", lambda a: mp.sin(a) + 1, lambda a: mp.cos(a)),
    # atanh(x/2) ≤ a ⟺ x ≤ 2·tanh(a): value 2·tanh(a) + 1, derivative 2·(1 − tanh(a)²)
    ("atanh(x/2) <= a", lambda a: 2 * mp.tanh(a) + 1, lambda a: 2 * (1 - mp.tanh(a) ** 2)),
])
def test_inverse_trigonometric_conditions_in_closed_form(cond, value, slope):
    text = f"param a = 0.3\nint ([-1, 1]) [{cond}] d(x)\n"
    psi = _condition(_program(text), "x")
    assert not _has_root(psi)  # before: an implicit root
    a = mp.mpf("0.3")
    _both_engines(text, 0.3, value(a), slope(a))


def test_an_angular_sector_by_atan2():
    # atan2(y, x) ≤ a on [-1, 1]², 0 ≤ a < π/4: all but the sector from the ray at angle a round to
    # the negative x-axis, whose area is 2 − tan(a)/2 (the upper half less the triangle under the
    # ray up to x = 1): area 2 + tan(a)/2, derivative 1/(2·cos(a)²).  Refused before (T207: acos
    # had no inverse).
    text = "param a = 0.3\nint ([-1, 1], [-1, 1]) [atan2(y, x) <= a] d(x, y)\n"
    a = mp.mpf("0.3")
    _two_variable_check(text, 2 + mp.tan(a) / 2, 1 / (2 * mp.cos(a) ** 2))


def test_asin_of_a_product():
    # asin(x·y) ≤ a ⟺ x·y ≤ s = sin(a): the complement is two hyperbolic corners of area
    # (1 − s) + s·ln(s) each; area 2 + 2s − 2s·ln(s), derivative −2·ln(s)·cos(a).  Refused before.
    text = "param a = 0.3\nint ([-1, 1], [-1, 1]) [asin(x * y) <= a] d(x, y)\n"
    a = mp.mpf("0.3")
    s = mp.sin(a)
    _two_variable_check(text, 2 + 2 * s - 2 * s * mp.log(s), -2 * mp.log(s) * mp.cos(a))


def _two_variable_check(text, value, slope):
    program = _program(text)
    exact_v = denote_program(program, {"a": 0.3})
    assert abs(float(exact_v.value) - float(value)) <= 1e-7 + float(exact_v.error or 0), (exact_v.value, value)
    exact_d = ddenote_program(program, {"a": 0.3}, {"a": 1})
    assert abs(exact_d.value - float(slope)) <= 1e-7 + exact_d.error, (exact_d.value, slope)
    mc_d = estimate_derivative(program, {"a": 0.3}, {"a": 1}, samples=4000, seed=3)
    assert abs(mc_d.value - float(slope)) <= 5 * mc_d.stderr + 1e-8, (mc_d.value, slope)
    mc_v = estimate_value(program, {"a": 0.3}, samples=20000, seed=3)
    assert abs(mc_v.value - float(value)) <= 5 * mc_v.stderr + 1e-9, (mc_v.value, value)
