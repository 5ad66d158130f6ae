"""Regressions found by differential testing (`langur fuzz`, langur/fuzz.py): each program shrunk by
hand, its true value worked out by hand in the comments, and the engine that was wrong named.
"""

import math

import pytest

from langur import operational
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.operational.naive import naive_derivative
from langur.transversality import check_loaded


def test_delta_root_outside_the_box_scores_zero_not_nan_1d():
    # Operational engine bug (fixed): the root −√a of x² − a lies outside the domain [0, 1]; the
    # domain's indicator is 0 there but sqrt(x) is NaN, and 0·NaN made the whole derivative NaN.
    #   ∫₀¹ [x² ≤ a]·√x dx = ∫₀^√a √x dx = (2/3)·a^(3/4),   D_a = (1/2)·a^(-1/4)
    # (all of it boundary: the delta at x = √a, weight √(√a) / |2√a| = a^(-1/4)/2).
    a = 0.37
    loaded = load_text("param a = 0.37\nint ([0, 1]) [x^2 <= a] * sqrt(x) d(x)\n")
    r = operational.estimate_derivative(loaded, {"a": a}, {"a": 1.0}, samples=1000, seed=0)
    assert r.boundary.value == pytest.approx(0.5 * a ** -0.25, rel=1e-12)
    assert r.boundary.stderr == 0.0 and r.regular.value == 0.0
    n = naive_derivative(loaded.program, {"a": a}, {"a": 1.0}, samples=50)
    assert n.boundary == pytest.approx(0.5 * a ** -0.25, rel=1e-12)


def test_delta_points_outside_the_box_score_zero_not_nan_2d():
    # Same bug on a declared diffeo in two variables: the zero set x + y = a is sampled along
    # y ∈ [0, 2] (U' = y's interval), x = a − y reaches −1.69 < −1.5 where sqrt(x + 1.5) is NaN.
    # By hand (a = 0.31): the delta lies on x = a − v, y = v, v ∈ [0, a], |det DΨ̂⁻¹| = 1, and
    # D_a π₀Ψ̂ = −1, so the boundary part is
    #   −0.7·∫₀^a ((v + a)³ − √(a − v + 1.5)) dv = −0.7·(15a⁴/4 − (2/3)((1.5 + a)^1.5 − 1.5^1.5)).
    a = 0.31
    hand = -0.7 * (15 * a ** 4 / 4 - (2 / 3) * ((1.5 + a) ** 1.5 - 1.5 ** 1.5))
    assert hand == pytest.approx(0.25481894, abs=1e-7)
    loaded = load_text(
        "param a = 0.31\n"
        "diffeo sh(x, y; c) = (x + y - c, y) inverse (u, v) = (u - v + c, v)\n"
        "int ([0, 2], [0, 2]) 0.7 * (ifge0 sh(x, y; a) then (y + a)^3 else sqrt(x + 1.5)) d(x, y)\n")
    r = operational.estimate_derivative(loaded, {"a": a}, {"a": 1.0}, samples=20000, seed=1)
    b = r.boundary
    assert math.isfinite(b.value) and 0 < b.stderr < 0.01
    assert abs(b.value - hand) <= 5 * b.stderr + 1e-9


# Exact (symbolic) engine bug, fixed: a jump [x ≤ a] multiplied by min(x, a), whose kink lies on
# the same zero set x = a, had its delta counted twice.  min(t, s) is ifge0 (t − s) then s else t
# (LANGUAGE.md §6), whose delta carries the weight ⟦s⟧ − ⟦t⟧ = a − x = 0 on x = a, so by Fig. 8 it
# adds nothing: the coincidence is harmless (the linter rightly reports nothing, cf. X308), and
# ⦇p⦈ = D⟦p⟧.  The cause: the decomposition wrote ifge0 Φ then s else r as [Φ ≥ 0]·s + [−Φ ≥ 0]·r,
# and on Φ = 0 both branches counted; the complement is now the strict [−Φ > 0] (Fig. 7 takes the
# then-branch at Φ = 0), which is what the delta restricted to Φ = 0 sees.
MIN_CASES = [
    # ∫₀² min(x, a)·[x ≤ a] dx = ∫₀^a x dx = a²/2 → D_a = a; ⦇p⦈ = δ(a − x)·min(x, a) = a, all boundary
    ("param a = 0.61\nint ([0, 2]) min(x, a) * [x <= a] d(x)\n", 0.61, 0.0, 0.61),
    # ∫₀² min(x, a)·[x > a] dx = a·(2 − a) → D_a = 2 − 2a = 0.78: regular ∫ [x > a]·1 = 2 − a = 1.39,
    # boundary δ(x − a)·(−1)·min(a, a) = −a = −0.61
    ("param a = 0.61\nint ([0, 2]) min(x, a) * [x > a] d(x)\n", 0.78, 1.39, -0.61),
]


