"""Automatic completion of conditions to diffeomorphisms (LANGUAGE.md §6, "Conditions over
variables"), validated numerically and independently of how the inverse was found:

* the inverse inverts: at random inputs u where a branch's guards hold, Ψ̂(branch(u)) = u;
* all roots are found: for random values of the other variables, every root of the condition in
  the solved variable's interval (found by bracketing sign changes on a fine grid and brentq) is
  the value of exactly one branch at u0 = 0 whose guards hold.
"""

from __future__ import annotations

import math
import random
import time
from fractions import Fraction as F

import numpy as np
import pytest
from scipy.optimize import brentq

from langur.core import Add, Const, IfDiffeo, Mul, Param, Pow, Prim, Var, const, free_params, sub
from langur.sympy_bridge import lambdify
from langur.syntax import diffeo as D
from langur.syntax.diffeo import CompletionError, complete

x, y = Var("x"), Var("y")


def P(n):
    return Param(n)


def fn(term, names):
    f = lambdify(term, names)
    return lambda *a: complex(f(*a))


def _real(z: complex) -> float | None:
    if not (math.isfinite(z.real) and math.isfinite(z.imag)) or abs(z.imag) > 1e-9:
        return None
    return z.real


def validate(psi, box: dict[str, tuple[float, float]], params: dict[str, tuple[float, float]], seed=0, trials=60):
    """Check the two properties in the module docstring; returns how many roots were matched."""
    rng = random.Random(seed)
    pnames = sorted(params)
    names = list(psi.inputs) + pnames
    fwd = [fn(f, list(psi.variables) + pnames) for f in psi.forward]
    branches = [([fn(c, names) for c in b.components], [fn(g, names) for g in b.guards]) for b in psi.branches]
    v = psi.solved_for
    iv = psi.variables.index(v)
    cond = fwd[0]
    matched = 0
    for _ in range(trials):
        pv = [rng.uniform(*params[p]) for p in pnames]
        # (1) Ψ̂(branch(u)) = u where the guards hold
        u = [rng.uniform(-0.5, 0.5)] + [rng.uniform(*box[w]) for w in psi.variables if w != v]
        for comps, guards in branches:
            gs = [_real(g(*u, *pv)) for g in guards]
            if any(gv is None or gv < 0 for gv in gs):
                continue
            xs = [_real(c(*u, *pv)) for c in comps]
            if any(xv is None for xv in xs):
                continue
            back = [_real(f(*xs, *pv)) for f in fwd]
            assert all(b is not None for b in back)
            assert np.allclose(back, u, rtol=1e-7, atol=1e-7), (psi, u, pv, xs, back)
        # (2) every root of the condition in v's interval is hit by exactly one branch at u0 = 0
        others = [rng.uniform(*box[w]) for w in psi.variables if w != v]
        u = [0.0] + others

        def at(t, others=others, pv=pv):
            args = list(others)
            args.insert(iv, t)
            return _real(cond(*args, *pv))

        lo, hi = box[v]
        grid = np.linspace(lo, hi, 4001)
        vals = [at(t) for t in grid]
        roots = []
        for a, b, fa, fb in zip(grid, grid[1:], vals, vals[1:]):
            if fa is None or fb is None:
                continue
            if fa == 0:
                roots.append(a)
            elif fa * fb < 0:
                r = brentq(at, a, b, xtol=1e-13)
                if abs(at(r)) < 1e-7:  # a sign change across a pole is not a root
                    roots.append(r)
        values = []
        for comps, guards in branches:
            gs = [_real(g(*u, *pv)) for g in guards]
            if any(gv is None or gv < 0 for gv in gs):
                continue
            xv = _real(comps[iv](*u, *pv))
            if xv is not None:
                values.append(xv)
        for r in roots:
            hits = [w for w in values if abs(w - r) < 1e-6 * (1 + abs(r))]
            assert len(hits) == 1, (psi.forward[0], r, values, pv, others)
            matched += 1
    return matched


def test_spec_example_y_less_than_x_plus_theta():
    # LANGUAGE.md §6: [y < x + θ] completes to Ψ̂(x,y;θ) = (x + θ − y, x), inverse (u0, u1) ↦ (u1, u1 + θ − u0)
    cond = sub(Add(x, P("theta")), y)
    psi = complete(cond, ("x", "y"))
    assert psi.solved_for == "y" and psi.forward == (cond, x) and psi.inputs == ("u0", "u1")
    (b,) = psi.branches
    comps = [fn(c, ["u0", "u1", "theta"]) for c in b.components]
    for u0, u1, th in [(0.3, -0.2, 0.1), (-1.0, 2.0, 0.5)]:
        assert abs(comps[0](u0, u1, th) - u1) < 1e-12
        assert abs(comps[1](u0, u1, th) - (u1 + th - u0)) < 1e-12
    assert validate(psi, {"x": (-1, 1), "y": (-1, 1)}, {"theta": (-0.5, 0.5)}) > 30


