"""Where a primitive is applied outside its domain (LANGUAGE.md §1, §3): an integral that does not exist.

⟦t · s⟧ = ⟦t⟧ · ⟦s⟧ evaluates both factors; only ⟦ifge0 t then s else r⟧ (Fig. 7) leaves the branch
not taken unevaluated.  A primitive applied outside its domain (``log`` of a non-positive number, a
root of a negative one, ``asin`` beyond [−1, 1], a division by zero; ``langur.primitives`` declares
each domain) is undefined there, and so is every product with it: ``[x >= 0] * log(x)`` on [−1, 1]
is 0 · undefined at every x < 0, and ⟦p⟧ does not exist.  The Def. 6.2 decomposition cannot show
it: the bracket's 0 is no piece at all (sympy's ``0·log(x)`` is 0), so the integrator never
evaluates log(x) at x < 0.  ``if x >= 0 then log(x) else 0`` is the guard: there log is evaluated
at x ≥ 0 only, and ∫₀¹ log x dx = −1.

:func:`undefined_part` walks the term as Fig. 7 evaluates it: each application of a primitive
defined on part of ℝ only, and each power with a fractional or negative exponent, is evaluated on
the box cut by the conditions of the conditionals enclosing it (not by a bracket factor beside it),
where its argument has one smooth value per sign pattern of the argument's own conditions (as
:func:`~langur.symbolic.decompose.apply_smooth` splits it).  It is undefined on a set of positive
measure when a point strictly inside the box has every condition > 0 and the argument strictly
outside the domain's closure (open sets: a neighbourhood of the point is such a set), or, for an
argument constant there, the constant outside the domain (``log(max(x, 0))`` at x < 0, a division
by a term that is 0 there).  The point is looked for on a grid (:data:`GRID`), then, where the
grid has none (a region thinner than its step), at :data:`SAMPLES` random points of the box, and
proved at its exact coordinates with 50 digits (:mod:`langur.precise`): undefined is
said only with a witness.  An argument whose interval enclosure over the box lies in the domain
(:func:`langur.enclosures.enclose`, mpmath's interval arithmetic) is not searched at all.
``langur check`` reports X311 "undefined" from this same search (``langur.lint.singular``,
blaming the application, through :func:`undefined_part`), and X307 from :func:`undefined_parts`,
which finds every such application (``langur.lint.domains``).
"""

from __future__ import annotations

import fractions
import functools
import math
from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..core import IfDiffeo, IfGe0, Let, Pow, Prim, Term, children
from ..enclosures import enclose
from ..precise import real_value
from ..primitives import REGISTRY, Domain
from ..sympy_bridge import symbols
from .decompose import Ctx, decide, decompose, sign_patterns, smooth_value
from .text import expr_text

#: Grid points per dimension of the box (the same as the integrability analysis's grid, ``langur.symbolic.integrability.GRID``).
GRID = {1: 401, 2: 41, 3: 15}
#: Random points of the box where a witness the grid misses is looked for (:func:`random_points`;
#: the linter's X307 evaluates the integrand at the same points, ``langur.lint.domains``).
SAMPLES = 4096

#: A fractional power: undefined at a negative base (LANGUAGE.md §1, whatever the denominator); a
#: negative one also at 0.  A negative integer power (a division): at 0.
_ROOT = Domain(0.0, math.inf, closed=True, why="its base is negative")
_NEGATIVE_ROOT = Domain(0.0, math.inf, why="its base is negative")
_DIVISION = Domain(poles=True, why="it divides by zero")


@dataclass(frozen=True)
class Undefined:
    """An application evaluated outside its domain on a set of positive measure of the box:
    ``what`` (its text at the parameter values), the domain's ``why``, a ``point`` of that set
    (variable name → exact coordinate), the ``application`` (the subterm of the program, for its
    span) and its ``argument`` there (its value on the sign pattern, parameters substituted)."""

    what: str
    why: str
    point: tuple[tuple[str, sp.Expr], ...]
    application: Term
    argument: sp.Expr

    @property
    def at(self) -> str:
        """The point as text: ``x = -1/2, y = 0``."""
        return ", ".join(f"{k} = {expr_text(v)}" for k, v in self.point)

    @property
    def reason(self) -> str:
        return (f"`{self.what}` is evaluated outside its domain ({self.why}) on a set of positive measure "
                f"(e.g. at {self.at}): the integrand is undefined there, a bracket factor 0 beside it included "
                "(⟦t · s⟧ = ⟦t⟧ · ⟦s⟧; only a conditional guards, LANGUAGE.md §1, §3)")


