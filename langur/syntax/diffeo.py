"""Diffeomorphisms for diffeomorphic conditionals (paper §4, §5.2; LANGUAGE.md §6).

Two jobs, both with sympy (through :mod:`langur.sympy_bridge`, every call time-boxed by :mod:`langur.timebox`):

* :func:`complete`: a condition ``t`` over variables that is not a declared diffeo is completed to
  ``Ψ̂ = (t, the other variables)`` by solving ``t = u₀`` for one variable ``v``.  The candidates
  are ranked (best first), ties broken by taking the *last* variable in order (LANGUAGE.md §6's
  example ``[y < x + θ]`` solves for ``y``), so the same term always gives the same Diffeo:

  0. ``t`` affine in ``v`` with a constant nonzero coefficient: one branch;
  1. affine in ``v`` with a coefficient over parameters only (``t*x - 1``): one branch, and the
     coefficient is recorded in ``Diffeo.nonzero``;
  2. ``v`` occurs once, under invertible steps (``+ c``, ``· c``, ``^ k``, ``exp``, ``log``,
     ``tanh``, ``atan``, and the periodic ``sin``/``cos``/``tan`` when the argument's range over the
     variables' box is bounded): one branch per inverse, each with guards ``≥ 0`` saying where it
     exists (``x^2 - a``: ``x = ±sqrt(u0 + a)``, guard ``u0 + a``; ``x^3 - a``: two branches with
     complementary guards); periodic inverses keep only the branches whose image meets the
     argument's range, so ``sin(x) - t`` on ``[0, 1]`` has one.  A factor ``c`` over parameters
     is recorded in ``nonzero``; a factor over other variables (``x*y - 1`` solved for ``y``)
     vanishes only on a null set, where Ψ̂ is not invertible (like a tangency, measure zero);
  3. the numerator of ``t - u₀`` is a polynomial of degree ≤ 2 in ``v`` (rational conditions
     such as ``x/(1+x) - a``): its roots, two branches with guard ``discriminant ≥ 0`` for
     degree 2;
  4. none of these, ``t`` mentions one variable only and its interval is bounded: one implicit-root
     branch per monotone piece between turning points (:mod:`langur.syntax.turning`, issue 18);
  5. none of these, ``t`` mentions several variables: solved for the last variable with a bounded
     interval in which ``t`` is *proved* strictly monotone on the box (interval enclosures of
     ``∂t/∂v``, :mod:`langur.syntax.monotone`), by one implicit-root branch.

  A variable whose inverse branch is infinite on the zero set (``u₀ = 0``: a division by the
  target, ``[(x - a)/(y + 0.5) >= 0]`` solved for ``y``) is not a candidate: the condition is
  solved for another variable (here ``x = a + u₀·(y + ½)``) or refused.

  Inverse branches are solved with these bounded strategies only (no open-ended
  ``sympy.solve``, whose solution sets for transcendental equations can be incomplete: a missed
  root would silently drop part of the derivative).

  Every branch is kept because the delta of the condition sums over all roots.  What cannot be
  completed raises :class:`CompletionError` (the desugarer turns it into a located T207).

* :func:`check_declared`: a ``diffeo`` declaration is checked: arity, ``Ψ̂(Ψ̂⁻¹(u)) = u`` and
  ``Ψ̂⁻¹(Ψ̂(x)) = x`` (symbolically, else numerically at random points), nonsingular Jacobian.
  :func:`instantiate` applies a checked declaration to actual variables and parameter terms.
"""

from __future__ import annotations

import math
import random
from dataclasses import replace
from functools import lru_cache

import sympy as sp

from ..core import (
    Diffeo,
    InverseBranch,
    Term,
    Var,
    diffeo_params,
    extend_diffeo,
    free_params,
    free_vars,
    substitute,
)
from ..primitives import REGISTRY, Inverse, Periodic, Primitive
from ..sympy_bridge import (
    FUNCTIONS,
    PRIMITIVE_OF,
    NotSmooth,
    from_sympy,
    may_vanish,
    symbol,
    to_sympy,
)
from ..timebox import run_with_timeout
from . import affine, turning
from .affine import fresh_inputs
from .folding import nonzero_constant, refolded
from .support import float_bounds

