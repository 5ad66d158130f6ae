"""Exact integration of ``Π [cond ≥ 0] · weight`` over a box by iterated integration (paper §6.3,
Def. 6.1–6.2; LANGUAGE.md §3–§4).

Regions are computed from the conditions, never by handing Piecewise/Heaviside/Min/Max to sympy's
``integrate`` (sympy 1.14 gets those wrong: #26071, #21426, #28091, #17321).  sympy only ever
integrates a SMOOTH weight in one variable (:func:`antiderivative`), time-boxed, and the bounds are
substituted afterwards.

* Each condition involving the integration variable ``v`` is solved for ``v`` into alternatives
  ``(extra conditions on the other symbols, lower bounds, upper bounds)``
  (:func:`alternatives`): linear and quadratic polynomials in ``v`` exactly, a Psi solved for ``v``
  with one branch through its inverse (a diffeomorphism's condition is monotone in ``v``).  A
  direction (sign of the derivative) that depends on parameters only is decided at the
  evaluation point; one that depends on outer variables becomes a case split.
* Innermost variables: ``v ∈ [max L, min U]`` is split into the cases "``l`` is the largest lower
  and ``u`` the smallest upper bound"; each case adds the comparisons as conditions on the outer
  variables and integrates ``F(u) − F(l)``, a smooth function with plain bounds.
* Outermost variable (only parameters left): ``F(Max(A, B)) − F(A)`` with ``A = Max(L)``,
  ``B = Min(U)`` — valid for all parameter values, e.g. ``∫₀¹[θ − x ≥ 0] = Max(0, Min(1, θ))``.
  Conditions that cannot be solved that way (several branches, transcendental) are handled by
  :func:`_generic_1d`: all roots, ordered at the evaluation point, sign of every condition on each
  sub-interval decided there.
* Every comparison of parameter-only quantities is decided at the evaluation point ``at`` and
  recorded in :attr:`Context.cell`: the closed form is valid in the parameter cell they define.
"""

from __future__ import annotations

import itertools
import math
import random
from dataclasses import dataclass, field
from typing import Sequence

import mpmath
import sympy as sp

from langur.implicit import unsolvable
from langur.symbolic import elementary, local, rational
from langur.symbolic.pieces import Psi
from langur.symbolic.text import math_lambdify, shared_lambdify
from langur.timebox import Deadline


class Unsupported(Exception):
    """No closed form by this method; the caller falls back to quadrature."""


@dataclass(frozen=True)
class Cond:
    """``expr ≥ 0`` (``expr > 0`` when ``strict``; strictness only matters for parameter-only
    comparisons, where it breaks ties between case splits)."""

    expr: sp.Expr
    strict: bool = False
    psi: Psi | None = None


#: The point's values as 40-digit Floats, by point (:meth:`Context.value` substitutes them in
#: every expression it evaluates: building them again each time was a third of its time).
_FLOATS40: dict = {}


def _floats40(at: dict) -> dict:
    key = tuple(at.items())
    out = _FLOATS40.get(key)
    if out is None:
        out = {k: sp.Float(float(v), 40) for k, v in at.items()}
        _remember(_FLOATS40, key, out, 64)
    return out


#: :meth:`Context.value`'s results by (expression, point): the same roots, bounds and relations are
#: evaluated again for ⟦p⟧, ⦇p⦈'s pieces and the check (a third of raytrace ∂/∂t's evaluations are
#: repeats).  sympy's equality tells Floats of different precisions apart, so a key is exact.
_VALUES: dict = {}
VALUES = 4096


#: :func:`_canonical`'s answers by (kind, expression): the same coefficients' signs are recorded
#: for each case of a decomposition and again for other partial derivatives.
_CANONICAL: dict = {}


def _canonical(rel_kind: str, expr) -> tuple:
    """``(p, p ⋈ 0)``: ``expr`` expanded, its positive content divided out (remembered)."""
    key = (rel_kind, sp.sympify(expr))
    out = _CANONICAL.get(key)
    if out is None:
        _, p = sp.expand(expr).as_content_primitive()
        out = (p, {">": sp.StrictGreaterThan, ">=": sp.GreaterThan, "=": sp.Eq}[rel_kind](p, 0))
        _remember(_CANONICAL, key, out)
    return out


class Deferred:
    """A weight made only when the integration needs it (``make()``, called once): a delta piece's
    weight holds sympy's determinant and simplification of det DΨ̂⁻¹ (a fifth of a second for the
    ray tracer's), which a region found empty at the evaluation point never uses.  The maker of one
    promises that the weight is not 0 (so ``weight == 0`` is rightly false for it); it stays
    unmade only in one variable where the conditions alone are large (:func:`_outermost`): the
    weight's size, which else chooses the method, does not matter there, and :func:`_generic_1d`
    asks for it only to integrate a non-empty interval.  Everywhere else it is made at once."""

    __slots__ = ("_make", "_made")

    def __init__(self, make):
        self._make, self._made = make, None

    def made(self) -> sp.Expr:
        if self._made is None:
            self._made = sp.sympify(self._make())
        return self._made


def _made(weight):
    """``weight``, a :class:`Deferred` one made."""
    return weight.made() if isinstance(weight, Deferred) else weight


