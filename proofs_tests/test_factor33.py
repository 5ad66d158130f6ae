"""fuzz33's F1: a product of ≥ 3 moving factors with no completion of its own was refused (a false T207).

In a ``def`` (no box) or on a box whose intervals all move, ``(x − a)(x − a − 0.3)(x − a + 0.2)``
has no completion as a whole (no variable can be isolated; the split along a variable needs a
constant box), and :func:`langur.syntax.poles.sign_factors` split such a condition only when a
*pole* moved, so the program was refused though the same condition inline / on a fixed box loads.
Almost everywhere ``[Π fᵢ ≥ 0]`` is the parity of the factors' signs (pole31), each factor affine
and completable on its own: the front end now splits whenever a factor moves, provided every factor
completes (else the condition's own T207, once).  bench/history/2026-11-29.md#factor33.

Hand values (all independent of the engines):
* f1a ``[(x − a)(x − a − 0.3)(x − a + 0.2) ≥ 0]`` on [0, 1], a = 0.61: x ∈ [a − 0.2, a] ∪ [a + 0.3, 1],
  ⟦p⟧ = 0.2 + 0.7 − a = 0.29, ∂a = −1.
* f1b ``[(x + y − a − 0.3)(x + 2y − b − 0.55)(x + y − a) ≤ 0]`` on [0, b + 1] × [0, a + 1]: for fixed x a
  cubic in y with positive leading coefficient (1·2·1), ≤ 0 on (−∞, r₁] ∪ [r₂, r₃]; the length clipped to
  [0, a + 1], integrated in x by scipy's quad with the kinks as breakpoints (|error| < 1e-13), and central
  differences (h = 1e-5): 0.3504, ∂a = 0.8, ∂b = −0.07.
* f1c ``[(2z − y − a)(2z − y − a − 0.15)(z − y − a) ≥ 0]`` on [a − 1, 1]³, a = 0.61 (3-D, every interval
  moving): for fixed y a cubic in z with leading coefficient 4, ≥ 0 on [r₁, r₂] ∪ [r₃, ∞); the same way
  (times 2 − a for x): 0.5677455, ∂a = −2.6811.
"""

from __future__ import annotations

import math

import pytest

from langur import operational
from langur.diagnostics import LangurError
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text

F1A = """param a = 0.61
def g(x: var, qa: param) = [(x - qa) * (x - (qa + 0.3)) * (x - (qa - 0.2)) >= 0]
int ([0, 1])
  g(x, a)
d(x)
"""
F1B = """param a = 0.61, b = 0.31
int ([0, b + 1], [0, a + 1])
  [(x + y - (a + 0.3)) * (x + 2 * y - (b + 0.55)) * (x + y - a) <= 0]
d(x, y)
"""
F1C = """param a = 0.61
int ([a - 1, 1], [a - 1, 1], [a - 1, 1])
  [(2 * z - y - a) * (2 * z - y - (a + 0.15)) * (z - y - a) >= 0]
d(x, y, z)
"""

CASES = [  # (program, ⟦p⟧ by hand, {parameter: ∂ by hand})
    pytest.param(F1A, 0.29, {"a": -1.0}, id="f1a-def"),
    pytest.param(F1B, 0.3504, {"a": 0.8, "b": -0.07}, id="f1b-moving-box"),
    pytest.param(F1C, 0.5677455, {"a": -2.6811}, id="f1c-3d-moving-box"),
]


@pytest.mark.parametrize("text, value, slopes", CASES)
def test_loads_and_both_engines_give_the_hand_values(text, value, slopes):
    # on main: load_text raised (T207 "cannot be completed to one")
    loaded = load_text(text)
    params = loaded.param_values()
    assert exact_eval(loaded.program, params).value == pytest.approx(value, rel=1e-9)
    mv = operational.estimate_value(loaded, params, samples=20_000, seed=7)
    assert abs(mv.value - value) <= 5 * mv.stderr + 1e-12, (mv.value, mv.stderr)
    for name, slope in slopes.items():
        d = exact_deriv(loaded.program, params, {name: 1}, check=True)
        assert not d.inconsistent, d.inconsistent
        assert d.value == pytest.approx(slope, rel=1e-9, abs=1e-12)
        assert d.theorem_8_1 is not None and d.theorem_8_1.holds, d.theorem_8_1
        mc = operational.estimate_derivative(loaded, params, {name: 1}, samples=20_000, seed=7)
        assert math.isfinite(mc.value) and abs(mc.value - slope) <= 5 * mc.stderr + 1e-12, (name, mc.value, mc.stderr)


