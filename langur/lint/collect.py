"""Collection for the transversality checker: which diffeomorphic conditions multiply.

Paper Fig. 8 (the derivative denotation) multiplies the delta of a condition by the other factors
of a product, by the jump ``T⟦s⟧ − ⟦r⟧`` of its branches (nesting), and — through the chain rule —
by ``f'(⟦t⟧)`` for a primitive or a power of a discontinuous ``t``, which jumps on the same set
(paper §7.3.2).  Summands never multiply.  :func:`collect` computes, for a pure core program, the
conditions (:class:`Occurrence`, with π₀Ψ̂ and the inverse branches as sympy expressions) and the
products they form (:class:`Product`), and marks the domain's bounds (LANGUAGE.md §6, §8.3).
:func:`call_sites` recovers, from the elaborated program, the def calls each condition was
inlined through, so that messages point at the user's text.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import sympy as sp

from ..core import (
    Add,
    Call,
    Const,
    Diffeo,
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
    children,
    extend_diffeo,
    shared,
    subterms,
)
from ..diagnostics import LangurError, Span, located
from ..sympy_bridge import NotSmooth, denote, exact_number, symbol, to_sympy
from .algebra import Undecided, vanishes

#: At most this many products of conditions are tracked (beyond: X310, analysis incomplete).
MAX_PRODUCTS = 4000

# ----------------------------------------------------------------------------------------------
# 1. Collection


@dataclass
class Occurrence:
    """One diffeomorphic conditional of the program (one node of the inlined core term)."""

    index: int
    psi: Diffeo
    span: Span | None
    f: sp.Expr  # π₀Ψ̂ over variable and declared-parameter symbols (let-bound names replaced)
    branches: tuple[tuple[dict, tuple], ...]  # ({x: expr over u′}, guards over u′) at u₀ = 0
    uprime: tuple[sp.Symbol, ...]  # the inputs u₁… that parameterize the zero set
    nonzero: tuple[sp.Expr, ...]
    bound: str | None = None  # "x >= 0" when this is a bound of the domain of integration
    bound_at: tuple[int, int] | None = None  # (variable index, 0 lower / 1 upper)
    sites: tuple[Span, ...] = ()  # call sites (outermost first) when it comes from a def's body
    node_span: Span | None = None  # the whole conditional (the condition alone is ``span``)
    continuous: bool = False  # its branches agree on the zero set: no delta (abs, min, max)
    node: IfDiffeo | None = field(default=None, repr=False, compare=False)  # the conditional itself
    moves: bool | None = field(default=None, repr=False)  # :func:`~.geometry.moving`'s answer, once known


@dataclass(frozen=True)
class Product:
    """A monomial of the derivative's structure: the conditions multiplying one another.

    ``squared``: occurrences multiplied by themselves (``[x<t]^2``), with the span of the power
    or primitive that did it."""

    ids: frozenset[int]
    squared: frozenset[tuple[int, Span | None]] = frozenset()


ONE = frozenset({Product(frozenset())})


def zero_set_branches(psi: Diffeo, env: dict[str, sp.Expr]) -> tuple[tuple[dict, tuple], ...]:
    """The zero set of π₀Ψ̂ through each inverse branch at u₀ = 0: ``({x: expr over u′}, guards)``
    (``psi`` already extended to all the program's variables)."""
    zero = {**env, psi.inputs[0]: sp.Integer(0)}
    return tuple(({symbol(x): to_sympy(c, zero) for x, c in zip(psi.variables, b.components)},
                  tuple(to_sympy(g, zero) for g in b.guards)) for b in psi.branches)


def jump_vanishes(jump: sp.Expr, branches, variables) -> bool:
    """Does ``jump`` (⟦s⟧ − ⟦r⟧ of a conditional) vanish on its zero set (``branches`` as
    :func:`zero_set_branches`)?  Then the conditional has no delta (``abs``, ``min``, ``max``)."""

    xs = {symbol(x) for x in variables}
    try:
        for comps, guards in branches:
            e = jump.xreplace(comps)
            if not vanishes(e, tuple(sym for sym in e.free_symbols if sym not in xs), guards):
                return False
    except Undecided:
        return False
    return True


@dataclass
class Collected:
    occurrences: list[Occurrence]
    products: frozenset[Product]
    variables: tuple[str, ...]
    truncated: bool = False


class _Collector:
    def __init__(self, program: Program, point: Mapping[str, object] | None = None):
        self.program = program
        self.point = {symbol(k): exact_number(v) for k, v in (point or {}).items() if v is not None}
        self.variables = program.variables
        self.occurrences: list[Occurrence] = []
        self.top: dict[int, int] = {}  # id(node) of a top-level factor → occurrence index
        self.truncated = False

    def decide(self, c: Term, env: dict[str, sp.Expr]) -> bool | None:
        """``c ≥ 0`` at the parameter values in force, or None (no values, or not decidable)."""
        if not self.point:
            return None
        try:
            v = sp.N(denote(c, env).xreplace(self.point), 30)
            return bool(v >= 0) if v.is_real else None
        except (TypeError, ValueError):
            return None

    def add(self, node: IfDiffeo, env: dict[str, sp.Expr]) -> int:
        psi = node.psi
        if set(psi.variables) != set(self.variables):
            psi = extend_diffeo(psi, tuple(self.variables))
        f = to_sympy(psi.forward[0], env)
        try:
            branches = zero_set_branches(psi, env)
        except LangurError as e:  # (Ψ̂'s inverse was built by sympy: its terms have no place)
            raise located(e, node.psi.span or node.span) from None
        occ = Occurrence(
            index=len(self.occurrences),
            psi=psi,
            span=node.psi.span or node.span,
            f=f,
            branches=tuple(branches),
            node_span=node.span,
            node=node,
            uprime=tuple(symbol(u) for u in psi.inputs[1:]),
            nonzero=tuple(to_sympy(t, env) for t in psi.nonzero),
        )
        self.occurrences.append(occ)
        return occ.index

    def continuous(self, occ: "Occurrence", s: Term, r: Term, env: dict[str, sp.Expr]) -> bool:
        """Is ``ifge0 ⌊Ψ⌋ then s else r`` continuous (smooth branches that agree on the zero set)?
        Then its delta has zero weight and it multiplies nothing (``abs``, ``min``, ``max``)."""
        try:
            jump = to_sympy(s, env) - to_sympy(r, env)
        except NotSmooth:
            return False
        if not jump_vanishes(jump, occ.branches, self.variables):
            return False
        occ.continuous = True
        return True

    def kink(self, occ: "Occurrence", s: Term, r: Term, env: dict[str, sp.Expr]) -> bool:
        """Is ``ifge0 ⌊Ψ⌋ then s else r`` a kink split (``[abs(x - a) <= 0.2]`` split at x = a by
        the desugarer): branches of the same shape whose conditions and smooth parts agree on
        the zero set, so that ⟦s⟧ − ⟦r⟧ vanishes there?  Then its delta has zero weight (it is
        ``continuous``), but its indicator still multiplies the conditions of its branches."""
        diffs = _differences(s, r)
        if diffs is None:
            return False
        try:
            jumps = [to_sympy(a, env) - to_sympy(b, env) for a, b in diffs]
        except NotSmooth:
            return False
        if not all(jump_vanishes(j, occ.branches, self.variables) for j in jumps):
            return False
        occ.continuous = True
        return True

    def times(
        self, A: frozenset[Product], B: frozenset[Product], site: Span | None = None
    ) -> frozenset[Product]:
        out = set()
        for m in A:
            for n in B:
                both = m.ids & n.ids
                out.add(Product(m.ids | n.ids, m.squared | n.squared | frozenset((i, site) for i in both)))
                if len(out) > MAX_PRODUCTS:
                    self.truncated = True
                    return frozenset(out)
        return frozenset(out)

    @shared
    def products(self, t: Term, env: dict[str, sp.Expr]) -> frozenset[Product]:
        """Which conditions multiply in ``t`` (one case per term former of Fig. 6 / Fig. 8)."""
        match t:
            case Const() | Var() | Param():
                # Fig. 8, constants, variables, parameters: ⦇c⦈ = ⦇x⦈ = 0, ⦇z⦈ = γ'(z): no jump
                return ONE
            case Add(a, b):
                # Fig. 8, sum: ⦇t + s⦈ = ⦇t⦈ + ⦇s⦈: summands never multiply
                out = self.products(a, env) | self.products(b, env)
                if len(out) > MAX_PRODUCTS:
                    self.truncated = True
                    out = frozenset(sorted(out, key=lambda p: sorted(p.ids))[:MAX_PRODUCTS])
                return out
            case Mul(a, b):
                # Fig. 8, product: ⦇t⦈·T⟦s⟧ + ⦇s⦈·T⟦t⟧: each delta meets the other factor's jumps
                # (a condition meets itself when both factors share it: a def called twice alike)
                return self.times(self.products(a, env), self.products(b, env), t.span)
            case Prim(_, a):
                # chain rule (LANGUAGE.md §1): f'(⟦a⟧)·⦇a⦈, and f'(⟦a⟧) jumps wherever a does
                A = self.products(a, env)
                return self.times(A, A, t.span)
            case Pow(a, k):
                # chain rule for t ^ k: k·t^(k−1)·⦇t⦈ (no jump left for k = 1, nothing for k = 0)
                if k == 0:
                    return ONE
                A = self.products(a, env)
                return A if k == 1 else self.times(A, A, t.span)
            case IfGe0(c, s, r):
                # Fig. 8, conditional on a variable-free condition: no delta in the variables; at
                # the parameter values in force only the branch it selects multiplies (a bound
                # `if c < 0 then a else b` is one interval, not both), else both may
                chosen = self.decide(c, env)
                if chosen is not None:
                    return self.products(s if chosen else r, env)
                return self.products(s, env) | self.products(r, env)
            case IfDiffeo(_, s, r):
                # Fig. 8, diffeomorphic conditional: δ(π₀Ψ̂)·(D_γ π₀Ψ̂)·T⟦s⟧−⟦r⟧ plus the branches
                # selected by [π₀Ψ̂ ≥ 0]: the condition multiplies every condition of both branches
                # — unless the jump ⟦s⟧ − ⟦r⟧ vanishes on the zero set (abs, min, max): no delta at all
                i = self.add(t, env)
                both = self.products(s, env) | self.products(r, env)
                if self.continuous(self.occurrences[i], s, r, env):
                    return both
                self.kink(self.occurrences[i], s, r, env)  # no delta, but [π₀Ψ̂ ≥ 0] multiplies
                return frozenset(Product(m.ids | {i}, m.squared) for m in both)
            case Let(name, bound, body):
                # Fig. 8, let: ⦇s⦈ with z ↦ ⟦t⟧; conditions in s see the bound value
                return self.products(body, {**env, name: to_sympy(bound, env)})
            case Call():
                raise ValueError("the transversality checker needs the inlined program (no Call nodes)")
        raise TypeError(f"not a core term: {t!r}")


def call_sites(loaded) -> list[tuple[Span | None, tuple[Span, ...]]] | None:
    """Each conditional of the main program in pre-order (as :func:`collect` visits the inlined
    program), with the ``Call`` sites of the elaborated program it was inlined through."""

    main = getattr(loaded, "main", None)
    if main is None or main.program is None:
        return None
    out: list = []

    visits = [0]
    inlined: set = set()

    def walk(t: Term, stack: tuple[Span, ...], depth: int):
        visits[0] += 1
        if depth > 200 or visits[0] > MAX_SITE_VISITS:  # a program shared after inlining: no sites
            raise RecursionError
        match t:
            case Call(module, name, args):
                if (module, name, args) in inlined:  # inlined once, shared (langur.syntax.inline)
                    return
                inlined.add((module, name, args))
                d = loaded.modules[module].defs[name]
                walk(d.body, stack + ((t.span,) if t.span is not None else ()), depth + 1)
            case IfDiffeo(_, s, r):
                out.append((t.span, stack))
                walk(s, stack, depth + 1)
                walk(r, stack, depth + 1)
            case Let(_, _, body):
                walk(body, stack, depth + 1)
            case IfGe0(_, s, r):
                walk(s, stack, depth + 1)
                walk(r, stack, depth + 1)
            case _:
                for ch in children(t):
                    walk(ch, stack, depth + 1)

    try:
        walk(main.program.body, (), 0)
    except (KeyError, RecursionError):
        return None
    return out


def _differences(s: Term, r: Term) -> list[tuple[Term, Term]] | None:
    """The pairs of smooth terms (conditions and leaves) that must agree for ``s`` and ``r`` to be
    equal, when they have the same shape (conditionals, sums, products, primitives and powers
    alike); None when their shapes differ."""
    if s == r:
        return []
    if isinstance(s, (IfDiffeo, IfGe0)) and isinstance(r, (IfDiffeo, IfGe0)):
        # two conditionals (a piece whose variables cancelled is an ifge0 on the parameters)
        a, b = _differences(s.then, r.then), _differences(s.orelse, r.orelse)
        if a is None or b is None:
            return None
        cs, cr = _condition(s), _condition(r)
        return ([] if cs == cr else [(cs, cr)]) + a + b
    match s, r:
        case (Add(a1, b1), Add(a2, b2)) | (Mul(a1, b1), Mul(a2, b2)):
            a, b = _differences(a1, a2), _differences(b1, b2)
            return None if a is None or b is None else a + b
        case Prim(f1, a1), Prim(f2, a2) if f1 == f2:
            return _differences(a1, a2)
        case Pow(a1, k1), Pow(a2, k2) if k1 == k2:
            return _differences(a1, a2)
    if any(isinstance(u, (IfDiffeo, IfGe0)) for u in (*subterms(s), *subterms(r))):
        return None
    return [(s, r)]


def _condition(t: IfDiffeo | IfGe0) -> Term:
    return t.psi.forward[0] if isinstance(t, IfDiffeo) else t.cond


def _factors(t: Term) -> list[Term]:
    return _factors(t.left) + _factors(t.right) if isinstance(t, Mul) else [t]


#: Most nodes :func:`call_sites` visits through the definitions: it walks every path, so a program
#: whose definitions share subterms (inlined as a DAG) would cost one visit per path; past this
#: its findings are located without the call sites they were inlined through.
MAX_SITE_VISITS = 200_000


def _bound_text(x: str, k: int, end: Term) -> str | None:
    """``x >= lo`` or ``x <= hi``, the bound as the linter's messages name it."""
    try:
        return f"{x} {'>=' if k == 0 else '<='} {sp.sstr(to_sympy(end))}"
    except (NotSmooth, KeyError):
        return None


def collect(program: Program, sites: list[tuple[Span | None, tuple[Span, ...]]] | None = None,
            point: Mapping[str, object] | None = None) -> Collected:
    """The conditions of ``program`` and the products they form (see the module docstring).

    ``sites`` (from :func:`call_sites`): for each conditional in pre-order, its span and the
    call sites it was inlined through; attached to the occurrences when they line up."""
    c = _Collector(program, point)
    prods = c.products(program.body, {})
    if (
        sites is not None
        and len(sites) == len(c.occurrences)
        and all(s == o.node_span for (s, _), o in zip(sites, c.occurrences))
    ):
        for (_, stack), o in zip(sites, c.occurrences):
            o.sites = stack
    # The domain's bounds [x ≥ lo]·[hi ≥ x] are the body's first conditions (Program.body, §6, §8.3).
    bounds = [(i, k, x, end) for i, (x, (lo, hi)) in enumerate(zip(program.variables, program.box))
              for k, end in enumerate((lo, hi))]
    if program.domain:  # the domain's indicators come first, each with its diffeomorphic conditionals
        occurrences = iter(c.occurrences)
        for (i, k, x, end), indicator in zip(bounds, (ind for iv in program.domain for ind in (iv.lower, iv.upper))):
            text = _bound_text(x, k, end)
            for _ in range(sum(isinstance(u, IfDiffeo) for u in subterms(indicator))):
                occ = next(occurrences, None)
                if occ is not None and text is not None:  # a bound that is not smooth: no label
                    occ.bound, occ.bound_at = text, (i, k)
    else:  # a box read off the integrand's own bounding indicators: label the factors it came from
        n_top = 0
        for fac in _factors(program.body):
            if not isinstance(fac, IfDiffeo):
                break
            n_top += 1
        for i, k, x, end in bounds:
            try:
                expr = symbol(x) - to_sympy(end) if k == 0 else to_sympy(end) - symbol(x)
            except (NotSmooth, KeyError):  # a bound that is not a smooth term: nothing to label
                continue
            for occ in c.occurrences[:n_top]:
                if occ.bound is None and sp.expand(occ.f - expr) == 0:
                    occ.bound, occ.bound_at = _bound_text(x, k, end), (i, k)
    return Collected(c.occurrences, prods, tuple(program.variables), c.truncated)