@pytest.mark.parametrize("text,total,regular,boundary", MIN_CASES)
def test_min_kink_on_a_jump_monte_carlo(text, total, regular, boundary):
    loaded = load_text(text)
    r = operational.estimate_derivative(loaded, {"a": 0.61}, {"a": 1.0}, samples=20000, seed=3)
    assert r.boundary.value == pytest.approx(boundary, rel=1e-12)  # 1-D delta: exact
    assert abs(r.regular.value - regular) <= 5 * r.regular.stderr + 1e-9


@pytest.mark.parametrize("text,total,regular,boundary", MIN_CASES)
def test_min_kink_on_a_jump_exact(text, total, regular, boundary):
    from langur import exact as api

    loaded = load_text(text)
    r = api.exact_deriv(loaded.program, loaded.param_values({}), {"a": 1}, check=False)
    assert r.boundary == pytest.approx(boundary, abs=1e-12)
    assert r.value == pytest.approx(total, abs=1e-12)


# Operational engine (fixed, issue 13): with --method stratified or qmc the reported standard error
# could be 0, or far too small, on a discontinuous integrand.  Stratified: the stratum holding the
# jump had both of its 2 points on one side (variance estimate 0); qmc: each scrambled 1-D Sobol'
# net puts exactly ⌊nθ⌋ or ⌈nθ⌉ points in [0, θ], and all K = 16 randomizations could agree.  Now
# both estimate the variance from 32 independent randomizations (stratified: replicates of a
# jittered grid).  What remained (when nθ is within ~1/K of an integer all replicates could agree)
# is fixed by shifting every replicate (qmc29: test_qmc29.py).  Hand values: ∫₀¹ [x ≤ θ] dx = θ;
# D_a ∫₀^{a+1} exp(min(x, a)) dx has regular part ∫_a^{a+1} e^a dx = e^a (found by
# `langur fuzz --method stratified --seed 41`).
STDERR_CASES = [
    ("qmc", "param t = 0.37\nint ([0, 1]) [x <= t] d(x)\n", {"t": 0.37}, None, 1, 0.37),
    ("stratified", "param a = 0.37\nint ([0, a + 1]) exp(min(x, a)) d(x)\n", {"a": 0.37}, "a", 42,
     math.exp(0.37)),
]


@pytest.mark.parametrize("method,text,params,wrt,seed,hand", STDERR_CASES)
def test_stratified_and_qmc_standard_errors_cover_the_error(method, text, params, wrt, seed, hand):
    loaded = load_text(text)
    if wrt is None:
        r = operational.estimate_value(loaded, params, samples=16384, seed=seed, method=method)
    else:
        r = operational.estimate_derivative(loaded, params, {wrt: 1.0}, samples=20000, seed=seed,
                                            method=method).regular
    assert abs(r.value - hand) <= 5 * r.stderr + 1e-9


def test_stratified_standard_error_covers_a_jump_over_many_seeds():
    # ∫₀¹ [x ≤ 0.37] dx = 0.37 by 40 seeds: the error within 5 standard errors every time, and
    # the standard error never 0 (the old two-points-per-stratum estimate was 0 on most seeds)
    loaded = load_text("param t = 0.37\nint ([0, 1]) [x <= t] d(x)\n")
    for seed in range(40):
        r = operational.estimate_value(loaded, {"t": 0.37}, samples=4096, seed=seed, method="stratified")
        assert r.stderr > 0 and abs(r.value - 0.37) <= 5 * r.stderr, (seed, r.value, r.stderr)


PIXEL = ("param rad = 0.5, xl = -1, xu = 1, yl = -1, yu = 1\n"
         "int ([xl, xu], [yl, yu]) if x^2 + y^2 < rad^2 then 1 else 0 d(x, y)\n")


