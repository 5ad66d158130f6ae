"""The naive evaluator: the operational semantics one sample at a time, in pure Python (§9).

A tree-walking interpreter of Fig. 7/8 over floats (``math``), the way a prototype such as
Potto evaluates a program at each sample.  It is the benchmark baseline (bench/bench_operational.py)
and an independent cross-check of the vectorized compiler in the tests: the same primitive rules
(``langur.primitives``), but no vectors, no compilation, no linking (it evaluates the inlined
program).
"""

from __future__ import annotations

import math
from fractions import Fraction

import numpy as np

from ..codes import NO_SLOPE_TO_CERTIFY, turning_points_beyond_split
from ..core import (
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Term,
    TooManyRoots,
    Var,
    free_vars,
)
from ..primitives import REGISTRY
from ..records import frozen
from .interval import tape_of
from .link import collect_sites
from .point import DELTA, TANGENT, VALUE
from .results import Estimate
from .roots import ROOT_HALVINGS
from .sample import design
from .signchanges import certified_brackets

NAN = float("nan")


def _derivative(op: str, a: float, v: float) -> float:
    """f'(a) from the primitive's registry entry, on one float (NaN outside the domain).  The
    registry's derivatives are numpy expressions: given numpy floats, a division by zero in the
    branch ``np.where`` discards is inf, not Python's ZeroDivisionError (sqrt at 0)."""
    with np.errstate(all="ignore"):
        return float(REGISTRY[op].derivative(np.float64(a), np.float64(v)))


def _pow(a: float, k: Fraction) -> float:
    if k < 0 and a == 0 or math.isnan(a):
        return NAN
    try:
        if k.denominator != 1 and a < 0:
            return NAN
        return a ** float(k)
    except (OverflowError, ZeroDivisionError):
        return math.inf


def _root(f, a: float, b: float, index: int | None, of: int, certify=None, root=None) -> float:
    """The sign change of ``f`` in ``[a, b]`` (``index`` None: the one of a monotone ``f``, NaN
    if none) or its ``index``-th one (``b`` if there are fewer; :class:`~langur.core.TooManyRoots`
    if more than ``of``), bisected: ``certify`` gives the brackets, each certified to hold one
    (:mod:`langur.operational.signchanges`)."""
    if index is not None:
        if certify is None:
            raise TooManyRoots(NO_SLOPE_TO_CERTIFY, root)
        brackets = certify(a, b)
        if len(brackets) > of:
            raise TooManyRoots(turning_points_beyond_split(len(brackets), of, "on the domain"), root)
        if index >= len(brackets):
            return b
        a, b = brackets[index]
    fa, fb = f(a), f(b)
    if fa == 0 or fb == 0:
        return a if fa == 0 else b
    if not (fa < 0) ^ (fb < 0):
        return NAN
    for _ in range(ROOT_HALVINGS):
        m = 0.5 * (a + b)
        if (f(m) < 0) == (fa < 0):
            a = m
        else:
            b = m
    return 0.5 * (a + b)


def _brackets(f, target: float, tape, x: str, lo: float, hi: float, params: dict, root,
              moving: dict) -> list[tuple[float, float]]:
    """The certified brackets of the sign changes of ``f`` (= equation − target) on ``[lo, hi]``,
    one point at a time (``f`` evaluated point by point, the enclosures by the shared tape);
    ``moving``: the other inputs the equation mentions (lenient on their null set, as the engine)."""
    def value(at, rows):
        return np.array([f(float(p)) + target for p in at])
    _, a, b = certified_brackets(value, tape, x, np.array([float(target)]), np.array([float(lo)]),
                                 np.array([float(hi)]), params, root, what=f"∂/∂{x}", others=moving,
                                 lenient=bool(moving))
    return list(zip(a.tolist(), b.tolist()))


class _Counter:
    __slots__ = ("n",)

    def __init__(self):
        self.n = 0


