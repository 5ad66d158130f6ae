"""Conditions in several variables with no closed-form inverse (issue 18, "several variables").

A condition proved strictly monotone in one variable ``v`` on the box (``∂f/∂v`` of one sign on
every sub-box of an interval enclosure, ``langur.syntax.monotone``) is completed by ``v``: one
inverse branch ``v = ImplicitRoot(f[other variables := u₁, …], v, u₀, lo, hi)``.  The exact engine
integrates the delta over the other inputs by quadrature (it says so: ``method``), the Monte Carlo
engine bisects per sample.

Each derivative is checked against central finite differences of the value computed here,
independently, by nested ``scipy.integrate.quad`` whose innermost integral (over the monotone
variable) is split at the root found by ``brentq`` — at parameters where the zero set crosses the
box, where it leaves it through part of its boundary, and where it misses it.
"""

import math

import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from langur import frontend
from langur.cli import main
from langur.core import IfDiffeo, ImplicitRoot, Var, free_vars, subterms
from langur.ddenote import ddenote_program
from langur.diagnostics import LangurError
from langur.operational import estimate_derivative

H = 1e-4  # central differences of the quadrature
EPS = dict(epsabs=1e-12, epsrel=1e-12, limit=200)


def _inner(f, h, lo, hi):
    """∫_lo^hi [f(v) ≥ 0]·h(v) dv for f monotone in v: split at its root (brentq)."""
    flo, fhi = f(lo), f(hi)
    if (flo >= 0) == (fhi >= 0):
        return quad(h, lo, hi, **EPS)[0] if flo >= 0 else 0.0
    r = brentq(f, lo, hi, xtol=1e-15)
    return quad(h, r, hi, **EPS)[0] if fhi >= 0 else quad(h, lo, r, **EPS)[0]


def _kinks(g, lo, hi):
    """Where ``g`` (monotone) crosses 0 on [lo, hi]: the outer integrand's kinks."""
    return [brentq(g, lo, hi, xtol=1e-15)] if g(lo) * g(hi) < 0 else []


def _outer(inner, lo, hi, points):
    return quad(inner, lo, hi, points=sorted(p for p in points if lo < p < hi) or None, **EPS)[0]


def g3(t):
    return t**3 + t


def cubic2(a):  # ∫∫_{[-1,1]²} [x³ + x + y³ + y − a ≥ 0]·(1 + xy + x) d(x, y), inner over y
    inner = lambda x: _inner(lambda y: g3(x) + g3(y) - a, lambda y: 1 + x * y + x, -1, 1)  # noqa: E731
    pts = _kinks(lambda x: g3(x) + g3(-1) - a, -1, 1) + _kinks(lambda x: g3(x) + g3(1) - a, -1, 1)
    return _outer(inner, -1, 1, pts)


def wiggle(a):  # ∫∫_{[-1,1]²} [x³ − x + y³ + y − a ≥ 0]·(1 + x) d(x, y): monotone in y only
    inner = lambda x: _inner(lambda y: x**3 - x + g3(y) - a, lambda y: 1 + x, -1, 1)  # noqa: E731
    grid = [-1 + i / 500 for i in range(1001)]
    pts = []
    for end in (-1, 1):  # x³ − x + g(±1) − a is not monotone in x: its roots by sign changes
        f = lambda x, e=end: x**3 - x + g3(e) - a  # noqa: E731
        pts += [brentq(f, p, q, xtol=1e-15) for p, q in zip(grid, grid[1:]) if f(p) * f(q) < 0]
    return _outer(inner, -1, 1, pts)


def expcubic(a):  # ∫∫_{[0,1]²} [eˣ + x + y³ + y − a ≥ 0]·(1 + xy) d(x, y)
    inner = lambda x: _inner(lambda y: math.exp(x) + x + g3(y) - a, lambda y: 1 + x * y, 0, 1)  # noqa: E731
    pts = _kinks(lambda x: math.exp(x) + x - a, 0, 1) + _kinks(lambda x: math.exp(x) + x + 2 - a, 0, 1)
    return _outer(inner, 0, 1, pts)


def quintic(a):  # ∫∫_{[-1,1]²} [x⁵ + xy² + x + y³ − a ≥ 0]·e^{y − x/2} d(x, y), inner over x
    f = lambda x, y: x**5 + x * y * y + x + y**3 - a  # noqa: E731
    inner = lambda y: _inner(lambda x: f(x, y), lambda x: math.exp(y - x / 2), -1, 1)  # noqa: E731
    grid = [-1 + i / 500 for i in range(1001)]
    pts = []
    for end in (-1, 1):
        g = lambda y, e=end: f(e, y)  # noqa: E731
        pts += [brentq(g, p, q, xtol=1e-15) for p, q in zip(grid, grid[1:]) if g(p) * g(q) < 0]
    return _outer(inner, -1, 1, pts)


