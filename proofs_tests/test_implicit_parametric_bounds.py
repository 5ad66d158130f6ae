"""Implicit roots on a domain whose bound moves with a parameter (issue 18).

``int ([0, a + 1]) [x^5 + x - a >= 0] … d(x)``: the condition has no closed-form inverse and the
domain's upper end moves with ``a``.  The implicit root's bracket follows the moving end (the
condition is monotone on the whole line, so one branch covers every interval).  In two variables
the condition is proved monotone in the variable whose bound moves.  Both engines are checked
against central differences of the value computed independently here (scipy quadrature between
roots found by brentq).
"""

import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from langur import frontend
from langur.ddenote import ddenote_program
from langur.diagnostics import LangurError
from langur.operational import estimate_derivative

ONE = "param a = 0.5\nint ([0, a + 1]) [x^5 + x - a >= 0] * (1 + x) d(x)\n"
TWO = "param a = 1.5\nint ([0, 1], [0, a + 1]) [x^5 + x + y^5 + y - a >= 0] * (1 + x * y) d(x, y)\n"
H = 1e-4


def one(a):
    """∫₀^{a+1} [x⁵ + x ≥ a]·(1 + x) dx: the root r of x⁵ + x = a (brentq), then the integral of
    1 + x from max(r, 0) to a + 1 in closed form."""
    r = brentq(lambda x: x**5 + x - a, -10, 10, xtol=1e-15)
    lo, hi = max(r, 0.0), a + 1
    return 0.0 if lo >= hi else (hi - lo) + (hi * hi - lo * lo) / 2


def two(a):
    """∫₀¹ ∫₀^{a+1} [x⁵ + x + y⁵ + y ≥ a]·(1 + x·y) dy dx: inner integral in closed form from the
    root in y (brentq), outer by scipy's quad."""
    def inner(x):
        c = a - x**5 - x
        r = brentq(lambda y: y**5 + y - c, -10, 10, xtol=1e-15)
        lo, hi = max(r, 0.0), a + 1
        return 0.0 if lo >= hi else (hi - lo) + x * (hi * hi - lo * lo) / 2
    return quad(inner, 0, 1, epsabs=1e-13, epsrel=1e-13, limit=200)[0]


@pytest.mark.parametrize("text, value, points, samples", [
    (ONE, one, [0.5, 3.0, -0.5], 500),  # root inside the moving interval, near its end, below it
    (TWO, two, [1.5, 0.2], 4000),
], ids=["one variable", "two variables"])
def test_both_engines_match_quadrature_differences(text, value, points, samples):
    program = frontend.load_text(text, "bound.lgr").program
    for a in points:
        fd = (value(a + H) - value(a - H)) / (2 * H)
        exact = ddenote_program(program, {"a": a}, {"a": 1})
        assert abs(exact.value - fd) <= 1e-6 * (1 + abs(fd)) + exact.error, (a, exact.value, fd)
        mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=samples, seed=5)
        assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-6 * (1 + abs(fd)), (a, mc.value, mc.stderr, fd)


def test_the_bracket_is_the_moving_interval():
    # the implicit root's bracket is [0, a + 1] itself (no constant interval could hold it)
    from langur.core import IfDiffeo, ImplicitRoot, Param, free_params, subterms

    program = frontend.load_text(ONE, "bound.lgr").program
    roots = [c for t in subterms(program.integrand) if isinstance(t, IfDiffeo)
             for b in t.psi.branches for c in b.components if isinstance(c, ImplicitRoot)]
    assert len(roots) == 1 and free_params(roots[0].hi) == {"a"} and not free_params(roots[0].lo)
    assert any(isinstance(u, Param) for u in subterms(roots[0].hi))


def test_turning_points_with_a_moving_bound_split_at_sign_changes_on_the_moving_interval():
    # x⁵ − x − a turns at ±5^(-1/4): its pieces end at the k-th sign changes of 5x⁴ − 1 on [0, a + 1]
    # itself (no clamping; test_turning_moving_bound checks the numbers)
    from langur.core import IfDiffeo, ImplicitRoot, free_params, subterms

    program = frontend.load_text("param a = 0.5\nint ([0, a + 1]) [x^5 - x - a >= 0] d(x)\n", "turns.lgr").program
    roots = [c for t in subterms(program.integrand) if isinstance(t, IfDiffeo)
             for b in t.psi.branches for c in b.components if isinstance(c, ImplicitRoot)]
    ends = [r.hi for r in roots[:-1]]
    assert ends and all(isinstance(e, ImplicitRoot) and e.index == k for k, e in enumerate(ends))
    assert all(free_params(e.hi) == {"a"} for e in ends)
    with pytest.raises(LangurError) as info:  # not continuous on the line: refused, with the reason
        frontend.load_text("param a = 0.5\nint ([1, a + 2]) [x^5 - x - log(x) - a >= 0] d(x)\n", "turns.lgr")
    assert "turns.lgr:2:19: error T207" in str(info.value) and "continuous" in str(info.value)
