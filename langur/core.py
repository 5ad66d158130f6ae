"""The core language Langur (paper §4; LANGUAGE.md §1), shared by every engine.

    t, s, r ::= c | x | z | t + s | t · s | f(t) | t ^ k
              | ifge0 t then s else r          -- t variable-free
              | ifge0 ⌊Ψ⌋ then s else r        -- Ψ a C¹ diffeomorphism in the variables
              | let z = t in s                 -- t variable-free
    p       ::= int t d(x1, …, xn)

The extension by smooth primitives ``f(t)`` and constant powers ``t ^ k`` is LANGUAGE.md §1's;
``t / s`` is ``t · s ^ -1`` and ``t − s`` is ``t + (−1)·s``.

Nodes are frozen dataclasses.  Every node may carry the source ``span`` it came from (for
diagnostics); spans never take part in equality or hashing, so ``parse(print(t)) == t`` compares
structure only.

``Call`` is not part of the paper's core: it appears only in a module's *elaborated* form (one
module's definitions with calls into other modules left as links, for separate compilation, §9).
``langur.syntax.inline.inline`` removes every ``Call``; the semantic functions ``denote`` and
``ddenote`` see pure core terms.
"""

from __future__ import annotations

import functools
import threading
from dataclasses import dataclass, field, replace
from fractions import Fraction
from typing import Callable, TypeVar, Union

from .diagnostics import Span

T = TypeVar("T")

PI = "pi"  # the one named constant: Const(PI) is π


def _span() -> Span | None:
    return field(default=None, compare=False, repr=False)  # type: ignore[return-value]


@dataclass(frozen=True)
class Const:
    """A constant ``c``: an exact rational, or the string ``"pi"`` for π."""

    value: Fraction | str
    span: Span | None = _span()


@dataclass(frozen=True)
class Var:
    """A variable of integration ``x`` (or an input ``u`` of an inverse diffeomorphism)."""

    name: str
    span: Span | None = _span()


@dataclass(frozen=True)
class Param:
    """A parameter ``z`` (declared, or bound by ``let``)."""

    name: str
    span: Span | None = _span()


@dataclass(frozen=True)
class Add:
    left: "Term"
    right: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class Mul:
    left: "Term"
    right: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class Prim:
    """A smooth primitive applied to a term: ``op`` names an entry of
    :data:`langur.primitives.REGISTRY`."""

    op: str
    arg: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class Pow:
    """``base ^ exponent`` with a constant rational exponent (``t / s`` is ``t · s ^ -1``)."""

    base: "Term"
    exponent: Fraction
    span: Span | None = _span()


@dataclass(frozen=True)
class IfGe0:
    """``ifge0 cond then then else orelse`` with a variable-free ``cond`` (Fig. 6, conditional)."""

    cond: "Term"
    then: "Term"
    orelse: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class IfDiffeo:
    """``ifge0 ⌊Ψ⌋ then then else orelse`` (Fig. 6, diffeomorphic conditional).

    The condition is ``π₀Ψ̂ ≥ 0``, i.e. ``psi.forward[0] ≥ 0``.
    """

    psi: "Diffeo"
    then: "Term"
    orelse: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class Let:
    """``let name = bound in body``: ``bound`` variable-free, ``name`` a parameter in ``body``."""

    name: str
    bound: "Term"
    body: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class Call:
    """A call of ``def name`` of module ``module`` (elaborated form only; see module docstring).

    ``args`` follow the def's argument kinds: a ``var`` argument is a term over variables, a
    ``param`` argument a variable-free term.
    """

    module: str
    name: str
    args: tuple["Term", ...]
    span: Span | None = _span()


@dataclass(frozen=True)
class ImplicitRoot:
    """An implicit root (issue 18: an inverse branch with no closed form).

    It occurs only in an :class:`InverseBranch`'s components and guards: ``equation`` is a smooth
    term over ``Var(variable)`` (bound here), parameters and, for a condition in several variables,
    Ψ̂⁻¹'s other inputs (the other variables' values), ``target`` a term over Ψ̂⁻¹'s inputs and
    parameters, ``lo`` and ``hi`` variable-free.

    * ``index`` is None: the one ``x`` in ``[lo, hi]`` with ``equation(x) = target``, where
      ``equation`` is strictly monotone on ``[lo, hi]`` (a piece between two turning points).  The
      branch's guard says that ``target`` lies between ``equation(lo)`` and ``equation(hi)``, so the
      root exists; outside it the root is undefined (NaN).
    * ``index`` is k: the k-th (from 0, increasing) of the points of ``[lo, hi]`` where
      ``equation − target`` changes sign, ``hi`` when there are only k or fewer; there must be at
      most ``of`` of them, or the term is undefined and evaluating it raises :class:`TooManyRoots`
      (a turning point that moves with the parameters, ``equation`` = ∂f/∂x).  ``slope`` is then
      ∂equation/∂variable as a term (over the same names): where an interval enclosure of it
      excludes 0 on a cell, ``equation`` has at most one zero there, so the engines certify that
      they miss no sign change (issue 18); without it they refuse to evaluate the term.

    Its derivative is the implicit function theorem's: ``∂x* = (∂target − ∂equation/∂θ · ∂θ) /
    ∂equation/∂x`` at ``x*``.
    """

    equation: "Term"
    variable: str
    target: "Term"
    lo: "Term"
    hi: "Term"
    index: int | None = None
    of: int = 0
    slope: "Term | None" = None
    span: Span | None = _span()