@dataclass
class Context:
    """Evaluation point, time budget and the decisions taken at the evaluation point."""

    at: dict
    deadline: Deadline
    params: frozenset = frozenset()
    cell: list = field(default_factory=list)
    generic: bool = False  # the generic 1-D path was used (cell also fixes the set of real roots)
    notes: list = field(default_factory=list)
    inconsistent: list = field(default_factory=list)  # closed forms that failed the cross-check

    def value(self, expr) -> complex:
        """``expr`` at the point with 30 digits (40-digit floats substituted), as a complex;
        remembered per (expression, point) (:data:`_VALUES`)."""
        return self.value_with(expr, {})

    def value_with(self, expr, numbers: dict) -> complex:
        """:meth:`value` of ``expr.xreplace(numbers)`` (``numbers``: symbols → sympy Floats), in
        one substitution: the tree is rebuilt once, from numbers only, instead of once with the
        floats ``numbers`` among the parameters' symbols (sympy's products and sums of symbolic
        terms, their assumptions) and again with the point's floats; remembered likewise."""
        expr = sp.sympify(expr)
        key = (expr, tuple(numbers.items()), tuple(self.at.items()))
        z = _VALUES.get(key)
        if z is None:
            e = expr.xreplace({**_floats40(self.at), **numbers})
            try:
                z = complex(e.evalf(30))
            except TypeError:
                raise ValueError(f"no value for {sorted(map(str, e.free_symbols))} in {expr}") from None
            _remember(_VALUES, key, z, VALUES)
        return z

    def exact_value(self, expr) -> complex:
        """:meth:`value` with the point's rational values substituted exactly (then evaluated to 30
        digits): a closed form's value at the point.  With 40-digit floats substituted, a closed
        form that is exactly 0 there came out as cancellation noise (Fig. 14's pixel at the
        origin: −2⁻¹²⁶ ≈ −1.17549435082e-38)."""
        exact = {k: v for k, v in self.at.items() if isinstance(v, sp.Rational)}
        expr = sp.sympify(expr)
        if exact and local.size(expr, local.LARGE_OPS) >= local.LARGE_OPS:
            q = rational.rational_value(expr, exact)  # a large rational form: Fractions, not sympy's nodes
            if q is not None:
                return complex(q)
        return self.value(expr.xreplace(exact) if exact else expr)

    def record(self, rel_kind: str, expr) -> None:
        """Add ``expr > 0`` / ``expr >= 0`` / ``expr = 0`` to the cell, canonically (positive
        content divided out, so ``4*a + 4 > 0`` and ``-a - 1 < 0`` are one entry)."""
        p, rel = _canonical(rel_kind, expr)
        if rel_kind == "=" and sp.Eq(-p, 0) in self.cell:
            return
        if rel not in (sp.true, sp.false) and rel not in self.cell:
            self.cell.append(rel)

    def record_relation(self, rel) -> None:
        if isinstance(rel, sp.Rel) and rel.rel_op in (">", "<", ">=", "<="):
            d = rel.lhs - rel.rhs if rel.rel_op[0] == ">" else rel.rhs - rel.lhs
            self.record(">" if len(rel.rel_op) == 1 else ">=", d)
        elif isinstance(rel, sp.Not) and isinstance(rel.args[0], sp.Rel):
            self.record_relation(rel.args[0].negated)
        elif rel not in self.cell:
            self.cell.append(rel)

    def decide(self, expr, strict: bool = False) -> bool:
        """``expr ≥ 0`` (``> 0``) for a parameter-only ``expr``, at the evaluation point; recorded."""
        expr = sp.sympify(expr)
        if expr.is_number:
            return self._decide_number(expr, strict)
        v = self.value(expr)
        if abs(v.imag) > 1e-20 * max(1.0, abs(v.real)):
            raise Unsupported(f"complex value of {expr} at the evaluation point")
        x = v.real
        if abs(x) < 1e-25:
            self.record("=", expr)
            return not strict
        self.record(">", expr if x > 0 else -expr)
        return x > 0

    def _decide_number(self, expr, strict: bool) -> bool:
        if expr.is_zero:
            return not strict
        if expr.is_extended_real is False:
            raise Unsupported(f"complex number {expr}")
        pos = expr.is_positive
        if pos is None:
            v = complex(expr.evalf(40))
            if abs(v.imag) > 1e-30:
                raise Unsupported(f"complex number {expr}")
            return v.real > 0 or (v.real == 0 and not strict)
        return bool(pos)

    def sign(self, expr) -> int:
        """Sign of a parameter-only expression at the evaluation point (recorded)."""
        if self.decide(expr, strict=True):
            return 1
        if self.decide(-expr, strict=True):
            return -1
        raise Unsupported(f"{expr} vanishes at the evaluation point")


# ------------------------------------------------------------------------------------------
# Antiderivatives of smooth weights.

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


def _remember(cache: dict, key, value, size: int = 2048) -> None:
    """``cache[key] = value``, the oldest entry dropped beyond ``size``."""
    if len(cache) >= size:
        cache.pop(next(iter(cache)))
    cache[key] = value


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
    """A smooth antiderivative of the smooth ``w`` in ``v`` (sympy, time-boxed), or Unsupported."""
    w = sp.sympify(w)
    if v not in w.free_symbols:
        return w * v
    if _mentions_bad(w, v):
        raise Unsupported(f"weight {w} is not smooth in {v}")
    quick = elementary.polynomial_antiderivative(w, v)
    if quick is not None:  # exact, in microseconds: never waits for sympy nor for the budget
        return quick
    for by_parts in (elementary.exponential_antiderivative, elementary.affine_power_antiderivative):
        divisors: list = []
        quick = by_parts(w, v, divisors)  # correct by construction where no divisor vanishes
        if quick is not None and all(_nonzero_here(k, ctx) for k in divisors):
            return quick
    if _has_gaussian(w, v):
        quick = elementary.gaussian_antiderivative(w, v)  # valid for all parameter values
        if quick is not None:
            return quick
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
                F = f"sympy integrate failed: {type(exc).__name__}"
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