@pytest.mark.parametrize("sx,sy", [(1, 1), (1, -1), (-1, 1), (-1, -1)])
def test_a_pixel_of_a_circle_in_every_quadrant(sx, sy):
    # Exact engine bug (fixed, issue 19): on the lower half the closed form ignored the pixel's
    # upper y bound (sympy's solve dropped the roots ±√(r² − yu²) of yu + √(r² − x²), whose
    # existence depends on yu's sign); the cross-check then raised an internal error.
    # d/dr of the disc's area inside [0.3, 0.7] × [0.2, 0.7] (mirrored into each quadrant) is the
    # length of the arc inside it, |∂_rΦ|/|∇Φ| = 1 for Φ = r² − x² − y²: the arc from angle
    # asin(0.2/0.5) to acos(0.3/0.5), so 0.5·(acos(0.6) − asin(0.4)) = 0.2578891860.
    xs, ys = sorted((0.3 * sx, 0.7 * sx)), sorted((0.2 * sy, 0.7 * sy))
    at = {"rad": 0.5, "xl": xs[0], "xu": xs[1], "yl": ys[0], "yu": ys[1]}
    d = exact_deriv(load_text(PIXEL).program, at, {"rad": 1}, check=False)
    assert d.method == "closed_form" and not d.inconsistent
    assert d.value == pytest.approx(0.5 * (math.acos(0.6) - math.asin(0.4)), abs=1e-12)


def test_a_thin_zero_set_in_a_wide_box_is_found_not_missed():
    # MC engine (issue 19): ∫ over [−9999, 9999] × [0, 1]² of [s − x − y − z > 0]; the zero set
    # z = s − x − y meets the box only for x ∈ [s − 2, s], a sliver of the sampled width 19998.
    # d/ds = area of {(x, y): 0 ≤ s − x − y ≤ 1, 0 ≤ y ≤ 1} = 1 (for each y, an x-interval of
    # length 1).  The sampler used to draw x over the whole width and report 0 ± 0 (certain and
    # wrong); it now encloses where the zero set meets the box first.
    loaded = load_text("param s = 1\nint ([-9999, 9999], [0, 1], [0, 1]) [s - x - y - z > 0] d(x, y, z)\n")
    for seed in range(4):
        r = operational.estimate_derivative(loaded, {"s": 1.0}, {"s": 1.0}, samples=10000, seed=seed)
        assert 0 < r.stderr < 0.05 and abs(r.value - 1.0) <= 5 * r.stderr + 1e-9
        assert not any("low hits" in n for n in r.notes)


def test_too_few_hits_on_a_zero_set_are_said():
    # fig9's ridge with 20 samples: every sample lands on it, but 20 cannot back a variance
    loaded = load_text("param theta = 0\nint ([-1, 1], [-1, 1]) [y < x + theta] * (1 + theta + x + y) d(x, y)\n")
    few = operational.estimate_derivative(loaded, {"theta": 0.0}, {"theta": 1.0}, samples=20, seed=0)
    assert any(n.startswith("low hits") for n in few.notes) and "low hits" in str(few.to_json()["notes"])
    many = operational.estimate_derivative(loaded, {"theta": 0.0}, {"theta": 1.0}, samples=2000, seed=0)
    assert not any("low hits" in n for n in many.notes)


def test_a_parameter_conditional_in_a_bound_is_accepted():
    # issue 19: `int ([a, if c < 0 then a else b]) t d(t)` was refused (T207, the whole line).  The
    # upper bound is b for c ≥ 0: ∫_a^b t dt = (b² − a²)/2 = 1/2 at a = 0, b = 1; d/db = b = 1,
    # d/da = −a = 0; and for c < 0 the interval is [a, a]: 0.  The linter takes the branch the
    # parameters select (no false X301 between [t ≥ a] and the other branch's [a ≥ t]).
    text = "param a = 0, b = 1, c = 0.5\nint ([a, if c < 0 then a else b]) t d(t)\n"
    loaded = load_text(text)
    assert exact_eval(loaded.program, {"a": 0, "b": 1, "c": 0.5}).value == pytest.approx(0.5, abs=1e-12)
    assert exact_eval(loaded.program, {"a": 0, "b": 1, "c": -0.5}).value == pytest.approx(0.0, abs=1e-12)
    d = exact_deriv(loaded.program, {"a": 0, "b": 1, "c": 0.5}, {"b": 1}, check=False)
    assert d.value == pytest.approx(1.0, abs=1e-12)
    assert not [f for f in check_loaded(loaded) if f.severity == "error"]


@pytest.mark.parametrize("fn,t,t1,dt,dt1", [("min", 0.3, 0.6, 1.0, 0.0), ("min", 0.6, 0.3, 0.0, 1.0),
                                              ("max", 0.3, 0.6, 0.0, 1.0)])
def test_min_and_max_of_parameters_in_a_condition(fn, t, t1, dt, dt1):
    # issue 19: `[x < min(t, t1)]` was refused (T207).  ∫₀¹ [x < m] dx = m for m in [0, 1], so the
    # derivative in t is 1 where m = t and 0 where m = t1 (both engines).
    loaded = load_text(f"param t = {t}, t1 = {t1}\nint ([0, 1]) [x < {fn}(t, t1)] d(x)\n")
    at = {"t": t, "t1": t1}
    for name, expected in (("t", dt), ("t1", dt1)):
        direction = {k: float(k == name) for k in at}
        assert exact_deriv(loaded.program, at, direction, check=False).value == pytest.approx(expected, abs=1e-12)
        mc = operational.estimate_derivative(loaded, at, direction, samples=1000, seed=0)
        assert mc.value == pytest.approx(expected, abs=1e-12)