class TooManyRoots(Exception):
    """An indexed :class:`ImplicitRoot` met more sign changes than its ``of`` (the completion
    split the domain into that many pieces at most), or sign changes it cannot certify it counted
    all of; ``span``: the condition's place in the source (issue 18)."""

    def __init__(self, message: str, span: Span | None = None):
        super().__init__(message)
        self.span = span


Term = Union[Const, Var, Param, Add, Mul, Prim, Pow, IfGe0, IfDiffeo, Let, Call, ImplicitRoot]


@dataclass(frozen=True)
class InverseBranch:
    """One branch of Ψ̂⁻¹: ``variables[i] = components[i](u⃗; z⃗)`` where every guard is ``≥ 0``.

    ``components`` are terms over ``Var(u)`` for the diffeo's ``inputs`` and over parameters.
    ``guards`` (same kind of terms) say where this branch exists, e.g. ``u0 + a`` for the branch
    ``x = sqrt(u0 + a)`` of ``x^2 - a``.  The branches' images partition (up to a null set) the part
    of ℝⁿ the program integrates over, so that

        ∫ h(x) δ(π₀Ψ̂(x)) dx = Σ_branches ∫_{guards ≥ 0} h(Ψ̂_b⁻¹(0, u')) |det DΨ̂_b⁻¹(0, u')| du'.
    """

    components: tuple["Term", ...]
    guards: tuple["Term", ...] = ()


@dataclass(frozen=True)
class Diffeo:
    """A (piecewise) C¹ diffeomorphism ``x⃗ ↦ Ψ̂(x⃗; z⃗)`` with its inverse branches (§4, §5).

    * ``variables``: Ψ̂'s inputs x⃗, in order (after inlining: all variables of the program).
    * ``forward``: Ψ̂'s components, terms over ``Var(x)`` and parameters; ``forward[0]`` = π₀Ψ̂ is
      the condition.
    * ``inputs``: the names of Ψ̂⁻¹'s inputs u⃗ (disjoint from ``variables`` and all parameters).
    * ``branches``: Ψ̂⁻¹, one :class:`InverseBranch` per branch (one for a true diffeomorphism).
    * ``solved_for``: for an automatically completed condition, the variable isolated from
      π₀Ψ̂ = u₀ (then ``forward = (condition, the other variables in order)``); else ``None``.
    * ``name``: the ``diffeo`` declaration's name, or ``None`` when completed.
    * ``nonzero``: variable-free terms that must not vanish for Ψ̂ to be a diffeomorphism (a
      parameter coefficient such as ``t`` in ``t*x - 1``).
    """

    variables: tuple[str, ...]
    forward: tuple["Term", ...]
    inputs: tuple[str, ...]
    branches: tuple[InverseBranch, ...]
    solved_for: str | None = None
    name: str | None = None
    nonzero: tuple["Term", ...] = ()
    span: Span | None = _span()

    @property
    def condition(self) -> "Term":
        """π₀Ψ̂."""
        return self.forward[0]


@dataclass(frozen=True)
class Interval:
    """One interval ``[lo, hi]`` of a program's domain ``int ([l1, u1], …) t d(x⃗)`` (LANGUAGE.md §6).

    ``lo`` and ``hi`` are variable-free terms (parameters allowed); ``lower`` and ``upper`` are the
    indicators ``[x − lo ≥ 0]`` and ``[hi − x ≥ 0]`` as the front end completed them (a diffeomorphic
    conditional; a conditional on the parameters around two of them when a bound is one), which
    multiply the integrand (§6 sugar, §8.3); ``span`` is the interval's text.
    """

    variable: str
    lo: "Term"
    hi: "Term"
    lower: "Term"
    upper: "Term"
    span: Span | None = _span()


