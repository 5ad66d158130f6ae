"""Exact values of the paper's examples (examples/) at their default parameters:
⟦p⟧, ⦇p⦈ = regular + boundary, standard AD (= regular) and the Theorem 8.1 check.

Every expected number is derived by hand in the comments (closed forms evaluated with mpmath).
"""

import os

import mpmath as mp
import pytest
import sympy as sp
from paths import EXAMPLES

from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load
from langur.sympy_bridge import symbol
from langur.theorem import check_theorem_8_1


def example(name, shader=None):
    modules = {"shader": os.path.join(str(EXAMPLES), shader)} if shader else None
    loaded = load(os.path.join(str(EXAMPLES), name), modules=modules)
    return loaded.program, loaded.param_values()


def close(a, b, tol=1e-9):
    return abs(float(a) - float(b)) <= tol * max(1.0, abs(float(b)))


def check_all(program, at, value, derivs, nearby=1):
    """⟦p⟧ = value; for each parameter z: ⦇p⦈(γ, e_z) = regular + boundary as given; Thm 8.1 holds."""
    den = denote_program(program, at)
    assert den.method == "closed_form" and close(den.value, value), (den.value, value)
    for z, (regular, boundary) in derivs.items():
        direction = {k: int(k == z) for k in at}
        der = ddenote_program(program, at, direction)
        assert der.method == "closed_form"
        assert close(der.regular.value, regular) and close(der.boundary.value, boundary), \
            (z, der.regular.value, der.boundary.value)
        assert close(der.value, regular + boundary) and der.standard_ad == der.regular.value
        th = check_theorem_8_1(program, at, direction, denotation=den, derivative=der, nearby=nearby)
        assert th.holds, th
        assert close(th.d_denotation, regular + boundary, 1e-6)
    return den


def test_fig1():
    # ∫₀¹ [x ≤ θ] dx = θ = 1/2; D_θ = 1: regular 0 (the integrand is flat in θ), boundary 1
    # (δ(θ − x) sifts to 1 at x = θ ∈ (0, 1)); standard AD = regular = 0.
    program, at = example("fig1.lgr")
    den = check_all(program, at, 0.5, {"theta": (0.0, 1.0)})
    # the closed form is exact: at θ = 3/10 it is 3/10
    assert sp.nsimplify(den.expr.subs(symbol("theta"), sp.Rational(3, 10))) == sp.Rational(3, 10)


def test_fig9():
    # ∫∫_{[-1,1]²} [y < x + θ](1 + θ + x + y) at θ = 0: area of {y ≤ x} is 2, and ∫∫_{y≤x} (x + y) = 0
    # (swapping x, y maps the half to its complement and keeps x + y; the full integral is 0): 2.
    # D_θ: regular ∫∫ [y ≤ x]·1 = 2; boundary: on y = x + θ (Ψ̂ = (x + θ − y, x), |det DΨ̂⁻¹| = 1)
    # ∫_{-1}^{1} (1 + θ + x + (x + θ)) dx at θ = 0 = ∫ (1 + 2x) = 2.  Total 4, standard AD 2.
    program, at = example("fig9.lgr")
    check_all(program, at, 2.0, {"theta": (2.0, 2.0)})


def risk_by_hand(a, b, mu):
    """R and its three partials (paper §2, Eq. 2–3), with N(x) = exp(−½((x−μ)/5)²), g = N(x; 2):
    R = ∫_a^b (N² − 2Ng) + ∫_{-10}^{10} g²  (−10 < a < b < 10), where
      ∫ N² = ∫ e^{−(x−μ)²/25} = (5√π/2)·erf((x−μ)/5),
      N·g = e^{−(2−μ)²/100}·e^{−(x−m)²/25} with m = (2+μ)/2, so ∫ N g = e^{−(2−μ)²/100}(5√π/2) erf((x−m)/5),
      ∫_{-10}^{10} g² = (5√π/2)(erf(8/5) + erf(12/5));
    ∂R/∂a = −N(a)(N(a) − 2g(a)),  ∂R/∂b = N(b)(N(b) − 2g(b))   (sifting, Eq. 3; no regular part),
    ∂R/∂μ = ∫_a^b 2(N − g)·∂_μN with ∂_μN = N·(x−μ)/25   (regular only):
      ∫ 2N²(x−μ)/25 = −N²  ⇒  N(a)² − N(b)²;
      ∫ 2Ng(x−μ)/25 = (2/25)e^{−(2−μ)²/100}[−(25/2)e^{−(x−m)²/25} + ((2−μ)/2)(5√π/2)erf((x−m)/5)]."""
    N = lambda x: mp.exp(-((x - mu) / 5) ** 2 / 2)
    g = lambda x: mp.exp(-((x - 2) / 5) ** 2 / 2)
    c = 5 * mp.sqrt(mp.pi) / 2
    m, k = (2 + mu) / 2, mp.exp(-(2 - mu) ** 2 / 100)
    R = (c * (mp.erf((b - mu) / 5) - mp.erf((a - mu) / 5))
         - 2 * k * c * (mp.erf((b - m) / 5) - mp.erf((a - m) / 5))
         + c * (mp.erf(mp.mpf(8) / 5) + mp.erf(mp.mpf(12) / 5)))
    F = lambda x: (2 / mp.mpf(25)) * k * (-(mp.mpf(25) / 2) * mp.exp(-(x - m) ** 2 / 25)
                                          + ((2 - mu) / 2) * c * mp.erf((x - m) / 5))
    dmu = N(a) ** 2 - N(b) ** 2 - (F(b) - F(a))
    return R, -N(a) * (N(a) - 2 * g(a)), N(b) * (N(b) - 2 * g(b)), dmu


