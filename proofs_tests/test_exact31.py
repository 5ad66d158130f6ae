"""A narrow peak in a wide box: the quadrature finds the mass, or says its error is an estimate
(paper §8.2's ⟦p⟧ at a point; branch exact31, bench/RESULTS.md).

``[x <= a]·exp(−x²)`` over [−10¹⁰, 10¹⁰] at a = ½: ``quad``'s 21 abscissae on [−10¹⁰, ½] are all
≥ 4·10⁷ from the peak, every value 0, so main (f95e3cc) printed ``exact : 0 (quadrature, error ≤
1e-10)`` and discarded the right closed form as "disagreeing".  Breakpoints at c ± 10ᵏ around the
centres of the weight's polynomial parts (:mod:`langur.symbolic.quadrature.wide`) let it find
the mass.  Hand values (independent of the engine: :func:`math.erf`, :func:`math.atan`,
scipy's Bessel K₀):

* ∫_{−∞}^{a} e^{−x²} = √π(erf(a) + 1)/2 = 1.3475…, d/da = e^{−a²} = 0.7788 (the tails beyond
  10¹⁰ are below any double);
* ∫_0^{2·10⁶} e^{−(x−10⁶)²} = √π·erf(10⁶) = √π;
* ∫_{−10¹²}^{a} dx/(1 + x²) = atan(a) + atan(10¹²) (main: "undefined: probably divergent");
* ∫ e^{−cosh x} over ℝ = 2K₀(1) (no elementary antiderivative: quadrature alone, its error an
  estimate on a range this wide), over (−∞, a]: K₀(1) + ∫_0^a e^{−cosh x}.
"""

from __future__ import annotations

import math

import pytest
import sympy as sp
from scipy import integrate as si
from scipy.special import k0

from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.symbolic.pieces import Method
from langur.symbolic.quadrature import ESTIMATE
from langur.symbolic.quadrature.wide import BELOW, WIDE, centres, spread

GAUSS = "param a = 0.5\nint ([-1e10, 1e10]) [x <= a]*exp(-x*x) d(x)\n"
COSH = "exp(-(exp(x) + exp(-x))/2)"


def _exact(text: str):
    loaded = load_text(text)
    return exact_eval(loaded.program, loaded.param_values())


@pytest.mark.parametrize("text, value", [
    (GAUSS, math.sqrt(math.pi) * (math.erf(0.5) + 1) / 2),
    ("int ([0, 2e6]) exp(-(x - 1e6)^2) d(x)\n", math.sqrt(math.pi)),
    ("param a = 0.5\nint ([-1e12, 1e12]) [x <= a]*(1/(1 + x^2)) d(x)\n", math.atan(0.5) + math.atan(1e12)),
    ("param a = 3\nint ([-1e9, 1e9]) exp(-(x - a)^2)*[x >= 0] d(x)\n", math.sqrt(math.pi) * (1 + math.erf(3)) / 2),
    # a peak of width 10⁻⁴ in [0, 1000] (main: 0 with "error ≤ 1e-10" too): √π/10⁴
    ("int ([0, 1000]) exp(-1e8*(x - 0.3)^2) d(x)\n", math.sqrt(math.pi) / 1e4),
])
def test_a_peak_in_a_wide_box_keeps_its_closed_form(text, value):
    r = _exact(text)
    assert not r.inconsistent, r.inconsistent  # main: "closed form … disagrees with quadrature 0.0"
    assert r.method == Method.CLOSED_FORM, r.notes
    assert r.value == pytest.approx(value, rel=1e-9)


def test_the_derivative_and_theorem_8_1():
    loaded = load_text(GAUSS)
    d = exact_deriv(loaded.program, loaded.param_values(), {"a": 1})
    assert d.value == pytest.approx(math.exp(-0.25), rel=1e-9)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds, d.theorem_8_1  # main: FAILS, D⟦p⟧ = 0


@pytest.mark.parametrize("text, value", [
    (f"int ([-1e6, 1e6]) {COSH} d(x)\n", 2 * k0(1.0)),
    (f"param a = 0.5\nint ([-1e8, 1e8]) [x <= a]*{COSH} d(x)\n",
     k0(1.0) + si.quad(lambda x: math.exp(-math.cosh(x)), 0, 0.5, epsabs=1e-14)[0]),
])
def test_quadrature_alone_on_a_wide_range_finds_the_mass_and_proves_it(text, value):
    r = _exact(text)
    assert r.method == Method.QUADRATURE
    assert r.value == pytest.approx(value, rel=1e-9)
    # interval enclosures (Gauss–Legendre with an enclosed remainder, bench/history/2026-11-29.md#proof33 prove the
    # estimate: "error ≤", and no "not a bound" note; until proof33 nothing backed a bound here
    assert ESTIMATE not in r.notes and abs(r.value - value) <= r.proved <= r.error
    assert r.how() == f"quadrature, error ≤ {r.error:.3g}"


def test_a_narrow_range_still_prints_a_bound():
    r = _exact(f"int ([0, 1]) {COSH} d(x)\n")
    assert r.method == Method.QUADRATURE
    ref = si.quad(lambda x: math.exp(-math.cosh(x)), 0, 1, epsabs=1e-14)[0]
    assert r.value == pytest.approx(ref, rel=1e-9)
    # the bound printed is what interval enclosures prove: since proof33 (bench/history/2026-11-29.md#proof33 within
    # quadrature's estimate, so "error ≤" again (exact32 proved only 2.96e-08: "error estimate …, proved ≤ …")
    assert ESTIMATE not in r.notes and abs(r.value - ref) <= r.proved <= r.error
    assert r.how() == f"quadrature, error ≤ {r.error:.3g}"


def test_breakpoints_only_on_ranges_wide_for_the_weight_and_close_to_its_centres():
    assert spread(-1.0, 1.0) == [] and spread(0.0, WIDE) == []  # narrow for the unit scale: as before
    got = spread(-1e10, 0.5)
    assert 0.0 in got and all(-1e10 < t < 0.5 for t in got) and got == sorted(set(got))
    # the piece next to the peak is BELOW decades narrower than the scale 1
    assert min(abs(t) for t in got if t < 0) == pytest.approx(10.0 ** -BELOW)
    # and every piece is at most 10 times farther from the centre than it is wide
    neg = sorted((t for t in got if t < 0), reverse=True)
    assert all(abs(b) <= 10 * (abs(b) - abs(a)) * (1 + 1e-12) for a, b in zip(neg, neg[1:]))
    near = spread(0.0, 1000.0, [(0.3, 1e-4)])  # a peak of width 10⁻⁴ at 0.3: cuts 10⁻⁶ from it
    assert 0.3 in near and min(abs(t - 0.3) for t in near if t != 0.3) == pytest.approx(1e-4 * 10.0 ** -BELOW)


def test_centres_of_the_weights_polynomial_parts():
    x = sp.Symbol("x")
    assert centres(sp.exp(-(x - 10**6) ** 2), x) == [(0.0, 1.0), (pytest.approx(1e6, rel=1e-12), 1.0)]  # once
    assert centres(1 / (1 + x**2), x) == [(0.0, 1.0)]  # poles ±i: real part 0
    assert centres(1 / (1 + (x - 5) ** 2), x) == [(0.0, 1.0), (pytest.approx(5.0, rel=1e-12), 1.0)]
    assert centres(sp.exp(-10**8 * (x - sp.Rational(3, 10)) ** 2), x) == [
        (0.0, 1.0), (pytest.approx(0.3, rel=1e-12), pytest.approx(1e-4, rel=1e-12))]
    assert centres(sp.sin(x) / x, x) == [(0.0, 1.0)]
