"""The Monte Carlo engine on the real example files (examples/, see paths.py), via the front end.

Every program's value and derivative is compared with a value computed by hand (derivations in
the comments) within 5 standard errors + 1e-9 (false-alarm rate < 1e-6 at these sample sizes;
seeds fixed); one-variable deltas are exact and compared to 1e-12.  Linked (separately compiled)
and inlined evaluation must agree bit for bit, and swapping the renderer's shader must recompile
exactly one def.
"""

from __future__ import annotations

import math
import os

import pytest
from paths import EXAMPLES

from langur.frontend import load
from langur.operational import (
    cache_stats,
    clear_cache,
    estimate_derivative,
    estimate_value,
    reset_cache_stats,
)
from langur.operational.link import CACHE, CompileCache
from langur.operational.results import Estimate

EX = str(EXAMPLES)
N = 40000


def ex(name, **mods):
    return load(os.path.join(EX, name), {k: os.path.join(EX, v) for k, v in mods.items()} or None)


def close(est, expected, slack=1e-9):
    return abs(est.value - expected) <= 5 * est.stderr + slack


def params_of(loaded, **over):
    p = {k: float(v) for k, v in loaded.param_values().items()}
    p.update(over)
    return p


# -- Fig. 1, Fig. 9 ---------------------------------------------------------------------------------

def test_fig1():
    # ∫₀¹ [x ≤ θ] = θ; D_θ = 1 exactly (one root, sifted), standard AD exactly 0
    L = ex("fig1.lgr")
    for prog in (L, L.program):
        v = estimate_value(prog, {"theta": 0.5}, samples=N, seed=1)
        assert close(v, 0.5)
        d = estimate_derivative(prog, {"theta": 0.5}, {"theta": 1}, samples=N, seed=1)
        assert d.value == 1.0 and d.stderr == 0.0
        assert d.standard_ad == Estimate(0.0, 0.0)


def test_fig9():
    # θ = 0: value 2; D_θ = regular ∫∫[y<x] = 2 + boundary ∫_{-1}^{1}(1 + 2x)dx = 2 (see test_operational)
    L = ex("fig9.lgr")
    assert close(estimate_value(L, {"theta": 0.0}, samples=N, seed=2), 2.0)
    d = estimate_derivative(L, {"theta": 0.0}, {"theta": 1}, samples=N, seed=2)
    assert close(d, 4.0) and close(d.regular, 2.0) and close(d.boundary, 2.0)


# -- risk (§2) ------------------------------------------------------------------------------------

def risk_by_hand(a, b, mu):
    """R = ∫_a^b N_μ² − 2∫_a^b N_μ N_2 + ∫_{-10}^{10} N_2², N_m(x) = exp(−(x−m)²/50).

    N_μ² = exp(−(x−μ)²/25); N_μ N_2 = exp(−(μ−2)²/100)·exp(−(x−m̄)²/25), m̄ = (μ+2)/2, since
    (x−μ)² + (x−2)² = 2(x−m̄)² + (μ−2)²/2; and ∫_l^u exp(−(x−m)²/25) = (5√π/2)(erf((u−m)/5) − erf((l−m)/5)).
    D_a R = −(N_μ(a)² − 2N_μ(a)N_2(a)), D_b R = N_μ(b)² − 2N_μ(b)N_2(b) (Leibniz / the window's deltas),
    D_μ R = −(N_μ(b)² − N_μ(a)²) − 2[−(μ−2)/50·I₂ + e^{−(μ−2)²/100}·(−½)(e^{−((b−m̄)/5)²} − e^{−((a−m̄)/5)²})]
    where I₂ = ∫_a^b N_μ N_2 (differentiating the erf closed forms: d/dm erf((u−m)/5) = −(2/(5√π))e^{−((u−m)/5)²}).
    """
    c = 5 * math.sqrt(math.pi) / 2

    def g(u, l, m):
        return c * (math.erf((u - m) / 5) - math.erf((l - m) / 5))

    def n(x, m):
        return math.exp(-((x - m) ** 2) / 50)

    mb = (mu + 2) / 2
    e = math.exp(-((mu - 2) ** 2) / 100)
    i1, i2, i3 = g(b, a, mu), e * g(b, a, mb), g(10, -10, 2)
    value = i1 - 2 * i2 + i3
    da = -(n(a, mu) ** 2 - 2 * n(a, mu) * n(a, 2))
    db = n(b, mu) ** 2 - 2 * n(b, mu) * n(b, 2)
    dmu = -(n(b, mu) ** 2 - n(a, mu) ** 2) - 2 * (-(mu - 2) / 50 * i2 + e * -0.5 * (
        math.exp(-(((b - mb) / 5) ** 2)) - math.exp(-(((a - mb) / 5) ** 2))))
    return value, da, db, dmu


