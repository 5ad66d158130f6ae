"""Campaign throughput, eighth pass (issue 13, camp8): less Python per innermost sub-interval of
the nested quadrature, the same numbers.

* :func:`quadrature.gausskronrod._gk21_panel` (QUADPACK's 21-point Gauss–Kronrod panel on the 21 values at
  once) gives bitwise the answer of QUADPACK's ``dqk21`` written out term by term (:func:`dqk21_reference`), and integrates a polynomial
  of degree 20 exactly (by hand: ∫₋₁¹ t²⁰ dt = 2/21);
* :func:`quadrature.gausskronrod._first_panel` on a weight constant in the innermost variable (numpy returns
  one number) gives ``c·(b − a)`` with the same answer as the 21 values spelled out;
* the conditions tested at each sub-interval's midpoint are tried in a move-to-front order
  (:meth:`quadrature.problem.NumProblem.tests`): a 3-D region cut by several conditions against its
  volume by hand, bitwise the value with the order frozen, and the order did move.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature.compiling import _vectorize
from langur.symbolic.quadrature.gausskronrod import (
    _EPMACH,
    _UFLOW,
    _WG_PAIR,
    _WK_PAIR,
    _X21,
    WGK,
    _first_panel,
    _gk21_panel,
)
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem


def dqk21_reference(y_minus, y_plus, y_centre, half: float):
    """The reference: QUADPACK's ``dqk21`` written out term by term on values already computed: ``y_minus[j]``/``y_plus[j]`` at
    centre ∓ half·XGK[j] (j < 10), ``y_centre`` at the centre.  Returns ``(result, abserr,
    resabs, resasc)`` as ``dqk21`` defines them (the error estimate rescaled as QUADPACK does)."""
    fsum = y_minus + y_plus
    resk = WGK[10] * y_centre + float(_WK_PAIR @ fsum)
    resg = float(_WG_PAIR @ fsum)
    resabs = WGK[10] * abs(y_centre) + float(_WK_PAIR @ (np.abs(y_minus) + np.abs(y_plus)))
    reskh = 0.5 * resk
    resasc = WGK[10] * abs(y_centre - reskh) + float(_WK_PAIR @ (np.abs(y_minus - reskh) + np.abs(y_plus - reskh)))
    dh = abs(half)
    result, resabs, resasc = resk * half, resabs * dh, resasc * dh
    abserr = abs((resk - resg) * half)
    if resasc != 0.0 and abserr != 0.0:
        abserr = resasc * min(1.0, (200.0 * abserr / resasc) ** 1.5)
    if resabs > _UFLOW / (50.0 * _EPMACH):
        abserr = max(_EPMACH * 50.0 * resabs, abserr)
    return result, abserr, resabs, resasc


def test_gk21_panel_is_dqk21_bitwise():
    rng = np.random.default_rng(8)
    cases = [rng.normal(size=21) * 10.0 ** rng.integers(-8, 8) for _ in range(200)]
    cases += [np.full(21, 3.7), np.zeros(21), np.full(21, -1e-300), np.exp(np.linspace(-3, 3, 21))]
    for y in cases:
        for half in (0.5, 1e-9, 3.25, -2.0):
            old = dqk21_reference(y[:10], y[10:20], float(y[20]), half)
            new = _gk21_panel(y, half)
            assert (new[0], new[1], new[2]) == (old[0], old[1], old[3])


def test_gk21_panel_integrates_a_degree_20_polynomial_exactly():
    t = 0.0 + 1.0 * _X21  # the abscissae of [−1, 1] in the panel's order
    result, abserr, _ = _gk21_panel(t ** 20, 1.0)
    assert abs(result - 2 / 21) <= 1e-15
    assert abserr <= 1e-3  # (the Gauss rule alone is off: QUADPACK's estimate says so)


def test_first_panel_of_a_constant_weight():
    y, z = sp.symbols("y z")
    vw = _vectorize([y, z], sp.Float(2.5) * sp.log(y + 2), {})
    assert np.ndim(vw(0.3, np.linspace(0, 1, 21))) == 0  # numpy returns one number: constant in z
    val, err = _first_panel(vw, (0.3,), 0.25, 1.75, 1e-11)
    assert abs(val - 2.5 * math.log(2.3) * 1.5) <= 1e-14 and err <= 1e-12
    spelled = _first_panel(lambda yy, tt: np.full(tt.shape, 2.5 * math.log(yy + 2)), (0.3,), 0.25, 1.75, 1e-11)
    assert (val, err) == spelled


def test_midpoint_tests_move_to_front_same_value():
    x, y, z, a = sp.symbols("x y z a")
    # the unit cube cut by z ≤ a, x + z ≤ 1 and y ≥ z: at each (x, y) the midpoint of a sub-interval
    # of z fails one of them or none
    piece = Piece((Condition(a - z), Condition(1 - x - z), Condition(y - z)), sp.Integer(1))
    box = [(0, 1), (0, 1), (0, 1)]
    at = {a: sp.Rational(1, 2)}
    _DONE.clear()
    prob = piece_problem(piece, [x, y, z], box, at)
    val, err = integrate_problem(prob)
    # volume: ∫_0^{1/2} (1 − z)·(1 − z) dz (for z ≤ 1/2: x ≤ 1 − z, y ≥ z) = [−(1 − z)³/3]_0^{1/2} = 7/24
    assert abs(val - 7 / 24) <= err + 1e-12
    order, reorder = prob.tests(2)
    assert reorder and order != prob.here(2)  # a failing condition was moved to the front

    frozen = piece_problem(piece, [x, y, z], box, at)
    frozen._tests = {lv: (list(frozen.here(lv)), False) for lv in range(3)}
    assert integrate_problem(frozen) == (val, err)
