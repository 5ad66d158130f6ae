"""The transverse rewrite of paper §7.3.2 (``langur check --fix``, ``langur deriv --rewrite``).

"Terms can often be written in a way that satisfies the transversality condition: replacing
``[x ≥ a]²`` with ``[x ≥ a]`` or ``sin([x ≥ a])`` with ``[x ≥ a]·sin(1)`` prior to
differentiation" (§7.3.2).  Where Def. 7.2 fails on a set of positive measure (X301: a condition
multiplied by itself through a product, a power, a primitive or nesting) the derivative
denotation counts a jump twice.  This rewrite removes exactly those multiplications, by two
pointwise identities of Fig. 7:

* **lift**: a conditional is lifted out of a smooth primitive or a power, and out of the sums and
  products between them, ``f(ifge0 ⌊Ψ⌋ then s else r) = ifge0 ⌊Ψ⌋ then f(s) else f(r)`` (so
  ``[x ≥ a]²`` is ``ifge0 x − a then 1 else 0``, ``exp(−2·[x ≥ a])`` is ``ifge0 x − a then
  exp(−2) else 1``, ``(x + [x ≥ a])²`` is ``ifge0 x − a then (x + 1)² else x²``); a product of
  factors that share a zero set is lifted the same way;
* **collapse**: a conditional nested in a branch of a conditional with the same zero set is
  decided by it (``ifge0 Φ then (ifge0 Φ then 1 else 0) else 0`` is ``ifge0 Φ then 1 else 0``;
  on the opposite side, ``[x ≥ t]·[x < t]`` is 0 almost everywhere).  Two conditions have the same
  zero set when their π₀Ψ̂ differ by a constant factor (its sign says which side is which).

Both identities hold pointwise off the zero sets, a null set, so ⟦p⟧ is unchanged; conditionals
whose branches agree on their zero set (``abs``, ``min``, ``max``: no delta) and variable-free
conditionals are left where they are.  A few constant folds keep the result readable (``1·t``,
``t + 0``, ``exp(0)``; ``0·t`` only for a ``t`` defined everywhere).  What it cannot lift (a
conditional under a ``let`` whose condition reads the bound name) it leaves, and says so.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from fractions import Fraction

import sympy as sp

from ..core import (
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Term,
    Var,
    extend_diffeo,
    free_params,
    map_children,
    subterms,
)
from ..diagnostics import Span
from ..primitives import REGISTRY
from ..sympy_bridge import NotSmooth, to_sympy
from .collect import jump_vanishes, zero_set_branches

ZERO, ONE = Const(Fraction(0)), Const(Fraction(1))


@dataclass
class Rewritten:
    """The rewritten program, and what was rewritten (the outermost nodes replaced)."""

    program: Program
    replaced: list[tuple[Term, Term]] = field(default_factory=list)  # (original node, its rewrite)
    left: list[str] = field(default_factory=list)  # what could not be rewritten, and why

    @property
    def changed(self) -> bool:
        return bool(self.replaced)


class _Rewriter:
    def __init__(self, variables: tuple[str, ...]):
        self.variables = variables
        self.replaced: list[tuple[Term, Term]] = []
        self.left: list[str] = []
        self._keys: dict[int, tuple] = {}

    # -- which conditions: zero sets and jumps ----------------------------------------------------

    def key(self, node: IfDiffeo, env: dict) -> tuple[sp.Expr, int] | None:
        """π₀Ψ̂ up to a positive factor, and the sign taken out: same zero set ⇔ same first part."""
        try:
            f = sp.expand(to_sympy(node.psi.forward[0], env))
        except (NotSmooth, KeyError, TypeError):
            return None
        _, prim = f.as_content_primitive()
        if prim.could_extract_minus_sign():
            return -prim, -1
        return prim, 1

    def jumps(self, node: IfDiffeo, env: dict) -> bool:
        """Does the conditional jump on its zero set (a delta in ⦇·⦈)?  ``abs``, ``min``, ``max``
        do not: their branches agree there (collect.py, ``continuous``)."""
        try:
            jump = to_sympy(node.then, env) - to_sympy(node.orelse, env)
        except (NotSmooth, KeyError, TypeError):
            return True
        psi = node.psi
        if set(psi.variables) != set(self.variables):
            psi = extend_diffeo(psi, self.variables)
        try:
            return not jump_vanishes(jump, zero_set_branches(psi, env), self.variables)
        except (NotSmooth, KeyError, TypeError):
            return True

    def keys_in(self, t: Term, env: dict) -> set:
        """Zero sets of the jumping conditionals of ``t`` (not looking into let-bound conditions)."""
        out = set()
        for u in subterms(t):
            if isinstance(u, IfDiffeo) and not (free_params(u.psi.forward[0]) & set(_let_names(t))):
                k = self.key(u, env)
                if k is not None and self.jumps(u, env):
                    out.add(k[0])
        return out

    # -- the rewrite: one case per term former (Fig. 6) -------------------------------------------

    def go(self, t: Term, env: dict) -> Term:
        """``t`` rewritten bottom-up: a rewrite happens where Fig. 8 would multiply a delta by a
        jump on its own zero set (collect.py, ``products``)."""
        match t:
            case Const() | Var() | Param():
                # Fig. 6, constant, variable, parameter: nothing to rewrite
                return t
            case Add(a, b):
                # Fig. 6, sum: summands never multiply
                return replace(t, left=self.go(a, env), right=self.go(b, env))
            case Mul(a, b):
                # Fig. 6, product: factors that jump on the same zero set are lifted and collapsed
                a2, b2 = self.go(a, env), self.go(b, env)
                node = replace(t, left=a2, right=b2)
                if self.keys_in(a2, env) & self.keys_in(b2, env):
                    return self.done(t, tidy(self.collapse(self.hoist(node, env), env, {})))
                return node
            case Prim(op, a):
                # LANGUAGE.md §1, primitive: f(⟦t⟧) jumps where t does, so the conditionals go out
                a2 = self.go(a, env)
                if self.keys_in(a2, env):
                    return self.done(t, tidy(self.collapse(self.push(lambda u: Prim(op, u), self.hoist(a2, env)),
                                                            env, {})))
                return replace(t, arg=a2)
            case Pow(a, k):
                # LANGUAGE.md §1, power: the same, unless k is 0 or 1 (no second factor of the jump)
                a2 = self.go(a, env)
                if k not in (0, 1) and self.keys_in(a2, env):
                    return self.done(t, tidy(self.collapse(self.push(lambda u: Pow(u, k), self.hoist(a2, env)),
                                                            env, {})))
                return replace(t, base=a2)
            case IfGe0(_, s, r):
                # Fig. 6, conditional on a variable-free condition: no delta, the branches are rewritten
                return replace(t, then=self.go(s, env), orelse=self.go(r, env))
            case IfDiffeo(_, s, r):
                # Fig. 6, diffeomorphic conditional: one nested in a branch of one with the same zero
                # set is decided by it (collapse)
                node = replace(t, then=self.go(s, env), orelse=self.go(r, env))
                k = self.key(node, env)
                if k is not None and k[0] in (self.keys_in(node.then, env) | self.keys_in(node.orelse, env)):
                    return self.done(t, tidy(self.collapse(node, env, {})))
                return node
            case Let(name, bound, body):
                # Fig. 6, let: the body sees the bound value
                return replace(t, body=self.go(body, {**env, name: to_sympy(bound, env)}))
            case Call():
                raise ValueError("the transverse rewrite needs the inlined program (no Call nodes)")
        raise TypeError(f"not a core term: {t!r}")

    def done(self, original: Term, new: Term) -> Term:
        new = _with_span(new, original.span)
        # an inner rewrite is subsumed by this one
        inner = {id(u) for u in subterms(original)}
        self.replaced = [(o, n) for o, n in self.replaced if id(o) not in inner]
        self.replaced.append((original, new))
        return new

    def hoist(self, t: Term, env: dict) -> Term:
        """``t`` with its jumping conditionals lifted to the top through sums, products and lets."""
        match t:
            case Add(a, b) | Mul(a, b):
                make = (lambda x, y: Add(x, y)) if isinstance(t, Add) else (lambda x, y: Mul(x, y))
                a2 = self.hoist(a, env)
                if self._liftable(a2, env):
                    return replace(a2, then=self.hoist(make(a2.then, b), env),
                                   orelse=self.hoist(make(a2.orelse, b), env))
                b2 = self.hoist(b, env)
                if self._liftable(b2, env):
                    return replace(b2, then=self.hoist(make(a2, b2.then), env),
                                   orelse=self.hoist(make(a2, b2.orelse), env))
                return make(a2, b2)
            case Let(name, bound, body):
                inner = {**env, name: to_sympy(bound, env)}
                b2 = self.hoist(body, inner)
                if isinstance(b2, IfDiffeo) and name not in free_params(b2.psi.forward[0]) \
                        and self.jumps(b2, inner):
                    return replace(b2, then=self.hoist(Let(name, bound, b2.then), env),
                                   orelse=self.hoist(Let(name, bound, b2.orelse), env))
                if self.keys_in(b2, inner):
                    self.left.append(f"a conditional under `let {name}` whose condition reads {name} is not lifted")
                return replace(t, body=b2)
            case IfDiffeo(_, s, r) if self.jumps(t, env):
                return replace(t, then=self.hoist(s, env), orelse=self.hoist(r, env))
            case IfGe0(_, s, r):
                return replace(t, then=self.hoist(s, env), orelse=self.hoist(r, env))
        return t

    def _liftable(self, t: Term, env: dict) -> bool:
        return isinstance(t, IfDiffeo) and self.jumps(t, env)

    def push(self, f, t: Term) -> Term:
        """``f`` applied at the leaves of the conditional tree ``t``."""
        if isinstance(t, (IfDiffeo, IfGe0)):
            return replace(t, then=self.push(f, t.then), orelse=self.push(f, t.orelse))
        return f(t)

    def collapse(self, t: Term, env: dict, known: dict) -> Term:
        """Conditionals decided by an enclosing one with the same zero set take their branch."""
        match t:
            case IfDiffeo(_, s, r):
                k = self.key(t, env)
                if k is not None and k[0] in known:
                    holds = known[k[0]] == (k[1] > 0)  # is this conditional's π₀Ψ̂ ≥ 0 there?
                    return self.collapse(s if holds else r, env, known)
                if k is None:
                    return replace(t, then=self.collapse(s, env, known), orelse=self.collapse(r, env, known))
                return replace(t, then=self.collapse(s, env, {**known, k[0]: k[1] > 0}),
                               orelse=self.collapse(r, env, {**known, k[0]: k[1] < 0}))
            case Let(name, bound, body):
                return replace(t, body=self.collapse(body, {**env, name: to_sympy(bound, env)}, known))
            case Const() | Var() | Param():
                return t

        return map_children(t, lambda c: self.collapse(c, env, known))


def _let_names(t: Term) -> list[str]:
    return [u.name for u in subterms(t) if isinstance(u, Let)]


def _with_span(t: Term, span: Span | None) -> Term:
    return replace(t, span=span) if span is not None else t


# ----------------------------------------------------------------------------------------------
# Constant folds that keep the value (and the places where it is undefined)


def _total(t: Term) -> bool:
    """Defined everywhere: no primitive, no negative or fractional power."""
    return not any(isinstance(u, Prim) or isinstance(u, Pow) and (u.exponent < 0 or u.exponent.denominator != 1)
                   for u in subterms(t))


def _num(t: Term) -> Fraction | None:
    return t.value if isinstance(t, Const) and not isinstance(t.value, str) else None


def tidy(t: Term) -> Term:
    """Fold ``1·t``, ``t·1``, ``t + 0``, rational arithmetic, ``exp(0)``…; ``0·t`` for a total ``t``;
    ``ifge0 Φ then s else s`` is ``s``."""

    t = map_children(t, tidy)
    span = t.span
    match t:
        case Add(a, b):
            x, y = _num(a), _num(b)
            if x is not None and y is not None:
                return Const(x + y, span)
            if x == 0:
                return b
            if y == 0:
                return a
        case Mul(a, b):
            x, y = _num(a), _num(b)
            if x is not None and y is not None:
                return Const(x * y, span)
            if x == 1:
                return b
            if y == 1:
                return a
            if x == 0 and _total(b) or y == 0 and _total(a):
                return Const(Fraction(0), span)
        case Pow(a, k):
            x = _num(a)
            if x is not None and k.denominator == 1 and (x != 0 or k > 0):
                return Const(x ** int(k), span)
            if x in (0, 1) and k > 0:
                return Const(x, span)
        case Prim(op, a):
            x = _num(a)
            y = REGISTRY[op].at(x) if x is not None else None
            if y is not None:
                return Const(y, span)
        case IfDiffeo(_, s, r) | IfGe0(_, s, r) if s == r:
            return s
    return t


# ----------------------------------------------------------------------------------------------


def transverse(program: Program) -> Rewritten:
    """The §7.3.2 rewrite of a pure core program (see the module docstring)."""
    rw = _Rewriter(tuple(program.variables))
    body = rw.go(program.body, {})
    return Rewritten(program.with_body(body), rw.replaced, list(dict.fromkeys(rw.left)))
