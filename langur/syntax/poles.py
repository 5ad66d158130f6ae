"""A condition whose sign changes where its completion does not look: the sign of its factors (§5, §7).

Fig. 8's rule for ``ifge0 ⌊Ψ⌋`` puts the derivative's delta on the zero set of π₀Ψ̂, which is
where the condition changes sign only when Ψ̂ is a C¹ diffeomorphism of ℝⁿ (Fig. 6, Def. 3.4).  A
condition written as a quotient or product of factors is none across a factor it was not solved
for: ``[(x − a)/(y + b) ≥ 0]`` completed as ``x = a + u₀·(y + b)`` changes sign at its pole
``y = −b`` with no root there, and ``[(x − a)·(y − b) ≥ 0]`` solved for ``y`` (``y = b + u₀/(x − a)``)
changes sign on ``x = a``, which Ψ̂⁻¹(0, ·) never reaches.  Where such a set moves with the
parameters the jump moves, and ⦇p⦈ — with the delta of the one zero set only — misses its part of
D⟦p⟧ (Theorem 8.1 fails: ``deriv --wrt b`` printed 0 for −2a).

Almost everywhere (off the factors' zero sets, a null set: nonzero analytic functions)

    [c · Π fᵢ^kᵢ ≥ 0]  =  [c ≥ 0] ⊕ [f₁ ≥ 0] ⊕ … (over the odd kᵢ)

(⊕: the parity of the signs — the condition holds where an even number of ``c``, ``f₁``, … are negative)

with ``c`` free of variables and the ``fᵢ`` the factors over variables; an even power is positive
a.e. and drops out.  Each ``[fᵢ ≥ 0]`` is a conditional of its own, completed to a diffeomorphism
of its own, so each moving sign change gets its delta (Fig. 8) and the zero sets meet
transversally where the factors' do (Def. 7.2).  ⟦p⟧ is unchanged: the integrands agree off a null
set, where the condition as written is 0/0 or undefined anyway (LANGUAGE.md §1).

:func:`sign_factors` decides when the split is needed: only when a factor over variables that
mentions a parameter (its sign change moves) is missed by the completion found for the condition
as a whole — so a pole that does not move, or a product whose completion reaches its one moving
factor, keeps today's completion (and its Ψ̂, closed forms, printed terms) — and whenever a factor
over variables has multiplicity > 1 (``(x − a)³``, ``(x − a)²·(exp(x) − 1.5)``): there ∂/∂x of
the condition vanishes on that factor's zero set, Ψ̂ is no diffeomorphism (Def. 3.4; a degenerate
turning point, X316, or a double root, X305/X315), while the parity rule's odd power keeps the
factor once and an even one drops it (a touch, no jump) — bench/history/2026-11-29.md#pole32.
A condition with no completion as a whole (in a ``def``, with no box; on a box whose intervals all
move) is split when a pole moves, or when it is a product with no pole of which some factor moves
and every factor completes on its own (``(x − a)(x − a − 0.3)(x − a + 0.2)``: fuzz33's F1,
bench/history/2026-11-29.md#factor33; a pole that does not move stays refused (T207).
"""

from __future__ import annotations

import sympy as sp

from ..core import (
    Call,
    Diffeo,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Let,
    Pow,
    Prim,
    Term,
    TooManyRoots,
    children,
    free_vars,
    map_children_kept,
    subterms,
)
from ..primitives import REGISTRY
from ..sympy_bridge import NotSmooth, from_sympy, symbol, to_sympy
from ..timebox import run_with_timeout
from .folding import defined_everywhere

#: At most this many factors over variables are split on (2k − 1 conditionals for k factors).
MAX_FACTORS = 6
#: CPU-second limit of the factoring and of the check that the completion reaches every factor.
TIME_LIMIT = 3.0


class TooManyFactors(Exception):
    """A condition changes sign at more moving factors than :data:`MAX_FACTORS`."""


class MovingPole(Exception):
    """A condition changes sign at a pole that moves with the parameters inside a factor that is
    not a polynomial (``exp(1/(x − b)) − 2``): no split into factors puts a delta there, so the
    derivative is refused (the message says why and how to rewrite)."""


def sign_factors(cond: Term, psi: Diffeo | None) -> tuple[Term | None, tuple[Term, ...]] | None:
    """``(c, (f₁, …))`` with ``[cond ≥ 0] = [c ≥ 0] ⊕ [f₁ ≥ 0] ⊕ …`` a.e. (``c`` None: a positive
    constant) when the sign of ``cond`` changes on a set that moves with the parameters and that
    ``psi`` (``cond``'s completion, None when it has none) does not parametrize; else None.
    Raises :class:`TooManyFactors`, :class:`MovingPole`."""
    try:
        expr = to_sympy(cond)
    except NotSmooth:
        return None
    try:
        found = run_with_timeout(lambda: _split(expr, cond, psi), TIME_LIMIT, cpu=True)
    except TimeoutError:
        return None
    if found is None:
        return None
    coefficient, factors = found
    if len(factors) > MAX_FACTORS:
        raise TooManyFactors(f"it changes sign at {len(factors)} factors, more than {MAX_FACTORS}")
    variables = sorted(free_vars(cond))
    params = sorted(s.name for s in coefficient.free_symbols | {s for f in factors for s in f.free_symbols}
                    if s.name not in variables)
    if coefficient.is_number and coefficient < 0 and factors:  # a negative constant: the first factor's sign flipped
        coefficient, factors = -coefficient, [-factors[0], *factors[1:]]
    # (a negative constant and only even powers, [−(x − a)² ≥ 0]: false a.e., ifge0 −1 — a constant condition)
    c = None if coefficient.is_number and coefficient > 0 else from_sympy(coefficient, (), params)
    return c, tuple(from_sympy(f, variables, params) for f in factors)


