"""Small constructors and generic traversals of core terms (paper §4.1).

The semantic functions are written as one ``match`` each in their own modules; these helpers are
structural only.  A term's direct subterms, :func:`~langur.core.terms.children`, are declared with
the terms; the readers of the attributes a node keeps (:mod:`langur.core.attributes`) are here.
"""

from __future__ import annotations

import functools
from dataclasses import replace
from fractions import Fraction
from typing import Callable

from ..diagnostics import Span
from .attributes import CALLS, DEPTH, FP, FV, MINUS_ONE, PSI_VARS, SIZE, SMOOTH
from .terms import (
    Add,
    Call,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Term,
    TooManyRoots,
    Var,
    children,
)

_MINUS_ONE = MINUS_ONE


def const(v: int | Fraction | str) -> Const:
    return Const(v if isinstance(v, str) else Fraction(v))


def neg(t: Term) -> Term:
    return Mul(Const(_MINUS_ONE), t)


def product(factors: list[Term], span: Span | None = None) -> Term:
    """``f1·f2·…·fn``, grouped from the left."""
    out = factors[0]
    for f in factors[1:]:
        out = Mul(out, f, span)
    return out


def sub(t: Term, s: Term) -> Term:
    return Add(t, neg(s))


def div(t: Term, s: Term) -> Term:
    return Mul(t, Pow(s, _MINUS_ONE))


def subterms(t: Term):
    """Pre-order iteration over ``t`` and its subterms, each distinct node (by identity) once: a
    term shared after inlining (a DAG) is visited once, not once per path."""
    seen: set[int] = set()
    stack = [t]
    while stack:
        u = stack.pop()
        if id(u) in seen:
            continue
        seen.add(id(u))
        yield u
        stack.extend(reversed(children(u)))


def own_root(program, root: ImplicitRoot) -> ImplicitRoot | None:
    """``program``'s own node equal to ``root`` (the first in pre-order, a diffeo's own terms and the
    box's bounds included), or None: ``root`` may be an equal program's node, met through an engine's
    memo of what it compiled, which equal terms share (their spans do not count)."""
    body, box = getattr(program, "body", None), getattr(program, "box", ())
    stack = [t for t in (body, *(t for bounds in box for t in bounds)) if t is not None][::-1]
    seen: set[int] = set()
    while stack:
        u = stack.pop()
        if id(u) in seen:
            continue
        seen.add(id(u))
        if isinstance(u, ImplicitRoot) and u == root:
            return u
        kids = children(u)
        if isinstance(u, IfDiffeo):  # (Ψ̂'s own terms, where a completion's implicit roots are)
            psi = u.psi
            kids += (*psi.forward, *psi.nonzero, *(c for b in psi.branches for c in (*b.components, *b.guards)))
        stack.extend(reversed(kids))
    return None


def refusals_located(entry):
    """An engine's public entry ``entry(program_or_loaded, …)``: a :class:`TooManyRoots` it raises
    names ``program``'s own node and place (:func:`own_root`), not an equal program's that the engine's
    memos kept (bench/history/2026-11-29.md#diag32."""

    @functools.wraps(entry)
    def located(program_or_loaded, *args, **kwargs):
        try:
            return entry(program_or_loaded, *args, **kwargs)
        except TooManyRoots as e:
            if e.root is None:
                raise
            own = own_root(getattr(program_or_loaded, "program", program_or_loaded), e.root)
            if own is None or own is e.root:
                raise
            raise TooManyRoots(str(e), own).with_traceback(e.__traceback__) from None

    return located


def free_vars(t: Term) -> frozenset[str]:
    """Names of variables occurring in ``t`` (including in diffeomorphic conditions; an implicit
    root binds its variable in its equation)."""
    return t.shape[FV]


def free_params(t: Term) -> frozenset[str]:
    """Names of parameters occurring free in ``t`` (``let`` binds its name in its body; a
    diffeomorphic conditional's include its condition's)."""
    return t.shape[FP]


def smooth(t: Term) -> bool:
    """No conditional and no call in ``t``: ⟦t⟧ is a smooth expression (where it is defined)."""
    return t.shape[SMOOTH]


def has_calls(t: Term) -> bool:
    """Whether ``t`` contains a ``Call``."""
    return t.shape[CALLS]


def tree_size(t: Term) -> int:
    """The number of nodes of ``t`` counted once per path (its size written out as a tree)."""
    return t.shape[SIZE]


def depth(t: Term) -> int:
    """The nesting depth of ``t`` (a leaf is 1); a completed condition (``Diffeo.name`` None)
    counts as a child of its conditional, a declared diffeo as a leaf: what the inlined program's
    depth limit (T230, ``langur.syntax.inline``) measures."""
    return t.shape[DEPTH]


def small_value(t: Term):
    """The exact value of the constant (variable-free, parameter-free) term ``t`` when rational
    arithmetic on small numbers decides it (every constant a rational of magnitude ≤ ``SMALL``
    with a denominator of at most ``SMALL_BITS`` bits, integer powers up to ``SMALL_EXPONENT``);
    ``None`` when ``t`` is not constant; ``False`` when it is but not decided so (π, primitives,
    fractional powers, large values)."""
    return t.small


def all_small(t: Term) -> bool:
    """Every subterm of ``t`` has a :func:`small_value` that is not ``False``."""
    return t.small_all


def diffeo_variables(t: Term) -> frozenset[tuple[str, ...]]:
    """The variable lists of the diffeomorphic conditionals in ``t``."""
    return t.shape[PSI_VARS]