#: CPU-second limit of one completion / one declaration check (CPU, not wall clock: what a program
#: completes to must not change with the machine's load).
TIME_LIMIT = 10.0
#: CPU-second limit of the symbolic proof that a declared inverse inverts (then: numeric check).
SYMBOLIC_LIMIT = 3.0
#: More inverse branches than this on the domain is treated as "infinitely many".
MAX_BRANCHES = 64

Box = tuple[tuple[str, float, float], ...]  # (variable, lo, hi); absent or infinite: unbounded


class CompletionError(Exception):
    """The condition cannot be completed to a diffeomorphism (the message says why)."""


class DiffeoCheckError(Exception):
    """A declared diffeo fails its check; ``code`` is the T2xx code (see ``langur.typesys``)."""

    def __init__(self, code: str, message: str):
        super().__init__(message)
        self.code = code


# ----------------------------------------------------------------------------------------------
# Automatic completion


def complete(cond: Term, variables: tuple[str, ...], box: Box = (), avoid: frozenset[str] = frozenset()) -> Diffeo:
    """Complete the condition ``cond`` (a smooth term over ``variables`` and parameters) to a
    diffeomorphism ``Ψ̂ = (cond, the other variables)`` (LANGUAGE.md §6, "Conditions over
    variables").  ``box`` bounds the variables (needed only by periodic inverses).
    ``avoid``: variables not to isolate (:mod:`langur.lint.recomplete`).
    Deterministic: equal arguments give equal results.  Raises :class:`CompletionError`."""
    direct = affine.complete(cond, tuple(variables), avoid)  # affine conditions: the same Diffeo, no sympy
    if direct is not None:
        return direct
    # (the span is part of the key: a completion's implicit roots carry the condition's place, named when
    # evaluating them is refused (X316); terms are equal whatever their spans, so without it a second file's
    # equal condition was refused at the first file's place)
    psi = _complete_cached(cond, tuple(variables), tuple(box), frozenset(avoid), getattr(cond, "span", None))
    return replace(psi, forward=(cond,) + psi.forward[1:], span=getattr(cond, "span", None))


@lru_cache(maxsize=4096)
def _complete_cached(cond: Term, variables: tuple[str, ...], box: Box, avoid: frozenset[str] = frozenset(),
                     span: object = None) -> Diffeo:
    occurring = [v for v in variables if v in free_vars(cond)]
    if not occurring:
        raise CompletionError("the condition has no variables (it is a plain ifge0)")
    if not set(occurring) - avoid:
        raise CompletionError("every variable it depends on is excluded")
    try:
        expr = to_sympy(cond)
    except NotSmooth as e:
        raise CompletionError(f"the condition contains {e}; only a smooth condition over variables "
                              "can be completed to a diffeomorphism") from None
    params = tuple(sorted(free_params(cond)))
    inputs = fresh_inputs(len(variables), set(variables) | set(params) | _symbol_names(expr))
    bounds = float_bounds(box)  # a parametric bound is unbounded here …
    ends = {v: (lo, hi) for v, lo, hi in box}  # … but an implicit root's bracket may follow it (issue 18)
    try:
        found = run_with_timeout(lambda: _choose(cond, expr, variables, occurring, inputs, params, bounds, ends, avoid),
                                 TIME_LIMIT, cpu=True)
    except TimeoutError:
        raise CompletionError(f"sympy could not invert the condition within {TIME_LIMIT:g} CPU s") from None
    if isinstance(found, str):
        raise CompletionError(found)
    return found


def _to_diffeo(cond, variables, inputs, params, v, branches, nonzero) -> Diffeo:
    """The Diffeo of ``cond`` solved for ``v`` (raises ValueError if a branch is not expressible)."""
    others = [x for x in variables if x != v]
    by_other = {x: Var(u) for x, u in zip(others, inputs[1:])}
    core_branches = []
    for vexpr, guards in branches:
        comp = from_sympy(vexpr, inputs, params)
        gs = []
        for g in guards:
            gt = from_sympy(g, inputs, params)
            if gt not in gs:
                gs.append(gt)
        core_branches.append(InverseBranch(tuple(comp if x == v else by_other[x] for x in variables), tuple(gs)))
    return Diffeo(variables=variables, forward=(cond,) + tuple(Var(x) for x in others), inputs=inputs,
                  branches=tuple(core_branches), solved_for=v, name=None,
                  nonzero=tuple(from_sympy(n, (), params) for n in nonzero))