@pytest.mark.parametrize("at", [(-1.0, 4.0, 1.0), (-7.0, 9.5, 2.5)])
def test_risk(at):
    L = ex("risk.lgr")
    a, b, mu = at
    p = {"a": a, "b": b, "mu": mu}
    value, da, db, dmu = risk_by_hand(a, b, mu)
    assert close(estimate_value(L, p, samples=N, seed=3), value)
    # the truncation points: regular part exactly 0, the deltas exact (one variable)
    for name, expected in (("a", da), ("b", db)):
        d = estimate_derivative(L, p, {name: 1}, samples=1000, seed=3)
        assert d.regular == Estimate(0.0, 0.0) and abs(d.value - expected) < 1e-12
    d = estimate_derivative(L, p, {"mu": 1}, samples=N, seed=3)
    assert d.boundary.value == 0.0 and close(d, dmu)
    assert d.standard_ad == d.regular
    # standard AD misses the truncation points entirely
    assert estimate_derivative(L, p, {"a": 1, "b": 1}, samples=1000).standard_ad.value == 0.0


# -- the renderer with its three shaders (§10.1) -------------------------------------------------

AL, BE = math.sqrt(2), 2.0
LG = math.log((AL + BE) / BE)
# c = −1: with t = x + y + c the lit part is t ∈ [0, 1] with density (1 − t); the boundary is the
# segment x + y = 1 in the unit square, parametrized by v = y with |det DΨ̂⁻¹| = 1, so the delta
# contributes s(t = 0).  With w = αt + β (α = √2, β = 2):
#   const: value ½, D_c = 0 + 1
#   lin:   value ∫(1−t)/w = −1/α + (1 + β/α)·ln((α+β)/β)/α;  D_c = −(1/α)(α/β − ln((α+β)/β)) + 1/β
#   quad:  value ∫(1−t)/w² = (α/β − ln((α+β)/β))/α²;
#          D_c = −(2/α)[(α+β)(1/(2β²) − 1/(2(α+β)²)) − (1/β − 1/(α+β))] + 1/β²
SHADERS = {
    "shader.lgr": (0.5, 0.0, 1.0),
    "lin_shader.lgr": (-1 / AL + (1 + BE / AL) * LG / AL, -(1 / AL) * (AL / BE - LG), 1 / BE),
    "quad_shader.lgr": ((AL / BE - LG) / AL ** 2,
                        -(2 / AL) * ((AL + BE) * (1 / (2 * BE ** 2) - 1 / (2 * (AL + BE) ** 2)) - (1 / BE - 1 / (AL + BE))),
                        1 / BE ** 2),
}


@pytest.mark.parametrize("shader", sorted(SHADERS))
def test_renderer(shader):
    value, regular, boundary = SHADERS[shader]
    L = ex("renderer.lgr", shader=shader)
    assert close(estimate_value(L, {"c": -1.0}, samples=N, seed=4), value)
    d = estimate_derivative(L, {"c": -1.0}, {"c": 1}, samples=N, seed=4)
    assert close(d.regular, regular) and close(d.boundary, boundary) and close(d, regular + boundary)


def test_module_without_program_is_a_clear_error():
    with pytest.raises(ValueError, match="no program"):
        estimate_value(ex("densities.lgr"), {})


# -- the degenerate examples: the derivative *denotation* -------------------------------------------