@dataclass(frozen=True)
class Program:
    """``int domain? integrand d(variables)`` (Fig. 11).

    ``domain``: the declared intervals, one per variable in order, or ``()`` when the program has
    none (then ``integrand`` bounds itself with indicator factors, Prop. 8.1).  ``box`` is a
    bounding box outside of which the integrand vanishes: one ``(lo, hi)`` pair of variable-free
    terms per variable (the domain, or read off the bounding indicators); it is what makes the
    integrand compactly supported (Prop. 8.1) and where samplers sample.  ``body`` is the term the
    semantics integrate: the domain's indicators times the integrand (§6 sugar).
    """

    integrand: "Term"
    variables: tuple[str, ...]
    box: tuple[tuple["Term", "Term"], ...]
    domain: tuple[Interval, ...] = ()
    span: Span | None = _span()

    @functools.cached_property
    def body(self) -> "Term":
        """``[x1 ≥ l1]·[u1 ≥ x1]·…·integrand`` (the domain's indicators first, in order)."""
        if not self.domain:
            return self.integrand
        return product([ind for iv in self.domain for ind in (iv.lower, iv.upper)] + [self.integrand], self.span)

    def with_body(self, body: "Term") -> "Program":
        """This program integrating ``body`` instead (a rewrite of :attr:`body`): the domain stays when
        ``body`` is still its indicators times an integrand, else it is dropped (the box stays)."""
        if self.domain and isinstance(body, Mul) and body.left == self.body.left:
            return replace(self, integrand=body.right)
        return replace(self, integrand=body, domain=())


# Terms are shared after inlining (a definition called twice is one subterm reached twice, §9): a
# term is then a DAG, and a recursive hash or equality would visit it once per path.  Each node's
# hash is computed once and kept; equality compares hashes before fields.  The kept hash is not
# pickled (string hashes differ between processes).


_EQUAL = threading.local()


def _sharing(cls):
    field_hash, field_eq = cls.__hash__, cls.__eq__

    def __hash__(self):
        try:
            return self.__dict__["_hash"]
        except KeyError:
            h = field_hash(self)
            object.__setattr__(self, "_hash", h)
            return h

    def __eq__(self, other):
        if self is other:
            return True
        if other.__class__ is not self.__class__:
            return NotImplemented
        if hash(self) != hash(other):
            return False
        # Two DAGs equal node for node: each pair of nodes is compared once (while the outermost
        # comparison runs), not once per path.
        known = getattr(_EQUAL, "pairs", None)
        outer = known is None
        if outer:
            known = _EQUAL.pairs = set()
        try:
            pair = (id(self), id(other))
            if pair in known:
                return True
            equal = field_eq(self, other)
            if equal:
                known.add(pair)
            return equal
        finally:
            if outer:
                _EQUAL.pairs = None

    def __getstate__(self):  # the kept hash, variables and parameters are recomputed
        return {k: v for k, v in self.__dict__.items() if not k.startswith("_")}

    field_repr = cls.__repr__

    def __repr__(self):  # written out, a shared term can have 2^40 nodes
        if cls in _TERMS and tree_size(self) > REPR_LIMIT:
            return f"<{cls.__name__}: {tree_size(self):,} nodes written out>"
        return field_repr(self)

    cls.__hash__, cls.__eq__, cls.__getstate__, cls.__repr__ = __hash__, __eq__, __getstate__, __repr__
    return cls


#: Largest term ``repr`` writes out (nodes); a larger one is summarized.
REPR_LIMIT = 10_000
_TERMS = (Const, Var, Param, Add, Mul, Prim, Pow, IfGe0, IfDiffeo, Let, Call, ImplicitRoot)

for _cls in (*_TERMS, InverseBranch, Diffeo, Interval, Program):
    _sharing(_cls)


_SCOPE = threading.local()
_MISSING = object()


def shared(fn):
    """Memoize a recursive pass over terms by the identity of its arguments, while any pass so
    decorated is running (one scope for all of them, opened by the outermost call and dropped when
    it returns): on a term shared after inlining (a DAG), each distinct node is computed once per
    context, not once per path.  The pass must be a function of its arguments: a context that
    changes (a ``let`` binding) is a new argument, never a mutation."""

    @functools.wraps(fn)
    def wrapper(*args):
        tables = getattr(_SCOPE, "tables", None)
        outer = tables is None
        if outer:
            tables = _SCOPE.tables = {}
            _SCOPE.keep = []  # the arguments stay alive, so that their identities stay theirs
        try:
            table = tables.setdefault(wrapper, {})
            key = tuple(map(id, args))
            hit = table.get(key, _MISSING)
            if hit is _MISSING:
                hit = table[key] = fn(*args)
                _SCOPE.keep.append(args)
            return hit
        finally:
            if outer:
                _SCOPE.tables = _SCOPE.keep = None

    return wrapper


