"""Antiderivatives of smooth weights in one variable (paper §6.3, Def. 6.2: the smooth functions
``h`` of a decomposable integrand, integrated between bounds that :mod:`langur.symbolic.regions`
computes from the conditions; LANGUAGE.md §4).

sympy only ever integrates a SMOOTH weight here (:func:`antiderivative`; never a Piecewise,
Heaviside, Min or Max, which sympy 1.14 integrates wrongly), time-boxed per attempt, after the
shapes it needs no sympy for (:mod:`langur.symbolic.elementary`); every answer of sympy's is
checked by differentiating it back (:func:`_derivative_matches`).  What sympy answered is
remembered per process, and handed between ``langur fuzz``'s workers
(:func:`antiderivatives_known`, :func:`antiderivatives_since`, :func:`learn_antiderivatives`).
"""

from __future__ import annotations

import random

import sympy as sp

from langur import failures
from langur.memo import remember as _remember
from langur.symbolic import elementary
from langur.symbolic.context import Context, Unsupported

_BAD = (sp.Integral, sp.Piecewise, sp.Heaviside, sp.DiracDelta, sp.Min, sp.Max, sp.Abs, sp.sign,
        sp.floor, sp.ceiling, sp.exp_polar, sp.polar_lift, sp.lowergamma, sp.uppergamma,
        sp.meijerg, sp.hyper)


def _mentions_bad(expr, v) -> bool:
    for node in sp.preorder_traversal(expr):
        if isinstance(node, _BAD) and v in node.free_symbols:
            return True
        if isinstance(node, (sp.Integral, sp.exp_polar, sp.polar_lift)):
            return True
    return False


def _resolve_piecewise(expr, v, ctx: Context):
    """Replace Piecewise with parameter-only conditions by the branch valid at ``at``."""

    def pick(pw):
        for e, c in pw.args:
            if c is sp.true:
                return e
            if v in c.free_symbols or c.free_symbols - ctx.params:
                raise Unsupported(f"antiderivative with condition {c}")
            ok = c.xreplace({k: sp.Float(float(x), 40) for k, x in ctx.at.items()})
            if ok not in (sp.true, sp.false):
                raise Unsupported(f"undecidable condition {c}")
            ctx.record_relation(c if ok is sp.true else sp.Not(c))
            if ok is sp.true:
                return e
        raise Unsupported("no Piecewise branch holds")

    return expr.replace(lambda e: isinstance(e, sp.Piecewise), pick)


def _gaussian_termwise(w, v):
    """∫ Σ poly(v)·exp(quadratic(v)) dv by completing the square (sympy misses the shifted case)."""
    total = sp.Integer(0)
    for term in sp.Add.make_args(sp.expand(sp.powsimp(sp.expand(w), combine="exp"))):
        term = sp.powsimp(term, combine="exp")
        exps = [f for f in sp.Mul.make_args(term) if isinstance(f, sp.exp) and v in f.free_symbols]
        if len(exps) == 1:
            e = sp.expand(exps[0].args[0])
            poly = e.as_poly(v)
            if poly is not None and poly.degree() == 2 and not any(c.has(v) for c in poly.all_coeffs()):
                a, b, _ = poly.all_coeffs()
                x0 = -b / (2 * a)
                s = sp.Dummy("s", real=True)
                shifted = sp.expand(term.xreplace({v: s + x0}))
                F = sp.integrate(shifted, s, conds="none")
                total += F.xreplace({s: v - x0})
                continue
        total += sp.integrate(term, v, conds="none")
    return total


def _has_gaussian(w, v) -> bool:
    for node in sp.preorder_traversal(w):
        if isinstance(node, sp.exp) and v in node.free_symbols:
            p = sp.expand(node.args[0]).as_poly(v)
            if p is not None and p.degree() == 2:
                return True
    return False