def test_logical_sugar_in_brackets():
    # issue 19: [A & B] is [A]·[B], [A | B] is 1 − (1 − [A])(1 − [B]), [not A] is 1 − [A].  On [0, 1]²
    # at a = 0.3, b = 0.6: the areas are ab = 0.18, a + b − ab = 0.72 and 1 − a = 0.7; in a their
    # derivatives are b = 0.6, 1 − b = 0.4 and −1 (each one delta on x = a), in b: a, 1 − a, 0.
    at = {"a": 0.3, "b": 0.6}
    for body, value, da, db in (("[x <= a & y <= b]", 0.18, 0.6, 0.3), ("[x <= a | y <= b]", 0.72, 0.4, 0.7),
                                ("[not x <= a]", 0.7, -1.0, 0.0)):
        loaded = load_text(f"param a = 0.3, b = 0.6\nint ([0, 1], [0, 1]) {body} d(x, y)\n")
        assert exact_eval(loaded.program, at).value == pytest.approx(value, abs=1e-12), body
        for name, expected in (("a", da), ("b", db)):
            d = exact_deriv(loaded.program, at, {k: float(k == name) for k in at}, check=False)
            assert d.value == pytest.approx(expected, abs=1e-12), (body, name)


def test_atan2_carries_its_branch_cut():
    # issue 19: atan2(y, x) is ifge0 y then acos(x/r) else −acos(x/r): its jump of 2π across
    # y = 0, x < 0 is a conditional, so it has its delta.  ∫₋₁¹ atan2(t, x) dx = ±π for t ≷ 0
    # (atan2(t, x) = π/2 − atan(x/t) for t > 0, the atan part odd).  On [−1, 1]², moving the cut
    # with c (atan2(y − c, x)): d/dc = 0 from the interior (odd in x) − 2π·1 from the cut along
    # x ∈ [−1, 0) (jump 2π, D_c(y − c) = −1): −2π.  Both engines.
    one = load_text("param t = 0.5\nint ([-1, 1]) atan2(t, x) d(x)\n")
    assert exact_eval(one.program, {"t": 0.5}).value == pytest.approx(math.pi, abs=1e-12)
    assert exact_eval(one.program, {"t": -0.5}).value == pytest.approx(-math.pi, abs=1e-12)
    two = load_text("param c = 0.2\nint ([-1, 1], [-1, 1]) atan2(y - c, x) d(x, y)\n")
    d = exact_deriv(two.program, {"c": 0.2}, {"c": 1.0}, check=False)
    assert d.value == pytest.approx(-2 * math.pi, abs=1e-6) and d.boundary == pytest.approx(-2 * math.pi, abs=1e-6)
    mc = operational.estimate_derivative(two, {"c": 0.2}, {"c": 1.0}, samples=40000, seed=0)
    assert abs(mc.value + 2 * math.pi) <= 5 * mc.stderr + 1e-9


def test_logical_sugar_in_if():
    # issue 19: if A & B then s else r is if A then (if B then s else r) else r (| and not alike).
    # On [0, 1]² at a = 0.3, b = 0.6: (if x ≤ a & y ≤ b then 2 else 1) integrates to 1 + ab = 1.18,
    # its derivative in a is b = 0.6 (the jump 1 along x = a for y ≤ b); (if x ≤ a | y ≤ b then x
    # else 0) to ∫∫ x·(1 − [x > a][y > b]) = 1/2 − (1 − a²)/2·(1 − b) = 0.318, in a: a·(1 − b) = 0.12;
    # (if not x ≤ a then 3 else 1) to 1 + 2(1 − a) = 2.4, in a: −2.
    at = {"a": 0.3, "b": 0.6}
    for body, value, da in (("if x <= a & y <= b then 2 else 1", 1.18, 0.6),
                            ("if x <= a | y <= b then x else 0", 0.318, 0.12),
                            ("if not x <= a then 3 else 1", 2.4, -2.0)):
        loaded = load_text(f"param a = 0.3, b = 0.6\nint ([0, 1], [0, 1]) {body} d(x, y)\n")
        assert exact_eval(loaded.program, at).value == pytest.approx(value, abs=1e-12), body
        d = exact_deriv(loaded.program, at, {"a": 1.0, "b": 0.0}, check=False)
        assert d.value == pytest.approx(da, abs=1e-12), body