def _symbol_names(expr: sp.Expr) -> set[str]:
    return {s.name for s in expr.free_symbols}


def _choose(cond, expr, variables, occurring, inputs, params, bounds, ends=None, avoid=frozenset()):
    """The Diffeo for the best-ranked variable not in ``avoid`` (ties: the last one), or a reason string."""
    found = []
    reasons = []
    allowed = [v for v in occurring if v not in avoid]
    for v in allowed:
        others = [x for x in variables if x != v]
        sub = {symbol(x): symbol(u) for x, u in zip(others, inputs[1:])}
        e = expr.subs(sub, simultaneous=True)
        ranges = {symbol(u): bounds.get(x, (-math.inf, math.inf)) for x, u in zip(others, inputs[1:])}
        ranges[symbol(v)] = bounds.get(v, (-math.inf, math.inf))
        result = _solve_for(e, symbol(v), symbol(inputs[0]), set(sub.values()), ranges)
        if isinstance(result, str):
            reasons.append(f"{v}: {result}{_shape(e, symbol(v), ranges[symbol(v)])}")
            continue
        rank, branches, nonzero = result
        if not branches:
            reasons.append(f"{v}: no inverse branch meets the domain")
            continue
        pole = _infinite_on_zero_set(branches, symbol(inputs[0]))
        if pole is not None:
            reasons.append(f"{v}: its inverse {v} = {pole} is infinite on the zero set (at {inputs[0]} = 0), "
                           "so Ψ̂ is not a diffeomorphism there (Def. 3.4)")
            continue
        found.append((rank, -variables.index(v), v, branches, nonzero))
    for rank, _, v, branches, nonzero in sorted(found, key=lambda f: f[:2]):
        try:
            return _to_diffeo(cond, variables, inputs, params, v, branches, nonzero)
        except ValueError as e:
            reasons.append(f"{v}: {e}")
    if len(occurring) == 1 and allowed:  # no closed form: implicit roots on the monotone pieces (issue 18)
        (v,) = occurring
        pieces = turning.complete_by_pieces(cond, expr, symbol(v), variables, inputs,
                                            (ends or bounds).get(v, (-math.inf, math.inf)))
        if isinstance(pieces, Diffeo):
            return pieces
        reasons.append(f"{v}: {pieces}")
    elif len(occurring) > 1:  # several variables: an implicit root in one it is proved monotone in (issue 18)
        for v in reversed(allowed):
            psi = turning.complete_by_monotone(cond, expr, symbol(v), variables, inputs, bounds, ends)
            if isinstance(psi, Diffeo):
                return psi
            reasons.append(f"{v} (implicitly): {psi}")
        for moving in (False, True):  # else split along a variable at its turning points (fixed ones first)
            for v in reversed(allowed):
                psi = turning.split_along(cond, expr, symbol(v), variables, inputs, bounds, moving)
                if isinstance(psi, Diffeo):
                    return psi
                if psi is not None:
                    reasons.append(f"{v} (split): {psi}")
        reasons.append("it is split along a variable at its turning points only where it is continuous on that "
                       "variable's whole interval for every value of the others: split the domain there (several "
                       "integrals), or declare a `diffeo` with its inverse")
    return "no variable can be isolated (" + "; ".join(reasons) + ")"


def _infinite_on_zero_set(branches, u0):
    """The first inverse branch that is not finite where the condition is 0 (``u0 = 0``: a division
    by the target, ``(x - a)/(y + ½) = u0`` solved for ``y``), or None.  Such a branch is no
    completion in that variable: Ψ̂⁻¹ must be finite on the zero set, where the delta of the
    condition sits (Def. 3.4, §5.2); solved for ``y`` the zero set ``x = a`` is no graph over ``x``.
    (An inverse infinite only where *another* variable takes one value, ``x = a + u0·(y + ½)``
    at ``y = −½``, fails on a null set only, like a tangency.)"""
    for vexpr, _ in branches:
        at_zero = vexpr.subs(u0, 0)
        if at_zero.has(sp.zoo, sp.oo, -sp.oo, sp.nan):
            return vexpr
    return None


