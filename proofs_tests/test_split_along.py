"""A condition in several variables monotone in none of them, split along one (issue 18).

``[x^3 - x + y^3 - y - a >= 0]`` on ``[-2, 2]²`` is monotone in neither variable on the box,
but ``∂/∂y = 3y² − 1`` depends on ``y`` only: cut at ``y = ±1/√3`` the condition is strictly
monotone in ``y`` on each strip, for every ``x``, so Ψ̂⁻¹ has one implicit-root branch per strip
(``langur.syntax.turning._split_along``).  Both engines are checked against central differences
(Richardson-extrapolated) of the value computed independently here: for each value of the other
variable the real roots of the cubic by ``numpy.roots``, the inner integral in closed form, the
outer one by scipy's ``quad`` with its breakpoints where the number of roots changes.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from langur import frontend
from langur.core import IfDiffeo, ImplicitRoot, subterms
from langur.ddenote import ddenote_program
from langur.diagnostics import LangurError
from langur.operational import estimate_derivative
from langur.sympy_bridge import to_sympy

K = 2 / (3 * math.sqrt(3))  # the cubic t³ − t has its turning values ±K

FIXED = "param a = 0.3\nint ([-2, 2], [-2, 2]) [x^3 - x + y^3 - y - a >= 0] * (1 + x * y + x) d(x, y)\n"
# ∂/∂y = 3y² − a moves with a: split along x instead (∂/∂x = 3x² − 1)
MOVING_IN_Y = "param a = 0.6\nint ([-1.5, 1.5], [-1.5, 1.5]) [x^3 - x + y^3 - a * y - 0.1 >= 0] * (1 + x) d(x, y)\n"


def _cubic_set_integral(c, lo, hi, weight):
    """∫ over {t ∈ [lo, hi] : t³ − t ≥ c} of weight(p, q) (its integral from p to q, closed form)."""
    roots = sorted(r.real for r in np.roots([1, 0, -1, -c]) if abs(r.imag) < 1e-9)
    ends = [lo] + [r for r in roots if lo < r < hi] + [hi]
    return sum(weight(p, q) for p, q in zip(ends, ends[1:]) if ((p + q) / 2) ** 3 - (p + q) / 2 >= c)


def _breaks(shift, lo, hi):
    """Where the inner cubic's number of roots changes: t³ − t − (shift ∓ K) = 0 on (lo, hi)."""
    return sorted(r.real for s in (K, -K) for r in np.roots([1, 0, -1, -(shift - s)])
                  if abs(r.imag) < 1e-9 and lo < r.real < hi)


def fixed(a):
    def inner(x):  # in y: {y³ − y ≥ a − x³ + x}, weight 1 + x·y + x
        return _cubic_set_integral(a - x**3 + x, -2.0, 2.0,
                                   lambda p, q: (q - p) * (1 + x) + x * (q * q - p * p) / 2)
    return quad(inner, -2, 2, points=_breaks(a, -2, 2), epsabs=1e-12, epsrel=1e-12, limit=400)[0]


def moving_in_y(a):
    def inner(y):  # in x: {x³ − x ≥ 0.1 + a·y − y³}, weight 1 + x
        return _cubic_set_integral(0.1 + a * y - y**3, -1.5, 1.5, lambda p, q: (q - p) + (q * q - p * p) / 2)
    cuts = sorted(r.real for s in (K, -K) for r in np.roots([-1, 0, a, 0.1 - s])
                  if abs(r.imag) < 1e-9 and -1.5 < r.real < 1.5)
    return quad(inner, -1.5, 1.5, points=cuts, epsabs=1e-12, epsrel=1e-12, limit=400)[0]


def richardson(value, a, h=1e-3):
    d = lambda h: (value(a + h) - value(a - h)) / (2 * h)  # noqa: E731
    return (4 * d(h) - d(2 * h)) / 3


@pytest.mark.parametrize("text, value, a", [(FIXED, fixed, 0.3), (FIXED, fixed, 1.0),
                                            (MOVING_IN_Y, moving_in_y, 0.6)],
                         ids=["fixed a=0.3", "fixed a=1", "split along x"])
def test_both_engines_match_quadrature_differences(text, value, a):
    program = frontend.load_text(text, "split.lgr").program
    fd = richardson(value, a)
    exact = ddenote_program(program, {"a": a}, {"a": 1})
    assert abs(exact.value - fd) <= 1e-6 * (1 + abs(fd)) + exact.error, (a, exact.value, fd)
    mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=4000, seed=2)
    assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-6 * (1 + abs(fd)), (a, mc.value, mc.stderr, fd)