def test_degenerate_examples():
    d = "degenerate/"
    # boundary.lgr, θ = 1: ∫₀¹[x ≤ 1] = 1 (every sample is 1); the denotation's derivative is 1
    # (the left derivative: at x = 1 the domain's [1 − x ≥ 0] holds at exactly 0)
    L = ex(d + "boundary.lgr")
    assert estimate_value(L, {"theta": 1.0}, samples=1000).to_json() == {"value": 1.0, "stderr": 0.0, "samples": 1000,
                                                                          "seed": 0, "method": "uniform"}
    assert estimate_derivative(L, {"theta": 1.0}, {"theta": 1}, samples=1000).value == 1.0
    # coincident.lgr, nested.lgr: value 1 − a = ½; the denotation counts the jump twice: −2 (§7.3.1)
    for f in ("coincident.lgr", "nested.lgr"):
        L = ex(d + f)
        assert close(estimate_value(L, {"a": 0.5}, samples=N, seed=5), 0.5)
        assert estimate_derivative(L, {"a": 0.5}, {"a": 1}, samples=1000).value == -2.0
    # equal_params.lgr, a = 0.3 < b = 0.6: value 1 − max(a, b) = 0.4; D_a = 0, D_b = −1 (exact)
    L = ex(d + "equal_params.lgr")
    assert close(estimate_value(L, {"a": 0.3, "b": 0.6}, samples=N, seed=5), 0.4)
    assert estimate_derivative(L, {"a": 0.3, "b": 0.6}, {"a": 1}, samples=100).value == 0.0
    assert estimate_derivative(L, {"a": 0.3, "b": 0.6}, {"b": 1}, samples=100).value == -1.0
    # tangent.lgr, a = 0: value ∫_{-1}^{1}(min(2x², 1) − x²) = 2[s³/3 + (1 − s) − (1 − s³)/3], s = 1/√2;
    # D_a = −2 (the lower parabola moves up over all x) + 2s (the upper one, where it is below y = 1)
    s = 1 / math.sqrt(2)
    L = ex(d + "tangent.lgr")
    assert close(estimate_value(L, {"a": 0.0}, samples=N, seed=5), 2 * (s ** 3 / 3 + (1 - s) - (1 - s ** 3) / 3))
    assert close(estimate_derivative(L, {"a": 0.0}, {"a": 1}, samples=N, seed=5), -2 + 2 * s)
    # three_lines.lgr, a = 0.25: value (1 − a)²; D_a = −2(1 − a) (the third line meets the region
    # only at the point (a, a))
    L = ex(d + "three_lines.lgr")
    assert close(estimate_value(L, {"a": 0.25}, samples=N, seed=5), 0.5625)
    assert close(estimate_derivative(L, {"a": 0.25}, {"a": 1}, samples=N, seed=5), -1.5)


# -- separate compilation (§9, Theorem 9.1) -----------------------------------------------------------

@pytest.mark.parametrize("name,mods", [("fig9.lgr", {}), ("risk.lgr", {}), ("renderer.lgr", {}),
                                       ("renderer.lgr", {"shader": "lin_shader.lgr"}),
                                       ("renderer.lgr", {"shader": "quad_shader.lgr"})])
@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_linked_and_inlined_agree_bit_for_bit(name, mods, method):
    L = ex(name, **mods)
    p = params_of(L)
    direction = {k: 1.0 + i for i, k in enumerate(p)}
    linked = estimate_derivative(L, p, direction, samples=3000, seed=11, method=method)
    assert cache_stats()["last_link"] == "linked"
    inlined = estimate_derivative(L.program, p, direction, samples=3000, seed=11, method=method)
    assert linked == inlined
    assert estimate_value(L, p, samples=3000, seed=11, method=method) == \
        estimate_value(L.program, p, samples=3000, seed=11, method=method)


def test_defs_own_samplers_are_consistent():
    # sites="defs": the zero sets sampled through each def's own Ψ̂ (renamed), fully separately;
    # different points, same expectation: risk's D_μ and the renderer's D_c by hand as above
    L = ex("renderer.lgr", shader="lin_shader.lgr")
    d = estimate_derivative(L, {"c": -1.0}, {"c": 1}, samples=N, seed=6, sites="defs")
    assert close(d, SHADERS["lin_shader.lgr"][1] + SHADERS["lin_shader.lgr"][2])
    L = ex("risk.lgr")
    _, da, db, _ = risk_by_hand(-1.0, 4.0, 1.0)
    d = estimate_derivative(L, {"a": -1.0, "b": 4.0, "mu": 1.0}, {"a": 1, "b": 2}, samples=100, sites="defs")
    assert abs(d.value - (da + 2 * db)) < 1e-12


def test_swapping_the_shader_recompiles_one_def():
    clear_cache()
    base = ex("renderer.lgr")
    estimate_derivative(base, {"c": -1.0}, {"c": 1}, samples=100)
    first = cache_stats()["compiled"]
    assert ("program", "renderer", None) in first and ("def", "shader", "shade") in first
    for shader in ("lin_shader.lgr", "quad_shader.lgr"):
        reset_cache_stats()
        L = ex("renderer.lgr", shader=shader)
        estimate_derivative(L, {"c": -1.0}, {"c": 1}, samples=100)
        assert cache_stats()["compiled"] == [("def", "shader", "shade")]
        assert cache_stats()["hits"] >= 1 and cache_stats()["last_link"] == "linked"
    # back to the first shader, and the same program again: nothing is recompiled
    reset_cache_stats()
    estimate_value(ex("renderer.lgr"), {"c": -1.0}, samples=100)
    estimate_value(ex("renderer.lgr", shader="lin_shader.lgr"), {"c": -1.0}, samples=100)
    assert cache_stats()["compiled"] == []