# ------------------------------------------------------------------------------------------
# Solving one condition for one variable.


@dataclass
class Alt:
    extra: list  # Conds free of v
    lowers: list  # v ≥ each
    uppers: list  # v ≤ each


def _direction(d, v, outer, ctx: Context, root) -> list[Alt]:
    """Half-line(s) for a condition with one root ``root`` whose derivative in v has sign of d."""
    d = sp.sympify(d)
    if not (d.free_symbols & set(outer)):
        s = ctx.sign(d)
        return [Alt([], [root], [])] if s > 0 else [Alt([], [], [root])]
    return [Alt([Cond(d, strict=True)], [root], []), Alt([Cond(-d)], [], [root])]


#: :func:`_polynomial_roots`' answers by (expression, variable).
_POLY_ROOTS: dict = {}


def _polynomial_roots(e, v):
    """For ``e`` a polynomial of degree 1 in ``v`` (coefficients free of it): ``(a, −b/a)`` (its
    leading coefficient and root, cancelled); of degree 2: ``(a, disc, r₋, r₊)`` (the roots
    (−b ∓ √disc)/2a); else None.  :func:`alternatives`' formulas, remembered by (expression,
    variable), of which they are a pure function: the same conditions come back in each case
    split and for each partial derivative; what depends on the point is decided after."""
    key = (e, v)
    if key in _POLY_ROOTS:
        return _POLY_ROOTS[key]
    poly = None
    try:
        poly = sp.Poly(e, v)
        if any(v in k.free_symbols for k in poly.all_coeffs()):
            poly = None
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        poly = None
    out = None
    if poly is not None and poly.degree() == 1:
        a, b = poly.all_coeffs()
        out = (a, sp.cancel(-b / a))
    elif poly is not None and poly.degree() == 2:
        a, b, d = poly.all_coeffs()
        disc = sp.expand(b**2 - 4 * a * d)
        out = (a, disc, (-b - sp.sqrt(disc)) / (2 * a), (-b + sp.sqrt(disc)) / (2 * a))
    _remember(_POLY_ROOTS, key, out)
    return out


def alternatives(c: Cond, v, outer, ctx: Context) -> list[Alt]:
    """``[c ≥ 0]`` as a disjoint union (up to null sets) of intervals in ``v``."""
    e = c.expr
    solved = _polynomial_roots(e, v)
    if solved is not None and len(solved) == 2:
        a, root = solved
        return _direction(a, v, outer, ctx, root)
    if solved is not None:
        a, disc, r_minus, r_plus = solved
        if a.free_symbols & set(outer):
            raise Unsupported("quadratic with a variable leading coefficient")
        if ctx.sign(a) < 0:  # c ≥ 0 between the roots
            return [Alt([Cond(disc)], [r_plus], [r_minus])]
        return [Alt([Cond(-disc, strict=True)], [], []),
                Alt([Cond(disc)], [], [r_minus]), Alt([Cond(disc)], [r_plus], [])]
    psi = c.psi
    if psi is not None and psi.solved_for == v and len(psi.branches) == 1 and not psi.branches[0].guards:
        sub = {psi.inputs[0]: sp.Integer(0)}
        sub.update(dict(zip(psi.inputs[1:], [x for x in psi.variables if x != v])))
        comp = dict(psi.branches[0].inverse)[v]
        root = comp.xreplace(sub)
        d = sp.diff(comp, psi.inputs[0]).xreplace(sub)
        return _direction(d, v, outer, ctx, root)
    raise Unsupported(f"cannot solve {e} >= 0 for {v} in closed form")


# ------------------------------------------------------------------------------------------
# Iterated integration.


def _dedupe(bounds):
    """``bounds`` without repeats: ``b`` is dropped when ``expand(b − o) == 0`` for a bound ``o``
    kept before it.  Two bounds with different exact values at one rational point
    (:func:`_rational_probe`) are not repeats, and are not expanded (expanding the difference of
    two large bounds costs tens of milliseconds); the expansion decides the rest, as before."""
    out, values = [], []
    for b in bounds:
        vb = _rational_probe(b)
        if not any((vb is None or vo is None or vb == vo) and sp.expand(b - o) == 0
                   for o, vo in zip(out, values)):
            out.append(b)
            values.append(vb)
    return out


def _rational_probe(e):
    """``e``'s exact value (a sympy Rational) with each symbol replaced by a fixed rational of its
    own (from its name), or None when that is not a rational number (a root, a pole)."""
    e = sp.sympify(e)
    z = e.xreplace(_probe_point(local.free_symbols(e)))
    return z if z.is_Rational else None


def _probe_point(symbols) -> dict:
    """:func:`_rational_probe`'s point: each symbol a fixed rational of its own (from its name)."""
    point = {}
    for s in symbols:
        q = _PROBE_RATIONALS.get(s.name)
        if q is None:
            q = _PROBE_RATIONALS[s.name] = sp.Rational(random.Random(s.name).randint(10**5, 10**6), 999983)
        point[s] = q
    return point


#: :func:`_rational_probe`'s value of each symbol, by name.
_PROBE_RATIONALS: dict = {}


def _prefilter(conds, ctx: Context):
    """Drop conditions true at ``at`` (parameter-only) or numerically true; None if one is false."""
    kept = []
    for c in conds:
        e = sp.sympify(c.expr)
        if not (e.free_symbols - ctx.params):
            if not ctx.decide(e, c.strict):
                return None
            continue
        kept.append(c)
    return kept