def _solve_for(e, v, u0, others: set, ranges):
    """Solve ``e = u0`` for ``v``: ``(rank, [(v_expr, [guards])], [nonzero])`` or a reason."""
    d = sp.diff(e, v)
    if v not in d.free_symbols and not (d.free_symbols & (others | {u0})):
        if d.is_zero:
            return "the condition does not depend on it"
        rest = e.subs(v, 0)
        sol = (u0 - rest) / d
        if not d.free_symbols:  # rank 0: constant coefficient
            return 0, [(sol, [])], []
        return 1, [(sol, [])], [d]  # rank 1: parameter coefficient, must not vanish
    try:
        branches, nonzero = _peel(e, u0, v, others | {u0}, ranges)
        if len(branches) > MAX_BRANCHES:
            return f"more than {MAX_BRANCHES} inverse branches on the domain"
        return 2, branches, nonzero
    except _Unpeelable as err:
        peel_reason = str(err)
    quad = _quadratic(e, u0, v, others)
    if quad is not None:
        return 3, quad[0], quad[1]
    return peel_reason


#: CPU-second limit of the search for turning points that explains a refusal.
SHAPE_LIMIT = 2.0


def _shape(e, v, interval) -> str:
    """Why a condition that cannot be inverted is refused, and what would make it acceptable
    (issue 18): its turning points in ``v`` on the domain (zeros of ∂e/∂v: each monotone piece
    between them has one inverse branch), or that it is monotone there with no closed-form inverse.
    Empty when sympy cannot tell within :data:`SHAPE_LIMIT`."""
    lo, hi = interval
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        return ""
    d = sp.diff(e, v)
    if d.free_symbols - {v}:
        return ""  # turning points that move with parameters or other variables: not analysed here
    dom = sp.Interval(sp.nsimplify(lo), sp.nsimplify(hi))
    try:
        zeros = run_with_timeout(lambda: sp.solveset(d, v, dom), SHAPE_LIMIT, cpu=True)
    except (TimeoutError, ValueError):  # (ValueError: mpmath's erfinv asked outside [-1, 1] inside solveset)
        return ""
    rewrite = ("; Langur completes a condition only where a variable can be isolated in closed form "
               "(it occurs once under invertible steps, or in a polynomial of degree ≤ 2): rewrite the "
               "condition so, or declare a `diffeo` with its inverse")
    if zeros is sp.S.EmptySet:
        return (f"; it is monotone in {v} on [{lo:g}, {hi:g}] (∂/∂{v} = {d} does not vanish there), "
                f"but Langur finds no closed form of its inverse{rewrite}")
    if isinstance(zeros, sp.FiniteSet) and len(zeros) <= 8:
        pts = ", ".join(str(z) for z in sorted(zeros, key=lambda z: float(z)))
        return (f"; it is not monotone in {v}: ∂/∂{v} = {d} vanishes at {v} = {pts} on [{lo:g}, {hi:g}] "
                f"(turning points: between them it has one inverse branch each, which Langur cannot write in closed form){rewrite}")
    return ""


class _Unpeelable(Exception):
    pass


def _peel(a, target, v, variables: set, ranges):
    """Invert ``a = target`` for ``v`` step by step; ``v`` must occur once along one path."""
    if a == v:
        return [(target, [])], []
    if a.is_Add or a.is_Mul:
        with_v = [p for p in a.args if v in p.free_symbols]
        if len(with_v) != 1:
            raise _Unpeelable(f"{v} occurs in several terms of {a}")
        part = with_v[0]
        # the other terms (factors) themselves: ``a / part`` would leave ``exp(1 - 2x)·exp(2x - 1)``
        # for ``a = -exp(2x - 1)`` (sympy does not cancel it), a ``rest`` still in ``v``
        rest = a.func(*(p for p in a.args if v not in p.free_symbols))
        if a.is_Add:
            return _peel(part, target - rest, v, variables, ranges)
        # a coefficient over parameters must not vanish (Diffeo.nonzero); one over other variables
        # vanishes on a null set only (where Ψ̂ is not invertible: measure zero, like a tangency)
        br, nz = _peel(part, target / rest, v, variables, ranges)
        return br, ([rest] if rest.free_symbols and not rest.free_symbols & variables else []) + nz
    if a.is_Pow:
        base, k = a.args
        if v in k.free_symbols or not k.is_Rational:
            raise _Unpeelable(f"non-constant exponent in {a}")
        if k < 0:
            return _peel(base ** (-k), 1 / target, v, variables, ranges)
        if k.is_integer and k % 2 == 0:
            root = target ** (1 / k)
            return _branches(base, [(root, [target]), (-root, [target])], v, variables, ranges)
        if k.is_integer:
            return _branches(base, [(target ** (1 / k), [target]), (-(-target) ** (1 / k), [-target])],
                             v, variables, ranges)
        return _branches(base, [(target ** (1 / k), [target])], v, variables, ranges)
    if len(a.args) == 1 and a.func in PRIMITIVE_OF:
        arg, p = a.args[0], REGISTRY[PRIMITIVE_OF[a.func]]
        match p.inverse:
            case Inverse(name, guard):  # a monotone f: x = f⁻¹(u) where the guard holds
                return _branches(arg, [(FUNCTIONS[name](target), [guard(target, sp.pi)] if guard else [])],
                                 v, variables, ranges)
            case Periodic():
                return _periodic(p, arg, target, v, variables, ranges)
    raise _Unpeelable(f"cannot invert {a}")