def _split(expr: sp.Expr, cond: Term, psi: Diffeo | None):
    variables = {s for s in expr.free_symbols if s.name in free_vars(cond)}
    quotient = sp.together(expr)
    coefficient, factors, poles, repeated = sp.S.One, [], [], False
    for arg in sp.Mul.make_args(quotient):
        if not arg.free_symbols & variables:
            coefficient *= arg
            continue
        base, k = arg.as_base_exp()
        if not k.is_Integer:
            return None  # a root of a term over variables: no sign change to split on where it is defined
        if base.is_polynomial(*variables):
            sub_coefficient, parts = sp.factor_list(base)
            coefficient *= sub_coefficient ** k
        else:
            parts = [(base, 1)]  # a transcendental factor (exp(x) - a): its own sign
        for part, m in parts:
            if not part.free_symbols & variables:
                coefficient *= part ** (m * k)
                continue
            repeated |= m * k > 1  # (a repeated pole, k < −1, is the parity rule's: no zero set to degenerate)
            if (m * k) % 2:
                factors.append(part)
                if k < 0:
                    poles.append(part)
    for f in factors:
        inner = _moving_pole(f, variables)
        if inner is not None:
            raise MovingPole(f"it changes sign where {inner} = 0, a pole that moves with the parameters, and no "
                             "conditional's zero set is there: the derivative's delta (Fig. 8) sits on the zero set "
                             "of the condition only and would miss that jump; write the condition so that the pole is "
                             "a factor's ([exp(1/(x - b)) >= 2] is [1/(x - b) >= log(2)]: a quotient, split at its "
                             "pole), or split the domain at the pole")
    if repeated:  # a factor of multiplicity > 1: a degenerate turning point (odd) or a touch (even) on it
        return coefficient, factors
    if len(factors) < 2 and not poles:
        return None  # one factor, not under a division: the condition itself, up to its coefficient
    moving = [f for f in factors if f.free_symbols - variables]
    if psi is None:  # no completion: split for a pole that moves, or a product with no pole of which a factor
        # moves (fuzz33's F1: bench/history/2026-11-29.md#factor33; the caller splits only if each factor completes on its
        # own); a fixed pole stays refused (T207), pole31's rule
        return (coefficient, factors) if any(f in moving for f in poles) or moving and not poles else None
    if not moving or _reaches(psi, moving, expr.free_symbols - variables):
        return None
    return coefficient, factors


def removable(cond: Term) -> Term | None:
    """``cond`` as the term sympy reads it (its continuous extension) when ``cond`` is undefined only
    at poles — zeros of the bases of its negative integer powers, a null set — and that term is
    defined everywhere (``x + 0·(1/(x − a))`` is ``x``; ``(x − a)/(x − a)·x`` is ``x``); else None.
    Both are one condition a.e. (⟦p⟧ is unchanged), but the term as written is undefined on its own
    zero set, where the derivative's delta evaluates it (Fig. 8: D π₀Ψ̂ at π₀Ψ̂ = 0): the exact
    engine, through sympy, gave the extension's −1 and Monte Carlo NaN.  The completion Ψ̂ is the
    extension's, a C¹ diffeomorphism (Def. 3.4): both engines evaluate that (bench/history/2026-11-29.md#pole32)."""
    for u in subterms(cond):
        if (type(u) is Pow and u.exponent.denominator != 1 or type(u) in (Call, ImplicitRoot, IfDiffeo)
                or type(u) is Prim and not REGISTRY[u.op].domain.everywhere):
            return None  # a root, a primitive with a restricted domain, …: undefined perhaps on more than a null set
    try:
        expr = to_sympy(cond)
        variables = sorted(free_vars(cond))
        out = from_sympy(expr, variables, sorted(s.name for s in expr.free_symbols if s.name not in variables))
    except (NotSmooth, ValueError):
        return None
    return out if defined_everywhere(out) else None


#: The largest subterm (in nodes) :func:`extended` hands to sympy, and how many it hands at most per
#: term (each a conversion to sympy and back): a bound on the front end's cost.
EXTEND_NODES = 400
EXTEND_TRIES = 16