def integrate_vars(conds, weight, variables: Sequence, box: dict, ctx: Context):
    """∫ over ``box`` of Π conds · weight in ``variables`` (innermost last); params decided at at."""
    conds = _prefilter(conds, ctx)
    if conds is None:
        return sp.Integer(0)
    if not variables:
        return _made(weight)
    if weight == 0:  # (a Deferred weight is not 0)
        return sp.Integer(0)
    v, outer = variables[-1], list(variables[:-1])
    dep = [c for c in conds if v in c.expr.free_symbols]
    rest = [c for c in conds if v not in c.expr.free_symbols]
    lo, hi = box[v]
    if not outer:
        if rest:
            raise Unsupported("condition on a variable outside the integration order")
        return _outermost(dep, weight, v, lo, hi, ctx)
    weight = _made(weight)
    F = None  # computed on first use: empty cases need no antiderivative
    total = sp.Integer(0)
    for combo in itertools.product(*[alternatives(c, v, outer, ctx) for c in dep]):
        extra = [x for alt in combo for x in alt.extra]
        L = _dedupe([lo] + [b for alt in combo for b in alt.lowers])
        U = _dedupe([hi] + [b for alt in combo for b in alt.uppers])
        for i, l in enumerate(L):
            for j, u in enumerate(U):
                new = [Cond(l - l2, strict=k < i) for k, l2 in enumerate(L) if k != i]
                new += [Cond(u2 - u, strict=k < j) for k, u2 in enumerate(U) if k != j]
                new.append(Cond(u - l))
                case = _prefilter(extra + new, ctx)
                if case is None:
                    continue
                if F is None:
                    F = antiderivative(weight, v, ctx)
                g = F.xreplace({v: u}) - F.xreplace({v: l})
                total += integrate_vars(rest + case, g, outer, box, ctx)
    return total


#: sympy's Max/Min of symbolic bounds by their arguments: building one compares every pair of
#: arguments (seconds on a campaign's program), and the same bounds come back for the value, each
#: partial derivative and the checks.
_EXTREMA: dict = {}


def _extremum(fn, args):
    """``fn(*args)`` (``sp.Max`` or ``sp.Min``), remembered."""
    key = (fn, tuple(args))
    out = _EXTREMA.get(key)
    if out is None:
        out = fn(*args)
        _remember(_EXTREMA, key, out)
    return out


def _outermost(conds, weight, v, lo, hi, ctx: Context):
    """Last variable: ``F(Max(A, B)) − F(A)`` per alternative, else the generic 1-D method (at
    once for large conditions: their Max/Min nests cost minutes, :mod:`langur.symbolic.local`).
    A :class:`Deferred` weight stays unmade when the conditions alone are large (then so are the
    conditions with any weight)."""
    exprs = [c.expr for c in conds]
    if isinstance(weight, Deferred) and not local.is_large(exprs, ctx.params):
        weight = weight.made()
    if isinstance(weight, Deferred) or local.is_large(exprs + [sp.sympify(weight)], ctx.params):
        return _generic_1d(conds, weight, v, lo, hi, ctx)
    sub = Context(ctx.at, ctx.deadline, ctx.params)
    try:
        alts = [alternatives(c, v, [], sub) for c in conds]
        F = None
        total = sp.Integer(0)
        for combo in itertools.product(*alts):
            extra = _prefilter([x for alt in combo for x in alt.extra], sub)
            if extra is None:
                continue
            A = _extremum(sp.Max, _dedupe([lo] + [b for alt in combo for b in alt.lowers]))
            B = _extremum(sp.Min, _dedupe([hi] + [b for alt in combo for b in alt.uppers]))
            top = _extremum(sp.Max, (A, B))
            if top == A:
                continue  # empty for every parameter value
            if F is None:
                F = antiderivative(weight, v, sub)
            total += F.xreplace({v: top}) - F.xreplace({v: A})
        ctx.cell.extend(r for r in sub.cell if r not in ctx.cell)
        return total
    except Unsupported:
        return _generic_1d(conds, weight, v, lo, hi, ctx)


#: sympy's solutions (unchecked: each call checks them at its own evaluation point) per condition
#: and variable.
_SOLVED: dict = {}


def _roots(c: Cond, v, ctx: Context, tidy: bool = True):
    """The real roots of ``c`` in ``v`` at the evaluation point (checked there); ``tidy``: sympy's
    solutions simplified (as they appear in closed forms), else as ``solve`` finds them without
    its ``simplify`` pass (the same roots, several times cheaper: enough to learn where they are)."""
    psi = c.psi
    if psi is not None and psi.solved_for == v and psi.branches:
        sub = {psi.inputs[0]: sp.Integer(0)}
        out = []
        for b in psi.branches:
            if all(ctx.decide(g.xreplace(sub)) for g in b.guards):
                out.append(dict(b.inverse)[v].xreplace(sub))
        return out
    # check=False: sympy's own check drops roots whose validity depends on a parameter's sign
    # (yu + sqrt(r² − x²) = 0 has the roots ±sqrt(r² − yu²) exactly when yu ≤ 0); each candidate
    # is checked at the evaluation point instead, which is where the closed form is valid.
    key = (c.expr, v, tidy)
    sols = _SOLVED.get(key)  # the same conditions come back for ⟦p⟧, each ⦇p⦈ and the checks
    if sols is None:
        try:
            sols = ctx.deadline.run(lambda: _solve(c.expr, v, tidy), cap=max(2.0, ctx.deadline.seconds / 4))
        except TimeoutError:
            raise Unsupported(f"solving {c.expr} = 0 for {v} timed out") from None
        except (NotImplementedError, ValueError, TypeError) as exc:
            raise Unsupported(f"cannot solve {c.expr} = 0 for {v}: {' '.join(str(exc).split())}") from None
        _remember(_SOLVED, key, sols)
    if not isinstance(sols, list):
        raise Unsupported(f"infinitely many roots of {c.expr} in {v}")
    return [r for r in sols if not isinstance(r, (dict, tuple)) and _vanishes_at(c.expr, v, r, ctx)]


