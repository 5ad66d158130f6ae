"""A defined delta integral is not called undefined (issue 9's converse; paper §7.3's delta pieces
through a closed-form square root, LANGUAGE.md §4).

``∫ [z³ − zy + 3(x − 0.3)² + 3(y − 0.5)² − a ≥ 0]`` over a box: its derivative in ``a`` is a delta
integral over the surface, x = 0.3 ± √R solved in closed form, whose weight 1/|6(x − 0.3)| = 1/(6√R)
grows like 1/√ at the rim R = 0 (integrable).  Where the cubic guard R(u, v) ≥ 0 has a double
root in v (u = 0.70735: a sliver opens), quadrature used to be asked for abscissae a few units in
the last place from the tangency, and kinks found twice ~10⁻¹⁶ apart gave ``quad`` sub-intervals
it cannot subdivide: the answer was "undefined".  The reference is independent: scipy's
algebraic-weight quadrature (QAWS) with R factored through its roots, so the 1/√ ends are exact.
"""

import math

import numpy as np
import pytest
import sympy as sp
from scipy import integrate
from scipy.optimize import brentq

from langur import frontend, operational
from langur.exact import exact_deriv
from langur.symbolic import quadrature
from langur.symbolic.pieces import Condition, Piece

A = -0.1
PROGRAM = ("param a = -0.1\n"
           "int ([-1, 1], [0.1, 1], [-1, 1]) [z^3 - z*y + 3*(x - 0.3)^2 + 3*(y - 0.5)^2 - a >= 0] d(x, y, z)\n")


def _reference_branch() -> float:
    """∫∫ [0 ≤ R ≤ 0.49] / (6√R) dv du over u ∈ [0.1, 1], v ∈ [−1, 1], R = (a − rest)/3 with
    rest = v³ − uv + 3(u − 0.5)²: one inverse branch (x = 0.3 + √R ∈ [−1, 1] ⇔ √R ≤ 0.7) of
    −d/da.  a − rest = −∏(v − rᵢ) over the cubic's roots; on a piece ending at a real root that
    factor is QAWS's weight (v − r)^(−1/2), the rest a smooth function."""

    def inner(u: float) -> float:
        q = 3 * (u - 0.5) ** 2 - A
        roots = np.roots([1.0, 0.0, -u, q])
        sing = sorted(float(r.real) for r in roots if abs(r.imag) < 1e-9 and -1 < r.real < 1)
        cuts = {-1.0, 1.0, *sing}
        for r in np.roots([1.0, 0.0, -u, q + 1.47]):  # √R = 0.7
            if abs(r.imag) < 1e-12 and -1 < r.real < 1:
                cuts.add(float(r.real))
        cuts = sorted(cuts)

        def d(v):
            return -np.prod([v - r for r in roots]).real

        total = 0.0
        for lo, hi in zip(cuts, cuts[1:]):
            if hi - lo < 1e-15 or not 0 < d(0.5 * (lo + hi)) <= 1.47:
                continue
            ends = [r for r in (lo, hi) if r in sing]
            others = [r for r in roots if not (abs(r.imag) < 1e-9 and float(r.real) in ends)]
            if ends:
                def g(v, others=others):
                    return 1 / (2 * math.sqrt(3 * abs(np.prod([v - r for r in others]))))
                wvar = (-0.5 if lo in sing else 0.0, -0.5 if hi in sing else 0.0)
                val, _ = integrate.quad(g, lo, hi, weight="alg", wvar=wvar, epsabs=1e-13, epsrel=1e-12, limit=200)
            else:
                val, _ = integrate.quad(lambda v: 1 / (2 * math.sqrt(3 * d(v))), lo, hi, epsabs=1e-13,
                                        epsrel=1e-12, limit=200)
            total += val
        return total

    def disc(u):  # the cubic's discriminant: where the sliver opens or closes
        return 4 * u ** 3 - 27 * (3 * (u - 0.5) ** 2 - A) ** 2

    us = np.linspace(0.1, 1, 1001)
    turns = [brentq(disc, s, t, xtol=1e-15) for s, t in zip(us, us[1:]) if disc(s) * disc(t) < 0]
    val, _ = integrate.quad(inner, 0.1, 1, epsabs=1e-11, epsrel=1e-11, limit=400, points=turns)
    return val


@pytest.fixture(scope="module")
def reference():
    return _reference_branch()


def test_tangent_sliver_branch_has_its_value(reference):
    u, v, a = sp.symbols("u v a", real=True)
    R = u * v / 3 - v ** 3 / 3 - (u - sp.Rational(1, 2)) ** 2 + a / 3
    conds = (Condition(R), Condition(sp.sqrt(R) + sp.Rational(13, 10)), Condition(sp.Rational(7, 10) - sp.sqrt(R)))
    problems = []
    val, err = quadrature.quad_pieces([Piece(conds, 1 / (6 * sp.sqrt(R)))], [u, v], [(0.1, 1), (-1, 1)],
                                      {a: A}, None, problems)  # raised UndefinedIntegral before
    assert all(p.converged for p in problems)
    assert abs(val - reference) <= err < 1e-5


def test_island_derivative_is_a_number(reference):
    loaded = frontend.load_text(PROGRAM)
    d = exact_deriv(loaded.program, {"a": A}, {"a": 1}, check=False)
    assert d.value is not None and math.isfinite(d.value)
    # both branches x = 0.3 ± √R: rest ≥ −0.59 on the box, so √R ≤ 0.4 and both stay in [−1, 1]
    assert abs(d.value - (-2 * reference)) <= d.error < 1e-5
    mc = operational.estimate_derivative(loaded, {"a": A}, {"a": 1}, samples=20000, seed=3)
    assert abs(mc.value - (-2 * reference)) <= 5 * mc.stderr + 1e-9