def evaluate(t: Term, rho: dict, gamma: dict, dgamma: dict, mode: int = VALUE, site: int = -1,
             counter: _Counter | None = None, dvars: dict | None = None) -> tuple[float, float]:
    """(⟦t⟧, d) at ONE point: d is the tangent (TANGENT) or the coefficient of δ_site per unit of
    D_γπ₀Ψ̂·γ' (DELTA).  Both branches of every conditional are walked, so that sites are numbered
    in pre-order like the compiler's."""
    counter = counter or _Counter()
    dvars = dvars or {}

    def go(u, g, dg):
        match u:
            case Const(c):
                return (math.pi if c == "pi" else float(c)), 0.0
            case Var(name):
                return rho[name], dvars.get(name, 0.0)
            case Param(name):
                return g[name], (dg.get(name, 0.0) if mode == TANGENT else 0.0)
            case Add(a, b):
                (x, dx), (y, dy) = go(a, g, dg), go(b, g, dg)
                return x + y, dx + dy
            case Mul(a, b):
                (x, dx), (y, dy) = go(a, g, dg), go(b, g, dg)
                return x * y, dx * y + dy * x
            case IfGe0(c, a, b):
                cv, _ = go(c, g, dg)
                sa, sb = go(a, g, dg), go(b, g, dg)
                return sa if cv >= 0 else sb
            case IfDiffeo(psi, a, b):
                k = counter.n
                counter.n += 1
                cv, _ = evaluate(psi.forward[0], rho, g, {}, VALUE)
                (s, ds), (r, dr) = go(a, g, dg), go(b, g, dg)
                d = ds if cv >= 0 else dr
                if mode == DELTA and k == site:
                    d = d + (s - r)
                return (s if cv >= 0 else r), d
            case Let(name, bound, body):
                v, dv = go(bound, g, dg)
                return go(body, {**g, name: v}, {**dg, name: dv})
            case Prim(op, a):
                x, dx = go(a, g, dg)
                v = REGISTRY[op].scalar(x)
                return v, (_derivative(op, x, v) * dx if dx != 0.0 else 0.0)
            case Pow(a, k):
                x, dx = go(a, g, dg)
                v = _pow(x, k)
                return v, (float(k) * _pow(x, k - 1) * dx if dx != 0.0 else 0.0)
            case Call():
                raise ValueError("the naive evaluator runs inlined programs only")
            case ImplicitRoot(eq, x, target, lo, hi, index, of, slope):
                # issue 18, implicit root (a Ψ̂⁻¹ component): bisection; ⦇x*⦈ by the implicit function theorem
                (tv, dt), (a, _), (b, db) = go(target, g, dg), go(lo, g, dg), go(hi, g, dg)
                # the equation may mention Ψ̂⁻¹'s other inputs (a condition in several variables)
                f = lambda at: evaluate(eq, {**rho, x: at}, g, {})[0] - tv  # noqa: E731
                moving = {k: np.array([float(rho[k])]) for k in sorted(free_vars(eq) - {x})}  # other inputs
                certify = None if slope is None else (
                    lambda lo, hi: _brackets(f, tv, tape_of([eq, slope], True), x, lo, hi, g, u, moving))
                r = _root(f, a, b, index, of, certify, u)
                if index is not None and r == b:
                    return r, db  # no index-th sign change: the bracket's end
                fx = evaluate(eq, {**rho, x: r}, g, {}, TANGENT, dvars={x: 1.0})[1]
                others = {k: d for k, d in dvars.items() if k != x}
                ft = evaluate(eq, {**rho, x: r}, g, dg, TANGENT, dvars=others)[1] if mode == TANGENT else 0.0
                return r, (dt - ft) / fx if fx else NAN
        raise TypeError(f"not a core term: {u!r}")

    return go(t, gamma, dgamma)


@frozen
class NaiveDerivative(Estimate):
    """⦇p⦈ ≈ ``value`` ± ``stderr`` = ``regular`` + ``boundary`` (the two parts' estimates)."""

    regular: float = 0.0
    boundary: float = 0.0


def _box(program: Program, params):
    return [(evaluate(lo, {}, params, {})[0], evaluate(hi, {}, params, {})[0]) for lo, hi in program.box]