def test_risk_all_three_partials():
    program, at = example("risk.lgr")
    a, b, mu = (mp.mpf(int(at[k])) for k in ("a", "b", "mu"))
    R, da, db, dmu = risk_by_hand(a, b, mu)
    check_all(program, at, R, {"a": (0.0, da), "b": (0.0, db), "mu": (dmu, 0.0)})
    # standard AD is 0 in a and b (paper Fig. 2b), the boundary part is everything


def test_renderer_constant_shader():
    # f(c) = ∫₀¹∫₀¹ [x + y + c ≥ 0] dx dy; at c = −1 the triangle above x + y = 1: ½.
    # With v = x + y (density ρ(v) = v on [0,1], 2 − v on [1,2]) f(c) = ∫_{v ≥ −c} ρ(v) s(v + c) dv,
    # f'(c) = ρ(−c)·s(0) + ∫ ρ(v) s'(v + c) dv; s = 1: f'(−1) = ρ(1) = 1, all of it boundary.
    program, at = example("renderer.lgr")
    check_all(program, at, 0.5, {"c": (0.0, 1.0)})


def test_renderer_linear_shader():
    # s(w) = 1/(√2 w + 2) with w = x + y + c.  At c = −1, w ∈ [0, 1] on the lit triangle with density 1 − w:
    # f = ∫₀¹ (1 − w)/(√2 w + 2) dw = −1/√2 + (1 + 1/√2)·ln(1 + 1/√2)
    #   (1 − w = −(√2 w + 2)/√2 + (1 + √2), ∫₀¹ dw/(√2 w + 2) = ln(1 + 1/√2)/√2).
    # boundary ρ(1)·s(0) = ½; regular ∫₀¹ (1 − w) s'(w) dw = [(1 − w)s]₀¹ + ∫₀¹ s = −½ + ln(1 + 1/√2)/√2.
    program, at = example("renderer.lgr", "lin_shader.lgr")
    r2, L = mp.sqrt(2), mp.log(1 + 1 / mp.sqrt(2))
    check_all(program, at, -1 / r2 + (1 + 1 / r2) * L, {"c": (-0.5 + L / r2, 0.5)})


def test_renderer_quadratic_shader():
    # s(w) = 1/(√2 w + 2)²:  ∫₀¹ s = (1/√2)(½ − 1/(2 + √2)),  ∫₀¹ dw/(√2 w + 2) = ln(1 + 1/√2)/√2,
    # f = ∫₀¹ (1 − w) s = −(1/√2)·ln(1 + 1/√2)/√2 + (1 + √2)·∫₀¹ s;
    # boundary s(0) = ¼; regular −s(0) + ∫₀¹ s.
    program, at = example("renderer.lgr", "quad_shader.lgr")
    r2, L = mp.sqrt(2), mp.log(1 + 1 / mp.sqrt(2))
    S = (1 / r2) * (mp.mpf(1) / 2 - 1 / (2 + r2))
    check_all(program, at, -L / 2 + (1 + r2) * S, {"c": (-0.25 + S, 0.25)})


def test_coincident_fails_theorem_8_1():
    # [x ≥ a]·[x ≥ a] on [0, 1]: ⟦p⟧ = 1 − a, D = −1, but the product rule counts the jump twice:
    # ⦇p⦈ = −2 (paper §7.3.1).  Theorem 8.1 assumes transversality and must be reported to fail.
    program, at = example(os.path.join("degenerate", "coincident.lgr"))
    den = denote_program(program, at)
    assert close(den.value, 0.5)
    der = ddenote_program(program, at, {"a": 1})
    assert close(der.value, -2.0) and close(der.boundary.value, -2.0)
    th = check_theorem_8_1(program, at, {"a": 1}, denotation=den, derivative=der)
    assert th.holds is False and close(th.d_denotation, -1.0) and close(th.derivative_denotation, -2.0)


@pytest.mark.parametrize("name", ["nested.lgr"])
def test_nested_self_conditional_fails_theorem_8_1(name):
    # ifge0 x − a then (ifge0 x − a then 1 else 0) else 0: ⟦p⟧ = 1 − a but ⦇p⦈ = −2 again (§7.3.2)
    program, at = example(os.path.join("degenerate", name))
    th = check_theorem_8_1(program, at, {"a": 1})
    assert th.holds is False and close(th.d_denotation, -1.0) and close(th.derivative_denotation, -2.0)