# ----------------------------------------------------------------------------------------------
# Small constructors and generic traversals.  The semantic functions are written as one `match`
# each in their own modules; these helpers are structural only.


def const(v: int | Fraction | str) -> Const:
    return Const(v if isinstance(v, str) else Fraction(v))


def neg(t: Term) -> Term:
    return Mul(Const(Fraction(-1)), t)


def product(factors: list[Term], span: Span | None = None) -> Term:
    """``f1·f2·…·fn``, grouped from the left."""
    out = factors[0]
    for f in factors[1:]:
        out = Mul(out, f, span=span)
    return out


def sub(t: Term, s: Term) -> Term:
    return Add(t, neg(s))


def div(t: Term, s: Term) -> Term:
    return Mul(t, Pow(s, Fraction(-1)))


def children(t: Term) -> tuple[Term, ...]:
    """Direct subterms of ``t`` (the diffeo's own terms are not children: see ``diffeo_terms``)."""
    match t:
        case Const() | Var() | Param():
            return ()
        case Add(a, b) | Mul(a, b):
            return (a, b)
        case Prim(_, a) | Pow(a, _):
            return (a,)
        case IfGe0(c, a, b):
            return (c, a, b)
        case IfDiffeo(_, a, b):
            return (a, b)
        case Let(_, a, b):
            return (a, b)
        case Call(_, _, args):
            return tuple(args)
        case ImplicitRoot(eq, _, target, lo, hi, slope=slope):
            return (eq, target, lo, hi) if slope is None else (eq, target, lo, hi, slope)
    raise TypeError(f"not a core term: {t!r}")


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


def _kept(t: Term, name: str, compute: Callable[[], T]) -> T:
    """``compute()``, kept on the node under ``name``: a shared term costs once."""
    try:
        return t.__dict__[name]
    except KeyError:
        out = compute()
        object.__setattr__(t, name, out)
        return out


def free_vars(t: Term) -> frozenset[str]:
    """Names of variables occurring in ``t`` (including in diffeomorphic conditions)."""
    match t:
        case Var(name):
            return frozenset({name})
        case IfDiffeo(psi, a, b):
            return _kept(t, "_fv", lambda: frozenset(psi.variables) | free_vars(a) | free_vars(b))
        case ImplicitRoot(eq, x, target, lo, hi, slope=slope):  # binds its variable in its equation (and slope)
            return _kept(t, "_fv", lambda: ((free_vars(eq) | (free_vars(slope) if slope is not None else frozenset()))
                                            - {x}) | free_vars(target) | free_vars(lo) | free_vars(hi))
        case _:
            return _kept(t, "_fv", lambda: frozenset().union(*(free_vars(c) for c in children(t))))


def free_params(t: Term) -> frozenset[str]:
    """Names of parameters occurring free in ``t`` (``let`` binds its name in its body)."""
    match t:
        case Param(name):
            return frozenset({name})
        case Let(name, bound, body):
            return _kept(t, "_fp", lambda: free_params(bound) | (free_params(body) - {name}))
        case IfDiffeo(psi, a, b):
            return _kept(t, "_fp", lambda: diffeo_params(psi) | free_params(a) | free_params(b))
        case _:
            return _kept(t, "_fp", lambda: frozenset().union(*(free_params(c) for c in children(t))))


def smooth(t: Term) -> bool:
    """No conditional and no call in ``t``: ⟦t⟧ is a smooth expression (where it is defined)."""
    match t:
        case IfGe0() | IfDiffeo() | Call():
            return False
        case Const() | Var() | Param():
            return True
        case _:
            return _kept(t, "_smooth", lambda: all(smooth(c) for c in children(t)))


def tree_size(t: Term) -> int:
    """The number of nodes of ``t`` counted once per path (its size written out as a tree),
    computed once per distinct node and kept on it (a subterm shared with an earlier program
    costs nothing)."""
    stack = [(t, False)]
    while stack:
        u, done = stack.pop()
        if "_size" in u.__dict__:
            continue
        if done:
            u.__dict__["_size"] = 1 + sum(c.__dict__["_size"] for c in children(u))
            continue
        stack.append((u, True))
        stack.extend((c, False) for c in children(u) if "_size" not in c.__dict__)
    return t.__dict__["_size"]


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