def _branches(inner, steps, v, variables, ranges):
    out, nonzero = [], []
    for value, guards in steps:
        br, nz = _peel(inner, value, v, variables, ranges)
        out.extend((x, guards + g) for x, g in br)
        nonzero.extend(n for n in nz if n not in nonzero)
    return out, nonzero


def _periodic(p: Primitive, arg, target, v, variables, ranges):
    """Inverse branches of ``f(arg) = target`` whose image meets the range of ``arg`` on the box."""
    lo, hi = _range(arg, ranges)
    if not (math.isfinite(lo) and math.isfinite(hi)):
        raise _Unpeelable(f"{p.name}({arg}) has infinitely many inverse branches unless {arg} "
                          "ranges over a bounded interval (give the variables a constant bounded domain)")
    pi, periodic = math.pi, p.inverse
    guards = [periodic.guard(target, sp.pi)] if periodic.guard else []
    # (inverse, image lo, image hi, period in units of π, guards)
    shapes = [(b.sign * FUNCTIONS[b.inverse](target) + b.offset * sp.pi, float(b.lo) * pi, float(b.hi) * pi,
               periodic.period, guards) for b in periodic.branches]
    steps = []
    for expr, ilo, ihi, period, guards in shapes:
        first = math.floor((lo - ihi) / (period * pi)) - 1
        last = math.ceil((hi - ilo) / (period * pi)) + 1
        if last - first > 4 * MAX_BRANCHES:
            raise _Unpeelable(f"more than {MAX_BRANCHES} inverse branches of {p.name} on the domain")
        for j in range(first, last + 1):
            a, b = ilo + j * period * pi, ihi + j * period * pi
            if max(a, lo) < min(b, hi) or (lo == hi and a <= lo <= b):
                steps.append((expr + j * period * sp.pi if j else expr, guards))
    if len(steps) > MAX_BRANCHES:
        raise _Unpeelable(f"more than {MAX_BRANCHES} inverse branches of {p.name} on the domain")
    return _branches(arg, _dedupe(steps), v, variables, ranges)


def _dedupe(steps):
    out = []
    for s in steps:
        if s not in out:
            out.append(s)
    return out


def _range(expr, ranges) -> tuple[float, float]:
    """An interval containing ``expr`` over the box (variables only; parameters: unbounded)."""
    syms = expr.free_symbols
    if any(s not in ranges for s in syms):
        return -math.inf, math.inf
    env = {}
    for s in syms:
        lo, hi = ranges[s]
        if not (math.isfinite(lo) and math.isfinite(hi)):
            return -math.inf, math.inf
        env[s] = sp.AccumBounds(sp.Float(lo), sp.Float(hi)) if lo < hi else sp.Float(lo)
    try:
        r = expr.subs(env)
        if isinstance(r, sp.AccumBounds):
            lo_, hi_ = float(r.min), float(r.max)
        else:
            lo_ = hi_ = float(r)
    except (TypeError, ValueError, AttributeError):
        return -math.inf, math.inf
    if math.isnan(lo_) or math.isnan(hi_):
        return -math.inf, math.inf
    return lo_, hi_