def test_defs_with_lets_module_params_and_param_expressions(tmp_path):
    # lib: param k; h(t, a) = let q = a·k in [t ≤ q]·exp(t·k).  main: ∫∫_{[0,1]²} h(x, a)·h(y, a + 0.1).
    # F(a, k) = G(a, k)·G(a + 0.1, k) with G(c, k) = ∫_0^{ck} e^{kt} dt = (e^{ck²} − 1)/k while ck ≤ 1;
    # ∂G/∂c = k·e^{ck²}, ∂G/∂k = (2ck²·e^{ck²} − (e^{ck²} − 1))/k².  At a = 0.3, k = 2 both jumps are inside.
    (tmp_path / "lib.lgr").write_text("param k = 2\ndef h(t: var, a: param) = let q = a * k in [t <= q] * exp(t * k)\n")
    (tmp_path / "main.lgr").write_text("from lib import h\nparam a = 0.3\n"
                                       "int ([0, 1], [0, 1]) h(x, a) * h(y, a + 0.1) d(x, y)\n")
    L = load(str(tmp_path / "main.lgr"))
    a, k = 0.3, 2.0

    def G(c):
        return (math.exp(c * k * k) - 1) / k

    def Gc(c):
        return k * math.exp(c * k * k)

    def Gk(c):
        return (2 * c * k * k * math.exp(c * k * k) - (math.exp(c * k * k) - 1)) / k ** 2

    p = {"a": a, "k": k}
    assert close(estimate_value(L, p, samples=N, seed=21), G(a) * G(a + 0.1))
    for direction, expected in (({"a": 1}, Gc(a) * G(a + .1) + G(a) * Gc(a + .1)),
                                ({"k": 1}, Gk(a) * G(a + .1) + G(a) * Gk(a + .1))):
        linked = estimate_derivative(L, p, direction, samples=N, seed=21)
        assert cache_stats()["last_link"] == "linked"
        assert linked == estimate_derivative(L.program, p, direction, samples=N, seed=21)
        assert close(linked, expected)


def test_general_var_argument_falls_back_to_the_inlined_program(tmp_path):
    # f(t) = [t ≥ a] called as f(2x): not a renaming, so the program is evaluated inlined.
    # ∫_0^1 [2x ≥ a] dx = 1 − a/2, D_a = −1/2 (exact: one root x = a/2 with |d(2x)/dx| = 2)
    (tmp_path / "lib.lgr").write_text("def f(t: var, a: param) = [t >= a]\n")
    (tmp_path / "main.lgr").write_text("from lib import f\nparam a = 0.6\nint ([0, 1]) f(2 * x, a) d(x)\n")
    L = load(str(tmp_path / "main.lgr"))
    d = estimate_derivative(L, {"a": 0.6}, {"a": 1}, samples=100)
    assert cache_stats()["last_link"] == "inlined"
    assert abs(d.value + 0.5) < 1e-12
    assert close(estimate_value(L, {"a": 0.6}, samples=N, seed=22), 0.7)


def test_the_engine_never_imports_sympy():
    import subprocess
    import sys

    code = "import sys, langur.operational; print('sympy' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"


@pytest.mark.parametrize("method", ["uniform", "stratified"])
def test_three_variables(method):
    # F(t) = ∫_{[0,1]³} [x + y + z ≤ t]·(1 + x) = t³/6 + t⁴/24 for t ≤ 1 (the simplex has volume t³/6
    # and ∫ x over it is t⁴/24); F'(t) = t²/2 + t³/6, all from the delta on the plane x + y + z = t
    # (a 2-dimensional zero set: u' = the two other variables, |det DΨ̂⁻¹| = 1 from a 3×3 Jacobian).
    L = load_text_("param t = 0.9\nint ([0, 1], [0, 1], [0, 1]) [x + y + z <= t] * (1 + x) d(x, y, z)\n")
    t = 0.9
    assert close(estimate_value(L, {"t": t}, samples=N, seed=23, method=method), t ** 3 / 6 + t ** 4 / 24)
    d = estimate_derivative(L, {"t": t}, {"t": 1}, samples=N, seed=23, method=method)
    assert d.regular.value == 0.0 and close(d, t ** 2 / 2 + t ** 3 / 6)