def extended(t: Term) -> Term:
    """``t`` with each largest smooth subterm that is undefined at poles only and that
    :func:`removable` extends (``1 + 0·(1/(x − a))`` is ``1``; ``(x − a)/(x − a)`` is ``1``)
    replaced by its continuous extension; ``t`` itself, node for node, where there is none.

    The same choice as :func:`removable`'s for a condition, for the integrand's other factors:
    they agree with the term as written off a null set, so ⟦p⟧ is unchanged (§4, Fig. 7), but the
    derivative's delta evaluates them on a jump's zero set (Fig. 8), which may be the pole: the
    exact engine, through sympy, read the extension there ((1 − a)·e^a for
    ``(1 + 0·(1/(x − a)))·exp(min(x, a))``) and Monte Carlo NaN (fuzz33's F2;
    bench/history/2026-11-29.md#zero33.  A pole that is no removable singularity stays as written (a true pole on a delta's
    zero set: the boundary term does not exist, and both engines say so)."""
    if defined_everywhere(t):
        return t
    smooth: dict[int, tuple[bool, bool, int]] = {}  # id → (no conditional, root, call, …; has a pole; nodes)
    tries = [EXTEND_TRIES]

    def shape(u: Term) -> tuple[bool, bool, int]:
        found = smooth.get(id(u))
        if found is None:
            tu = type(u)
            ok = not (tu in (Call, ImplicitRoot, IfDiffeo, IfGe0, Let) or tu is Pow and u.exponent.denominator != 1
                      or tu is Prim and not REGISTRY[u.op].domain.everywhere)
            pole = tu is Pow and u.exponent < 0 and bool(free_vars(u.base))
            nodes = 1
            for c in children(u):
                c_ok, c_pole, c_nodes = shape(c)
                ok, pole, nodes = ok and c_ok, pole or c_pole, nodes + c_nodes
            found = smooth[id(u)] = (ok, pole, nodes)
        return found

    done: dict[int, Term] = {}

    def go(u: Term) -> Term:
        out = done.get(id(u))
        if out is not None:
            return out
        ok, pole, nodes = shape(u)
        out = None
        if not pole:
            out = u
        elif ok and nodes <= EXTEND_NODES and tries[0] > 0:
            tries[0] -= 1
            out = removable(u)
        if out is None:
            out = map_children_kept(u, go)
        done[id(u)] = out
        return out

    return go(t)


def _moving_pole(f: sp.Expr, variables: set) -> sp.Expr | None:
    """A pole inside ``f`` where ``f`` changes sign and that moves: the base of an odd negative
    power, or the argument of ``tan``'s cosine, over variables and mentioning a parameter."""
    for node in sp.preorder_traversal(f):
        if node.is_Pow and node.exp.is_Integer and node.exp < 0 and node.exp % 2:
            base = node.base
        elif isinstance(node, sp.tan):
            base = sp.cos(node.args[0])
        else:
            continue
        if base.free_symbols & variables and base.free_symbols - variables:
            return base
    return None


#: Values of the parameters (and of the zero set's other coordinates) at which :func:`_reaches`
#: compares (two, so that a coincidence at one is not taken for identity; distinct per symbol, so
#: that ``a = b`` is not one of them).
_PROBES = (lambda j: sp.Rational(2 * j + 3, 7), lambda j: sp.Rational(-(3 * j + 5), 11))


def _reaches(psi: Diffeo, factors: list[sp.Expr], params: set) -> bool:
    """Whether every factor vanishes on some inverse branch's image of the zero set ``u₀ = 0``: the
    completion's delta then sits on each factor's sign change, as Fig. 8 needs.  Identically in the
    parameters, or else at each of two points of theirs where a branch's image is defined (a branch
    ``x = ±sqrt(u₀ + a²)`` reaches ``x − a`` as ``Abs(a)``; ``erfinv(1/a − 2)`` exists for some ``a``
    only); where no image is defined at either point, the completion is kept (no evidence it misses)."""
    u0 = symbol(psi.inputs[0])
    images = []
    for branch in psi.branches:
        try:
            images.append({symbol(x): to_sympy(c).subs(u0, 0) for x, c in zip(psi.variables, branch.components)})
        except NotSmooth:
            continue
    for f in factors:
        on = [f.subs(image, simultaneous=True) for image in images]
        if any(_vanishes(v) for v in on):
            continue
        # the parameters and the zero set's other coordinates u' at two points
        ordered = sorted(set().union(*(v.free_symbols for v in on)) | params, key=lambda s: s.name)
        probes = [{p: probe(j) for j, p in enumerate(ordered)} for probe in _PROBES]
        defined = [[w for w in (v.subs(at) for v in on) if _defined(w)] for at in probes]
        if any(values and not any(abs(complex(w.evalf(30))) < 1e-20 for w in values) for values in defined):
            return False
    return True


def _defined(value: sp.Expr) -> bool:
    """A real, finite number (an image of the zero set that exists at these parameter values)."""
    try:
        z = complex(value.evalf(30))
    except (TypeError, ValueError, TooManyRoots):
        return False
    return z == z and abs(z.real) != float("inf") and abs(z.imag) <= 1e-20 * (1 + abs(z.real))


def _vanishes(value: sp.Expr) -> bool:
    return not value.has(sp.zoo, sp.oo, -sp.oo, sp.nan) and sp.simplify(value) == 0


__all__ = ["MAX_FACTORS", "MovingPole", "TooManyFactors", "extended", "removable", "sign_factors"]
