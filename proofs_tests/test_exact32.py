"""The exact engine claims what it proves, and Monte Carlo says when it saw nothing (paper §8.2's
⟦p⟧ at a point; branch exact32, bench/RESULTS.md).

* A narrow peak between ``quad``'s abscissae on a normal-width range: ``exp(-1e8*(x - 0.3)^2)`` on
  [0, 1] (width 10⁻⁴; main 36a3225 printed ``0 (quadrature, error ≤ 1e-10)`` and discarded the
  right closed form as "disagreeing").  Interval enclosures of the piece's integral
  (:mod:`langur.symbolic.quadrature.enclosed`) now decide between the two, and back a quadrature's
  error only where they prove it.
* Where every Monte Carlo sample is 0, the standard error 0 bounds nothing: the note and the
  agreement line say so, on a missed peak and on an empty pixel alike.

Values computed independently: by hand (√π/10⁴, e^(−0.01)), mpmath at 30 digits with the peak as
a breakpoint, and the periodic peaks' sum 31·π·e^(−a/2)·I₀(a/2) (∫₀^π e^(−a sin²t) dt) by
mpmath's Bessel function.
"""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import mpmath
import pytest
import sympy as sp

from langur import operational
from langur.commands._common import agreement
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.symbolic import integrate
from langur.symbolic.context import Context
from langur.symbolic.pieces import Method
from langur.symbolic.quadrature.enclosed import Enclosed, enclose_integral
from langur.timebox import Deadline

ROOT = Path(__file__).resolve().parents[1]
PEAK = "int ([0, 1]) exp(-1e8*(x - 0.3)^2) d(x)\n"
# (width 10⁻⁴: since diverge33's pass at the integrand's own scale, quad finds a peak of width 10⁻³
# — one of its abscissae sees e^(−100) and the tolerance is scaled to it —, so the enclosure's cases
# need a peak that every abscissa misses, its integrand 0 in doubles; bench/history/2026-11-29.md#diverge33
MOVING = "param a = {a}\nint ([0, 1]) [x <= a]*exp(-1e8*(x - 0.37)^2) d(x)\n"
NEAR = "param a = {a}\nint ([0, 1]) [x <= a]*exp(-1e6*(x - 0.37)^2) d(x)\n"
HIDDEN = "int ([0, 1]) exp(-1e8*sin(x - 0.37)^2) d(x)\n"  # sympy finds no antiderivative
PEAKS = "int ([0, 100]) exp(-1e4*sin(x - 37.3)^2) d(x)\n"  # 31 peaks of width 10⁻²
WIDE = "param a = 0.5\nint ([-1e10, 1e10]) [x <= a]*exp(-x*x) d(x)\n"


def _loaded(text: str):
    loaded = load_text(text)
    return loaded, loaded.param_values()


def _exact(text: str):
    loaded, at = _loaded(text)
    return exact_eval(loaded.program, at)


@pytest.mark.parametrize("text, value", [
    (PEAK, math.sqrt(math.pi) / 1e4),  # main: 0 (quadrature, error ≤ 1e-10)
    (MOVING.format(a=0.5), math.sqrt(math.pi) / 1e4),  # the quadrature cross-check alone: 0 ± 1e-10 (its note)
])
def test_a_closed_form_the_quadrature_missed_is_proved_and_kept(text, value):
    r = _exact(text)
    assert r.method == Method.CLOSED_FORM, r.notes
    assert not r.inconsistent, r.inconsistent  # main: "closed form … disagrees with quadrature 0.0"
    assert r.value == pytest.approx(value, rel=1e-9)
    assert any("closed form kept" in n and "outside the interval enclosure" in n for n in r.notes), r.notes


def test_near_the_peak_and_the_derivative():
    loaded, at = _loaded(NEAR.format(a=0.3701))  # (a breakpoint at a, 10⁻⁴ from the peak: quadrature sees it)
    r = exact_eval(loaded.program, at)
    assert r.method == Method.CLOSED_FORM and r.value == pytest.approx(math.sqrt(math.pi) / 2e3 * (1 + math.erf(0.1)))
    d = exact_deriv(loaded.program, at, {"a": 1}, check=False)
    assert d.value == pytest.approx(math.exp(-0.01), rel=1e-9)  # the delta at x = a: e^(−10⁶·10⁻⁸)


def _mp(f, points):
    with mpmath.workdps(30):
        return float(mpmath.quad(f, points, maxdegree=10))


def test_a_missed_peak_without_closed_form_is_found_and_its_error_proved():
    r = _exact(HIDDEN)
    ref = _mp(lambda x: mpmath.exp(-10**8 * mpmath.sin(x - mpmath.mpf("0.37")) ** 2), [0, 0.3699, 0.37, 0.3701, 1])
    assert ref == pytest.approx(math.sqrt(math.pi) / 1e4 * (1 + 1 / 4e8), rel=1e-9)  # √π/10⁴·(1 + 1/(4·10⁸)), by hand
    assert r.method == Method.QUADRATURE
    assert abs(r.value - ref) <= r.proved <= 1e-6 * ref  # the quadrature alone: 0 ± 1e-10 (the note)
    assert r.how().startswith("quadrature, error ≤ ")
    assert any("missed mass" in n for n in r.notes)