CASES = [
    # (name, condition, variables, box, parameter ranges, solved_for, number of branches)
    ("affine-param-coefficient", sub(Mul(P("t"), x), const(1)), ("x",), {"x": (0.0, 2.0)}, {"t": (0.6, 3.0)}, "x", 1),
    ("graph", sub(sub(y, Pow(x, F(2))), P("a")), ("x", "y"), {"x": (-1, 1), "y": (-1, 2)}, {"a": (-0.5, 0.5)}, "y", 1),
    ("exp", sub(Prim("exp", x), P("a")), ("x",), {"x": (-2, 2)}, {"a": (0.2, 5.0)}, "x", 1),
    ("log", sub(Prim("log", x), P("a")), ("x",), {"x": (0.01, 3)}, {"a": (-2, 1)}, "x", 1),
    ("sqrt", sub(Prim("sqrt", x), P("a")), ("x",), {"x": (0, 3)}, {"a": (0.1, 1.5)}, "x", 1),
    ("tanh", sub(Prim("tanh", x), P("a")), ("x",), {"x": (-3, 3)}, {"a": (-0.9, 0.9)}, "x", 1),
    ("atan", sub(Prim("atan", Mul(const(2), x)), P("a")), ("x",), {"x": (-3, 3)}, {"a": (-1.2, 1.2)}, "x", 1),
    ("square", sub(Pow(x, F(2)), P("a")), ("x",), {"x": (-2, 2)}, {"a": (0.05, 3)}, "x", 2),
    ("cube", sub(Pow(x, F(3)), P("a")), ("x",), {"x": (-2, 2)}, {"a": (-5, 5)}, "x", 2),
    ("sin-on-unit", sub(Prim("sin", x), P("t")), ("x",), {"x": (0.0, 1.0)}, {"t": (0.05, 0.8)}, "x", 1),
    ("sin-on-0-10", sub(Prim("sin", x), P("t")), ("x",), {"x": (0.0, 10.0)}, {"t": (-0.9, 0.9)}, "x", 4),
    ("cos-on-0-7", sub(Prim("cos", x), P("t")), ("x",), {"x": (0.0, 7.0)}, {"t": (-0.9, 0.9)}, "x", 3),
    ("tan-with-poles", sub(Prim("tan", x), P("t")), ("x",), {"x": (-1.0, 4.0)}, {"t": (-3, 3)}, "x", 2),
    ("circle", sub(Add(Pow(x, F(2)), Pow(y, F(2))), P("r")), ("x", "y"), {"x": (-1, 1), "y": (-1, 1)},
     {"r": (0.2, 0.9)}, "y", 2),
    ("hyperbola", sub(Mul(x, y), const(1)), ("x", "y"), {"x": (0.5, 2), "y": (0.2, 3)}, {}, "y", 1),
    ("rational", sub(Mul(x, Pow(Add(x, const(1)), F(-1))), P("a")), ("x",), {"x": (0, 3)}, {"a": (0.05, 0.7)}, "x", 1),
    ("quadratic-two-terms", sub(Add(Pow(x, F(2)), Mul(x, y)), P("a")), ("x", "y"), {"x": (-2, 2), "y": (-1, 1)},
     {"a": (0.1, 1.0)}, "y", 1),
    ("quadratic-formula", sub(Add(Pow(x, F(2)), Mul(const(3), x)), P("a")), ("x",), {"x": (-5, 3)}, {"a": (-2, 4)}, "x", 2),
    ("three-variables", sub(Add(Add(x, Mul(const(2), y)), Var("z")), P("a")), ("x", "y", "z"),
     {"x": (0, 1), "y": (0, 1), "z": (0, 1)}, {"a": (0.5, 2)}, "z", 1),
]


@pytest.mark.parametrize("name,cond,variables,box,params,solved,nbranches", CASES, ids=[c[0] for c in CASES])
def test_completion_inverts_and_finds_every_root(name, cond, variables, box, params, solved, nbranches):
    nb = tuple((v, float(lo), float(hi)) for v, (lo, hi) in box.items())
    psi = complete(cond, variables, nb)
    assert psi.solved_for == solved
    assert len(psi.branches) == nbranches
    assert psi.forward[0] == cond and psi.variables == variables
    assert psi.forward[1:] == tuple(Var(v) for v in variables if v != solved)
    matched = validate(psi, box, params)
    assert matched >= 20, f"too few roots checked ({matched})"


def test_parameter_coefficient_is_recorded_nonzero():
    psi = complete(sub(Mul(P("t"), x), const(1)), ("x",))
    assert psi.nonzero == (P("t"),)
    assert complete(sub(x, P("t")), ("x",)).nonzero == ()


def test_guards_say_where_branches_exist():
    # x^2 - a: x = ±sqrt(u0 + a), both guarded by u0 + a >= 0
    psi = complete(sub(Pow(x, F(2)), P("a")), ("x",))
    g = [fn(b.guards[0], ["u0", "a"]) for b in psi.branches]
    assert all(len(b.guards) == 1 for b in psi.branches)
    assert all(gi(0.0, 1.0).real >= 0 and gi(0.0, -1.0).real < 0 for gi in g)
    # exp(x) - a: x = log(u0 + a), which exists where u0 + a > 0
    (b,) = complete(sub(Prim("exp", x), P("a")), ("x",)).branches
    assert fn(b.guards[0], ["u0", "a"])(-2.0, 1.0).real < 0