def falling(a):  # ∫∫_{[-1,1]²} [a − g(x) − g(y) − xy/2 ≥ 0]·(1 + x) d(x, y): decreasing in y
    f = lambda x, y: a - g3(x) - g3(y) - x * y / 2  # noqa: E731
    inner = lambda x: _inner(lambda y: f(x, y), lambda y: 1 + x, -1, 1)  # noqa: E731
    return _outer(inner, -1, 1, _kinks(lambda x: f(x, -1), -1, 1) + _kinks(lambda x: f(x, 1), -1, 1))


def cubic3(a):  # ∫∫∫_{[-1,1]×[-1,1]×[0,1]} [g(x) + g(y) + g(z) − a ≥ 0]·(1 + xz), innermost over z
    def middle(x):
        inner = lambda y: _inner(lambda z: g3(x) + g3(y) + g3(z) - a, lambda z: 1 + x * z, 0, 1)  # noqa: E731
        pts = _kinks(lambda y: g3(x) + g3(y) - a, -1, 1) + _kinks(lambda y: g3(x) + g3(y) + 2 - a, -1, 1)
        return quad(inner, -1, 1, points=sorted(pts) or None, epsabs=1e-11, epsrel=1e-11, limit=200)[0]
    return quad(middle, -1, 1, epsabs=1e-10, epsrel=1e-10, limit=200)[0]


CASES = [
    # (name, program, value by quadrature, solved for, parameters: crossing, leaving through part
    #  of the boundary, missing the box)
    ("cubic2", "param a = 0.5\nint ([-1, 1], [-1, 1]) [x^3 + x + y^3 + y - a >= 0] * (1 + x * y + x) d(x, y)\n",
     cubic2, "y", [0.5, 3.0, 4.5, -5.0]),
    ("wiggle", "param a = 0.3\nint ([-1, 1], [-1, 1]) [x^3 - x + y^3 + y - a >= 0] * (1 + x) d(x, y)\n",
     wiggle, "y", [0.3, 2.2, 3.0]),
    ("expcubic", "param a = 2\nint ([0, 1], [0, 1]) [exp(x) + x + y^3 + y - a >= 0] * (1 + x * y) d(x, y)\n",
     expcubic, "y", [2.0, 5.0, 7.0]),
    ("falling", "param a = 0.5\nint ([-1, 1], [-1, 1]) [a - x^3 - x - y^3 - y - x * y / 2 >= 0] * (1 + x) d(x, y)\n",
     falling, "y", [0.5, 3.5, 6.0]),
    ("quintic", "param a = 0.5\nint ([-1, 1], [-1, 1]) [x^5 + x * y^2 + x + y^3 - a >= 0] * exp(y - x / 2) d(x, y)\n",
     quintic, "x", [0.5, 3.5, 5.0]),
]
CUBIC3 = ("param a = 0.5\nint ([-1, 1], [-1, 1], [0, 1]) [x^3 + x + y^3 + y + z^3 + z - a >= 0] * (1 + x * z) "
          "d(x, y, z)\n")


def _load(text):
    return frontend.load_text(text, "case.lgr")


def _site(program):
    (site,) = [t for t in subterms(program.integrand) if isinstance(t, IfDiffeo)]
    return site


def _check(program, value, a, samples=2000):
    fd = (value(a + H) - value(a - H)) / (2 * H)
    exact = ddenote_program(program, {"a": a}, {"a": 1})
    assert abs(exact.value - fd) <= 1e-6 * (1 + abs(fd)) + exact.error, (a, exact.value, fd)
    mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=samples, seed=3)
    assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-6 * (1 + abs(fd)), (a, mc.value, mc.stderr, fd)
    assert abs(mc.value - exact.value) <= 5 * mc.stderr + 1e-9 * (1 + abs(fd)), (a, mc.value, exact.value)
    return fd, exact, mc


@pytest.mark.parametrize("name, text, value, solved_for, points", CASES, ids=[c[0] for c in CASES])
def test_derivatives_match_finite_differences(name, text, value, solved_for, points):
    program = _load(text).program
    site = _site(program)
    assert site.psi.solved_for == solved_for and len(site.psi.branches) == 1
    (branch,) = site.psi.branches
    root = branch.components[site.psi.variables.index(solved_for)]
    assert isinstance(root, ImplicitRoot) and root.variable == solved_for
    seen = set()
    for a in points:
        fd, exact, mc = _check(program, value, a)
        if fd != 0:  # the zero set meets the box: the exact delta needed quadrature over u₁, and said so
            assert exact.boundary.method.startswith("quadrature"), exact.boundary.method
        seen.add(fd == 0)
    assert seen == {True, False}  # both a zero set in the box and one missing it were tested


def test_three_variables():
    # innermost z: the exact engine integrates the delta over (u₁, u₂) by quadrature
    program = _load(CUBIC3).program
    assert _site(program).psi.solved_for == "z"
    fd, exact, _ = _check(program, cubic3, 0.5, samples=1000)
    assert fd != 0 and exact.boundary.method.startswith("quadrature")
    fd, exact, _ = _check(program, cubic3, 7.0, samples=500)  # max of the condition + a is 6: missed
    assert fd == 0 and exact.value == 0


