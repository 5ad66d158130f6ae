"""Split along a variable whose turning points move with the *other variables* (issue 18).

``[x^3 - x*y + y^3 - a >= 0]`` on [−1, 1]² (a folium) cannot be solved for either variable in
closed form and is monotone in neither: ∂/∂y = 3y² − x, so its turning points y = ±√(x/3) move
with x (and appear at x = 0).  It is split along y at the k-th certified sign changes of 3y² − u₁
(u₁: Ψ̂⁻¹'s other input, the value of x), at most 2 of them (Descartes' bound for 3y² − u₁), one
implicit-root branch per piece (``turning.split_along``).  The split lives in Ψ̂⁻¹ only, so it
adds no delta: both engines are checked against central differences of the value computed
independently here (for each x the real roots of the cubic in y by ``numpy.roots`` and the inner
integral in closed form; scipy's ``quad`` over x, split where the number of roots changes), with
parameter values where the zero set crosses the square, where its roots leave it, and outside.

Also here: the lenient certification on the null set where two turning points merge, the bound on
the number of turning points of a polynomial slope (which lifts X316 for polynomials: 8 moving
turning points of a degree-9 condition), and the linter's report of the critical points of such a
condition (X306, X305 with ``--at``).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.integrate import quad

from langur import frontend
from langur.core import IfDiffeo, ImplicitRoot, TooManyRoots, Var, subterms
from langur.ddenote import ddenote_program
from langur.enclosures import certified_brackets as exact_brackets
from langur.enclosures import interval_function
from langur.lint.tangent import tangent_findings
from langur.operational import estimate_derivative
from langur.operational.interval import tape_of
from langur.operational.signchanges import certified_brackets as mc_brackets
from langur.sympy_bridge import from_sympy
from langur.syntax.turning import MOVING_PIECES, turning_bound

TEXT = "param a = 0.1\nint ([-1, 1], [-1, 1]) [x^3 - x * y + y^3 - a >= 0] * (1 + x + y) d(x, y)\n"
H = 1e-4


def value(a):
    """∫∫ [x³ − x·y + y³ ≥ a] (1 + x + y) over [−1, 1]², independently of Langur."""
    def inner(x):
        c = x**3 - a  # y³ − x·y + c ≥ 0
        roots = sorted(z.real for z in np.roots([1, 0, -x, c]) if abs(z.imag) < 1e-9 and -1 < z.real < 1)
        pts = [-1.0] + roots + [1.0]
        return sum((q - p) * (1 + x) + (q * q - p * p) / 2 for p, q in zip(pts, pts[1:])
                   if ((p + q) / 2) ** 3 - x * (p + q) / 2 + c >= 0)
    breaks = [z.real for z in np.roots(np.polyadd(27 * np.polymul([1, 0, 0, -a], [1, 0, 0, -a]), [-4, 0, 0, 0]))
              if abs(z.imag) < 1e-9 and -1 < z.real < 1]  # a double root in y: 4x³ = 27(x³ − a)²
    breaks += [z.real for yb in (-1.0, 1.0) for z in np.roots([1, 0, -yb, yb**3 - a])
               if abs(z.imag) < 1e-9 and -1 < z.real < 1]  # a root on the square's side y = ±1
    return quad(inner, -1, 1, points=sorted(breaks) or None, limit=500, epsabs=1e-13, epsrel=1e-13)[0]


def fd(a):
    return (value(a + H) - value(a - H)) / (2 * H)


def _program():
    return frontend.load_text(TEXT, "folium.lgr").program


def test_it_is_split_along_y_at_turning_points_that_move_with_x():
    program = _program()
    roots = [c for t in subterms(program.integrand) if isinstance(t, IfDiffeo)
             for b in t.psi.branches for c in b.components if isinstance(c, ImplicitRoot)]
    assert len(roots) == 3 and {r.variable for r in roots} == {"y"}
    ends = [r.hi for r in roots[:-1]]
    assert all(isinstance(e, ImplicitRoot) and e.index == k and e.of == 2 for k, e in enumerate(ends))
    assert all(Var("u1") in subterms(e.equation) for e in ends)  # 3y² − u1: moves with x's value


@pytest.mark.parametrize("a", [0.1, -0.5, 0.9, 1.5, -3.5])
def test_monte_carlo_matches_quadrature_differences(a):
    # 0.1, −0.5: the zero set crosses the square (turning points appear at x = 0 inside it);
    # 0.9: near the top value 1, the region shrinks to the corner; 1.5, −3.5: no zero set inside
    reference = fd(a)
    mc = estimate_derivative(_program(), {"a": a}, {"a": 1.0}, samples=4000, seed=3)
    assert abs(mc.value - reference) <= 5 * mc.stderr + 1e-6, (a, mc.value, mc.stderr, reference)
    if a in (1.5, -3.5):
        assert reference == 0.0 and mc.value == 0.0


def test_exact_engine_matches_quadrature_differences_and_monte_carlo():
    a = -0.5
    reference = fd(a)  # −0.17040490 (five-point differences agree to 1e-9)
    exact = ddenote_program(_program(), {"a": a}, {"a": 1})
    assert abs(exact.value - reference) <= 1e-6 * (1 + abs(reference)) + exact.error, (exact.value, reference)
    mc = estimate_derivative(_program(), {"a": a}, {"a": 1.0}, samples=4000, seed=5)
    assert abs(mc.value - exact.value) <= 5 * mc.stderr + 1e-6, (mc.value, mc.stderr, exact.value)


def _slope():
    x, u = sp.symbols("x u1", real=True)
    g = 3 * x**2 - u
    return x, u, g, tape_of([from_sympy(g, ("x", "u1")), from_sympy(sp.diff(g, x), ("x", "u1"))], True)


def test_two_turning_points_merging_on_a_null_set_are_not_refused_when_lenient():
    # at u1 = 0, 3x² − u1 has a double zero at 0 (no sign change): neither enclosure certifies the
    # cells around it; for turning points that move with integration variables that is a null set
    x, u, g, tape = _slope()

    def value(at, rows, u1):
        return 3 * np.asarray(at) ** 2 - u1

    lo, hi = np.array([-1.0]), np.array([1.0])
    for u1, expected in [(0.0, []), (0.03, [-0.1, 0.1])]:
        rows, a_, b_ = mc_brackets(lambda at, rows, u1=u1: value(at, rows, u1), tape, "x", np.zeros(1), lo, hi, {},
                                   others={"u1": np.array([u1])}, lenient=True)
        assert len(a_) == len(expected) and all(p <= e <= q for p, q, e in zip(a_, b_, expected))
        found = exact_brackets(lambda z, u1=u1: 3 * z**2 - u1, lambda X, u1=u1: interval_function(x, g, (u,))(X, u1),
                               lambda X, u1=u1: interval_function(x, sp.diff(g, x), (u,))(X, u1), 0, -1, 1, lenient=True)
        assert len(found) == len(expected) and all(p <= e <= q for (p, q), e in zip(found, expected))
    with pytest.raises(TooManyRoots):  # not lenient (a parameter at a degenerate value): refused
        mc_brackets(lambda at, rows: value(at, rows, 0.0), tape, "x", np.zeros(1), lo, hi, {},
                    others={"u1": np.array([0.0])})
    with pytest.raises(TooManyRoots):
        exact_brackets(lambda z: 3 * z**2, lambda X: interval_function(x, g, (u,))(X, 0),
                       lambda X: interval_function(x, sp.diff(g, x), (u,))(X, 0), 0, -1, 1)


def test_a_polynomial_slope_is_split_for_as_many_turning_points_as_it_can_have():
    x, a, y = sp.symbols("x a y", real=True)
    assert turning_bound(3 * x**2 - a, x) == 2  # degree 2
    assert turning_bound(20 * x**19 - a, x) == 3  # two monomials: Descartes, at most 1 + 1 + 1
    assert turning_bound(3 * x**2 - y * x + a, x) == 2
    assert turning_bound(sp.cos(a * x) * a, x) == MOVING_PIECES - 1  # not a polynomial: unbounded in a


CHEBYSHEV = ("param a = 0.05\n"
             "int ([-1, 1]) [256*x^9 - 576*x^7 + 432*x^5 - 120*x^3 + 9*x + a*x^2 - 0.1 >= 0] * (1 + x) d(x)\n")


def test_eight_moving_turning_points_of_a_polynomial_are_not_refused():
    # T₉(x) + a·x² − 0.1 has 8 turning points on [−1, 1] near a = 0 (more than the 7 of a
    # non-polynomial condition, which would be X316); its slope is a polynomial of degree 8
    program = frontend.load_text(CHEBYSHEV, "cheb.lgr").program
    coeffs = [256, 0, -576, 0, 432, 0, -120, 0, 9, 0]

    def value(a):
        p = np.polyadd(coeffs, [a, 0, -0.1])
        roots = sorted(r.real for r in np.roots(p) if abs(r.imag) < 1e-10 and -1 < r.real < 1)
        pts = [-1.0] + roots + [1.0]
        return sum((q - p_) + (q * q - p_ * p_) / 2 for p_, q in zip(pts, pts[1:])
                   if np.polyval(p, (p_ + q) / 2) >= 0)
    a = 0.05
    reference = (value(a + 1e-6) - value(a - 1e-6)) / 2e-6
    mc = estimate_derivative(program, {"a": a}, {"a": 1.0}, samples=2000, seed=0)
    assert abs(mc.value - reference) <= 5 * mc.stderr + 1e-5 * (1 + abs(reference)), (mc.value, reference)


def test_the_linter_reports_the_critical_points_on_the_zero_set():
    # ∇(x³ − x·y + y³) = 0 at (0, 0) (a saddle: the folium's node at a = 0) and at (1/3, 1/3) (a
    # minimum, value −1/27): there the zero set is not smooth and the derivative is not defined
    program = _program()
    found = tangent_findings(program, {"a": 0.1}, False)
    critical = [f for f in found if f.code == "X306" and "critical point" in f.message]
    assert sorted(f.message.split(" when ")[1].split(":")[0] for f in critical) == ["a = -1/27", "a = 0"]
    at_node = tangent_findings(program, {"a": 0.0}, True)
    assert [f.code for f in at_node if "critical point (x, y) = (0, 0)" in f.message] == ["X305"]
    assert not [f for f in tangent_findings(program, {"a": 0.2}, True) if f.code == "X305"]