def _quadratic(e, u0, v, others):
    """Roots of ``e = u0`` when its numerator is a polynomial of degree ≤ 2 in ``v``."""
    num = sp.numer(sp.together(e - u0))
    try:
        poly = sp.Poly(num, v)
    except sp.PolynomialError:
        return None
    if poly.degree() < 1 or poly.degree() > 2 or any(v in c.free_symbols for c in poly.all_coeffs()):
        return None
    coeffs = poly.all_coeffs()
    lead = coeffs[0]
    nonzero = [lead] if lead.free_symbols and not (lead.free_symbols & (others | {u0})) else []
    if poly.degree() == 1:
        return [(-coeffs[1] / lead, [])], nonzero
    a, b, c = coeffs
    disc = b ** 2 - 4 * a * c
    return [((-b + sp.sqrt(disc)) / (2 * a), [disc]), ((-b - sp.sqrt(disc)) / (2 * a), [disc])], nonzero


# ----------------------------------------------------------------------------------------------
# Declared diffeomorphisms


def check_declared(name: str, variables: tuple[str, ...], params: tuple[str, ...], forward: tuple[Term, ...],
                   inputs: tuple[str, ...], inverse: tuple[Term, ...]) -> Diffeo:
    """Check ``diffeo name(variables; params) = forward inverse (inputs) = inverse`` (§5.2) and
    return it as a :class:`Diffeo` in the declaration's own names (inputs renamed apart from the
    variables and parameters if needed).  Raises :class:`DiffeoCheckError` (T214 arity, T215
    inverse does not invert, T216 singular Jacobian)."""
    n = len(variables)
    if len(forward) != n:
        raise DiffeoCheckError("T214", f"diffeo {name} has {n} variable(s) but {len(forward)} forward "
                               "component(s); Ψ̂ must map ℝⁿ to ℝⁿ")
    if len(inputs) != n:
        raise DiffeoCheckError("T214", f"diffeo {name}'s inverse takes {len(inputs)} input(s), expected {n}")
    if len(inverse) != n:
        raise DiffeoCheckError("T214", f"diffeo {name}'s inverse has {len(inverse)} component(s), expected {n}")
    if set(inputs) & (set(variables) | set(params)):
        new = fresh_inputs(n, set(variables) | set(params) | set(inputs))
        inverse = tuple(substitute(c, {a: Var(b) for a, b in zip(inputs, new)}) for c in inverse)
        inputs = new
    try:
        nonzero = run_with_timeout(lambda: _check(name, variables, params, forward, inputs, inverse), TIME_LIMIT, cpu=True)
    except TimeoutError:
        raise DiffeoCheckError("T215", f"diffeo {name}: could not check within {TIME_LIMIT:g} CPU s that the inverse "
                               "inverts Ψ̂ and that its Jacobian is nonsingular (simplify the declaration)") from None
    return Diffeo(variables=tuple(variables), forward=tuple(forward), inputs=tuple(inputs),
                  branches=(InverseBranch(tuple(inverse)),), solved_for=None, name=name, nonzero=nonzero)


def _check(name, variables, params, forward, inputs, inverse):
    xs = [symbol(x) for x in variables]
    us = [symbol(u) for u in inputs]
    F = [to_sympy(f) for f in forward]
    G = [to_sympy(g) for g in inverse]
    J = sp.Matrix(F).jacobian(xs)
    det = sp.simplify(J.det())
    if det == 0:
        raise DiffeoCheckError("T216", f"diffeo {name} has a singular Jacobian: det DΨ̂ = 0 everywhere")
    _numeric_inverse(name, variables, params, inputs, F, G, xs, us)
    on_zero_set = [g.subs(us[0], 0) for g in G]
    if any(g.has(sp.zoo, sp.oo, -sp.oo, sp.nan) for g in on_zero_set) and may_vanish(F[0], xs):
        # Ψ̂⁻¹(0, u') is where the delta of the condition sits (LANGUAGE.md §4): infinite there, Ψ̂
        # maps no point onto its zero set's coordinates — DΨ̂ is singular all along the zero set
        raise DiffeoCheckError("T216", f"diffeo {name}'s inverse is infinite on the zero set of its condition "
                               f"({', '.join(f'{x} = {g}' for x, g in zip(variables, G))} at {inputs[0]} = 0): "
                               "Ψ̂ is not a diffeomorphism there (det DΨ̂ = 0 on it), and the derivative's delta "
                               "cannot be taken through it; solve the condition for another variable")
    if det.free_symbols & set(xs):
        if len(det.free_symbols & set(xs)) == 1:
            (x,) = det.free_symbols & set(xs)
            zeros = sp.solveset(det, x, sp.S.Reals)
            if isinstance(zeros, sp.FiniteSet) and len(zeros) > 0:
                raise DiffeoCheckError("T216", f"diffeo {name} has a singular Jacobian where {x} = "
                                       f"{min(zeros, key=str)} (det DΨ̂ = {det})")
        return ()
    if det.free_symbols:
        return (from_sympy(det, (), params),)
    return ()