def _domain(t: Term) -> Domain | None:
    """The domain of the primitive or power ``t`` applies, when it is not all of ℝ."""
    match t:
        case Prim(op, _) if not REGISTRY[op].domain.everywhere:
            return REGISTRY[op].domain
        case Pow(_, k) if k.denominator != 1:
            return _ROOT if k > 0 else _NEGATIVE_ROOT
        case Pow(_, k) if k < 0:
            return _DIVISION
    return None


def has_partial(t: Term) -> bool:
    """Whether ``t`` applies a primitive or power defined on part of ℝ only (anywhere: whatever the
    evaluation point decides)."""
    return _partial(t, {})


def _partial(t: Term, known: dict[int, bool]) -> bool:
    """Whether ``t`` holds an application :func:`_domain` knows (each distinct node once)."""
    stack = [(t, False)]
    while stack:
        u, done = stack.pop()
        if id(u) in known:
            continue
        if done:
            known[id(u)] = _domain(u) is not None or any(known[id(k)] for k in _parts(u))
            continue
        stack.append((u, True))
        stack += [(k, False) for k in _parts(u) if id(k) not in known]
    return known[id(t)]


def _parts(t: Term) -> tuple[Term, ...]:
    """The subterms Fig. 7 evaluates with ``t``: its children, and a diffeomorphic condition's π₀Ψ̂."""
    return (t.psi.forward[0], *children(t)) if isinstance(t, IfDiffeo) else children(t)


def applications(t: Term, ctx: Ctx) -> list[tuple[Term, Domain, sp.Expr, tuple[sp.Expr, ...]]]:
    """Each application of :func:`_domain` in ``t`` as ``(term, domain, argument, path)`` per sign
    pattern of its argument: ``argument`` its value there, ``path`` the conditions ``c ≥ 0`` of the
    pattern and of the branches of the conditionals enclosing it (Fig. 7: ⟦ifge0 t then s else r⟧
    evaluates the branch taken; a variable-free condition is decided at ``ctx.at`` as
    :func:`~langur.symbolic.decompose.decompose` decides it; ⟦t · s⟧ evaluates both factors)."""
    out: list[tuple[Term, Domain, sp.Expr, tuple[sp.Expr, ...]]] = []
    known: dict[int, bool] = {}
    if not _partial(t, known):
        return out
    seen: set = set()
    alive = [ctx]  # the contexts stay alive, so that their identities stay theirs
    stack: list[tuple[Term, Ctx, tuple[sp.Expr, ...]]] = [(t, ctx, ())]
    while stack:  # pre-order, in the order of the text (as ``core.subterms``): the first one found is blamed
        u, c, path = stack.pop()
        if not known[id(u)] or (id(u), id(c), path) in seen:
            continue
        seen.add((id(u), id(c), path))
        match u:
            case Prim(_, a) | Pow(a, _) if _domain(u) is not None:
                # LANGUAGE.md §1: f(t) evaluates t, then f where t's value is
                out += [(u, _domain(u), v, path + tuple(k.expr for k in pattern))
                        for pattern, v in sign_patterns(decompose(a, c))]
                stack.append((a, c, path))
            case IfGe0(cond, a, b):
                # Fig. 7, conditional on a variable-free condition: the branch taken (both, undecided)
                chosen = decide(smooth_value(cond, c), c.at)
                stack += ([(b, c, path)] if chosen is not True else []) + \
                    ([(a, c, path)] if chosen is not False else []) + [(cond, c, path)]
            case IfDiffeo(psi, a, b):
                # Fig. 7, diffeomorphic conditional: s where π₀Ψ̂ ≥ 0, r where π₀Ψ̂ < 0
                phi = smooth_value(psi.forward[0], c)
                stack += [(b, c, path + (-phi,)), (a, c, path + (phi,)), (psi.forward[0], c, path)]
            case Let(name, bound, body):
                # Fig. 7, let: the body with z ↦ ⟦t⟧
                alive.append(c.bind(name, smooth_value(bound, c)))
                stack += [(body, alive[-1], path), (bound, c, path)]
            case _:
                stack += [(k, c, path) for k in reversed(children(u))]
    return out