def diffeo_params(psi: Diffeo) -> frozenset[str]:
    out: frozenset[str] = frozenset()
    for f in psi.forward:
        out |= free_params(f)
    return out


def substitute(
    t: Term,
    variables: dict[str, Term] | None = None,
    params: dict[str, Term] | None = None,
) -> Term:
    """Capture-avoiding enough substitution of variables and parameters in ``t``.

    Variables inside a diffeomorphic condition may only be renamed to other variables (a
    diffeomorphism composed with an arbitrary map is no longer one): callers that need more
    must re-complete the condition (``langur.syntax.diffeo``).
    """
    variables = variables or {}
    params = params or {}

    def go(u: Term, ps: dict[str, Term]) -> Term:
        match u:
            case Var(name):
                return variables.get(name, u)
            case Param(name):
                return ps.get(name, u)
            case Const():
                return u
            case Let(name, bound, body):
                inner = {k: v for k, v in ps.items() if k != name}
                return replace(u, bound=go(bound, ps), body=go(body, inner))
            case IfDiffeo(psi, a, b):
                return replace(u, psi=substitute_diffeo(psi, variables, ps), then=go(a, ps), orelse=go(b, ps))
            case ImplicitRoot(eq, x, target, lo, hi, slope=slope):  # its variable is bound in its equation
                inner = {k: v for k, v in variables.items() if k != x}
                return replace(u, equation=substitute(eq, inner, ps), target=go(target, ps), lo=go(lo, ps),
                               hi=go(hi, ps), slope=None if slope is None else substitute(slope, inner, ps))
            case _:
                return map_children(u, lambda c: go(c, ps))

    return go(t, params)


def map_children(t: Term, f: Callable[[Term], Term]) -> Term:
    """Rebuild ``t`` with ``f`` applied to each direct child (see :func:`children`)."""
    match t:
        case Const() | Var() | Param():
            return t
        case Add(a, b):
            return replace(t, left=f(a), right=f(b))
        case Mul(a, b):
            return replace(t, left=f(a), right=f(b))
        case Prim(_, a):
            return replace(t, arg=f(a))
        case Pow(a, _):
            return replace(t, base=f(a))
        case IfGe0(c, a, b):
            return replace(t, cond=f(c), then=f(a), orelse=f(b))
        case IfDiffeo(_, a, b):
            return replace(t, then=f(a), orelse=f(b))
        case Let(_, a, b):
            return replace(t, bound=f(a), body=f(b))
        case Call(_, _, args):
            return replace(t, args=tuple(f(a) for a in args))
        case ImplicitRoot(eq, _, target, lo, hi, slope=slope):
            return replace(t, equation=f(eq), target=f(target), lo=f(lo), hi=f(hi),
                           slope=None if slope is None else f(slope))
    raise TypeError(f"not a core term: {t!r}")


def map_children_kept(t: Term, f: Callable[[Term], Term]) -> Term:
    """:func:`map_children`, but ``t`` itself, node for node, when ``f`` returns every child
    unchanged (by identity: a rewrite that changes nothing keeps the term's sharing)."""
    kids = children(t)
    new = tuple(f(c) for c in kids)
    if all(n is c for n, c in zip(new, kids)):
        return t
    it = iter(new)
    return map_children(t, lambda _: next(it))


def substitute_diffeo(psi: Diffeo, variables: dict[str, Term], params: dict[str, Term]) -> Diffeo:
    """Rename Ψ's variables (each must map to a ``Var``) and substitute its parameters."""
    renames: dict[str, str] = {}
    for x in psi.variables:
        if x in variables:
            target = variables[x]
            if not isinstance(target, Var):
                raise ValueError(f"diffeomorphism variable {x} can only be renamed, not replaced by {target!r}")
            renames[x] = target.name
    vmap = {x: Var(y) for x, y in renames.items()}
    return replace(
        psi,
        variables=tuple(renames.get(x, x) for x in psi.variables),
        forward=tuple(substitute(f, vmap, params) for f in psi.forward),
        branches=tuple(
            InverseBranch(
                tuple(substitute(c, {}, params) for c in b.components),
                tuple(substitute(g, {}, params) for g in b.guards),
            )
            for b in psi.branches
        ),
        solved_for=renames.get(psi.solved_for, psi.solved_for) if psi.solved_for else None,
        nonzero=tuple(substitute(n, {}, params) for n in psi.nonzero),
    )


def extend_diffeo(psi: Diffeo, variables: tuple[str, ...]) -> Diffeo:
    """Ψ̂ on a subset of ``variables`` extended by the identity on the rest, inputs in that order.

    The result's ``variables`` are exactly ``variables``; forward gains the missing variables as
    extra components; every branch gains matching identity components on fresh inputs.
    """
    missing = [x for x in variables if x not in psi.variables]
    if not missing and psi.variables == variables:
        return psi
    taken = set(psi.inputs) | set(variables)
    fresh = []
    k = len(psi.inputs)
    for _ in missing:
        while f"u{k}" in taken:
            k += 1
        fresh.append(f"u{k}")
        taken.add(f"u{k}")
    forward = psi.forward + tuple(Var(x) for x in missing)
    inputs = psi.inputs + tuple(fresh)
    branches = []
    for b in psi.branches:
        by_name = dict(zip(psi.variables, b.components))
        by_name.update({x: Var(u) for x, u in zip(missing, fresh)})
        branches.append(InverseBranch(tuple(by_name[x] for x in variables), b.guards))
    return replace(psi, variables=variables, forward=forward, inputs=inputs, branches=tuple(branches))