def test_the_def_and_the_inline_condition_agree():
    # the same condition written in the program (which loaded on main too) gives the def's value
    inline = load_text("param a = 0.61\nint ([0, 1]) [(x - a) * (x - (a + 0.3)) * (x - (a - 0.2)) >= 0] d(x)\n")
    viadef = load_text(F1A)
    for loaded in (inline, viadef):
        assert exact_eval(loaded.program, loaded.param_values()).value == pytest.approx(0.29, rel=1e-12)


def test_a_factor_with_no_completion_keeps_the_conditions_refusal_once():
    # (x⁵ + x − 0.5) has no completion without a box (a def): the split is not taken, and the condition's
    # own T207 is reported once (splitting anyway gave the factor's T207 twice: once per conditional of
    # the parity chain, about a term the program does not show)
    text = ("param a = 0.61\n"
            "def g(x: var, qa: param) = [(x - qa) * (x * x * x * x * x + x - 0.5) * (x - 0.1 * qa) >= 0]\n"
            "int ([0, 1]) g(x, a) d(x)\n")
    with pytest.raises(LangurError) as caught:
        load_text(text)
    message = str(caught.value)
    assert [d.code for d in caught.value.diagnostics] == ["T207"], message
    assert "(-qa + x)*(-qa/10 + x)*(x**5 + x - 1/2)" in message, message


def _f1b(a: float, b: float) -> float:
    """f1b by the docstring's third way: for fixed x the cubic in y (leading coefficient 1·2·1 > 0) is ≤ 0 on
    (−∞, r₁] ∪ [r₂, r₃]; that length clipped to [0, a + 1], integrated in x by quad with the kinks as breakpoints."""
    from scipy.integrate import quad

    def length(x):
        r = sorted([a + 0.3 - x, (b + 0.55 - x) / 2, a - x])
        def clip(lo, up):
            return max(0.0, min(up, a + 1) - max(lo, 0.0))
        return clip(-math.inf, r[0]) + clip(r[1], r[2])
    kinks = [a, a + 0.3, b + 0.55, 2 * a - b - 0.55, 2 * a - b + 0.05]
    return quad(length, 0, b + 1, points=sorted(p for p in kinks if 0 < p < b + 1), limit=500,
                epsabs=1e-13, epsrel=1e-13)[0]


def _f1c(a: float) -> float:
    """f1c likewise: for fixed y the cubic in z (leading coefficient 4) is ≥ 0 on [r₁, r₂] ∪ [r₃, ∞), clipped to
    [a − 1, 1]; times 2 − a, the x interval's length."""
    from scipy.integrate import quad

    def length(y):
        r = sorted([(y + a) / 2, (y + a + 0.15) / 2, y + a])
        def clip(lo, up):
            return max(0.0, min(up, 1.0) - max(lo, a - 1))
        return clip(r[0], r[1]) + clip(r[2], math.inf)
    kinks = [-a, 0.15 - a, 2 * (a - 1) - a, 2 * (a - 1) - a - 0.15, 2 - a, 1.85 - a, -1.0, 1 - a]
    return (2 - a) * quad(length, a - 1, 1, points=sorted(p for p in kinks if a - 1 < p < 1), limit=500,
                          epsabs=1e-13, epsrel=1e-13)[0]


def test_the_hand_values_of_f1b_and_f1c_by_a_third_way():
    h = 1e-5
    assert _f1b(0.61, 0.31) == pytest.approx(0.3504, abs=1e-11)
    assert (_f1b(0.61 + h, 0.31) - _f1b(0.61 - h, 0.31)) / (2 * h) == pytest.approx(0.8, abs=1e-7)
    assert (_f1b(0.61, 0.31 + h) - _f1b(0.61, 0.31 - h)) / (2 * h) == pytest.approx(-0.07, abs=1e-7)
    assert _f1c(0.61) == pytest.approx(0.5677455, abs=1e-11)
    assert (_f1c(0.61 + h) - _f1c(0.61 - h)) / (2 * h) == pytest.approx(-2.6811, abs=1e-7)