def _solve(expr, v, tidy: bool):
    """sympy's ``solve`` as :func:`_roots` asks it, or its failure when it is known from the shape
    (:func:`langur.implicit.unsolvable`: 0.1–0.2 s saved each time, the same message)."""
    known = unsolvable(expr, v)
    if known is not None:
        raise NotImplementedError(known)
    return sp.solve(expr, v, dict=False, check=False, simplify=tidy)


#: :func:`_closed_roots` and :func:`_vanishes_at` by (condition, variable[, root], point): the same
#: conditions come back at the same point for ⟦p⟧ (the check), ⦇p⦈'s regular and delta pieces.
_CLOSED_ROOTS: dict = {}
_VANISHES: dict = {}


def _closed_roots(c: Cond, v, ctx: Context):
    """The roots, and the poles, of a condition (one of a large problem's) whose numerator and
    denominator are of degree ≤ 2 in ``v`` (:func:`local.closed_roots`), the roots checked at the
    evaluation point; None when it is not of that shape."""
    if c.psi is not None:
        return None
    key = (c.expr, v, tuple(ctx.at.items()))
    if key in _CLOSED_ROOTS:
        out = _CLOSED_ROOTS[key]
        return None if out is None else list(out)
    found = local.closed_roots(c.expr, v, ctx.value)
    out = None
    if found is not None:
        roots, poles = found
        out = [r for r in roots if _vanishes_at(c.expr, v, r, ctx)] + list(poles)
    _remember(_CLOSED_ROOTS, key, None if out is None else tuple(out))
    return out


def _vanishes_at(expr, v, root, ctx: Context) -> bool:
    """``expr`` is zero at ``v = root`` at the evaluation point (a true root there, not one that
    only an unchecked solution formula gives)."""
    key = (expr, v, root, tuple(ctx.at.items()))
    hit = _VANISHES.get(key)
    if hit is None:
        hit = _VANISHES[key] = _vanishes_at_point(expr, v, root, ctx)
        if len(_VANISHES) > 2048:
            _VANISHES.pop(next(iter(_VANISHES)))
    return hit


def _vanishes_at_point(expr, v, root, ctx: Context) -> bool:
    try:
        z = ctx.value(root)
        if abs(z.imag) > 1e-12 * max(1.0, abs(z.real)):
            return False
        residual = ctx.value_with(expr, {v: sp.Float(z.real, 40)})
    except (TypeError, ValueError, ZeroDivisionError):
        return False
    return abs(residual) <= 1e-9 * max(1.0, abs(z.real))


def _away_from_zero(c: Cond, v, lo: float, hi: float, ctx: Context) -> bool:
    """Whether ``c.expr`` = e + k·√A (e, k free of ``v``, A a polynomial of degree 1 or 2 in ``v``;
    no Psi solved for ``v``) stays away from 0 on [lo, hi] at the evaluation point, by far more
    than :func:`_vanishes_at_point`'s tolerance: then no root sympy's ``solve`` gives passes that
    check and :func:`_inside` (lo, hi), and solving is not needed to know it (a quadratic
    condition's roots compared with the box: √(4r² − 4x²)/2 − 1 ≥ 0 for the disc of radius r).
    |e + k√A| ≥ |e| where A < 0 (k√A imaginary) and where k√A has e's sign; else
    ≥ |e| − |k|·√(max A)."""
    psi, expr = c.psi, c.expr
    if psi is not None and psi.solved_for == v and psi.branches:
        return False
    shape = _root_shape(expr, v)
    if shape is None:
        return False
    e, k, coeffs = shape
    try:
        nums = [ctx.value(x) for x in [e, k, *coeffs]]
    except (TypeError, ValueError, ZeroDivisionError):
        return False
    if any(abs(z.imag) > 1e-20 * max(1.0, abs(z.real)) for z in nums):
        return False
    e_v, k_v, *a = [z.real for z in nums]
    if k_v == 0:
        return False
    bound = abs(e_v)
    if e_v * k_v <= 0:
        def at(x):
            return sum(ak * x ** (len(a) - 1 - i) for i, ak in enumerate(a))
        tops = [at(lo), at(hi)]
        if len(a) == 3 and a[0] < 0 and lo < -a[1] / (2 * a[0]) < hi:
            tops.append(at(-a[1] / (2 * a[0])))
        if max(tops) > 0:
            bound = abs(e_v) - abs(k_v) * max(tops) ** 0.5
    return bound > 1e-6 * max(1.0, abs(lo), abs(hi), abs(e_v))


#: :func:`_root_shape`'s answers by (expression, variable).
_ROOT_SHAPES: dict = {}