def _numeric_inverse(name, variables, params, inputs, F, G, xs, us):
    """Ψ̂⁻¹∘Ψ̂ = id and Ψ̂∘Ψ̂⁻¹ = id, symbolically if sympy can, else at random points."""
    ps = [symbol(p) for p in params]
    there = [f.subs(dict(zip(xs, G)), simultaneous=True) - u for f, u in zip(F, us)]
    back = [g.subs(dict(zip(us, F)), simultaneous=True) - x for g, x in zip(G, xs)]
    try:  # a symbolic proof when sympy finds one quickly; otherwise the numeric check decides
        if run_with_timeout(lambda: all(sp.simplify(d) == 0 for d in there + back), SYMBOLIC_LIMIT, cpu=True):
            return
    except TimeoutError:
        pass
    rng = random.Random(0)
    checked = 0
    for _ in range(40):
        env = {s: sp.Rational(rng.randint(-300, 300), 100) for s in xs + us + ps}
        for diffs, what, pt in ((there, "Ψ̂(Ψ̂⁻¹(u)) ≠ u", us), (back, "Ψ̂⁻¹(Ψ̂(x)) ≠ x", xs)):
            for d in diffs:
                try:
                    val = complex(d.subs(env).evalf())
                except (TypeError, ValueError):
                    continue
                if math.isnan(val.real) or math.isnan(val.imag) or abs(val.imag) > 1e-12:
                    continue  # outside the (real) domain of a component: no evidence either way
                checked += 1
                if abs(val) > 1e-9 * (1 + abs(val)):
                    where = ", ".join(f"{s}={env[s]}" for s in pt + ps)
                    raise DiffeoCheckError("T215", f"diffeo {name}: the inverse does not invert: {what} at {where}")
    if not checked:
        raise DiffeoCheckError("T215", f"diffeo {name}: could not verify that the inverse inverts Ψ̂")


def instantiate(psi: Diffeo, decl_params: tuple[str, ...], var_names: tuple[str, ...],
                param_terms: tuple[Term, ...], program_variables: tuple[str, ...] | None = None) -> Diffeo:
    """The declared ``psi`` (parameters ``decl_params`` in declaration order) applied to distinct
    variables ``var_names`` and variable-free ``param_terms``: inputs renamed to fresh ``u0 …``
    (apart from the variables and parameters), then extended by the identity to
    ``program_variables`` (``core.extend_diffeo``) when given."""
    pmap = dict(zip(decl_params, param_terms))
    vmap = {x: Var(y) for x, y in zip(psi.variables, var_names)}
    taken = set(var_names) | set(program_variables or ()) | (diffeo_params(psi) - set(pmap))
    for t in param_terms:
        taken |= free_params(t)
    new_inputs = fresh_inputs(len(psi.inputs), taken)
    imap = {a: Var(b) for a, b in zip(psi.inputs, new_inputs)}
    out = Diffeo(  # (the parameters put in: `k * x - c` with k = 1 is `x - c`, syntax/folding.py)
        variables=tuple(var_names),
        forward=tuple(refolded(substitute(f, vmap, pmap)) for f in psi.forward),
        inputs=new_inputs,
        branches=tuple(InverseBranch(tuple(refolded(substitute(c, imap, pmap)) for c in b.components),
                                     tuple(refolded(substitute(g, imap, pmap)) for g in b.guards))
                       for b in psi.branches),
        solved_for=None, name=psi.name,
        # (a constant other than 0 never vanishes: `needs k ≠ 0` with k = 1 says nothing)
        nonzero=tuple(z for z in (refolded(substitute(z, {}, pmap)) for z in psi.nonzero) if not nonzero_constant(z)))
    if program_variables is not None:
        out = extend_diffeo(out, tuple(program_variables))
    return out