def test_the_delta_is_the_sum_over_the_boundary_curve():
    # by hand: d/da ∫∫ [F ≥ a]·h = −∫ h(x, y*(x)) / |∂F/∂y| dx over the x where the root y* exists
    program = _load(CASES[0][1]).program
    a = 0.5

    def integrand(x):
        c = a - g3(x)
        if not g3(-1) <= c <= g3(1):
            return 0.0
        y = brentq(lambda t: g3(t) - c, -1, 1, xtol=1e-15)
        return -(1 + x * y + x) / (3 * y * y + 1)
    lo = brentq(lambda x: g3(x) + g3(1) - a, -1, 1)
    by_hand = quad(integrand, lo, 1, **EPS)[0]
    exact = ddenote_program(program, {"a": a}, {"a": 1})
    assert abs(exact.value - by_hand) <= 1e-8 + exact.error


@pytest.mark.parametrize("cond", ["sin(3*x) + sin(3*y) + x*y - a >= 0", "x^3 - x*y + y^3 - y - a >= 0"])
def test_a_condition_monotone_in_no_variable_is_split_along_one(cond):
    # monotone in no variable, and each slope depends on the other variable (∂/∂y = 3cos(3y) + x,
    # 3y² − x − 1): split along y at its turning points, which move with x (test_split_along_moving.py)
    site = _site(_load(f"param a = 0.5\nint ([-1, 1], [-1, 1]) [{cond}] d(x, y)\n").program)
    assert site.psi.solved_for == "y" and len(site.psi.branches) > 1


def test_a_condition_with_a_pole_in_the_box_is_refused():
    # not monotone in either variable, and not continuous on the box (a pole on x + y = −1/2): no split
    with pytest.raises(LangurError) as info:
        _load("param a = 0.5\nint ([-1, 1], [-1, 1]) [x^3 - x*y + y^3 + 1/(x + y + 0.5) - a >= 0] d(x, y)\n")
    (d,) = info.value.diagnostics
    says = ["not monotone in x", "not monotone in y", "it is continuous in y on"]
    assert d.code == "T207" and all(s in d.message for s in says), d.message


def test_monotone_in_every_variable_is_completed_by_the_last():
    # eˣ + x + eʸ + y − a: ∂/∂x = eˣ + 1 and ∂/∂y = eʸ + 1 are proved positive on the box; y is taken
    site = _site(_load("param a = 0.5\nint ([-2, 2], [-2, 2]) [exp(x) + x + exp(y) + y - a >= 0] d(x, y)\n").program)
    (branch,) = site.psi.branches
    assert site.psi.solved_for == "y" and branch.components[0] == Var(site.psi.inputs[1])
    root = branch.components[1]
    assert isinstance(root, ImplicitRoot) and site.psi.inputs[1] in free_vars(root.equation)


def test_the_naive_evaluator_solves_the_same_roots():
    from langur.operational.naive import naive_derivative

    program = _load(CASES[3][1]).program
    slow = naive_derivative(program, {"a": 0.5}, {"a": 1.0}, samples=20, seed=1)
    fast = estimate_derivative(program, {"a": 0.5}, {"a": 1.0}, samples=20, seed=1)
    assert abs(slow.value - fast.value) < 1e-9 * (1 + abs(fast.value))


def test_cli_on_the_example(capsys):
    from pathlib import Path

    path = str(Path(__file__).resolve().parent.parent / "examples" / "implicit2d.lgr")
    assert main(["check", path]) == 0
    assert main(["show", path, "--wrt", "a"]) == 0
    assert "root(" in capsys.readouterr().out
    assert main(["eval", path, "--samples", "2000"]) == 0
    assert "engines agree" in capsys.readouterr().out
    assert main(["deriv", path, "--samples", "2000", "--no-theorem"]) == 0
    out = capsys.readouterr().out
    fd = (cubic2(0.5 + H) - cubic2(0.5 - H)) / (2 * H)
    assert "engines agree" in out and f"{fd:.6f}"[:8] in out.replace(" ", "")


def test_the_certificate_splits_the_box_where_one_enclosure_is_not_enough():
    import sympy as sp

    from langur.syntax.monotone import Monotone, certify

    x, y = sp.symbols("x y", real=True)
    f = x**3 - x**2 + x + x * y  # ∂/∂x = 3x² − 2x + 1 + y ≥ 2/3 on [-1, 1] × [0, 1] (minimum at x = 1/3)
    assert (3 * x**2 - 2 * x + 1).subs(x, sp.AccumBounds(-1, 1)).min < 0  # one enclosure straddles 0
    assert certify(f, x, {x: (-1.0, 1.0), y: (0.0, 1.0)}) == Monotone(1)
    assert certify(-f, x, {x: (-1.0, 1.0), y: (0.0, 1.0)}) == Monotone(-1)
    # with y down to −1 the slope 3x² − 2x + 1 + y is −1/3 at (1/3, −1) and positive at (1, 0)
    assert "takes both signs" in certify(f, x, {x: (-1.0, 1.0), y: (-1.0, 1.0)})