def _root_shape(expr, v):
    """``(e, k, [A's coefficients])`` when ``expr`` = e + k·√A with e, k free of ``v`` and A a
    polynomial of degree 1 or 2 in ``v``, else None (:func:`_away_from_zero`'s shape); remembered
    by (expression, variable), of which it is a pure function (the same conditions come back in
    each case split of ⟦p⟧ and each branch of a delta piece)."""
    key = (expr, v)
    if key in _ROOT_SHAPES:
        return _ROOT_SHAPES[key]
    out = None
    with_v = [t for t in expr.args if v in t.free_symbols] if isinstance(expr, sp.Add) else []
    roots = [f for f in sp.Mul.make_args(with_v[0]) if v in f.free_symbols] if len(with_v) == 1 else []
    if len(roots) == 1 and isinstance(roots[0], sp.Pow) and roots[0].exp == sp.S.Half:
        try:
            poly = sp.Poly(roots[0].base, v)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            poly = None
        if poly is not None:
            coeffs = poly.all_coeffs()
            if poly.degree() in (1, 2) and not any(v in a.free_symbols for a in coeffs):
                e = sp.Add(*[t for t in expr.args if v not in t.free_symbols])
                k = sp.Mul(*[f for f in sp.Mul.make_args(with_v[0]) if v not in f.free_symbols])
                out = (e, k, coeffs)
    _remember(_ROOT_SHAPES, key, out)
    return out


#: How far (relative) a root's 30-digit value must be from every double's rounding boundary, from
#: the interval's ends and from the imaginary-part thresholds for :func:`_only_repeats` to vouch
#: for the double of another form of it: sympy's ``evalf(30)`` of two forms of one number agree
#: to ~1e-30 of it, ten orders of magnitude inside this margin.
REPEAT_MARGIN = 1e-20


def _only_repeats(expr, v, lo: float, hi: float, known: set, ctx: Context) -> bool:
    """Whether every root of the condition ``expr`` that :func:`_generic_1d` would add with the tidy
    solve (sympy's ``solve`` with its ``simplify`` pass) is certainly a repeat of a point already
    there (a double in ``known``), so that the tidy solve — most of ``solve``'s time — cannot
    change anything; from sympy's untidy solutions, which must be known (:data:`_SOLVED`).

    The tidy solutions are the untidy ones simplified (:func:`_roots`: the same numbers; that is
    what :func:`_generic_1d` already relies on when no untidy root is inside).  Each untidy
    candidate's value is taken with 30 digits, and it must be, by :data:`REPEAT_MARGIN` relative,
    either clearly not real (then no form of it passes :func:`_vanishes_at_point`), or clearly
    outside ``[lo, hi]`` (then no form of it is :func:`_inside`), or a real number whose double
    is certain — farther than the margin from both rounding boundaries around it — and is one of
    ``known``.  Such a number's other forms have the same double, so the tidy root would be
    sorted right after the point already there and dropped as its repeat (whatever else is kept,
    a repeat with an equal double placed after its twin is dropped when its twin is, or is not:
    it is compared with the same last kept point)."""
    sols = _SOLVED.get((expr, v, False))
    if not isinstance(sols, list) or not sols:
        return False
    floats = _floats40(ctx.at)
    for s in sols:
        if isinstance(s, (dict, tuple)):
            return False
        try:
            z = sp.sympify(s).xreplace(floats).evalf(30)
            re, im = (mpmath.mpmathify(part) for part in z.as_real_imag())
        except (TypeError, ValueError, AttributeError):
            return False
        if not (mpmath.isfinite(re) and mpmath.isfinite(im)):
            return False
        size = max(1, abs(re))
        if abs(im) > 1e-9 * size:
            continue  # not real: every form of it fails the 1e-12 test of _vanishes_at_point
        if abs(im) > REPEAT_MARGIN * size:
            return False  # (nearly real: leave it to the tidy solve)
        margin = REPEAT_MARGIN * size
        if re < lo - margin or re > hi + margin:
            continue  # outside: no form of it is inside (lo, hi)
        d = float(re)
        if d not in known or d == 0.0:
            return False
        below, above = math.nextafter(d, -math.inf), math.nextafter(d, math.inf)
        with mpmath.workprec(200):  # (the midpoints of doubles are exact at 200 bits)
            if not (re - (mpmath.mpf(d) + mpmath.mpf(below)) / 2 > margin
                    and (mpmath.mpf(d) + mpmath.mpf(above)) / 2 - re > margin):
                return False
    return True


def _radicand(c: Cond, v, seen: set):
    """``P`` when ``c.expr`` is k·√P with k a positive rational, ``P`` a polynomial of degree 1 or 2
    in ``v`` (coefficients free of it) and ``P`` the expression of a condition whose roots
    :func:`_generic_1d` has already placed (``seen``); None otherwise.  The real zeros of k·√P are
    those of P, and sympy's ``solve`` of k·√P finds P's (it squares the radical away: checked on
    the examples' and random conditions, proofs_tests/test_exact_speed15r.py), so with P's roots
    certain repeats (:func:`_only_repeats`) so are those of k·√P: neither solve can change the
    points (the √(4r² − 4x²) ≥ 0 of the disc's ⟦p⟧, the width of its inner interval)."""
    if c.psi is not None:
        return None
    k, root = c.expr.as_coeff_Mul()
    if not (k.is_Rational and k > 0 and isinstance(root, sp.Pow) and root.exp == sp.S.Half):
        return None
    base = root.base
    if base not in seen:
        return None
    try:
        poly = sp.Poly(base, v)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if poly.degree() not in (1, 2) or any(v in a.free_symbols for a in poly.all_coeffs()):
        return None
    return base


#: Points per sub-interval at which :func:`_no_missed_root` looks for a sign change.
MISSED_ROOT_PROBES = 8