def _constant_symbols(w) -> dict:
    """Positive irrational constants (√2, π, …) of ``w`` mapped to positive dummy symbols."""
    reps = {}
    for a in w.atoms(sp.Pow, sp.NumberSymbol):
        if a.is_number and not a.is_Rational and a.is_positive and not a.free_symbols:
            if isinstance(a, sp.Pow) and not (a.base.is_Rational and a.exp.is_Rational):
                continue
            reps[a] = sp.Dummy("c", positive=True)
    return reps


#: sympy's raw answers (or failure reasons) per (weight, variable, attempt): the same weights come
#: back at other parameter values (Theorem 8.1 checks, finite differences, the other partial
#: derivatives of a campaign's program).
_CACHE: dict = {}
#: Attempts that ran out of time, with the time they had: retried only with more.
_TIMED_OUT: dict = {}
#: Seconds one sympy integrate attempt may take.  Measured over the examples and a seeded fuzz
#: campaign (388 successful attempts): every success took under 2.8 s on a quiet machine (5 s leaves
#: room for a loaded one); an attempt that is going to fail runs until stopped, and used to be given
#: a third of the whole budget (6.7 s of 20), several times per weight and call, so one hard program
#: cost minutes before its quadrature was reported.
ATTEMPT_CAP = 5.0


def antiderivatives_known() -> set:
    """The keys of the antiderivatives (and definite failures) this process remembers."""
    return set(_CACHE)


def antiderivatives_since(known: set) -> dict:
    """What this process has learned since :func:`antiderivatives_known` returned ``known``:
    ``langur fuzz``'s workers hand it back, so that the units forked after them do not ask sympy
    again (time-outs are not handed on: they depend on the machine's load)."""
    return {k: v for k, v in _CACHE.items() if k not in known}


def learn_antiderivatives(entries: dict) -> None:
    for k, v in entries.items():
        _remember(_CACHE, k, v)


#: :func:`_derivative_matches`' verdicts by (F, w, variable, point): a pure function of them (its
#: random points come from a fixed seed), asked again when the same weight comes back (the other
#: branch of a delta piece, the other partial derivatives).
_MATCHES: dict = {}


def _derivative_matches(F, w, v, ctx: Context) -> bool:
    """d/dv F = w at a few pseudo-random points (parameters at ``at``): sympy's integrate has
    returned wrong antiderivatives (even 0) for symbolic constants; catch that early (remembered:
    :data:`_MATCHES`)."""
    key = (F, sp.sympify(w), v, tuple(ctx.at.items()))
    hit = _MATCHES.get(key)
    if hit is None:
        hit = _derivative_matches_here(F, w, v, ctx)
        _remember(_MATCHES, key, hit)
    return hit


def _derivative_matches_here(F, w, v, ctx: Context) -> bool:
    """:func:`_derivative_matches`' computation."""
    try:
        d = sp.diff(F, v) - w
    except Exception:  # noqa: BLE001
        return False
    syms = sorted(d.free_symbols - set(ctx.at), key=str)
    rng = random.Random(7)
    checked = 0
    for _ in range(8):
        pt = {k: sp.Float(float(x), 30) for k, x in ctx.at.items()}
        pt.update({s: sp.Float(rng.uniform(-1.5, 1.5), 30) for s in syms})
        try:
            dv = complex(d.xreplace(pt).evalf(25))
            wv = complex(sp.sympify(w).xreplace(pt).evalf(25))
            fv = complex(F.xreplace(pt).evalf(25))
        except (TypeError, ValueError, ZeroDivisionError):
            continue
        if _finite(wv) and not _finite(fv):
            return False  # singular at the evaluation point (e.g. sin(θx)/θ at θ = 0)
        if not all(map(_finite, (dv, wv))):
            continue
        if abs(dv) > 1e-9 * (1 + abs(wv)):
            return False
        checked += 1
        if checked >= 3:
            break
    return True


