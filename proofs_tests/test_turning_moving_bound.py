"""Turning points together with a domain bound that moves with a parameter (issue 18, item 2).

``int ([0, a + 1]) [x^3 - x - a >= 0] …``: the condition turns at x = ±1/√3 and the domain's end
moves with ``a``, so the turning point 1/√3 enters the domain as ``a`` grows past 1/√3 − 1 and
roots appear and vanish inside it (and leave it through the moving end).  The pieces' ends are the
certified k-th sign changes of ∂f/∂x on the moving interval itself (``turning._moving_ends``), as
for turning points that move; ``x^3 - a*x - 1/10`` has both.  Both engines are checked against
central differences of the value computed independently here with mpmath (40 digits: quadrature
between the polynomial's real roots), and the linter reports the tangent parameter value.
"""

from __future__ import annotations

import mpmath
import pytest

from langur import frontend
from langur.ddenote import ddenote_program
from langur.operational import estimate_derivative

FIXED = "param a = 0.5\nint ([0, a + 1]) [x^3 - x - a >= 0] * (1 + x) d(x)\n"
MOVING = "param a = 1\nint ([0, a + 1]) [x^3 - a * x - 0.1 >= 0] * (1 + x) d(x)\n"


def _value(coeffs, a):
    """∫₀^{a+1} [p(x) ≥ 0]·(1 + x) dx for the cubic p with ``coeffs(a)`` (highest first): mpmath's
    quadrature on each interval between the real roots in (0, a + 1) where p ≥ 0."""
    with mpmath.workdps(40):
        a = mpmath.mpf(a)
        c = coeffs(a)
        lo, hi = mpmath.mpf(0), a + 1
        cuts = sorted(r.real for r in mpmath.polyroots(c, maxsteps=200, extraprec=200)
                      if abs(r.imag) < mpmath.mpf(10) ** -30 and lo < r.real < hi)
        pts = [lo] + cuts + [hi]
        total = mpmath.mpf(0)
        for p, q in zip(pts, pts[1:]):
            if mpmath.polyval(c, (p + q) / 2) >= 0:
                total += mpmath.quad(lambda x: 1 + x, [p, q])
        return total


def _fd(coeffs, a, h=1e-8):
    with mpmath.workdps(40):
        return float((_value(coeffs, mpmath.mpf(a) + h) - _value(coeffs, mpmath.mpf(a) - h)) / (2 * h))


def _fixed(a):
    return [1, 0, -1, -a]


def _moving(a):
    return [1, 0, -a, -mpmath.mpf(1) / 10]


@pytest.mark.parametrize("text, coeffs, points", [
    # a = −0.6: 1/√3 outside [0, 0.4], no root; −0.35: two roots, one past the moving end; −0.2: one
    # root inside, the other outside; 2: one root right of 1/√3 (−0.4: test_roots_appear_…)
    (FIXED, _fixed, [-0.6, -0.35, -0.2, 2.0]),
    # turning point √(a/3) moving too: 0.05 (one root near 0.47, domain [0, 1.05]), 2.5
    (MOVING, _moving, [0.05, 2.5]),
], ids=["fixed turning points", "moving turning points"])
def test_both_engines_match_mpmath_differences(text, coeffs, points):
    program = frontend.load_text(text, "bound.lgr").program
    for a in points:
        fd = _fd(coeffs, a)
        exact = ddenote_program(program, {"a": a}, {"a": 1})
        assert abs(exact.value - fd) <= 1e-7 * (1 + abs(fd)) + exact.error, (a, exact.value, fd)
        mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=500, seed=3)
        assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-7 * (1 + abs(fd)), (a, mc.value, mc.stderr, fd)


def test_roots_appear_inside_the_moving_domain():
    # between a = −0.4 and −0.35 a root pair appears at 1/√3 (which the domain [0, a + 1] then
    # holds): the derivative jumps from the domain end's 1·(a + 2) to a sum with the roots' terms
    program = frontend.load_text(FIXED, "bound.lgr").program
    before = ddenote_program(program, {"a": -0.4}, {"a": 1}).value
    after = ddenote_program(program, {"a": -0.35}, {"a": 1}).value
    assert abs(before - (-0.4 + 2)) < 1e-9  # no root yet: only the moving end, (1 + x) at x = a + 1
    assert abs(after - _fd(_fixed, -0.35)) < 1e-7 and abs(after - before) > 0.5


def test_the_linter_reports_the_tangent_value_in_the_domain(tmp_path):
    from langur.cli import main

    path = tmp_path / "bound.lgr"
    path.write_text(FIXED)
    root = -2 / (3 * 3 ** 0.5)  # f(1/√3) = 0: the two roots merge on the turning point
    report = tmp_path / "out.txt"

    def run(*args):
        import contextlib
        import io
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf), contextlib.redirect_stderr(buf):
            code = main(["check", str(path), *args])
        report.write_text(buf.getvalue())
        return code, buf.getvalue()

    code, out = run()
    assert code == 0 and "X306" in out and "sqrt(3)/3" in out and "-2*sqrt(3)/9" in out
    assert "x = -sqrt(3)/3" not in out  # never in [0, a + 1]
    code, out = run("--at", f"a={root!r}")
    assert code == 1 and "error X305" in out