def _inside(r, lo: float, hi: float, ctx: Context) -> bool:
    """The root ``r`` is real and strictly between ``lo`` and ``hi`` at the evaluation point."""
    z = ctx.value(r)
    return abs(z.imag) <= 1e-12 * max(1.0, abs(z.real)) and lo < z.real < hi


#: Compiled (float) conditions by (expression, variable, parameters), for the sign probes.
_PROBES: dict = {}
#: A probe's float value at most this large (absolute) is recomputed with 30 digits.
PROBE_DOUBT = 1e-6


def _probe(expr, v, m: float, ctx: Context) -> complex | None:
    """``expr`` at ``v = m`` at the evaluation point, for a sign: in floats (compiled once per
    condition), recomputed with 30 digits (:meth:`Context.value`) when the float is within
    :data:`PROBE_DOUBT` of 0, not finite or not real; None where it is undefined."""
    params = _probe_parameters(expr, ctx)
    key = (expr, v, params)
    fn = _PROBES.get(key)
    if fn is None:
        try:
            fn = math_lambdify((v, *params), expr)  # (shared subtrees printed once)
        except Exception:  # noqa: BLE001 - anything math cannot print: the exact path only
            fn = False
        _remember(_PROBES, key, fn)
    if fn is not False:
        try:
            x = float(fn(m, *[float(ctx.at[k]) for k in params]))
            if abs(x) > PROBE_DOUBT and x == x and abs(x) != float("inf"):
                return complex(x)
        except (ValueError, ZeroDivisionError, OverflowError, TypeError, NameError):
            pass
    z = _nonreal_probe(expr, v, m, params, ctx)
    if z is not None:
        return z
    try:
        return ctx.value(expr.xreplace({v: sp.Float(m, 40)}))
    except (TypeError, ValueError, ZeroDivisionError):
        return None


#: :func:`_probe_parameters`' answers by (expression, the point's symbols).
_PARAMETERS: dict = {}


def _probe_parameters(expr, ctx: Context) -> tuple:
    """The point's symbols that ``expr`` holds, sorted by name: a probe's arguments after the
    variable; remembered by (expression, the point's symbols) — a pure function of the key —
    instead of a walk of the expression at each of the 8 probes per sub-interval."""
    key = (expr, tuple(ctx.at))
    out = _PARAMETERS.get(key)
    if out is None:
        free = local.free_symbols(expr)
        out = tuple(sorted((k for k in ctx.at if k in free), key=str))
        _remember(_PARAMETERS, key, out)
    return out


#: The sign probes' mpmath functions, by the key of :data:`_PROBES`.
_MP_PROBES: dict = {}


def _nonreal_probe(expr, v, m: float, params: tuple, ctx: Context) -> complex | None:
    """:func:`_probe`'s value when it is clearly not real (a square root or logarithm of a
    negative number: the float function's domain error), from a compiled mpmath function with
    40 digits and the same inputs as :meth:`Context.value`'s (the doubles of the point, and ``m``):
    an imaginary part above 1e-15 of the value's size, where the 30-digit evaluation differs by
    ~1e-30 of it, so that its imaginary part is above the 1e-20 under which the probes' callers
    take a value as real — they use a probe only to ask whether it is real and, if so, its sign.
    None otherwise (then the 30-digit evaluation, as before)."""
    key = (expr, v, params)
    fn = _MP_PROBES.get(key)
    if fn is None:
        try:
            fn = shared_lambdify([v, *params], expr, "mpmath")
        except Exception:  # noqa: BLE001 - anything mpmath cannot print: the 30-digit path only
            fn = False
        _remember(_MP_PROBES, key, fn)
    if fn is False:
        return None
    try:
        with mpmath.workdps(40):
            z = complex(fn(mpmath.mpf(m), *[mpmath.mpf(float(ctx.at[k])) for k in params]))
    except Exception:  # noqa: BLE001 - undefined there, or not a number: the 30-digit path decides
        return None
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        return None
    return z if abs(z.imag) > 1e-15 * max(1.0, abs(z.real)) else None


def _no_missed_root(conds, v, a: float, b: float, ctx: Context) -> None:
    """No condition changes sign strictly between two consecutive roots ``a < b`` (at the
    evaluation point): sympy's ``solve`` returns ``[]`` for equations it cannot solve (a quintic
    with a parameter: ``y^5 + y - a``), which would otherwise read as "no root" and give a wrong
    closed form.  Raises :class:`Unsupported` (the piece goes to quadrature)."""
    for c in conds:
        signs = set()
        for k in range(1, MISSED_ROOT_PROBES + 1):
            m = a + (b - a) * k / (MISSED_ROOT_PROBES + 1)
            z = _probe(c.expr, v, m, ctx)
            if z is not None and abs(z.imag) <= 1e-20 and z.real != 0:
                signs.add(z.real > 0)
        if len(signs) == 2:
            raise Unsupported(f"{c.expr} changes sign between {a:.6g} and {b:.6g} in {v}, where sympy "
                              "found no root")