def _nonzero_here(k, ctx: Context) -> bool:
    """``k`` (a coefficient free of the integration variable) is not zero at the evaluation point,
    or it depends on outer variables (then, as for sympy's generic antiderivatives, only on a null
    set); :func:`_derivative_matches` makes the same test by sampling."""
    if k.free_symbols - set(ctx.at):
        return True
    try:
        return ctx.value(k) != 0
    except (TypeError, ValueError, ZeroDivisionError):
        return False


def _finite(z: complex) -> bool:
    return z == z and abs(z) != float("inf")


def antiderivative(w, v, ctx: Context):
    """A smooth antiderivative of the smooth ``w`` in ``v`` (sympy, time-boxed), or Unsupported; of
    ``P + sign(s)·Q`` (|s| of one affine s, atan2's angle and its derivative:
    :func:`elementary.sign_split`) a continuous one, smooth where s ≠ 0."""
    w = sp.sympify(w)
    if v not in w.free_symbols:
        return w * v
    if _mentions_bad(w, v):
        # (but |s| of one affine s, as the chain rule writes atan2's derivative, is sign(s)·s)
        split = elementary.sign_split(w, v) if w.has(sp.Abs) else None
        if split is None or not all(_nonzero_here(k, ctx) for k in split.divisors):
            raise Unsupported(f"weight {w} is not smooth in {v}")
        return _sign_split_antiderivative(split, w, v, ctx)
    quick = elementary.polynomial_antiderivative(w, v)
    if quick is not None:  # exact, in microseconds: never waits for sympy nor for the budget
        return quick
    for by_parts in (elementary.exponential_antiderivative, elementary.affine_power_antiderivative,
                     elementary.power_log_antiderivative):
        divisors: list = []
        quick = by_parts(w, v, divisors)  # correct by construction where no divisor vanishes
        if quick is not None and all(_nonzero_here(k, ctx) for k in divisors):
            return quick
    if _has_gaussian(w, v):
        quick = elementary.gaussian_antiderivative(w, v)  # valid for all parameter values
        if quick is not None:
            return quick
    split = elementary.sign_split(w, v)
    if split is not None and all(_nonzero_here(k, ctx) for k in split.divisors):
        return _sign_split_antiderivative(split, w, v, ctx)
    why = elementary.hopeless(w, v)
    if why:  # decided early: one short look by sympy's heuristics, then the piece's quadrature
        return _last_look(w, v, ctx, why)
    reps = _constant_symbols(w)
    back = {d: c for c, d in reps.items()}
    wa = w.xreplace(reps)  # algebraic constants as positive symbols: sympy is much faster on them
    # Generic symbols can be wrong at the constants' actual values (a discriminant that vanishes
    # only at √2): every candidate is verified by _derivative_matches below.
    attempts = [  # (attempt, whether it is sympy's full algorithm: skipped after a time-out)
        ((lambda: sp.integrate(wa, v, meijerg=False, risch=False, conds="none").xreplace(back)), False)
        if reps else (None, False),
        (lambda: sp.Add(*[sp.integrate(t, v, meijerg=False, risch=False, conds="none")
                          for t in sp.Add.make_args(w)]), False),
        (lambda: sp.integrate(w, v, conds="none"), True),
        (lambda: _gaussian_termwise(w, v), False),
        # last: keep sympy's case distinctions (∫cos(θx) = x if θ = 0) and pick the one at `at`
        (lambda: sp.integrate(w, v, conds="piecewise"), True),
    ]
    if _has_gaussian(w, v):  # sympy's general algorithms are slow and fail on shifted Gaussians
        attempts.insert(0, attempts.pop(3))
    reasons = []
    timed_out = False  # the heuristic attempts ran out of time: the full algorithm will too
    for n, (attempt, full) in enumerate(attempts):
        if attempt is None or (full and timed_out):
            continue
        key = (w, v, n)
        cap = min(ATTEMPT_CAP, max(0.0, ctx.deadline.remaining()))
        if key in _CACHE:
            F = _CACHE[key]
        elif _TIMED_OUT.get(key, -1.0) >= cap:
            reasons.append("sympy integrate timed out")
            timed_out = True
            continue
        else:
            try:
                F = ctx.deadline.run(attempt, cap=cap)
            except TimeoutError:
                reasons.append("sympy integrate timed out")
                timed_out = True
                _remember(_TIMED_OUT, key, cap)
                continue
            except Exception as exc:  # sympy raises all sorts of errors on hard inputs
                F = f"no antiderivative of {w} in {v} found: {failures.why(exc)}"
            _remember(_CACHE, key, F)
        if isinstance(F, str):
            reasons.append(F)
            continue
        try:
            F = _resolve_piecewise(F, v, ctx)
        except Unsupported as exc:
            reasons.append(str(exc))
            continue
        if _mentions_bad(F, v) or F.has(sp.zoo, sp.nan):
            reasons.append(f"no elementary antiderivative of {w} in {v}")
            continue
        if not _derivative_matches(F, w, v, ctx):
            reasons.append(f"sympy's antiderivative of {w} in {v} fails d/d{v} F = w")
            continue
        return F
    raise Unsupported("; ".join(dict.fromkeys(reasons)) or f"no antiderivative of {w}")


