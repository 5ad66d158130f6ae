"""⟦t⟧ as a simply decomposable function (paper Def. 6.2, Theorem 6.1), built structurally.

``decompose(t)`` returns ⟦t⟧ as a list of :class:`~langur.symbolic.pieces.Piece`s, i.e. as

    ⟦t⟧(x⃗, z⃗) = Σ_i ( Π_j [Φ_ij(x⃗, z⃗) ≥ 0] ) · g_i(x⃗, z⃗)          (Def. 6.2)

with smooth weights ``g_i``.  It follows the proof of Theorem 6.1 (one case per term former)
instead of parsing the ``Piecewise`` that ``langur.denote.denote`` returns:

* a smooth term (no conditional) is one piece, its weight ⟦t⟧ from :func:`langur.sympy_bridge.denote`;
* a diffeomorphic conditional ``ifge0 ⌊Ψ⌋ then s else r`` is ``[π₀Ψ̂ ≥ 0]·⟦s⟧ + [−π₀Ψ̂ > 0]·⟦r⟧``
  (exactly Fig. 7: the then-branch holds on the zero set); every condition keeps its Ψ̂ as a
  :class:`~langur.symbolic.pieces.Psi` with all inverse branches, and the complement's Ψ̂ is Ψ̂
  with its first component negated (inverse branches: ``u₀ ↦ −u₀``);
* a conditional on a variable-free condition is smooth in the variables: it is decided at the
  evaluation point ``at`` when one is given, else kept as a ``Piecewise`` in the parameters;
* products distribute; a smooth primitive (or power) of a discontinuous argument is split over
  the sign patterns of its argument's conditions.

This module also turns a core Diffeo into a sympy ``Psi`` (all inverse branches), for ``ddenote``.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

import sympy as sp

from ..core import (
    Add,
    Call,
    Diffeo,
    IfDiffeo,
    IfGe0,
    Let,
    Mul,
    Pow,
    Prim,
    Term,
    children,
    extend_diffeo,
    shared,
    smooth,
)
from ..diagnostics import LangurError, located
from ..memo import remember
from ..sympy_bridge import FUNCTIONS, const_expr, denote, symbol, symbols
from .pieces import Branch, Condition, Piece, Psi

#: Above this many distinct conditions under one primitive, the sign-pattern split is refused.
MAX_SPLIT_CONDITIONS = 12


# ----------------------------------------------------------------------------------------------
# Context


@dataclass(frozen=True)
class Ctx:
    """What the semantic functions carry down the term.

    ``env``: let-bound parameter → its denotation (in the declared parameters), so every
    expression is over variables and declared parameters only; ``at``: the evaluation point
    (symbols → numbers) deciding variable-free conditionals, or None to keep them symbolic;
    ``variables``: the program's variables, to which every Ψ̂ is extended.
    """

    env: Mapping[str, sp.Expr] = field(default_factory=dict)
    at: Mapping[sp.Symbol, sp.Expr] | None = None
    variables: tuple[str, ...] | None = None

    def bind(self, name: str, value: sp.Expr) -> Ctx:
        return replace(self, env={**self.env, name: value})


# ----------------------------------------------------------------------------------------------
# Conditions and Ψ̂


#: :func:`psi_of`'s answers by (Diffeo, the context's let bindings, point and variables): the same
#: diffeomorphic conditions are made into Ψ̂ again for ⟦p⟧, each piece of ⦇p⦈ and the check (raytrace
#: ∂t: 32 times, 9 distinct).  Not kept when a binding or the point holds a Float (sympy's equality
#: does not see a Float's precision); at most :data:`PSIS` kept (the oldest dropped).
_PSIS: dict = {}
PSIS = 1024


def psi_of(diffeo: Diffeo, ctx: Ctx) -> Psi:
    """The core Diffeo (extended to the program's variables) as a sympy ``Psi``, all branches
    (remembered, :data:`_PSIS`)."""
    values = (*ctx.env.values(), *(ctx.at.values() if ctx.at is not None else ()))
    if any(isinstance(v, sp.Basic) and v.has(sp.Float) or isinstance(v, float) for v in values):
        return _psi_of(diffeo, ctx)
    key = (diffeo, tuple(ctx.env.items()), None if ctx.at is None else tuple(ctx.at.items()), ctx.variables)
    try:
        hit = _PSIS.get(key)
    except TypeError:  # (a value without a hash: not remembered)
        return _psi_of(diffeo, ctx)
    if hit is None:
        hit = remember(_PSIS, key, _psi_of(diffeo, ctx), PSIS)
    return hit


def _psi_of(diffeo: Diffeo, ctx: Ctx) -> Psi:
    if ctx.variables is not None and tuple(diffeo.variables) != tuple(ctx.variables):
        diffeo = extend_diffeo(diffeo, tuple(ctx.variables))
    branches = tuple(
        Branch(tuple((symbol(v), smooth_value(c, ctx)) for v, c in zip(diffeo.variables, b.components)),
               tuple(smooth_value(g, ctx) for g in b.guards))
        for b in diffeo.branches)
    return Psi(variables=symbols(diffeo.variables),
               forward=tuple(smooth_value(f, ctx) for f in diffeo.forward),
               inputs=symbols(diffeo.inputs),
               branches=branches,
               solved_for=symbol(diffeo.solved_for) if diffeo.solved_for else None)


def negate_psi(psi: Psi) -> Psi:
    """Ψ̂ with π₀ negated: same zero set; on the inverse side ``u₀ ↦ −u₀``."""
    u0 = psi.inputs[0]
    flip = {u0: -u0}
    branches = tuple(Branch(tuple((v, e.xreplace(flip)) for v, e in b.inverse),
                            tuple(g.xreplace(flip) for g in b.guards)) for b in psi.branches)
    return replace(psi, forward=(-psi.forward[0],) + tuple(psi.forward[1:]), branches=branches)


def condition_of(diffeo: Diffeo, ctx: Ctx, origin: object = None) -> Condition:
    psi = psi_of(diffeo, ctx)
    return Condition(psi.forward[0], psi, origin)


def complement(c: Condition) -> Condition:
    """[−Φ > 0]: the complement of [Φ ≥ 0] (exactly, also on the zero set Φ = 0, where Fig. 7
    takes the then-branch; the complement of a strict condition is again non-strict)."""
    return Condition(-c.expr, negate_psi(c.psi) if c.psi is not None else None, c.origin, not c.strict)


# ----------------------------------------------------------------------------------------------
# Operations on lists of pieces


def leaf(e: sp.Expr) -> list[Piece]:
    return [] if e == 0 else [Piece((), e)]


def dedupe(conds: Iterable[Condition]) -> tuple[Condition, ...]:
    seen: dict[sp.Expr, Condition] = {}
    for c in conds:
        prev = seen.get(c.expr)
        if prev is None or (c.strict and not prev.strict):  # [Φ ≥ 0]·[Φ > 0] = [Φ > 0]
            seen[c.expr] = c
    return tuple(seen.values())


def normalize(pieces: Iterable[Piece], drop_complements: bool = True) -> list[Piece]:
    """Merge pieces with the same conditions, drop repeated conditions ([c]·[c] = [c]), drop
    pieces with a condition and its complement (a null set) and zero weights."""
    merged: dict[frozenset, Piece] = {}
    for p in pieces:
        conds = dedupe(p.conditions)
        exprs = {c.expr for c in conds}
        if drop_complements and any(-e in exprs for e in exprs):
            continue
        key = frozenset(exprs)
        if key in merged:
            merged[key] = Piece(merged[key].conditions, merged[key].weight + p.weight)
        else:
            merged[key] = Piece(conds, p.weight)
    return [p for p in merged.values() if p.weight != 0]


def multiply(ps: Sequence[Piece], qs: Sequence[Piece]) -> list[Piece]:
    """(Σ_i P_i)·(Σ_j Q_j) = Σ_ij P_i·Q_j."""
    return normalize(Piece(p.conditions + q.conditions, p.weight * q.weight) for p in ps for q in qs)


def scale(ps: Sequence[Piece], factor: sp.Expr) -> list[Piece]:
    return [Piece(p.conditions, factor * p.weight) for p in ps]


def with_conditions(ps: Sequence[Piece], conds: tuple[Condition, ...]) -> list[Piece]:
    return normalize(Piece(conds + p.conditions, p.weight) for p in ps)


def collapse(ps: Sequence[Piece], what: str = "term") -> sp.Expr:
    """Σ weights of a decomposition that must have no conditions (a smooth function)."""
    if any(p.conditions for p in ps):
        raise TypeError(f"{what} is not smooth in the variables (it has a diffeomorphic conditional)")
    return sp.Add(*[p.weight for p in ps])


def apply_smooth(f: Callable[[sp.Expr], sp.Expr], ps: Sequence[Piece]) -> list[Piece]:
    """f(Σ_i Π_j [Φ_ij ≥ 0]·g_i), split over the sign patterns of the distinct conditions."""
    if not any(p.conditions for p in ps):
        return leaf(f(sp.Add(*[p.weight for p in ps])))
    return normalize([Piece(pattern, f(value)) for pattern, value in sign_patterns(ps)])


def sign_patterns(ps: Sequence[Piece]) -> list[tuple[tuple[Condition, ...], sp.Expr]]:
    """Σ_i Π_j [Φ_ij ≥ 0]·g_i as its smooth value on each sign pattern of its distinct conditions
    (every pattern, a value 0 included: the argument of a primitive, which sees its value there)."""
    if not any(p.conditions for p in ps):
        return [((), sp.Add(*[p.weight for p in ps]))]
    keys: list[Condition] = []
    for p in ps:
        for c in p.conditions:
            if all(c.expr != k.expr and -c.expr != k.expr for k in keys):
                keys.append(c)
    if len(keys) > MAX_SPLIT_CONDITIONS:
        raise NotImplementedError(f"a primitive of a term with {len(keys)} distinct discontinuities")
    out = []
    for signs in itertools.product((True, False), repeat=len(keys)):
        pattern = tuple(k if s else complement(k) for k, s in zip(keys, signs))
        holds = {c.expr for c in pattern}
        out.append((pattern, sp.Add(*[p.weight for p in ps if all(c.expr in holds for c in p.conditions)])))
    return out


def decide(cond: sp.Expr, at: Mapping[sp.Symbol, sp.Expr] | None) -> bool | None:
    """``cond ≥ 0`` at the evaluation point, or None when it cannot be decided there."""
    if at is None or not cond.free_symbols <= set(at):
        return None
    v = cond.xreplace(dict(at))
    try:
        return bool(sp.N(v, 30) >= 0)
    except TypeError:
        return None


def select(cond: sp.Expr, then, orelse, at, wrap: Callable[[object, sp.Expr, bool], object]):
    """A conditional on a variable-free condition: decided at ``at`` if possible; else both
    branches with their weights wrapped by ``wrap(item, cond, branch)`` into Piecewise."""
    chosen = decide(cond, at)
    if chosen is True:
        return then
    if chosen is False:
        return orelse
    return wrap(then, cond, True) + wrap(orelse, cond, False)


def gate(weight: sp.Expr, cond: sp.Expr, branch: bool) -> sp.Expr:
    """``weight`` where ``cond ≥ 0`` (branch True) or where ``cond < 0`` (False), else 0."""
    if branch:
        return sp.Piecewise((weight, cond >= 0), (0, True))
    return sp.Piecewise((0, cond >= 0), (weight, True))


def _gate_pieces(ps: list[Piece], cond: sp.Expr, branch: bool) -> list[Piece]:
    return [Piece(p.conditions, gate(p.weight, cond, branch)) for p in ps]


# ----------------------------------------------------------------------------------------------
# The decomposition (Theorem 6.1, one case per term former)


@shared
def decompose(t: Term, ctx: Ctx | None = None) -> list[Piece]:
    """⟦t⟧ as a sum of products of simple discontinuities times smooth weights (Def. 6.2)."""
    ctx = ctx or Ctx()
    if smooth(t):  # Theorem 6.1, smooth term: one piece, no condition (constants, variables, ...)
        return leaf(denote(t, ctx.env))
    match t:
        case Add(a, b):  # Fig. 7, sum
            return normalize(decompose(a, ctx) + decompose(b, ctx))
        case Mul(a, b):  # Fig. 7, product: products distribute
            return multiply(decompose(a, ctx), decompose(b, ctx))
        case Prim(op, a):  # LANGUAGE.md §1, smooth primitive: split over sign patterns
            return apply_smooth(FUNCTIONS[op], decompose(a, ctx))
        case Pow(a, k):  # LANGUAGE.md §1, constant power
            power = const_expr(k)
            return apply_smooth(lambda w: w ** power, decompose(a, ctx))
        case IfGe0(c, a, b):  # Fig. 7, conditional: smooth in the variables
            return normalize(select(smooth_value(c, ctx), decompose(a, ctx), decompose(b, ctx), ctx.at,
                                    _gate_pieces))
        case IfDiffeo(psi, a, b):  # Fig. 7, diffeomorphic conditional: [Φ ≥ 0]·⟦s⟧ + [−Φ > 0]·⟦r⟧
            try:
                c = condition_of(psi, ctx, t.span)
            except LangurError as e:  # (Ψ̂'s inverse was built by sympy: its terms have no place)
                raise located(e, t.span) from None
            return normalize(with_conditions(decompose(a, ctx), (c,))
                             + with_conditions(decompose(b, ctx), (complement(c),)))
        case Let(name, bound, body):  # Fig. 7, let: ⟦s⟧ with z ↦ ⟦t⟧
            return decompose(body, ctx.bind(name, smooth_value(bound, ctx)))
        case Call(module, name, _):
            raise TypeError(f"call of {module}.{name} left in a core term: inline it first")
    raise TypeError(f"not a core term: {t!r}")


def decided_cell(t: Term, ctx: Ctx) -> list[sp.Rel]:
    """The relations on the parameters that :func:`select` decided at ``ctx.at`` while
    decomposing ``t`` (``t1 - t >= 0`` where ``if t < t1 …`` took its first branch): a closed form
    built on those decisions is valid only where they hold.  Follows the branches taken, as
    :func:`decompose` does; each distinct node once per context."""
    out: list[sp.Rel] = []
    seen: set[tuple[int, int]] = set()
    alive = [ctx]  # the contexts stay alive, so that their identities stay theirs
    stack = [(t, ctx)]
    while stack:
        u, c = stack.pop()
        if (id(u), id(c)) in seen or smooth(u):
            continue
        seen.add((id(u), id(c)))
        match u:
            case IfGe0(cond, a, b):
                value = smooth_value(cond, c)
                chosen = decide(value, c.at)
                if chosen is not None:
                    out.append(value >= 0 if chosen else value < 0)
                stack += [(a, c)] if chosen is True else [(b, c)] if chosen is False else [(a, c), (b, c)]
            case Let(name, bound, body):
                alive.append(c.bind(name, smooth_value(bound, c)))
                stack.append((body, alive[-1]))
            case _:
                stack += [(k, c) for k in children(u)]
    return list(dict.fromkeys(r for r in out if r not in (sp.true, sp.false)))


def smooth_value(t: Term, ctx: Ctx | None = None) -> sp.Expr:
    """⟦t⟧ of a term without diffeomorphic conditionals (a variable-free term, a Ψ̂ component)."""
    return collapse(decompose(t, ctx), "term")


def as_expr(ps: Sequence[Piece]) -> sp.Expr:
    """A decomposition back as one sympy expression (indicators as Piecewise), for display."""
    terms = []
    for p in ps:
        cond = sp.And(*[c.expr >= 0 for c in p.conditions])
        terms.append(p.weight if cond is sp.true else sp.Piecewise((p.weight, cond), (0, True)))
    return sp.Add(*terms)
