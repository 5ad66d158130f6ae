"""Moving turning points are certified complete (issue 18).

A condition whose turning points move with the parameters is split at the k-th sign change of
∂f/∂x.  Counting them on a grid of 512 points missed two turning points inside one cell, in both
engines alike (they agreed on a wrong number).  Now each engine certifies every cell on its own
(interval enclosures of ∂f/∂x and ∂²f/∂x²; the exact engine with mpmath's intervals, the Monte
Carlo engine with ``operational/interval.py``), and refuses where it cannot (X316).

The references here are independent: the value by mpmath quadrature between roots found by a fine
scan and ``findroot``, differentiated by central differences at 40 digits.
"""

import math
import subprocess
import sys

import mpmath
import numpy as np
import pytest
import sympy as sp

from langur import frontend
from langur.core import Add, Const, Mul, Pow, TooManyRoots, Var
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.enclosures import certified_brackets, interval_function
from langur.operational import estimate_derivative
from langur.operational.interval import _periodic, tape_of
from langur.operational.naive import naive_derivative
from langur.operational.signchanges import certified_brackets as mc_brackets

# x − a·atan((x − s)/w) − s: turning points where 1 + ((x − s)/w)² = a/w, i.e. s ± w·sqrt(a/w − 1):
# for a = 0.002 at 0.0009 and 0.0029, 0.002 apart, both inside the cell [0, 2/512] of the old grid
S, W = 0.0019, 0.001
CLOSE = f"param a = 0.002\nint ([-1, 1]) [x - a * atan((x - {S}) / {W}) - {S} >= 0] * (1 + x) d(x)\n"
DEGENERATE = "param a = 0\nint ([-1, 1]) [(x - 0.3)^3 - a * (x - 0.3) + 0.5 >= 0] * (1 + x) d(x)\n"


def close_value(a):
    """∫₋₁¹ [f ≥ 0]·(1 + x) dx at 40 digits: the roots of f by a scan of 20001 points refined by
    mpmath's findroot, then the integral of 1 + x between them by mpmath.quad."""
    a = mpmath.mpf(a)
    s, w = mpmath.mpf(S), mpmath.mpf(W)
    f = lambda x: x - a * mpmath.atan((x - s) / w) - s  # noqa: E731
    xs = np.linspace(-1, 1, 20001)
    v = xs - float(a) * np.arctan((xs - S) / W) - S
    cells = np.nonzero((v[1:] >= 0) != (v[:-1] >= 0))[0]
    roots = [mpmath.findroot(f, (mpmath.mpf(xs[i]), mpmath.mpf(xs[i + 1])), solver="anderson") for i in cells]
    ends = [mpmath.mpf(-1)] + roots + [mpmath.mpf(1)]
    total = sum(mpmath.quad(lambda x: 1 + x, [p, q]) for p, q in zip(ends, ends[1:]) if f((p + q) / 2) >= 0)
    return total, len(roots)


def close_derivative(a):
    with mpmath.workdps(40):
        h = mpmath.mpf("1e-10")
        return float((close_value(mpmath.mpf(a) + h)[0] - close_value(mpmath.mpf(a) - h)[0]) / (2 * h))


@pytest.fixture(scope="module")
def close():
    return frontend.load_text(CLOSE, "close.lgr").program


def test_the_two_turning_points_lie_in_one_cell_of_a_512_grid():
    # the case is the one the grid missed: both turning points strictly inside one cell
    for a in (0.002, 0.003):
        d = W * math.sqrt(a / W - 1)
        cell = [math.floor((S + e + 1) / (2 / 512)) for e in (-d, d)]
        assert cell[0] == cell[1], (a, cell)
    assert close_value(0.002)[1] == 3  # and three roots between them at a = 0.002


@pytest.mark.parametrize("a", [0.002, 0.003, 0.0005])  # three roots, three, one (no turning point)
def test_both_engines_match_quadrature_finite_differences(close, a):
    fd = close_derivative(a)
    exact = ddenote_program(close, {"a": a}, {"a": 1})
    assert abs(exact.value - fd) <= 1e-7 * (1 + abs(fd)) + exact.error, (a, exact.value, fd)
    mc = estimate_derivative(close, {"a": a}, {"a": 1}, samples=200, seed=4)
    assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-7 * (1 + abs(fd)), (a, mc.value, fd)


def test_the_value_matches_quadrature(close):
    exact = denote_program(close, {"a": 0.002})
    assert abs(float(exact.value) - float(close_value(0.002)[0])) <= 1e-9 + float(exact.error or 0)


def test_the_naive_evaluator_certifies_the_same_brackets(close):
    slow = naive_derivative(close, {"a": 0.002}, {"a": 1.0}, samples=5, seed=1)
    fast = estimate_derivative(close, {"a": 0.002}, {"a": 1.0}, samples=5, seed=1)
    assert abs(slow.value - fast.value) < 1e-9 * (1 + abs(fast.value))