def undefined_part(t: Term, ctx: Ctx, variables: Sequence[str],
                   box: Sequence[tuple[sp.Expr, sp.Expr]]) -> Undefined | None:
    """An application in ``t`` evaluated outside its domain on a set of positive measure of the
    box (module docstring) at the parameter values ``ctx.at``: the first one found, in the order
    of the text; None when none is found.  :func:`undefined_parts`' answer for the same question
    when it was the last one asked (``langur check`` asks X307's, then X311's: one search)."""
    if _LAST and _LAST[0] is t and _LAST[1] == _key(ctx, variables, box):
        return _LAST[2][0] if _LAST[2] else None
    return next(iter(_undefined(t, ctx, variables, box, set()) or ()), None)


#: :func:`undefined_parts`' last question and answer: ``[term, key, answer]`` (the term kept, so its
#: identity stays its own).
_LAST: list = []


def _key(ctx: Ctx, variables: Sequence[str], box: Sequence[tuple[sp.Expr, sp.Expr]]) -> tuple:
    """The rest of the question (``srepr``: a Float's precision counts, which sympy's equality ignores)."""
    return (sp.srepr(sorted((ctx.at or {}).items(), key=str)), sp.srepr(sorted(ctx.env.items())),
            tuple(variables), sp.srepr(tuple(map(tuple, box))))


def undefined_parts(t: Term, ctx: Ctx, variables: Sequence[str],
                    box: Sequence[tuple[sp.Expr, sp.Expr]]) -> list[Undefined] | None:
    """Every application in ``t`` evaluated outside its domain on a set of positive measure of
    the box at ``ctx.at``, each once (its first witness), in the order of the text; None when
    nothing can be decided (an argument with too many discontinuities to split, a bound of the
    box not a finite number).  An application whose argument is in a parameter without a value,
    or none of whose witnesses the grid finds, is not among them: nothing is claimed."""
    done: set[int] = set()
    found = _undefined(t, ctx, variables, box, done)
    out = None if found is None else []
    for u in found or ():
        out.append(u)
        done.add(id(u.application))  # (its other sign patterns and paths are not looked at)
    _LAST[:] = [t, _key(ctx, variables, box), out]
    return out


def _undefined(t: Term, ctx: Ctx, variables: Sequence[str], box: Sequence[tuple[sp.Expr, sp.Expr]],
               done: set[int]) -> Iterator[Undefined] | None:
    """The applications of ``t`` found undefined (module docstring), lazily, skipping those whose
    identity is in ``done`` when their turn comes; None when nothing can be decided."""
    try:
        found = applications(t, ctx)
    except NotImplementedError:  # (too many discontinuities to split an argument: nothing is claimed)
        return None
    if not found:
        return iter(())
    at = dict(ctx.at or {})
    xs = symbols(tuple(variables))
    ends = [(sp.sympify(lo).xreplace(at), sp.sympify(hi).xreplace(at)) for lo, hi in box]
    try:
        fbox = np.array([(float(lo), float(hi)) for lo, hi in ends])
    except TypeError:  # (a bound still in a parameter: nothing is decided)
        return None
    if not (np.all(np.isfinite(fbox)) and np.all(fbox[:, 0] < fbox[:, 1])):
        return None
    return _witnessed(found, at, xs, ends, fbox, done)