def load_text_(text):
    from langur.frontend import load_text

    return load_text(text)


@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_linking_bit_for_bit_with_renamed_swapped_and_nested_calls(tmp_path, method):
    # calls with swapped variables (g(y, x, …)), a param argument that is an expression (c + a), a
    # def called twice, a let around a call, a fold (circle): linked == inlined, bit for bit
    (tmp_path / "lib.lgr").write_text(
        "def win(t: var, a: param, b: param) = [a <= t <= b]\n"
        "def g(u: var, v: var, c: param) = if u + 2*v >= c then exp(u*v) else u - v\n"
        "def circ(p: var, q: var, r: param) = [p^2 + q^2 <= r^2] * win(p, -r, r)\n")
    (tmp_path / "main.lgr").write_text(
        "from lib import win, g, circ\nparam a = 0.2, b = 0.7, c = 0.5, r = 0.6\n"
        "int ([0, 1], [0, 1]) win(y, a, b) * g(x, y, c + a) * win(x, a*b, b)"
        " + (let z = 2*c in g(y, x, z) * circ(x, y, r)) d(x, y)\n")
    L = load(str(tmp_path / "main.lgr"))
    p = params_of(L)
    for direction in ({k: 1.0 for k in p}, {"r": 1.0}, {"a": -2.0, "c": 0.5}):
        linked = estimate_derivative(L, p, direction, samples=2000, seed=24, method=method)
        assert cache_stats()["last_link"] == "linked"
        assert linked == estimate_derivative(L.program, p, direction, samples=2000, seed=24, method=method)


@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_circle_folds_have_finite_variance(method):
    # D_r ∫∫_{[-1,1]²} [x² + y² ≤ r²]·(1 + xy + y) = ∮_{|p|=r} (1 + xy + y) ds = 2πr (xy and y
    # integrate to 0 over the circle); r = 0.5: π.  The completed condition has two branches
    # y = ±√(r² − x²) that fold at x = ±r, where |det DΨ̂⁻¹| = 1/(2|y|) is not square-integrable;
    # the fold map (sample.SiteSampler.fold_map) makes the variance finite and the stderr honest.
    L = load_text_("param r = 0.5\nint ([-1, 1], [-1, 1]) [x^2 + y^2 <= r^2] * (1 + x*y + y) d(x, y)\n")
    k = 7.91 if method == "qmc" else 5.0
    d = estimate_derivative(L, {"r": 0.5}, {"r": 1}, samples=N, seed=25, method=method)
    assert abs(d.value - math.pi) <= k * d.stderr + 1e-9 and d.stderr < 0.05
    assert d.regular.value == 0.0


def test_naive_follows_the_fold_map():
    from langur.operational.naive import naive_derivative

    L = load_text_("param r = 0.5\nint ([-1, 1], [-1, 1]) [x^2 + y^2 <= r^2] * (1 + x*y + y) * exp(x) d(x, y)\n")
    for m in ("uniform", "stratified"):
        a = estimate_derivative(L.program, {"r": 0.5}, {"r": 1}, samples=300, seed=1, method=m)
        b = naive_derivative(L.program, {"r": 0.5}, {"r": 1}, samples=300, seed=1, method=m)
        assert abs(a.value - b.value) < 1e-12 and abs(a.stderr - b.stderr) < 1e-12


def test_a_caller_owned_cache_compiles_apart_and_gives_the_same_bits():
    """§9's compiled units live in a CompileCache the caller may own: evaluating through a fresh
    one compiles the renderer's defs into it (not into the shared one) and draws the same bits."""
    loaded = ex("renderer.lgr")
    mine = CompileCache()
    before = dict(CACHE.units)
    d = estimate_derivative(loaded, {"c": -0.5}, {"c": 1.0}, samples=2000, seed=5, cache=mine)
    assert mine.stats()["last_link"] == "linked" and mine.units and CACHE.units == before
    assert [c[0] for c in mine.stats()["compiled"]].count("def") >= 1
    assert d == estimate_derivative(loaded, {"c": -0.5}, {"c": 1.0}, samples=2000, seed=5)
    again = estimate_derivative(loaded, {"c": -0.5}, {"c": 1.0}, samples=2000, seed=5, cache=mine)
    assert again == d and mine.stats()["hits"] >= 1
