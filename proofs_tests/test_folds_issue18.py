"""Issue 18: a delta through an implicit root is singular along its fold (roots8).

Splitting ``z`` at the turning points of ``z³ − z`` gives implicit-root branches whose delta weight
1/|∂f/∂z(z*)| grows like 1/√ where z* reaches a turning point.  In one coordinate (a 2-D program)
the fold is a point and quadrature integrates it; the value is checked here against an independent
reference: V(a) = ∫ L(a − g(x)) dx with g(t) = t³ − t and L(c) = |{y ∈ [−1, 1] : g(y) ≥ c}| from
the cubic's trigonometric roots, integrated by scipy's ``quad`` with the kinks as breakpoints, and
dV/da by central differences with Richardson extrapolation (h = 1e−3, 1e−4).  In two coordinates
(the 3-D separable cubic) the fold is a curve, singular where ∂f/∂y vanishes on it too: the exact
engine integrates it in about 20 CPU s (roots9, test_folds3d_issue18.py); when its quadrature does
not finish within :data:`~langur.symbolic.quadrature.fold.FOLD_SECONDS` it must say it has no value (an
engine limitation), not that the integral is undefined — tested here with that limit cut to 1 s.
"""

from __future__ import annotations

import numpy as np
import pytest
from cubic_reference import L, M, g
from scipy import integrate

from langur import exact as api
from langur import frontend
from langur.ddenote import ddenote_program
from langur.symbolic import quadrature
from langur.symbolic.quadrature import fold


def value(a):
    pts = set()
    for k in (-M, M, 0.0):  # where a − g(x) crosses L's kinks
        pts.update(float(r.real) for r in np.roots([1, 0, -1, -(a - k)]) if abs(r.imag) < 1e-12 and -1.5 < r.real < 1.5)
    v, _ = integrate.quad(lambda x: L(a - g(x)), -1.5, 1.5, points=sorted(pts), limit=400, epsabs=1e-13, epsrel=1e-13)
    return v


def derivative(a):
    d = [(value(a + h) - value(a - h)) / (2 * h) for h in (1e-3, 1e-4)]
    return d[1] + (d[1] - d[0]) / 99  # the h² term removed


TWO = "param a = 0.3\nint ([-1.5, 1.5], [-1, 1]) [x^3 - x + y^3 - y - a >= 0] d(x, y)\n"
THREE = ("param a = 0.3\n"
         "int ([-1.5, 1.5], [-1.5, 1.5], [-1, 1]) [x^3 - x + y^3 - y + z^3 - z - a >= 0] d(x, y, z)\n")


@pytest.mark.parametrize("a", [0.3])
def test_one_coordinate_fold_is_integrated(a):
    ref = derivative(a)
    r = ddenote_program(frontend.load_text(TWO, "two.lgr").program, {"a": a}, {"a": 1})
    assert abs(float(r.value) - ref) <= 1e-8 + r.error, (float(r.value), r.error, ref)


def test_fold_curve_is_an_engine_limitation_not_undefined(monkeypatch):
    monkeypatch.setattr(fold, "FOLD_SECONDS", 1.0)
    program = frontend.load_text(THREE, "three.lgr").program
    with pytest.raises(api.ExactUnavailable, match="singular along the fold") as info:
        api.exact_deriv(program, {"a": 0.3}, {"a": 1})
    assert not isinstance(info.value, api.ExactUndefined)


def test_a_pole_in_a_plain_problem_is_still_undefined():
    import sympy as sp

    from langur.symbolic.pieces import Piece

    x, y = sp.symbols("x y", real=True)
    with pytest.raises(quadrature.UndefinedIntegral):
        quadrature.quad_pieces([Piece((), 1 / (x - y))], [x, y], [(0, 1), (0, 1)], {})