def _sign_split_antiderivative(split: elementary.SignSplit, w, v, ctx: Context):
    """An antiderivative of ``P + sign(s)·Q`` (:func:`elementary.sign_split`: atan2's angle of an
    affine ``y`` and its derivative): ``∫P + sign(s)·(G − G(s = 0))`` with ``G = ∫Q``, continuous
    across s = 0 (so ``F(b) − F(a)`` holds on any interval, across s = 0 or ending on it) and of
    derivative ``P + sign(s)·Q`` wherever s ≠ 0; P and Q are smooth and integrated as any weight.
    Unsupported when G is not finite at s = 0; checked by differentiation like sympy's answers."""
    G = antiderivative(split.Q, v, ctx)
    zero = v - split.s  # (s = v + d)
    at_zero = G.xreplace({v: zero})
    if at_zero.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
        raise Unsupported(f"no antiderivative of {split.Q} in {v} finite at {v} = {zero}")
    F = antiderivative(split.P, v, ctx) + sp.sign(split.s) * (G - at_zero)
    if not _derivative_matches(F, w, v, ctx):
        raise Unsupported(f"the antiderivative {F} of {w} in {v} fails d/d{v} F = w")
    return F


#: Seconds sympy's heuristics may spend on a weight :func:`elementary.hopeless` gave up on: a sum
#: of non-elementary terms can still have an elementary antiderivative (eˣ/x − eˣ/x² = (eˣ/x)'),
#: which sympy finds quickly when it does.
LAST_LOOK = 0.25


def _last_look(w, v, ctx: Context, why: str):
    key = (w, v, "last look")
    F = _CACHE.get(key)
    if F is None:
        cap = min(LAST_LOOK, max(0.0, ctx.deadline.remaining()))
        if _TIMED_OUT.get(key, -1.0) >= cap:
            raise Unsupported(why)
        try:
            F = ctx.deadline.run(lambda: sp.integrate(w, v, risch=False, meijerg=False, conds="none"), cap=cap)
            _remember(_CACHE, key, F)
        except TimeoutError:  # remembered with the time it had, like every attempt's
            _remember(_TIMED_OUT, key, cap)
            raise Unsupported(why) from None
        except Exception:  # noqa: BLE001 - sympy raises all sorts of errors on hard inputs
            F = why
            _remember(_CACHE, key, F)
    if isinstance(F, str) or _mentions_bad(F, v) or F.has(sp.zoo, sp.nan) or not _derivative_matches(F, w, v, ctx):
        raise Unsupported(why)
    return F
