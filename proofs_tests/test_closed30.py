"""Closed forms of conditions with a pole in the integration variable (Def. 6.2, §6.3).

A condition changes sign where it passes through 0 and where it has a pole.  ``1/(x + y + 1/2) − a``
falls from +∞ to −a on each side of ``y = −x − 1/2``: it has one root in ``y`` and its completion
Ψ̂ (solved for ``y``, one inverse branch ``y = 1/(u₀ + a) − x − 1/2``) is a diffeomorphism of the
plane without that line, but it is not monotone on the whole line.  The exact engine solved
``[c ≥ 0]`` from Ψ̂'s one root and direction as the half-line ``y ≤ 1/a − x − 1/2`` (main at 147990f:
closed form 3.875 = the area of ``x + y ≤ 3/2``, caught by the quadrature cross-check as "internal
error: closed form 3.875 disagrees with quadrature 2.75").  It now solves a quotient N/D of
polynomials in the variable by the signs of N and D, and does not use a one-branch Ψ̂ whose
condition has a pole in the variable (``1/log x − a``, ``atanh(1/(x + 3)) − a``: those go to the
generic method or to quadrature).

Hand values.  s = x + y on [−1, 1]² has density f(s) = 2 − |s| on [−2, 2];
``[1/(s + 1/2) ≥ a]`` is ``0 < s + 1/2 ≤ 1/a`` for a > 0, ``s + 1/2 > 0 or s + 1/2 ≤ 1/a`` for
a < 0.  So

* a = 1/2: s ∈ (−1/2, 3/2]: ∫ f = (2 − 1/8) + (3 − 9/8) = 7/8 + 15/8 = 11/4;
  d/da = f(3/2) · d(1/a − 1/2)/da = (1/2)(−4) = −2;
* a = 1/4: s ∈ (−1/2, 2]: 7/8 + 2 = 23/8 (the same closed form, the cell a > 0);
* a = 2: s ∈ (−1/2, 0]: 7/8; d/da = f(0)(−1/4) = −1/2;
* a = −1: s > −1/2 or s ≤ −3/2: 23/8 + 1/8 = 3; d/da = f(−3/2)(−1) = −1/2.

In one variable, ``[1/(x + 1/2) ≥ a]`` on [−1, 1]: a = 1/2: x ∈ (−1/2, 1], 3/2; a = 2: (−1/2, 0],
1/2, d/da = −1/a² = −1/4; a = −1: x > −1/2 (x ≤ −3/2 is outside), 3/2.
``[1/log x ≥ 1]`` on [1/2, 2]: log x ∈ (0, 1], x ∈ (1, 2]: 1 (main: closed form 3/2).
``[atanh(1/(x + 3)) ≥ −1/2]`` on [−1, 1]: atanh of a positive number is positive: 2 (main: 0).
``[(x − a)/(x + 1/5) ≤ 1/2]`` on [−1, 1] at a = 3/10: with t = x + 1/5 > 0 it is x ≤ 2a + 1/5, with
t < 0 it is x ≥ 2a + 1/5 (empty): x ∈ (−1/5, 4/5], 1 (main: 9/5); d/da = 2.
``[(x − a)/(y + 1/2) ≥ 0]`` on [−1, 1]² at a = 3/10: x ≥ a above y = −1/2, x ≤ a below:
(1 − a)·3/2 + (1 + a)·1/2 = 17/10 (main: KeyError 'ComplexInfinity': the completion solved for y
is infinite on the zero set x = a, and its root was compiled as a hint; the derivative of this
program is not defined, X315).

The generic one-variable method (roots ordered at the point, each interval's sign probed) takes
the poles as points too: ``[1/log x ≥ 1]`` on [19/20, 2] is again x ∈ (1, 2], 1 (main: its probes
all fell right of the pole at 1, closed form 21/20); ``[tan x ≤ 1/2]`` on [0, 2] is
[0, atan(1/2)] ∪ (π/2, 2]: atan(1/2) + 2 − π/2 (main: quadrature), d/da = 1/(1 + a²) = 4/5.
"""

from __future__ import annotations

import math

import pytest

from langur import operational
from langur.denote import denote_program
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.symbolic.pieces import Method

PLANE = "int ([-1, 1], [-1, 1]) [1/(x + y + 0.5) - a >= 0] d(x, y)"
LINE = "int ([-1, 1]) [1/(x + 0.5) - a >= 0] d(x)"


def _load(body: str, a: str):
    return load_text(f"param a = {a}\n{body}\n")