def test_a_degenerate_turning_point_is_refused_by_both_engines():
    # (x − 0.3)³ − a·(x − 0.3) at a = 0: ∂f/∂x = 3(x − 0.3)² and ∂²f/∂x² both vanish at 0.3
    program = frontend.load_text(DEGENERATE, "degenerate.lgr").program
    with pytest.raises(TooManyRoots, match="cannot certify.*0.3"):
        ddenote_program(program, {"a": 0.0}, {"a": 1})
    with pytest.raises(TooManyRoots, match="cannot certify.*0.3"):
        estimate_derivative(program, {"a": 0.0}, {"a": 1}, samples=100, seed=0)
    # off the degenerate value both engines answer (and agree)
    exact = ddenote_program(program, {"a": 0.2}, {"a": 1})
    mc = estimate_derivative(program, {"a": 0.2}, {"a": 1}, samples=200, seed=0)
    assert abs(exact.value - mc.value) <= 5 * mc.stderr + 1e-9


def test_the_refusal_is_located_x316_with_exit_status_1(tmp_path):
    f = tmp_path / "degenerate.lgr"
    f.write_text(DEGENERATE)
    r = subprocess.run([sys.executable, "-m", "langur", "deriv", str(f), "--wrt", "a", "--no-theorem"],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1, r
    lines = [ln for ln in r.stderr.splitlines() if "X316" in ln]
    # col 16: the condition's expression (before fold31 the desugarer's `… - 0` around it carried the bracket's col 15)
    assert len(lines) == 2 and all(ln.startswith(f"{f}:2:16: error X316 ") for ln in lines), r.stderr
    assert "no exact value" in lines[0] and "no Monte Carlo value" in lines[1]
    assert "Traceback" not in r.stderr


def _g(k):  # (x − 0.1)(x − 0.1 − k): two zeros k apart; its derivative 2x − 0.2 − k
    return sp.Symbol("x"), (sp.Symbol("x") - sp.Rational(1, 10)) * (sp.Symbol("x") - sp.Rational(1, 10) - k)


@pytest.mark.parametrize("k", [1e-3, 1e-6])
def test_both_certifiers_count_two_zeros_closer_than_any_grid(k):
    # exact side: mpmath intervals
    x, g = _g(sp.Float(k, 30))
    fn = sp.lambdify(x, g, "mpmath")
    found = certified_brackets(fn, interval_function(x, g), interval_function(x, sp.diff(g, x)), 0, -1, 1)
    assert len(found) == 2
    assert found[0][0] <= 0.1 <= found[0][1] and found[1][0] <= 0.1 + k <= found[1][1]
    # Monte Carlo side: the same function as a core term, enclosed by operational/interval.py
    xv = Var("x")
    term = Mul(Add(xv, Const(-0.1)), Add(xv, Const(-(0.1 + k))))
    slope = Add(Mul(Const(2.0), xv), Const(-(0.2 + k)))
    tape = tape_of([term, slope], True)
    value = lambda at, rows: (at - 0.1) * (at - 0.1 - k)  # noqa: E731
    rows, a, b = mc_brackets(value, tape, "x", np.zeros(1), np.array([-1.0]), np.array([1.0]), {})
    assert list(rows) == [0, 0] and a[0] <= 0.1 <= b[0] and a[1] <= 0.1 + k <= b[1]


def test_a_double_zero_is_refused_not_counted_by_both_certifiers():
    x = sp.Symbol("x")
    g = (x - sp.Rational(1, 3)) ** 2  # touches 0 at 1/3: g and g' vanish together
    fn = sp.lambdify(x, g, "mpmath")
    with pytest.raises(TooManyRoots, match="cannot certify"):
        certified_brackets(fn, interval_function(x, g), interval_function(x, sp.diff(g, x)), 0, -1, 1)
    xv = Var("x")
    tape = tape_of([Pow(Add(xv, Const(-1 / 3)), 2), Mul(Const(2.0), Add(xv, Const(-1 / 3)))], True)
    with pytest.raises(TooManyRoots, match="cannot certify"):
        mc_brackets(lambda at, rows: (at - 1 / 3) ** 2, tape, "x", np.zeros(1), np.array([-1.0]),
                    np.array([1.0]), {})


def test_tight_sine_and_cosine_enclosures_contain_the_function():
    rng = np.random.default_rng(7)
    lo = rng.uniform(-20, 20, 5000)
    hi = lo + rng.exponential(1.0, 5000)
    for op, fn in (("sin", np.sin), ("cos", np.cos)):
        el, eh = _periodic({}, {}, op, (lo, hi))
        t = rng.uniform(0, 1, (20, 5000))
        vals = fn(lo + (hi - lo) * t)
        assert np.all(vals >= el - 1e-15) and np.all(vals <= eh + 1e-15)
        narrow = hi - lo < 0.1  # and they shrink with the interval (what certification needs)
        assert np.all((eh - el)[narrow] <= 0.1 + 1e-9)