def _witnessed(found, at, xs, ends, fbox: np.ndarray, done: set[int]) -> Iterator[Undefined]:
    """Each application of ``found`` (:func:`applications`) with a witness (module docstring)."""
    for term, domain, v, path in found:
        if id(term) in done:
            continue
        v = sp.sympify(v).xreplace(at)
        exprs = [sp.sympify(c).xreplace(at) for c in path]
        if (v.free_symbols | set().union(*(e.free_symbols for e in exprs))) - set(xs):
            continue  # (a parameter without a value: nothing is decided)
        conds = [e for e in exprs if e.free_symbols]
        if not all(_at_least_zero(e) for e in exprs if not e.free_symbols):
            continue  # (a branch not taken at these parameters: the application is not evaluated there)
        if v.free_symbols:
            # a varying argument: outside the closure of the domain on an open set (its ends, and
            # the poles of tan or of a division, are a null set); the sets where it is beyond an end
            beyond = [[g] for g in _beyond(domain, v) if _may_be_positive(g, xs, ends)]
            why = domain.why
        elif _constant_inside(domain, v):
            continue
        else:  # a constant outside the domain: wherever the path holds
            beyond = [[]]
            why = domain.why if domain is _DIVISION else \
                f"its {'base' if isinstance(term, Pow) else 'argument'} is {expr_text(v)} there"
        for outside in beyond:
            point = _witness(conds + outside, xs, ends, fbox)
            if point is not None:
                yield Undefined(_what(term, v), why, tuple((str(x), p) for x, p in zip(xs, point)), term, v)
                break


def _what(term: Term, v: sp.Expr) -> str:
    """The application as text, its argument at the parameter values on the pattern."""
    arg = expr_text(v) if v.is_Atom else f"({expr_text(v)})"
    match term:
        case Prim(op, _):
            return f"{op}({expr_text(v)})"
        case Pow(_, k) if k == -1:
            return f"1/{arg}"
        case Pow(_, k):
            return f"{arg}^{'(' + str(k) + ')' if k.denominator != 1 or k < 0 else k}"
    return expr_text(v)


def _at_least_zero(e: sp.Expr) -> bool:
    return real_value(e) >= 0


def _constant_inside(domain: Domain, v: sp.Expr) -> bool:
    """A constant argument inside the domain (exactly)."""
    z = real_value(v)
    if not math.isfinite(z):
        return False
    if domain.poles:  # a division: 0; tan: where cos is 0
        return v != 0 if domain is _DIVISION else sp.cos(v) != 0
    if z == domain.lo or z == domain.hi:  # at an end: decided exactly
        return domain.closed or v not in (sp.nsimplify(domain.lo), sp.nsimplify(domain.hi))
    return domain.contains(z)


def _beyond(domain: Domain, v: sp.Expr) -> list[sp.Expr]:
    """``g`` with ``g > 0`` where ``v`` lies strictly outside the closure of the domain."""
    out = []
    if math.isfinite(domain.lo):
        out.append(sp.nsimplify(domain.lo) - v)
    if math.isfinite(domain.hi):
        out.append(v - sp.nsimplify(domain.hi))
    return out


# ----------------------------------------------------------------------------------------------
# Enclosures: a proof, without sampling, that g ≤ 0 on the box


def _may_be_positive(g: sp.Expr, xs, ends) -> bool:
    """False when an interval enclosure of ``g`` over the box (its exact ``ends``;
    :func:`langur.enclosures.enclose`: mpmath's interval arithmetic, rounded outward) proves
    ``g ≤ 0`` there."""
    bound = enclose(g, dict(zip(xs, ends)))
    return bound is None or bound.b > 0


# ----------------------------------------------------------------------------------------------
# Witnesses


@functools.lru_cache(maxsize=1024)  # one condition bounds many applications
def _compiled(exprs: tuple, xs: tuple):
    """``exprs`` compiled for numpy over ``xs``, ``erf`` the primitive's own (numpy has none; sympy
    would print ``math.erf``, which takes no array); False: sympy cannot compile them."""
    try:
        return sp.lambdify(list(xs), list(exprs), modules=[{"erf": REGISTRY["erf"].value}, "numpy"])
    except Exception:  # noqa: BLE001 - sympy cannot print everything for numpy: nothing is claimed then
        return False