def test_one_branch_per_strip_cut_at_the_turning_points():
    program = frontend.load_text(FIXED, "split.lgr").program
    (site,) = [t for t in subterms(program.integrand) if isinstance(t, IfDiffeo)]
    assert site.psi.solved_for == "y" and len(site.psi.branches) == 3
    roots = [b.components[1] for b in site.psi.branches]
    assert all(isinstance(r, ImplicitRoot) and r.index is None for r in roots)
    ends = [float(to_sympy(r.lo)) for r in roots] + [float(to_sympy(roots[-1].hi))]
    assert ends == pytest.approx([-2, -1 / math.sqrt(3), 1 / math.sqrt(3), 2], abs=1e-12)


def test_split_along_turning_points_that_move_with_the_other_variable():
    # ∂/∂x = y + 3cos(3x) depends on y, ∂/∂y = x + 3cos(3y) on x: the strips move with the other
    # variable; split along y at the certified sign changes of ∂/∂y (test_split_along_moving.py)
    program = frontend.load_text("param a = 0.1\nint ([-1, 1], [-1, 1]) [sin(3*x) + sin(3*y) + x*y - a >= 0] "
                                 "d(x, y)\n", "moving.lgr").program
    roots = [c for t in subterms(program.integrand) if isinstance(t, IfDiffeo)
             for b in t.psi.branches for c in b.components if isinstance(c, ImplicitRoot)]
    assert {r.variable for r in roots} == {"y"} and len(roots) == 8  # not a polynomial: 7 slots
    assert all("u1" in {v.name for v in subterms(r.hi.equation) if hasattr(v, "name")} for r in roots[:-1])


def test_still_refused_with_a_pole_in_the_box():
    # the turning points move with the other variable, but the condition is not continuous on the
    # box (1/(x + y) on the diagonal): a root bisected across the pole would be no root
    with pytest.raises(LangurError, match="T207"):
        frontend.load_text("param a = 0.1\nint ([-1, 1], [-1, 1]) [x^3 - x*y + y^3 + 1/(x + y + 0.5) - a >= 0] "
                           "d(x, y)\n", "no.lgr")


def test_the_linter_does_not_report_the_folds_as_merging_roots():
    # a root reaching a strip's end (y = ±1/√3) happens along a curve of x: a fold, not two roots
    # merging for a parameter value (the derivative exists, the tests above compute it)
    from langur.transversality import check_program

    # (its critical points on the zero set are: ∇f = 0 at (±1/√3, ±1/√3), where f + a = ∓2K, 0, 0, ±2K)
    loaded = frontend.load_text(FIXED, "split.lgr")
    found = [f for f in check_program(loaded.program, loaded.params) if f.code in ("X305", "X306")]
    assert all("critical point" in f.message for f in found) and len(found) == 4
    assert sorted(f.message.split(" when ")[1].split(":")[0] for f in found) == \
        ["a = -4*sqrt(3)/9", "a = 0", "a = 0", "a = 4*sqrt(3)/9"]  # ±2K = ±4/(3√3)


def sine_sum(a):
    """∫∫_{[0,1]²} [x + sin 3x + y + sin 3y ≥ a]: h(t) = t + sin 3t rises to its turning point
    acos(−1/3)/3 and falls after it; the measure of {y : h(y) ≥ c} from the two roots (brentq)."""
    h = lambda t: t + math.sin(3 * t)  # noqa: E731
    tp = math.acos(-1 / 3) / 3

    def measure(c):
        if h(tp) < c:
            return 0.0
        lo = 0.0 if h(0) >= c else brentq(lambda t: h(t) - c, 0, tp, xtol=1e-15)
        hi = 1.0 if h(1) >= c else brentq(lambda t: h(t) - c, tp, 1, xtol=1e-15)
        return hi - lo
    return quad(lambda x: measure(a - h(x)), 0, 1, points=[tp], epsabs=1e-13, epsrel=1e-13, limit=500)[0]


def test_a_sum_of_two_non_monotone_functions_is_split_along_y():
    # T207 before (monotone in neither x nor y on [0, 1]²); ∂/∂y = 1 + 3cos 3y depends on y only
    program = frontend.load_text("param a = 0.5\nint ([0, 1], [0, 1]) [x + sin(3 * x) + y + sin(3 * y) >= a] d(x, y)\n",
                                 "sines.lgr").program
    fd = richardson(sine_sum, 0.5)
    exact = ddenote_program(program, {"a": 0.5}, {"a": 1})
    assert abs(exact.value - fd) <= 1e-6 * (1 + abs(fd)) + exact.error, (exact.value, fd)
    mc = estimate_derivative(program, {"a": 0.5}, {"a": 1}, samples=4000, seed=2)
    assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-6 * (1 + abs(fd)), (mc.value, mc.stderr, fd)