def _generic_1d(conds, weight, v, lo, hi, ctx: Context):
    """Roots of all conditions, ordered at ``at``; conditions decided per sub-interval at ``at``.
    A :class:`Deferred` weight (the conditions alone large) is made for the first non-empty
    sub-interval, if any."""
    lo_v, hi_v = ctx.value(lo).real, ctx.value(hi).real
    pts = [(lo_v, lo), (hi_v, hi)]
    if isinstance(weight, Deferred) and not local.is_large([c.expr for c in conds], ctx.params):
        weight = weight.made()
    large = isinstance(weight, Deferred) or \
        local.is_large([c.expr for c in conds] + [sp.sympify(weight)], ctx.params)
    unsure = []  # conditions whose roots sympy solved (it may miss some): sign changes looked for
    seen: set = set()  # the conditions whose roots are among pts
    for c in conds:
        rs = _closed_roots(c, v, ctx) if large else None
        if rs is None:
            # sympy's roots untidied first: when none lies inside (lo, hi) here, none enters the
            # closed form, and solve's simplify pass (most of its time) is not needed; nor solve
            # itself when the condition is seen to stay away from 0 there
            # (nor either solve when every root it could add is a certain repeat of a point there)
            known = {p[0] for p in pts}
            base = _radicand(c, v, seen)
            if base is not None and _only_repeats(base, v, lo_v, hi_v, known, ctx):
                rs = []  # k·√P whose P came before: P's roots, all repeats
            else:
                rs = [] if _away_from_zero(c, v, lo_v, hi_v, ctx) else _roots(c, v, ctx, tidy=False)
                if any(_inside(r, lo_v, hi_v, ctx) for r in rs) and \
                        not _only_repeats(c.expr, v, lo_v, hi_v, known, ctx):
                    rs = _roots(c, v, ctx)
            unsure.append(c)
        seen.add(c.expr)
        for r in rs:
            if _inside(r, lo_v, hi_v, ctx):
                pts.append((ctx.value(r).real, r))
    pts.sort(key=lambda p: p[0])
    uniq = []
    for p in pts:
        if uniq and abs(p[0] - uniq[-1][0]) < 1e-13 * max(1.0, abs(p[0])):
            continue
        uniq.append(p)
    for (a, ea), (b, eb) in zip(uniq, uniq[1:]):
        if not (eb - ea).is_number:
            if large:  # (expanding the difference of two large bounds costs seconds)
                rel = sp.StrictGreaterThan(eb - ea, 0, evaluate=False)  # (undecidable: not tried)
                if rel not in ctx.cell:
                    ctx.cell.append(rel)
            else:
                ctx.record(">", eb - ea)
        _no_missed_root(unsure, v, a, b, ctx)
    ctx.generic = True
    total = sp.Integer(0)
    start = None
    F = None
    made = None  # (the weight, its degree when large) once an interval needs it

    def definite(a, b):
        nonlocal F, made
        if made is None:
            w = sp.sympify(_made(weight))
            made = (w, local.degree(w, frozenset((v,))) if large else None)
        w, deg = made
        if deg is not None and deg <= local.MAX_DEGREE:  # a large polynomial: never expanded
            return local.newton_cotes(w, v, a, b, deg)
        F = F if F is not None else antiderivative(w, v, ctx)
        return F.xreplace({v: b}) - F.xreplace({v: a})
    for (a, ea), (b, eb) in zip(uniq, uniq[1:]):
        m = (a + b) / 2
        ok = True
        for c in conds:
            z = _probe(c.expr, v, m, ctx)
            if z is None:
                raise Unsupported(f"{c.expr} has no value at {v} = {m:.6g} at the evaluation point")
            if abs(z.imag) > 1e-20 or not (z.real > 0 or (z.real == 0 and not c.strict)):
                ok = False
                break
        if ok and start is None:
            start = ea
        if not ok and start is not None:
            total += definite(start, ea)
            start = None
    if start is not None:
        total += definite(start, uniq[-1][1])
    return total


def integrate_region(conds: Sequence[Cond], weight, variables: Sequence, box: dict, ctx: Context):
    """Exact ∫ Π conds · weight over ``box``, trying each integration order.

    Parameter-only conditions of the input stay exact as a Piecewise factor; comparisons made
    during the decomposition are decided at ``at`` (``ctx.cell``); a :class:`Deferred` weight
    is made here unless there is one variable."""
    if isinstance(weight, Deferred) and len(variables) != 1:
        weight = weight.made()
    top = []
    others = []
    for c in conds:
        e = sp.sympify(c.expr)
        if e.free_symbols & set(variables):
            others.append(c)
        elif e.is_number:
            if not ctx.decide(e, c.strict):
                return sp.Integer(0)
        else:
            top.append(e > 0 if c.strict else e >= 0)
    if len(variables) == 2 and ((others and local.wants_cell_forms()) or
                                local.is_large([c.expr for c in others] + [sp.sympify(weight)], ctx.params)):
        # a convex polygon decided at the point (large affine regions: Max/Min nests cost minutes)
        sub = Context(ctx.at, ctx.deadline, ctx.params)
        val = local.polygon_integral(others, sp.sympify(weight), *variables, box, sub)
        if val is not None:
            ctx.cell.extend(r for r in sub.cell if r not in ctx.cell)
            return sp.Piecewise((val, sp.And(*top)), (0, True)) if top else val
    failures = []
    orders = list(itertools.permutations(variables))
    orders.sort(key=lambda o: o != tuple(variables))
    for order in orders:
        sub = Context(ctx.at, ctx.deadline, ctx.params)
        try:
            val = integrate_vars(others, weight, list(order), box, sub)
        except Unsupported as exc:
            failures.append(str(exc))
            if ctx.deadline.remaining() <= 0:
                break
            continue
        ctx.cell.extend(r for r in sub.cell if r not in ctx.cell)
        ctx.generic = ctx.generic or sub.generic
        if top:
            val = sp.Piecewise((val, sp.And(*top)), (0, True))
        return val
    raise Unsupported(failures[0] if failures else "no integration order")