def _exact(body: str, a: str):
    loaded = _load(body, a)
    return exact_eval(loaded.program, loaded.param_values())


@pytest.mark.parametrize("body, a, value", [
    (PLANE, "0.5", 11 / 4),
    (PLANE, "2", 7 / 8),
    (PLANE, "-1", 3.0),
    (LINE, "0.5", 3 / 2),
    (LINE, "2", 1 / 2),
    (LINE, "-1", 3 / 2),
    ("int ([-1, 1]) [(x - a)/(x + 0.2) <= 0.5] d(x)", "0.3", 1.0),
    ("int ([-1, 1], [-1, 1]) [(x - a)/(y + 0.5) >= 0] d(x, y)", "0.3", 1.7),
])
def test_a_pole_in_the_variable_gives_the_right_closed_form(body, a, value):
    r = _exact(body, a)
    assert not r.inconsistent, r.inconsistent  # main: closed form 3.875 (2.0 in one variable)
    assert not any("disagrees" in n for n in r.notes), r.notes
    assert r.method == Method.CLOSED_FORM
    assert r.value == pytest.approx(value, rel=1e-12, abs=1e-12)


def test_the_closed_form_holds_in_its_cell():
    loaded = _load(PLANE, "0.5")
    r = denote_program(loaded.program, loaded.param_values())
    assert r.method == Method.CLOSED_FORM and r.expr is not None
    (a,) = r.expr.free_symbols
    assert float(r.expr.subs(a, 0.5)) == pytest.approx(11 / 4, rel=1e-12)
    assert float(r.expr.subs(a, 0.25)) == pytest.approx(23 / 8, rel=1e-12)


@pytest.mark.parametrize("body, a, slope", [
    (PLANE, "0.5", -2.0),
    (PLANE, "2", -0.5),
    (PLANE, "-1", -0.5),
    (LINE, "2", -0.25),
    ("int ([-1, 1]) [(x - a)/(x + 0.2) <= 0.5] d(x)", "0.3", 2.0),
])
def test_derivative_by_hand_and_by_monte_carlo(body, a, slope):
    loaded = _load(body, a)
    params = loaded.param_values()
    d = exact_deriv(loaded.program, params, {"a": 1}, check=False)
    assert not d.inconsistent
    assert d.value == pytest.approx(slope, rel=1e-9)
    mc = operational.estimate_derivative(loaded, params, {"a": 1}, samples=20_000, seed=7)
    assert abs(mc.value - slope) <= 5 * mc.stderr + 1e-12, (mc.value, mc.stderr)


@pytest.mark.parametrize("text, value", [
    ("param a = 1\nint ([0.5, 2]) [1/log(x) - a >= 0] d(x)\n", 1.0),
    ("param a = -0.5\nint ([-1, 1]) [atanh(1/(x + 3)) - a >= 0] d(x)\n", 2.0),
])
def test_no_one_root_solution_for_a_condition_with_a_pole(text, value):
    loaded = load_text(text)
    r = exact_eval(loaded.program, loaded.param_values())
    assert not r.inconsistent, r.inconsistent  # main: closed forms 1.5 and 0, caught by the cross-check
    assert r.value == pytest.approx(value, abs=1e-8)
    mc = operational.estimate_value(loaded, loaded.param_values(), samples=20_000, seed=7)
    assert abs(mc.value - value) <= 5 * mc.stderr + 1e-12


@pytest.mark.parametrize("text, value, slope", [
    ("param a = 1\nint ([0.95, 2]) [1/log(x) - a >= 0] d(x)\n", 1.0, 0.0),
    ("param a = 0.5\nint ([0, 2]) [tan(x) - a <= 0] d(x)\n", math.atan(0.5) + 2 - math.pi / 2, 0.8),
])
def test_the_generic_method_takes_poles_as_points(text, value, slope):
    loaded = load_text(text)
    params = loaded.param_values()
    r = exact_eval(loaded.program, params)
    assert not r.inconsistent, r.inconsistent  # main: closed form 1.05 for the first
    assert r.method == Method.CLOSED_FORM  # main: quadrature for the second
    assert r.value == pytest.approx(value, rel=1e-12)
    d = exact_deriv(loaded.program, params, {"a": 1}, check=False)
    assert d.value == pytest.approx(slope, rel=1e-12, abs=1e-12)
    mc = operational.estimate_derivative(loaded, params, {"a": 1}, samples=20_000, seed=7)
    assert abs(mc.value - slope) <= 5 * mc.stderr + 1e-12
