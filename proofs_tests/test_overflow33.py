"""Huge parameter values (bench/history/2026-11-29.md#overflow33; hostile33 found both).

Monte Carlo: a standard error squares its samples' deviations, so samples of 1e200 (finite) gave
``± inf`` (their squares are 1e400).  Both the estimate and its standard error are homogeneous of
degree 1 in the samples: they are now computed on the samples scaled by a power of two when the
plain formula overflows (:mod:`langur.operational.scaled`).  Hand values, with n samples of
f = a·u, u uniform on [0, 1]: mean a/2, standard error ≈ a/√(12 n); and since scaling by a power of
two is exact, the standard error at a = 2ᵏ·c is 2ᵏ times the one at c, bit for bit.

Exact: ``int ([0, 1]) a^2 * x * [x <= a] d(x)`` at a = 1e200 is a²/2 = 5e399, no double.  Its
quadrature stops on values beyond the doubles, which used to end the call before the closed form was
sought ("no exact value: quadrature … too large for a float"); the closed form is now found, and
``eval`` says what it is and why no value is given: its value, 5e399, is beyond the doubles (while
``deriv``, whose value 2a·… is a double, gives it)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from langur import operational
from langur.exact import ExactUnavailable, exact_eval
from langur.frontend import load_text
from langur.operational.estimate import tail_notes
from langur.operational.sample import Design

N = 10_000


def _value(a: float, method: str = "uniform", body: str = "a * x"):
    loaded = load_text(f"param a = 1\nint ([0, 1]) {body} d(x)\n")
    return operational.estimate_value(loaded, {"a": a}, samples=N, seed=3, method=method)


@pytest.mark.parametrize("k", [150, 160, 200, 250, 300])
@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_value_standard_error_finite_and_right_at_huge_scales(k, method):
    # main: ± inf from k = 160 on (k = 150 is finite there too: the check that nothing else changed)
    a = 10.0 ** k
    est = _value(a, method)
    assert math.isfinite(est.stderr) and est.stderr > 0, est
    assert abs(est.value - a / 2) <= 5 * est.stderr, (est.value, est.stderr)
    if method == "uniform":  # the i.i.d. design's standard error: σ/√n with σ = a/√12
        assert est.stderr == pytest.approx(a / math.sqrt(12 * N), rel=0.05)
    # homogeneity: at a = 2^e·m the estimate is 2^e times the one at m, exactly (same seed, same draws)
    m, e = math.frexp(a)
    small = _value(m, method)
    assert (est.value, est.stderr) == (math.ldexp(small.value, e), math.ldexp(small.stderr, e))


@pytest.mark.parametrize("k", [160, 200, 300])
def test_derivative_boundary_standard_error_finite(k):
    # d/db ∫∫ a·y·[x ≤ b] over [0, 1]² = ∫₀¹ a·y dy = a/2 (the delta's zero set x = b); its score is
    # a·y at uniform y: standard error a/√(12 n).  main: the boundary's variance (a/√(12n))² = ∞.
    a = 10.0 ** k
    loaded = load_text("param a = 1, b = 0.5\nint ([0, 1], [0, 1]) a * y * [x <= b] d(x, y)\n")
    d = operational.estimate_derivative(loaded, {"a": a, "b": 0.5}, {"b": 1}, samples=N, seed=5)
    assert math.isfinite(d.stderr) and math.isfinite(d.boundary.stderr), d
    assert d.boundary.stderr == pytest.approx(a / math.sqrt(12 * N), rel=0.05)
    assert d.stderr == pytest.approx(d.boundary.stderr, rel=1e-12)  # the regular part is 0 ± 0
    assert abs(d.value - a / 2) <= 5 * d.stderr


def test_heavy_tail_note_at_huge_scale():
    # one sample carrying most of the sum of squares is seen at any scale (main: at 1e200 the sum of
    # squares was ∞ and the note was lost)
    f = np.ones(1000)
    f[17] = 100.0  # 100² / (999 + 100²) = 91 %
    plain = tail_notes(f)
    assert plain and "91%" in plain[0]
    assert tail_notes(f * 1e200) == plain


def test_ordinary_samples_bit_for_bit_the_plain_formula():
    # the rescaling is taken only where the plain formula overflowed
    f = np.random.default_rng(1).normal(3.0, 2.0, 5000)
    d = Design(np.zeros((5000, 1)), "uniform")
    assert d.mean(f) == (float(np.mean(f)), float(np.std(f, ddof=1)) / math.sqrt(5000))


@pytest.mark.parametrize("box, power, hand", [("[0, 1]", 2, "5.00000e+399"), ("[0, a]", 2, "5.00000e+799"),
                                               ("[0, 1]", 3, "5.00000e+599")])
def test_exact_eval_says_the_closed_form_value_is_beyond_the_doubles(box, power, hand):
    # a^power·x·[x ≤ a] at a = 1e200: a^power·min(1, a)²/2 or a^power·a²/2, by hand.  main: "quadrature
    # over x in [0, 1]: the integrand's values are too large for a float" (no closed form sought)
    loaded = load_text(f"param a = 1e200\nint ({box}) a^{power} * x * [x <= a] d(x)\n")
    with pytest.raises(ExactUnavailable) as info:
        exact_eval(loaded.program, loaded.param_values())
    assert hand in info.value.reason and "finite number too large for a float" in info.value.reason, info.value.reason


def test_exact_eval_names_the_closed_form_of_exp_1000x():
    # ∫₀¹ exp(1000x + a) dx = (e^{1000+a} − e^a)/1000 = 3.2481e431 at a = 0.5 (by hand: e^1000 = 1.9701e434,
    # e^0.5 = 1.6487); main: only "quadrature … too large for a float"
    loaded = load_text("param a = 0.5\nint ([0, 1]) exp(1000 * x + a) d(x)\n")
    with pytest.raises(ExactUnavailable) as info:
        exact_eval(loaded.program, loaded.param_values())
    assert "3.24810e+431" in info.value.reason
    log10 = 1000.5 / math.log(10) - 3  # the hand value's decimal logarithm (e^a's share: 1e-431 of it)
    assert (math.floor(log10), 10 ** (log10 % 1)) == (431, pytest.approx(3.24810, rel=1e-5))


def test_exact_eval_value_that_is_a_double_unchanged():
    # a·x·[x ≤ a] at a = 1e200: a/2 = 5e199 (a double), closed form as before
    loaded = load_text("param a = 1e200\nint ([0, 1]) a * x * [x <= a] d(x)\n")
    assert exact_eval(loaded.program, loaded.param_values()).value == pytest.approx(5e199, rel=1e-14)


def test_derivative_regular_standard_error_finite():
    # d/db ∫₀¹ a·b·x dx = a/2 (no delta): the regular part's samples a·x, standard error a/√(12 n).
    # main: the total's reg_se ** 2 overflowed (here it is combined by hypot)
    a = 1e200
    loaded = load_text("param a = 1, b = 1\nint ([0, 1]) a * b * x d(x)\n")
    d = operational.estimate_derivative(loaded, {"a": a, "b": 1.0}, {"b": 1}, samples=N, seed=5)
    assert d.regular.stderr == pytest.approx(a / math.sqrt(12 * N), rel=0.05)
    assert d.stderr == d.regular.stderr and abs(d.value - a / 2) <= 5 * d.stderr