def test_thirty_one_missed_peaks():
    a = mpmath.mpf(10) ** 4
    ref = float(31 * mpmath.pi * mpmath.exp(-a / 2) * mpmath.besseli(0, a / 2))  # peaks at 37.3 + kπ, k = −11…19
    r = _exact(PEAKS)  # main: 7.9e-14 with "error ≤ 1e-10"
    assert abs(r.value - ref) <= r.proved <= 1e-3
    assert r.how() == f"quadrature, error ≤ {r.error:.3g}"


def test_a_bound_is_printed_only_where_proved():
    cosh = "exp(-(exp(x) + exp(-x))/2)"
    r = _exact(f"int ([0, 1]) {cosh} d(x)\n")  # 0.3125…: enclosed within the estimate since proof33
    ref = _mp(lambda x: mpmath.exp(-mpmath.cosh(x)), [0, 1])
    assert abs(r.value - ref) <= max(r.error, 1e-15) and r.proved is not None and abs(r.value - ref) <= r.proved
    assert r.proved <= r.error and r.how() == f"quadrature, error ≤ {r.error:.3g}"
    # two variables, a curved boundary: proved, but wider than the estimate, so both are printed
    r = _exact("param a = 0.5\nint ([-1, 1], [-1, 1]) [x^3 + x + y^3 + y >= a] * (1 + x * y + x) d(x, y)\n")
    assert r.method == Method.QUADRATURE and r.error < r.proved
    assert r.how() == f"quadrature, error estimate {r.error:.3g}, proved ≤ {r.proved:.3g}"
    # a delta through an implicit root (examples/implicit2d.lgr): no proof, so no bound is claimed
    loaded, at = _loaded("param a = 0.5\nint ([-1, 1], [-1, 1]) [x^3 + x + y^3 + y >= a] d(x, y)\n")
    d = exact_deriv(loaded.program, at, {"a": 1}, check=False)
    assert d.method == Method.QUADRATURE and d.proved is None  # main: "error ≤ 2.08e-10"
    assert d.how() == f"quadrature, error estimate {d.error:.3g}"


def test_enclosures_hold_the_exact_integrals():
    x, y = sp.symbols("x y")
    e = enclose_integral([1 - x - y], sp.exp(x), [x, y], [(0, 1), (0, 1)], {})  # ∫∫_{x+y≤1} eˣ = e − 2
    assert e.lo <= math.e - 2 <= e.hi and e.hi - e.lo < 0.2
    e = enclose_integral([], x**2, [x], [(sp.Rational(1, 3), 1)], {})  # ∫_{1/3}^1 x² = 26/81
    assert e.lo <= 26 / 81 <= e.hi and e.hi - e.lo < 1e-6
    a = sp.Symbol("a")
    e = enclose_integral([a - x], sp.Integer(1), [x], [(0, 1)], {a: sp.Rational(1, 3)})  # [x ≤ a]: a
    assert e.lo <= 1 / 3 <= e.hi
    assert enclose_integral([], sp.Abs(x - a), [x], [(0, 1)], {}) is None  # a free symbol: no proof
    assert enclose_integral([], 1 / x, [x], [(0, 1)], {}) is None  # never finite: no proof


def _ctx():
    return Context({}, Deadline(5.0), frozenset())


def test_a_closed_form_outside_the_enclosure_is_refuted():
    exc = integrate.IntegrationMismatch(1.0, 0.5, 1e-10, sp.Integer(1), "piece 0")
    ctx = _ctx()
    assert integrate._judged(exc, Enclosed(0.49, 0.51, 10), ctx, "piece 0") is None
    assert "the closed form is wrong, the quadrature kept" in ctx.notes[0]
    ctx = _ctx()  # both inside: undecided, the quadrature stands as before (no note)
    assert integrate._judged(exc, Enclosed(0.0, 2.0, 10), ctx, "piece 0") is None and not ctx.notes
    ctx = _ctx()
    assert integrate._judged(exc, Enclosed(0.99, 1.01, 10), ctx, "piece 0") is not None
    assert "closed form kept" in ctx.notes[0]


def test_monte_carlo_says_when_every_sample_was_0():
    loaded, at = _loaded(WIDE)
    v = operational.estimate_value(loaded, at, samples=1000, seed=0)
    assert v.value == 0 and v.stderr == 0 and v.all_zero
    assert any(n.startswith("every one of the 1000 samples was 0") for n in v.notes)
    line = agreement(1.3475, 0.0, v.value, v.stderr, v.all_zero)
    assert line.startswith("engines DISAGREE") and "every MC sample was 0: MC saw none of the mass" in line
    assert agreement(0.0, 0.0, 0.0, 0.0, True) == ("engines agree: |exact − MC| = 0 "
                                                  "(every MC sample was 0: consistent, not evidence)")
    assert agreement(0.0, 0.0, 0.0, 0.0) == "engines agree: |exact − MC| = 0 (MC SE = 0)"  # as before
    # fig1's derivative: every tangent sample is 0, but the delta's root is not: seen
    loaded, at = _loaded("param theta = 0.5\nint ([0, 1]) [x <= theta] d(x)\n")
    d = operational.estimate_derivative(loaded, at, {"theta": 1.0}, samples=1000, seed=0)
    assert d.value == 1 and not d.all_zero and not any("every one" in n for n in d.notes)


def test_the_empty_pixel_says_so_too():
    out = subprocess.run([sys.executable, "-P", "-m", "langur", "eval", "examples/raytrace/scene.lgr", "--engine", "mc"],
                         cwd=ROOT, capture_output=True, text=True, timeout=300,
                         env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"}).stdout
    assert "  MC    : 0 ± 0" in out and "note: every one of the 10000 samples was 0" in out, out
