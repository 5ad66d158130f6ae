"""The Monte Carlo engine (langur/operational) against hand-computed values.

Programs are built as core terms following the desugaring conventions (LANGUAGE.md §6: a domain
is a product of completed indicators [x ≥ l]·[u ≥ x] in front of the integrand), so these tests
do not depend on the front end; test_operational_examples.py runs the real .lgr files.

Statistics: a Monte Carlo estimate must lie within 5 standard errors (+ 1e-9) of the hand value.
With N ≥ 20000 i.i.d. samples of bounded integrands the estimate is normal to high accuracy and
P(|Z| > 5) ≈ 5.7e-7 < 1e-6 (randomized QMC: a t₁₅ bound, see ``close``); seeds are fixed, so
each test is deterministic anyway.
One-variable deltas are exact (one evaluation per root): those are compared to 1e-12.
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np
import pytest

from langur.core import (
    Add,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Var,
    const,
    sub,
)
from langur.operational import estimate_derivative, estimate_value
from langur.operational.naive import naive_derivative, naive_value
from langur.operational.results import Estimate

x, y = Var("x"), Var("y")
u0, u1 = Var("u0"), Var("u1")
ONE, ZERO = const(1), const(0)


def completed(cond, variables, solved, branches):
    """A condition completed by solving for ``solved``: forward = (cond, other variables);
    ``branches`` = [(components for every variable in order, guards)] over u0 (the condition)
    and u1… (the other variables in order)."""
    others = tuple(v for v in variables if v != solved)
    inputs = tuple(f"u{i}" for i in range(len(variables)))
    return Diffeo(variables, (cond,) + tuple(Var(o) for o in others), inputs,
                  tuple(InverseBranch(tuple(c), tuple(g)) for c, g in branches), solved_for=solved)


def ind(psi):
    return IfDiffeo(psi, ONE, ZERO)


def with_domain(variables, bounds, body):
    """int ([l1,u1],…) body d(variables): [v ≥ l]·[u ≥ v]·…·body, each indicator solved for v."""
    factors = []
    for v, (lo, hi) in zip(variables, bounds):
        def comps(expr, v=v):
            out, k = [], 1
            for w in variables:
                if w == v:
                    out.append(expr)
                else:
                    out.append(Var(f"u{k}"))
                    k += 1
            return out
        factors.append(ind(completed(sub(Var(v), lo), variables, v, [(comps(Add(u0, lo)), ())])))
        factors.append(ind(completed(sub(hi, Var(v)), variables, v, [(comps(sub(hi, u0)), ())])))
    t = factors[0]
    for f in factors[1:]:
        t = Mul(t, f)
    return Program(Mul(t, body), tuple(variables), tuple(bounds))


def close(est: dict, expected: float, slack: float = 1e-9, method: str = "uniform") -> bool:
    """Within 5 standard errors (+ slack), for every ``method``: the replicate designs (stratified,
    qmc) estimate their standard error from 32 independent replicates and widen it for their 31
    degrees of freedom (qmc29), so 5 of them are a two-sided 5.7e-7 there too (before, with 16
    randomizations, this took the t₁₅ quantile ≈ 7.9 for qmc)."""
    return abs(est.value - expected) <= 5.0 * est.stderr + slack


# -- Fig. 1 ----------------------------------------------------------------------------------------

theta = Param("theta")
# ∫₀¹ [x ≤ θ] dx: [θ − x ≥ 0] solved for x: x = θ − u0
FIG1 = with_domain(("x",), [(ZERO, ONE)], ind(completed(sub(theta, x), ("x",), "x", [([sub(theta, u0)], ())])))


def test_fig1_value_and_exact_derivative():
    # ⟦p⟧ = θ = 0.5; D_θ = 1 from the single delta at x = θ (exact), standard AD 0 (the integrand is
    # piecewise constant, so every sample's tangent is exactly 0)
    v = estimate_value(FIG1, {"theta": 0.5}, samples=20000, seed=1)
    assert close(v, 0.5) and v.stderr > 0
    d = estimate_derivative(FIG1, {"theta": 0.5}, {"theta": 1}, samples=20000, seed=1)
    assert d.value == 1.0 and d.stderr == 0.0
    assert d.standard_ad == Estimate(0.0, 0.0)
    assert d.boundary == Estimate(1.0, 0.0)
    assert d.regular.value + d.boundary.value == d.value


def test_fig1_outside_the_domain_the_delta_scores_zero():
    # θ = 1.5: the root x = 1.5 lies outside [0,1]; the domain indicator [1 − x ≥ 0] kills it
    d = estimate_derivative(FIG1, {"theta": 1.5}, {"theta": 1}, samples=1000, seed=0)
    assert d.value == 0.0 and d.stderr == 0.0


@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_methods_are_honest_on_fig1(method):
    for th in (0.3, 0.77):
        v = estimate_value(FIG1, {"theta": th}, samples=20000, seed=3, method=method)
        assert close(v, th, method=method), (method, th, v)
        assert v.method == method


def test_same_seed_same_bits_other_seed_other_bits():
    a = estimate_value(FIG9, {"theta": 0.1}, samples=5000, seed=7)
    b = estimate_value(FIG9, {"theta": 0.1}, samples=5000, seed=7)
    c = estimate_value(FIG9, {"theta": 0.1}, samples=5000, seed=8)
    assert a == b and a.value != c.value
    for m in ("stratified", "qmc"):
        d1 = estimate_derivative(FIG9, {"theta": 0.1}, {"theta": 1}, samples=4096, seed=7, method=m)
        d2 = estimate_derivative(FIG9, {"theta": 0.1}, {"theta": 1}, samples=4096, seed=7, method=m)
        assert d1 == d2


# -- Fig. 9 ----------------------------------------------------------------------------------------

# ∫∫_{[-1,1]²} [y < x + θ]·(1 + θ + x + y): condition x + θ − y solved for y: y = u1 + θ − u0, x = u1
FIG9 = with_domain(("x", "y"), [(const(-1), ONE)] * 2,
                   Mul(ind(completed(sub(Add(x, theta), y), ("x", "y"), "y", [([u1, sub(Add(u1, theta), u0)], ())])),
                       Add(Add(Add(ONE, theta), x), y)))


@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_fig9(method):
    # θ = 0: value ∫∫_{y<x} (1 + x + y) = 2 (the region has area 2; x + y is odd under
    # (x,y) ↦ (−y,−x), which preserves it).  D_θ: regular ∫∫[y<x]·1 = 2; boundary
    # ∫ δ(x − y)(1 + x + y) = ∫_{-1}^{1} (1 + 2x)·|det DΨ̂⁻¹| dx with det = 1, = 2.  Total 4.
    v = estimate_value(FIG9, {"theta": 0.0}, samples=40000, seed=2, method=method)
    assert close(v, 2.0, method=method)
    d = estimate_derivative(FIG9, {"theta": 0.0}, {"theta": 1}, samples=40000, seed=2, method=method)
    assert close(d.regular, 2.0, method=method) and close(d.boundary, 2.0, method=method)
    assert close(d, 4.0, method=method)
    assert d.standard_ad == d.regular


# -- where Potto's prototype is biased ------------------------------------------------------------

def test_declared_diffeo_whose_other_coordinate_is_not_a_variable():
    # Ψ̂(x, y; k) = (k − 2x + y, x + 2y), inverse: y = (u0 − k + 2u1)/5, x = (u1 − 2u0 + 2k)/5,
    # |det DΨ̂⁻¹| = 1/5.  F(k) = ∫∫_{[0,1]²} [y ≥ 2x − k]·(x + y).  At k = 1.2 the line
    # x = (y + k)/2 leaves the square at y = 0.8:
    #   F = ∫_0^0.8 ((y+1.2)²/8 + (y² + 1.2y)/2) dy + ∫_0.8^1 (1/2 + y) dy = 98/375 + 104/375 + 7/25 = 307/375
    #   F'(k) = ∫_0^0.8 ½·(x + y)|_{x=(y+k)/2} dy = ½ ∫_0^0.8 (1.5y + 0.6) dy = 0.48, all from the delta;
    # u1 = x + 2y ranges over the enclosure [0, 3] of the unit square.
    k = Param("k")
    fifth = const(Fraction(1, 5))
    psi = Diffeo(("x", "y"), (Add(sub(k, Mul(const(2), x)), y), Add(x, Mul(const(2), y))), ("u0", "u1"),
                 (InverseBranch((Mul(fifth, Add(sub(u1, Mul(const(2), u0)), Mul(const(2), k))),
                                 Mul(fifth, Add(sub(u0, k), Mul(const(2), u1))))),), name="shear")
    prog = with_domain(("x", "y"), [(ZERO, ONE)] * 2, Mul(IfDiffeo(psi, ONE, ZERO), Add(x, y)))
    v = estimate_value(prog, {"k": 1.2}, samples=40000, seed=4)
    assert close(v, 307 / 375)
    d = estimate_derivative(prog, {"k": 1.2}, {"k": 1}, samples=40000, seed=4)
    assert d.regular == Estimate(0.0, 0.0)
    assert close(d, 0.48) and d.stderr < 0.02


@pytest.mark.parametrize("solved", ["x", "y"])
def test_delta_solved_for_either_variable(solved):
    # F(θ) = ∫∫_{[0,1]²} [y − x − θ ≥ 0]·y = ∫_θ^1 y(y − θ) dy = (1 − θ³)/3 − θ(1 − θ²)/2,
    # F'(θ) = −∫_θ^1 y dy = −(1 − θ²)/2; θ = 0.3: F = 0.187833…, F' = −0.455.
    cond = sub(sub(y, x), theta)
    if solved == "x":  # x = u1 − θ − u0, y = u1
        psi = completed(cond, ("x", "y"), "x", [([sub(sub(u1, theta), u0), u1], ())])
    else:  # x = u1, y = u0 + u1 + θ
        psi = completed(cond, ("x", "y"), "y", [([u1, Add(Add(u0, u1), theta)], ())])
    prog = with_domain(("x", "y"), [(ZERO, ONE)] * 2, Mul(ind(psi), y))
    th = 0.3
    assert close(estimate_value(prog, {"theta": th}, samples=40000, seed=5), (1 - th ** 3) / 3 - th * (1 - th ** 2) / 2)
    d = estimate_derivative(prog, {"theta": th}, {"theta": 1}, samples=40000, seed=5)
    assert d.regular.value == 0.0 and close(d, -(1 - th ** 2) / 2)


def test_several_roots_in_one_variable_are_exact():
    # F(a) = ∫_{-2}^{2} [x² − a ≥ 0]·(x + 3) dx = 12 − 6√a; F'(a) = −3/√a: the delta δ(x² − a)·(−1)
    # sifts at both roots ±√a with weight 1/|2x|: −((√a + 3) + (−√a + 3))/(2√a) = −3/√a.
    a = Param("a")
    psi = completed(sub(Mul(x, x), a), ("x",), "x",
                    [([Pow(Add(u0, a), Fraction(1, 2))], (Add(u0, a),)),
                     ([Mul(const(-1), Pow(Add(u0, a), Fraction(1, 2)))], (Add(u0, a),))])
    prog = with_domain(("x",), [(const(-2), const(2))], Mul(ind(psi), Add(x, const(3))))
    for av in (1.0, 0.49):
        d = estimate_derivative(prog, {"a": av}, {"a": 1}, samples=20000, seed=6)
        assert d.regular.value == 0.0
        assert d.boundary.stderr == 0.0 and abs(d.value + 3 / math.sqrt(av)) < 1e-12
        assert close(estimate_value(prog, {"a": av}, samples=40000, seed=6), 12 - 6 * math.sqrt(av))
    # a < 0: the guard u0 + a ≥ 0 fails, no root, derivative 0 (F = 20 is constant there)
    assert estimate_derivative(prog, {"a": -0.5}, {"a": 1}, samples=100).value == 0.0


def test_several_roots_in_two_variables():
    # F(a) = ∫∫_{[-1,1]²} [y² − a ≥ 0]·(1 + x) = 2·(2 − 2√a); F'(a) = −2/√a (a = 0.25: F = 2, F' = −4).
    # Branches y = ±√(u0 + a), x = u1; |det DΨ̂⁻¹| = 1/(2|y|).
    a = Param("a")
    r = Pow(Add(u0, a), Fraction(1, 2))
    psi = completed(sub(Mul(y, y), a), ("x", "y"), "y",
                    [([u1, r], (Add(u0, a),)), ([u1, Mul(const(-1), r)], (Add(u0, a),))])
    prog = with_domain(("x", "y"), [(const(-1), ONE)] * 2, Mul(ind(psi), Add(ONE, x)))
    assert close(estimate_value(prog, {"a": 0.25}, samples=40000, seed=7), 2.0)
    d = estimate_derivative(prog, {"a": 0.25}, {"a": 1}, samples=40000, seed=7)
    assert d.regular.value == 0.0 and close(d, -4.0)


def test_parametric_bounds_leibniz():
    # ∫_a^b x² dx = (b³ − a³)/3; in direction (a', b') = (1, 1) its derivative is b² − a²,
    # from the domain's own indicators [x ≥ a], [b ≥ x] (exact: one variable).
    a, b = Param("a"), Param("b")
    prog = with_domain(("x",), [(a, b)], Mul(x, x))
    d = estimate_derivative(prog, {"a": 0.5, "b": 2.0}, {"a": 1, "b": 1}, samples=20000, seed=8)
    assert d.regular == Estimate(0.0, 0.0)
    assert abs(d.value - (4 - 0.25)) < 1e-12
    d = estimate_derivative(prog, {"a": 0.5, "b": 2.0}, {"a": 1}, samples=100, seed=8)
    assert abs(d.value + 0.25) < 1e-12
    assert close(estimate_value(prog, {"a": 0.5, "b": 2.0}, samples=40000, seed=8), (8 - 0.125) / 3)


def test_parametric_bounds_in_two_variables():
    # ∫_0^1 ∫_0^c (x + y) dy dx = c/2 + c²/2; D_c = 1/2 + c (c = 0.6: 1.1); the delta at y = c
    # contributes ∫_0^1 (x + c) dx = 1/2 + c, the regular part 0.
    c = Param("c")
    prog = with_domain(("x", "y"), [(ZERO, ONE), (ZERO, c)], Add(x, y))
    v = estimate_value(prog, {"c": 0.6}, samples=40000, seed=9)
    assert close(v, 0.3 + 0.18)
    d = estimate_derivative(prog, {"c": 0.6}, {"c": 1}, samples=40000, seed=9)
    assert close(d, 1.1) and d.regular.value == 0.0


def test_let_and_parameter_conditionals():
    # ∫_0^1 let z = 2θ in ifge0 θ then [x ≤ z]·x else 0, θ = 0.25: value ∫_0^0.5 x = 1/8.
    # D_θ: the delta at x = z with D_θ(z − x) = 2: 2 · x|_{x=0.5} = 1 (exact), regular 0.
    z = Param("z")
    body = Let("z", Mul(const(2), theta),
               IfGe0(theta, Mul(ind(completed(sub(z, x), ("x",), "x", [([sub(z, u0)], ())])), x), ZERO))
    prog = with_domain(("x",), [(ZERO, ONE)], body)
    assert close(estimate_value(prog, {"theta": 0.25}, samples=40000, seed=10), 0.125)
    d = estimate_derivative(prog, {"theta": 0.25}, {"theta": 1}, samples=1000, seed=10)
    assert abs(d.value - 1.0) < 1e-12 and d.stderr == 0.0
    # θ < 0: the else branch, constant 0
    assert estimate_derivative(prog, {"theta": -0.25}, {"theta": 1}, samples=1000).value == 0.0


def test_smooth_primitives_tangents():
    # ∫_0^1 exp(θx) dx = (e^θ − 1)/θ; D_θ = ∫_0^1 x e^{θx} dx = ((θ − 1)e^θ + 1)/θ²  (θ = 0.7)
    prog = with_domain(("x",), [(ZERO, ONE)], Prim("exp", Mul(theta, x)))
    th = 0.7
    d = estimate_derivative(prog, {"theta": th}, {"theta": 1}, samples=40000, seed=11)
    assert close(d, ((th - 1) * math.exp(th) + 1) / th ** 2) and d.boundary.value == 0.0
    # ∫_1^2 log(θx)/x dx = log θ·log 2 + (log 2)²/2, D_θ = log 2/θ
    prog = with_domain(("x",), [(ONE, const(2))], Mul(Prim("log", Mul(theta, x)), Pow(x, Fraction(-1))))
    assert close(estimate_value(prog, {"theta": th}, samples=40000, seed=11),
                 math.log(th) * math.log(2) + math.log(2) ** 2 / 2)
    assert close(estimate_derivative(prog, {"theta": th}, {"theta": 1}, samples=40000, seed=11), math.log(2) / th)


def test_outside_primitive_domain_is_nan():
    prog = with_domain(("x",), [(ZERO, ONE)], Prim("log", sub(x, const(2))))
    assert math.isnan(estimate_value(prog, {}, samples=100).value)
    prog = with_domain(("x",), [(ZERO, ONE)], Prim("sqrt", Mul(const(-1), Add(x, const(1)))))
    assert math.isnan(estimate_value(prog, {}, samples=100).value)


def test_pi_constant():
    prog = with_domain(("x",), [(ZERO, Const("pi"))], Prim("sin", x))
    assert close(estimate_value(prog, {}, samples=40000, seed=12), 2.0)


# -- the degenerate examples: the derivative *denotation* (not D of the integral) -------------------

def test_coincident_and_nested_jumps_count_twice():
    # [x ≥ a]·[x ≥ a] and ifge0 x − a then (ifge0 x − a then 1 else 0) else 0 on [0,1]: the
    # derivative denotation is −2 where D_a(1 − a) = −1 (paper §7.3.1): each site scores −1 at x = a
    # because the other condition, evaluated there, holds (≥ 0 at exactly 0).
    a = Param("a")
    j = completed(sub(x, a), ("x",), "x", [([Add(u0, a)], ())])
    for body in (Mul(ind(j), ind(j)), IfDiffeo(j, ind(j), ZERO)):
        prog = with_domain(("x",), [(ZERO, ONE)], body)
        d = estimate_derivative(prog, {"a": 0.5}, {"a": 1}, samples=100)
        assert d.value == -2.0
        assert close(estimate_value(prog, {"a": 0.5}, samples=40000, seed=13), 0.5)


# -- the naive per-sample evaluator agrees with the compiled one ------------------------------------

def test_naive_and_vectorized_agree_on_the_same_points():
    from langur.operational.compile import compile_term
    from langur.operational.naive import evaluate
    from langur.operational.point import DELTA, TANGENT, UNLINKED, VALUE, Point

    a = Param("a")
    j = completed(sub(Mul(x, x), a), ("x", "y"), "x",
                  [([Pow(Add(u0, a), Fraction(1, 2)), u1], (Add(u0, a),))])
    body = Let("w", Mul(a, theta),
               Add(Mul(IfDiffeo(j, Prim("exp", Mul(Param("w"), y)), Prim("atan", Mul(x, y))),
                       Pow(Add(Mul(x, x), const(2)), Fraction(-3, 2))),
                   Mul(Prim("tanh", Add(x, theta)), Prim("sqrt", Add(Mul(y, y), a)))))
    unit = compile_term(body)
    rng = np.random.default_rng(0)
    pts = {"x": rng.uniform(-2, 2, 200), "y": rng.uniform(-2, 2, 200)}
    p, dp = {"a": 0.7, "theta": -0.3}, {"a": 0.4, "theta": 1.0}
    with np.errstate(all="ignore"):
        v, _ = unit.fn(Point(pts, p, mode=VALUE), UNLINKED)
        _, t = unit.fn(Point(pts, p, dparams=dp, mode=TANGENT), UNLINKED)
        _, g = unit.fn(Point(pts, p, mode=DELTA, site=np.zeros(200, dtype=int), sites=frozenset({0})), UNLINKED)
    for i in range(200):
        rho = {"x": pts["x"][i], "y": pts["y"][i]}
        nv = evaluate(body, rho, p, {})[0]
        nt = evaluate(body, rho, p, dp, TANGENT)[1]
        ng = evaluate(body, rho, p, {}, DELTA, site=0)[1]
        for mine, ref in ((v[i], nv), (t[i], nt), (g[i], ng)):
            assert abs(mine - ref) <= 1e-12 * max(1.0, abs(ref)), (i, mine, ref)


def test_naive_estimators_reproduce_the_engine():
    for prog, p, dp in ((FIG9, {"theta": 0.2}, {"theta": 1.0}), (FIG1, {"theta": 0.4}, {"theta": 1.0})):
        for m in ("uniform", "stratified"):
            fast = estimate_derivative(prog, p, dp, samples=500, seed=3, method=m)
            slow = naive_derivative(prog, p, dp, samples=500, seed=3, method=m)
            assert abs(fast.value - slow.value) < 1e-12 and abs(fast.stderr - slow.stderr) < 1e-12
            fv, sv = estimate_value(prog, p, samples=500, seed=3, method=m), naive_value(prog, p, samples=500,
                                                                                          seed=3, method=m)
            assert abs(fv.value - sv.value) < 1e-12


# -- property: compiled and naive evaluators agree on random terms ----------------------------------

from hypothesis import example, given, settings
from hypothesis import strategies as st


def _param_terms():
    leaves = st.one_of(st.sampled_from([Param("a"), Param("b")]),
                       st.integers(-3, 3).map(lambda k: const(Fraction(k, 2))))
    return st.recursive(leaves, lambda c: st.one_of(st.builds(Add, c, c), st.builds(Mul, c, c)), max_leaves=4)


def _terms():
    leaves = st.one_of(st.sampled_from([x, y, Param("a"), Param("b"), Const("pi")]),
                       st.integers(-4, 4).map(lambda k: const(Fraction(k, 3))))
    jump = completed(sub(x, Param("a")), ("x", "y"), "x", [([Add(u0, Param("a")), u1], ())])

    def extend(c):
        return st.one_of(
            st.builds(Add, c, c), st.builds(Mul, c, c),
            st.builds(Prim, st.sampled_from(["exp", "log", "sin", "cos", "tan", "sqrt", "tanh", "atan",
                                             "asin", "acos", "atanh"]), c),
            st.builds(Pow, c, st.sampled_from([Fraction(-1), Fraction(2), Fraction(3), Fraction(1, 2),
                                               Fraction(-3, 2)])),
            st.builds(IfGe0, _param_terms(), c, c),
            st.builds(lambda s, r: IfDiffeo(jump, s, r), c, c),
            st.builds(lambda t, s: Let("a", t, s), _param_terms(), c))
    return st.recursive(leaves, extend, max_leaves=12)


def _agree(mine, ref, tol=1e-9):
    if not (math.isfinite(ref) and math.isfinite(mine)):
        return True  # both engines may legitimately differ on 0·∞ (an exact zero tangent is skipped)
    return abs(mine - ref) <= tol * max(1.0, abs(ref))


@settings(max_examples=60, deadline=None)
@given(_terms(), st.floats(-1.5, 1.5), st.floats(-1.5, 1.5))
@example(Prim("sqrt", Param("a")), 0.0, 0.0)  # found: d/da sqrt(a) at 0 divided a Python float by zero
def test_random_terms_compiled_equals_naive(term, av, bv):
    from langur.operational.compile import compile_term
    from langur.operational.naive import evaluate
    from langur.operational.point import DELTA, TANGENT, UNLINKED, VALUE, Point

    unit = compile_term(term)
    pts = {"x": np.linspace(-2, 2, 9), "y": np.linspace(1.7, -1.3, 9)}
    p, dp = {"a": av, "b": bv}, {"a": 1.0, "b": -0.5}
    with np.errstate(all="ignore"):
        v = np.broadcast_to(unit.fn(Point(pts, p, mode=VALUE), UNLINKED)[0], (9,))
        t = unit.fn(Point(pts, p, dparams=dp, mode=TANGENT), UNLINKED)[1]
        t = np.broadcast_to(0.0 if t is None else t, (9,))
        g = unit.fn(Point(pts, p, mode=DELTA, site=np.zeros(9, dtype=int), sites=frozenset({0})), UNLINKED)[1]
        g = np.broadcast_to(0.0 if g is None else g, (9,))
    for i in range(9):
        rho = {"x": float(pts["x"][i]), "y": float(pts["y"][i])}
        nv = evaluate(term, rho, p, {})[0]
        if math.isfinite(nv):  # values have no skipped zeros: finite in one engine means finite in both
            assert math.isfinite(v[i]) and _agree(v[i], nv), (v[i], nv)
        assert _agree(t[i], evaluate(term, rho, p, dp, TANGENT)[1])
        assert _agree(g[i], evaluate(term, rho, p, {}, DELTA, site=0)[1])


def test_parameter_singularities_are_nan_not_exceptions():
    # found by the property test: d/da log(a) at a = 0 divided a Python float by zero
    from langur.operational.compile import compile_term
    from langur.operational.point import TANGENT, UNLINKED, Point

    a = Param("a")
    for op, at in (("log", 0.0), ("atanh", 1.0), ("atanh", -1.0), ("log", -2.0)):
        with np.errstate(all="ignore"):  # as the estimators evaluate
            v, d = compile_term(Prim(op, a)).fn(Point({}, {"a": at}, dparams={"a": 1.0}, mode=TANGENT), UNLINKED)
        assert not math.isfinite(float(v)) and math.isnan(float(d))
    prog = with_domain(("x",), [(ZERO, ONE)], Mul(x, Prim("log", a)))
    d = estimate_derivative(prog, {"a": 0.0}, {"a": 1}, samples=100)
    assert math.isnan(d.value) and math.isnan(d.regular.value)


def test_a_shared_subterm_is_evaluated_once_per_point_with_the_same_numbers():
    # s = (x + a)·(x + 1) shared by one term (a DAG, as substituted lets and vectors make it) is
    # compiled once and evaluated once per point: x is read twice, not six times; the value and
    # tangent are bit for bit those of the term written out with separate copies; once its three
    # references are read, the point no longer holds s's arrays
    from langur.operational.compile import compile_term
    from langur.operational.point import TANGENT, UNLINKED, Point

    class Reads(dict):
        count = 0

        def __getitem__(self, k):
            Reads.count += 1
            return dict.__getitem__(self, k)

    def s():
        return Mul(Add(Var("x"), Param("a")), Add(Var("x"), const(1)))

    one = s()
    dag = Add(Mul(one, one), Prim("exp", one))
    tree = Add(Mul(s(), s()), Prim("exp", s()))
    x = np.linspace(-1, 1, 7)
    pt_dag = Point(Reads(x=x), {"a": 0.3}, dparams={"a": 1.0}, mode=TANGENT)
    v1, d1 = compile_term(dag).fn(pt_dag, UNLINKED)
    assert Reads.count == 2 and pt_dag.memo == {}
    pt_tree = Point(Reads(x=x), {"a": 0.3}, dparams={"a": 1.0}, mode=TANGENT)
    v2, d2 = compile_term(tree).fn(pt_tree, UNLINKED)
    assert Reads.count == 2 + 6
    assert np.array_equal(v1, v2) and np.array_equal(d1, d2)