def _witness(exprs: list[sp.Expr], xs, ends, fbox: np.ndarray) -> tuple[sp.Expr, ...] | None:
    """An exact point strictly inside the box where every ``e`` of ``exprs`` is > 0, proved with
    :data:`~langur.precise.DIGITS` digits: looked for on the grid (:data:`GRID`: round
    coordinates), then, where it has none, at :func:`random_points` (a region thinner than the
    grid's step: ``log(x)`` on [−0.001, 1]), each moved to a nearby short rational (None when
    neither has one)."""
    n = len(xs)
    k = GRID.get(n, 7)
    axes = [np.linspace(lo, hi, k) for lo, hi in fbox]
    index = np.indices((k,) * n).reshape(n, -1).T  # each grid point's indices
    pts = np.stack([axes[i][index[:, i]] for i in range(n)], axis=1)
    found = _proved(exprs, xs, pts, fbox, lambda h: tuple(lo + (hi - lo) * sp.Rational(int(i), k - 1)
                                                           for (lo, hi), i in zip(ends, index[h])))
    if found is None:
        pts = random_points(fbox)
        found = _proved(exprs, xs, pts, fbox, lambda h: _inside(tuple(map(_short, pts[h])), ends))
    return found


def random_points(fbox) -> np.ndarray:
    """:data:`SAMPLES` points of the box ``fbox`` (rows: its sides' ends, doubles) uniformly at
    random, one row each, the same every time (seed 0)."""
    rng = np.random.default_rng(0)
    return np.stack([_uniform(rng, lo, hi) for lo, hi in fbox], axis=1)


def _uniform(rng, lo: float, hi: float) -> np.ndarray:
    """``rng.uniform(lo, hi, SAMPLES)``, also where ``hi − lo`` is beyond the doubles ([−1e308, 1e308]:
    numpy refuses, OverflowError): there ``lo·(1 − u) + hi·u`` of the same draws ``u``."""
    if np.isfinite(hi - lo):
        return rng.uniform(lo, hi, SAMPLES)
    u = rng.random(SAMPLES)
    return lo * (1 - u) + hi * u


def _short(v: float) -> sp.Rational:
    """The rational nearest ``v`` with a denominator at most 10⁶ (a short text; within 10⁻⁶/q of ``v``)."""
    return sp.Rational(fractions.Fraction(float(v)).limit_denominator(10 ** 6))


def _inside(point: tuple[sp.Expr, ...], ends) -> tuple[sp.Expr, ...] | None:
    """``point`` when it is strictly inside the box (proved), else None."""
    inside = all(real_value(p - lo) > 0 and real_value(hi - p) > 0 for p, (lo, hi) in zip(point, ends))
    return point if inside else None


def _proved(exprs: list[sp.Expr], xs, pts: np.ndarray, fbox: np.ndarray, exact) -> tuple[sp.Expr, ...] | None:
    """The exact point ``exact(h)`` of one of the points ``pts`` strictly inside the box where every
    ``e`` of ``exprs`` is > 0 in doubles (the middle one, the first, the last), when it is proved
    there; None (``exact`` may say None too)."""
    n = len(xs)
    margin = 1e-9 * float(np.max(fbox[:, 1] - fbox[:, 0]))
    ok = np.all((pts > fbox[:, 0] + margin) & (pts < fbox[:, 1] - margin), axis=1)
    if exprs:
        f = _compiled(tuple(exprs), tuple(xs))
        if f is False:
            return None
        with np.errstate(all="ignore"):
            try:
                values = f(*[pts[:, i] for i in range(n)])
            except (TypeError, ValueError, ZeroDivisionError, OverflowError, AttributeError, NameError):
                return None
        for val in values:
            val = np.broadcast_to(np.asarray(val), (len(pts),))
            if np.iscomplexobj(val):
                val = np.where(np.abs(val.imag) <= 1e-12 * np.abs(val.real), val.real, np.nan)
            ok &= np.nan_to_num(np.asarray(val, dtype=float), nan=-1.0) > margin
    hits = np.flatnonzero(ok)
    for h in hits[[len(hits) // 2, 0, -1]] if len(hits) else ():
        point = exact(h)
        if point is None:
            continue
        sub = dict(zip(xs, point))
        if all(_proved_positive(e.xreplace(sub)) for e in exprs):
            return point
    return None


def _proved_positive(e: sp.Expr) -> bool:
    return real_value(e) > 1e-30
