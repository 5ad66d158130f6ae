"""Campaign throughput, fifth pass (issue 13): the nested quadrature's innermost level with less
Python per outer abscissa — the 21 abscissae of a panel in one multiply-add, polynomial
coefficients from ``math`` taken as they are, each level's root finders looked up once per
problem — each checked against an independent reference.

* :func:`quadrature.gausskronrod._gk21_panel` (QUADPACK's 21-point panel) integrates every polynomial of degree ≤ 31 exactly (the
  Kronrod extension of the 10-point Gauss rule): checked against the power rule, and its error
  estimate against QUADPACK's ``dqk21`` as scipy's ``quad`` reports it after one panel.
* :func:`quadrature.gausskronrod._first_panel` on ``exp`` against mpmath.
* A 3-D simplex ``[x + y + z ≤ s]`` with weight ``z²`` at two values of the parameter ``s``
  (∫ = s⁵/60 by hand, for s ≤ 1), a 2-D quarter disc (πr²/4) and a disc cut by the box against
  mpmath's circular-segment area: the polynomial root finders (affine and quadratic conditions,
  integer and float coefficients) give the right breakpoints at every outer abscissa.
"""

from __future__ import annotations

import math
import warnings

import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy import integrate as si

from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature.gausskronrod import XGK, _first_panel, _gk21_panel
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem
from langur.symbolic.quadrature.roots import _poly_roots


@pytest.mark.parametrize("k", [0, 1, 5, 17, 30, 31])
def test_gauss_kronrod_21_is_exact_to_degree_31(k):
    # ∫_{-1}^{1} (t + 1)^k dt = 2^(k+1)/(k+1), by the power rule
    x = np.array(XGK[:10])
    f = lambda t: (t + 1.0) ** k  # noqa: E731
    res, err, _ = _gk21_panel(np.concatenate([f(-x), f(x), [f(0.0)]]), 1.0)
    exact = 2.0 ** (k + 1) / (k + 1)
    assert abs(res - exact) <= 1e-13 * exact


def test_gauss_kronrod_21_error_estimate_is_quadpacks():
    # scipy's quad stops after its first 21-point panel when that panel meets the tolerance: its
    # result and error estimate are then dqk21's, computed by QUADPACK itself
    f = lambda t: math.cos(3.0 * t) + t ** 4  # noqa: E731
    a, b = 0.2, 1.3
    c, h = 0.5 * (a + b), 0.5 * (b - a)
    x = np.array(XGK[:10])
    ym = np.array([f(c - h * t) for t in x])
    yp = np.array([f(c + h * t) for t in x])
    res, err, _ = _gk21_panel(np.concatenate([ym, yp, [f(c)]]), h)
    with warnings.catch_warnings():
        warnings.simplefilter("error", si.IntegrationWarning)
        ref, ref_err, info = si.quad(f, a, b, epsabs=1e-6, epsrel=1e-6, full_output=True)
    assert info["last"] == 1  # one panel: QUADPACK's numbers are dqk21's
    assert abs(res - ref) <= 1e-15 * abs(ref)
    assert err == pytest.approx(ref_err, rel=1e-6)
    exact = (math.sin(3 * b) - math.sin(3 * a)) / 3 + (b ** 5 - a ** 5) / 5
    assert abs(res - exact) <= err


def test_first_panel_against_mpmath():
    mpmath.mp.dps = 30
    exact = float(mpmath.quad(mpmath.exp, [0.25, 1.75]))
    val, err = _first_panel(np.exp, (), 0.25, 1.75, 1e-11)
    assert abs(val - exact) <= max(err, 1e-15)
    assert err <= 1e-11


def _problem(piece, variables, box, at):
    _DONE.clear()
    return piece_problem(piece, variables, box, at)


def test_simplex_with_parameter_at_two_points():
    x, y, z, s = sp.symbols("x y z s")
    piece = Piece((Condition(s - x - y - z),), z ** 2)
    for value in ("0.8", "0.55"):
        prob = _problem(piece, [x, y, z], [(0, 1), (0, 1), (0, 1)], {s: sp.Rational(value)})
        val, err = integrate_problem(prob)
        exact = float(sp.Rational(value) ** 5 / 60)  # ∫_0^s z² (s − z)²/2 dz = s⁵/60
        assert abs(val - exact) <= err + 1e-13
        # the innermost condition is affine in z: its root finder is the polynomial one
        assert all(finder is not None for _, finder in prob.finders(2))


def test_quarter_disc_and_cut_disc():
    x, y, a = sp.symbols("x y a")
    r = sp.Rational(7, 10)
    quarter = Piece((Condition(r ** 2 - x ** 2 - y ** 2),), sp.Integer(1))
    val, err = integrate_problem(_problem(quarter, [x, y], [(0, 1), (0, 1)], {}))
    assert abs(val - math.pi * 0.49 / 4) <= err + 1e-13
    # a disc centred at (a, 0) with float coefficients after substitution, against mpmath
    cut = Piece((Condition(sp.Rational(4, 25) - (x - a) ** 2 - y ** 2),), x + 1)
    mpmath.mp.dps = 30
    av = mpmath.mpf("0.3")

    def inner(t):
        return (t + 1) * mpmath.sqrt(max(mpmath.mpf(0), mpmath.mpf(4) / 25 - (t - av) ** 2))

    exact = float(mpmath.quad(inner, [0, av, av + mpmath.mpf("0.4")]))
    val, err = integrate_problem(_problem(cut, [x, y], [(0, 1), (0, 1)], {a: sp.Rational(3, 10)}))
    assert abs(val - exact) <= err + 1e-12


def test_root_finder_accepts_integer_and_float_coefficients():
    x, y = sp.symbols("x y")
    finder = _poly_roots(2 * y - x - 1, [x, y], 1)  # coefficients 2 (an int) and -x - 1 (a float)
    assert finder(0.5) == [0.75]
    finder = _poly_roots(y ** 2 - x, [x, y], 1)
    assert sorted(finder(0.25)) == [-0.5, 0.5]
    assert finder(-1.0) == []  # no real root
    assert _poly_roots(y ** 2 - sp.sqrt(x), [x, y], 1)(-1.0) == []  # a coefficient undefined there