def _inside(x: dict, boxd: dict) -> bool:
    """x in the closed box B, widened by 1e-9 of each side's scale (as the engine's estimate._inside)."""
    for v, (lo, hi) in boxd.items():
        tol = 1e-9 * max(1.0, abs(lo), abs(hi))
        if not (lo - tol <= x[v] <= hi + tol):
            return False
    return True


def naive_value(program: Program, params: dict, *, samples=10000, seed=0, method="uniform") -> Estimate:
    """⟦p⟧ by Monte Carlo, one sample at a time (same design and seed as the vectorized engine)."""
    rng = np.random.default_rng(seed)
    box = _box(program, params)
    d = design(rng, len(program.variables), samples, method)
    vol = math.prod(hi - lo for lo, hi in box)
    f = []
    for row in d.points.tolist():
        rho = {x: lo + r * (hi - lo) for x, r, (lo, hi) in zip(program.variables, row, box)}
        f.append(evaluate(program.body, rho, params, {})[0])
    mean, se = d.mean(np.array(f))
    return Estimate(vol * mean, vol * se)


def naive_derivative(program: Program, params: dict, direction: dict, *, samples=10000, seed=0,
                     method="uniform") -> NaiveDerivative:
    """⦇p⦈ by Monte Carlo, one sample (and, for deltas, one site and one root) at a time."""
    rng = np.random.default_rng(seed)
    box = _box(program, params)
    variables = program.variables
    d = design(rng, len(variables), samples, method)
    vol = math.prod(hi - lo for lo, hi in box)
    dp = {k: float(v) for k, v in direction.items() if float(v) != 0.0}
    f = []
    for row in d.points.tolist():
        rho = {x: lo + r * (hi - lo) for x, r, (lo, hi) in zip(variables, row, box)}
        f.append(evaluate(program.body, rho, params, dp, TANGENT)[1])
    mean, se = d.mean(np.array(f))
    reg, reg_se = vol * mean, vol * se
    sites = []
    collect_sites(program.body, {}, {}, variables, None, sites)
    bnd, bvar = 0.0, 0.0
    boxd = dict(zip(variables, box))
    for k, site in enumerate(sites):
        if not (site.deps & set(dp)):
            continue
        sm = site.sampler
        des = design(rng, len(variables) - 1, samples, method)
        region = sm.shrink(sm.region(boxd, params), boxd, params)
        if any(not (b > a) for a, b in region):
            continue
        uvol = math.prod(b - a for a, b in region)
        psi = sm.psi
        scores = []
        folds = len(sm.coords) == 1 and any(br.guards for br in psi.branches)
        if folds:  # the same change of variables at folds as the engine (sample.SiteSampler.fold_map)
            mapped, factors = sm.fold_map(des.points[:, 0], region[0][0], region[0][1], params)
        for i, row in enumerate(des.points.tolist()):
            u = {psi.inputs[0]: 0.0}
            for (name, _, _), r, (a, b) in zip(sm.coords, row, region):
                u[name] = a + r * (b - a)
            factor = 1.0
            if folds:
                u[sm.coords[0][0]], factor = float(mapped[i]), float(factors[i])
                if factor == 0.0:
                    scores.append(0.0)
                    continue
            total = 0.0
            for br in psi.branches:
                if any(evaluate(gd, u, params, {})[0] < 0 for gd in br.guards):
                    continue
                x = {v: evaluate(c, u, params, {})[0] for v, c in zip(variables, br.components)}
                if not _inside(x, boxd):
                    continue  # outside B the domain's indicators vanish (even where the integrand is NaN)
                jac = np.array([[evaluate(c, u, params, {}, TANGENT, dvars={ui: 1.0})[1] for ui in psi.inputs]
                                for c in br.components])
                w = abs(float(np.linalg.det(jac))) if len(variables) > 1 else abs(jac[0, 0])
                dpsi = evaluate(psi.forward[0], x, params, dp, TANGENT)[1]
                g = evaluate(program.body, x, params, {}, DELTA, site=k)[1]
                total += dpsi * g * w * factor
            scores.append(total)
        mean, se = des.mean(np.array(scores))
        bnd += uvol * mean
        bvar += (uvol * se) ** 2
    return NaiveDerivative(reg + bnd, math.sqrt(reg_se ** 2 + bvar), reg, bnd)