def test_preference_affine_constant_then_last_variable():
    # x + y^2 - a: x is affine with a constant coefficient, y is not: solve for x
    assert complete(sub(Add(x, Pow(y, F(2))), P("a")), ("x", "y")).solved_for == "x"
    # both affine with constant coefficients: the last variable (LANGUAGE.md's example)
    assert complete(sub(Add(x, y), P("a")), ("x", "y")).solved_for == "y"
    assert complete(sub(Add(x, y), P("a")), ("y", "x")).solved_for == "x"
    # constant coefficient beats parameter coefficient, even for an earlier variable
    assert complete(sub(Add(x, Mul(P("t"), y)), P("a")), ("x", "y")).solved_for == "x"
    # parameter coefficient beats a nonlinear occurrence
    assert complete(sub(Add(Mul(P("t"), x), Prim("exp", y)), P("a")), ("x", "y")).solved_for == "x"


def test_deterministic():
    cond = sub(Add(Pow(x, F(2)), Pow(y, F(2))), P("r"))
    first = complete(cond, ("x", "y"))
    D._complete_cached.cache_clear()
    assert complete(cond, ("x", "y")) == first


def test_inputs_renamed_apart_from_names_in_use():
    psi = complete(sub(Var("u0"), P("u1")), ("u0",))
    assert not set(psi.inputs) & {"u0", "u1"}
    assert free_params(psi.branches[0].components[0]) == {"u1"}


@pytest.mark.parametrize("cond,variables,box,why", [
    (sub(Prim("sin", Pow(x, F(-1))), P("a")), ("x",), (("x", -1.0, 1.0),), "infinitely many"),
    (sub(Prim("sin", x), P("a")), ("x",), (), "infinitely many"),
    (sub(Add(x, Prim("sin", x)), P("a")), ("x",), (), "no variable can be isolated"),
    (sub(IfDiffeo(complete(x, ("x",)), x, const(0)), P("a")), ("x",), (), "conditional"),
    (sub(Prim("sin", Mul(const(1000), x)), P("a")), ("x",), (("x", 0.0, 1.0),), "branches"),
])
def test_rejections(cond, variables, box, why):
    with pytest.raises(CompletionError, match=why):
        complete(cond, variables, box)


def test_completion_is_fast_and_bounded():
    t0 = time.process_time()
    for k in range(2, 12):
        D._complete_cached.cache_clear()
        complete(sub(Add(Pow(x, F(k)), Mul(Const(F(k)), y)), P("a")), ("x", "y"))
    assert time.process_time() - t0 < 20


def test_the_validator_itself_catches_a_missing_branch_and_a_wrong_inverse():
    from dataclasses import replace

    psi = complete(sub(Prim("sin", x), P("t")), ("x",), (("x", 0.0, 10.0),))
    box, params = {"x": (0.0, 10.0)}, {"t": (-0.9, 0.9)}
    with pytest.raises(AssertionError):
        validate(replace(psi, branches=psi.branches[:-1]), box, params)
    wrong = replace(psi.branches[0], components=(Add(psi.branches[0].components[0], const(F(1, 100))),))
    with pytest.raises(AssertionError):
        validate(replace(psi, branches=(wrong,) + psi.branches[1:]), box, params)


def _random_condition(rng: random.Random, depth: int):
    if depth == 0:
        r = rng.random()
        if r < 0.4:
            return Var(rng.choice("xy"))
        if r < 0.6:
            return P("a")
        return Const(F(rng.randint(1, 5), rng.choice([1, 2])))
    r = rng.random()
    if r < 0.3:
        return Add(_random_condition(rng, depth - 1), _random_condition(rng, depth - 1))
    if r < 0.5:
        return Mul(_random_condition(rng, depth - 1), _random_condition(rng, depth - 1))
    if r < 0.75:
        op = rng.choice(["exp", "log", "sin", "cos", "tan", "sqrt", "tanh", "atan"])
        return Prim(op, _random_condition(rng, depth - 1))
    return Pow(_random_condition(rng, depth - 1), rng.choice([F(2), F(3), F(-1), F(1, 2), F(-2)]))


def test_random_conditions_complete_correctly_or_are_rejected():
    """Random smooth conditions in x, y: each completion found is validated like the cases above."""
    from langur.core import free_vars

    rng = random.Random(7)
    box = {"x": (0.1, 2.0), "y": (-1.0, 1.5)}
    nb = tuple((k, *v) for k, v in box.items())
    completed = 0
    while completed < 40:
        cond = sub(_random_condition(rng, rng.randint(1, 3)), P("a"))
        if not free_vars(cond):
            continue
        try:
            psi = complete(cond, ("x", "y"), nb)
        except CompletionError:
            continue
        completed += 1
        with np.errstate(all="ignore"):
            validate(psi, box, {"a": (-1.0, 1.0)}, seed=completed, trials=8)
