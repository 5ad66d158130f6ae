"""The terms of the core language Langur (paper §4.1; LANGUAGE.md §1), shared by every engine.

    t, s, r ::= c | x | z | t + s | t · s | f(t) | t ^ k
              | ifge0 t then s else r          -- t variable-free
              | ifge0 ⌊Ψ⌋ then s else r        -- Ψ a C¹ diffeomorphism in the variables
              | let z = t in s                 -- t variable-free
    p       ::= int t d(x1, …, xn)

The extension by smooth primitives ``f(t)`` and constant powers ``t ^ k`` is LANGUAGE.md §1's;
``t / s`` is ``t · s ^ -1`` and ``t − s`` is ``t + (−1)·s``.

Nodes are frozen dataclasses, stored in slots (:mod:`langur.core.slots`).  Every node may carry the
source ``span`` it came from (for diagnostics); spans never take part in equality or hashing, so
``parse(print(t)) == t`` compares structure only.

Programs ``p`` are declared in :mod:`langur.core.programs`.  A node computes the attributes it keeps
when it is built, from its children's (:mod:`langur.core.attributes`; ``_annotate`` below for the
nodes without arithmetic of their own), and its hash once (:mod:`langur.core.sharing`).  Each
constructor (``__new__``) fills a node of its class's layout and returns it as a node of its class (``slots._built``, written out).

``Call`` is not part of the paper's core: it appears only in a module's *elaborated* form (one
module's definitions with calls into other modules left as links, for separate compilation, §9).
``langur.syntax.inline.inline`` removes every ``Call``; the semantic functions ``denote`` and
``ddenote`` see pure core terms.
"""

from __future__ import annotations

from dataclasses import field
from fractions import Fraction
from typing import Union

from ..diagnostics import Span
from ..records import frozen
from .attributes import (
    _EMPTY,
    _INT_IDS,
    _LEAF_SHAPE,
    BINDERS,
    CALLS,
    DEPTH,
    DFP,
    FP,
    FV,
    OPS,
    PSI_VARS,
    SCOPED,
    SIZE,
    SMALL_BITS,
    SMOOTH,
    _binary,
    _ifdiffeo,
    _in_range,
    _join,
    _names,
    _param_shape,
    _small_power,
    _unary,
    _var_shape,
)
from .sharing import _sharing
from .slots import _slotted

_new = object.__new__

PI = "pi"  # the one named constant: Const(PI) is π


def _span() -> Span | None:
    return field(default=None, compare=False, repr=False)  # type: ignore[return-value]


@frozen
class Const:
    """A constant ``c``: an exact rational, or the string ``"pi"`` for π."""

    value: Fraction | str
    span: Span | None = _span()

    def __new__(cls, value, span=None):
        t = _new(cls.__base__)
        t.value, t.span, t._hash, t.typed, t.memo, t.shape = value, span, None, None, None, _LEAF_SHAPE
        if id(value) in _INT_IDS:  # (an integer of INT_FRACTIONS, or −1: small, without Fraction's properties)
            t.small, t.small_all = value, True
        elif type(value) is not Fraction:
            t.small = t.small_all = False
        elif value.denominator.bit_length() > SMALL_BITS or value.numerator.bit_length() >= 1000:
            t.small = v = _in_range(value)
            t.small_all = v is not False
        else:
            t.small, t.small_all = value, True
        t.__class__ = cls  # (slots._built, written out here and below: every node is built so)
        return t


@frozen
class Var:
    """A variable of integration ``x`` (or an input ``u`` of an inverse diffeomorphism)."""

    name: str
    span: Span | None = _span()

    def __new__(cls, name, span=None):
        t = _new(cls.__base__)
        t.name, t.span, t._hash, t.typed, t.memo = name, span, None, None, None
        t.shape, t.small, t.small_all = _var_shape(name), None, True  # (a leaf's attributes: its shape, no small value but a constant's)
        t.__class__ = cls
        return t


@frozen
class Param:
    """A parameter ``z`` (declared, or bound by ``let``)."""

    name: str
    span: Span | None = _span()

    def __new__(cls, name, span=None):
        t = _new(cls.__base__)
        t.name, t.span, t._hash, t.typed, t.memo = name, span, None, None, None
        t.shape, t.small, t.small_all = _param_shape(name), None, True
        t.__class__ = cls
        return t


@frozen
class Add:
    left: "Term"
    right: "Term"
    span: Span | None = _span()

    def __new__(cls, left, right, span=None):
        t = _new(cls.__base__)
        t.left, t.right, t.span, t._hash, t.typed, t.memo = left, right, span, None, None, None
        _binary(t, left, right, False)
        t.__class__ = cls
        return t


@frozen
class Mul:
    left: "Term"
    right: "Term"
    span: Span | None = _span()

    def __new__(cls, left, right, span=None):
        t = _new(cls.__base__)
        t.left, t.right, t.span, t._hash, t.typed, t.memo = left, right, span, None, None, None
        _binary(t, left, right, True)
        t.__class__ = cls
        return t


@frozen
class Prim:
    """A smooth primitive applied to a term: ``op`` names an entry of
    :data:`langur.primitives.REGISTRY`."""

    op: str
    arg: "Term"
    span: Span | None = _span()

    def __new__(cls, op, arg, span=None):
        t = _new(cls.__base__)
        t.op, t.arg, t.span, t._hash, t.typed, t.memo = op, arg, span, None, None, None
        _unary(t, arg, False if arg.small is not None else None, True, op)
        t.__class__ = cls
        return t


@frozen
class Pow:
    """``base ^ exponent`` with a constant rational exponent (``t / s`` is ``t · s ^ -1``)."""

    base: "Term"
    exponent: Fraction
    span: Span | None = _span()

    def __new__(cls, base, exponent, span=None):
        t = _new(cls.__base__)
        t.base, t.exponent, t.span, t._hash, t.typed, t.memo = base, exponent, span, None, None, None
        _unary(t, base, _small_power(base.small, exponent),
               type(exponent) is Fraction or isinstance(exponent, Fraction), None)
        t.__class__ = cls
        return t


@frozen
class IfGe0:
    """``ifge0 cond then then else orelse`` with a variable-free ``cond`` (Fig. 6, conditional)."""

    cond: "Term"
    then: "Term"
    orelse: "Term"
    span: Span | None = _span()

    def __new__(cls, cond, then, orelse, span=None):
        t = _new(cls.__base__)
        t.cond, t.then, t.orelse, t.span, t._hash, t.typed, t.memo = cond, then, orelse, span, None, None, None
        _annotate(t, cls)
        t.__class__ = cls
        return t


@frozen
class IfDiffeo:
    """``ifge0 ⌊Ψ⌋ then then else orelse`` (Fig. 6, diffeomorphic conditional).

    The condition is ``π₀Ψ̂ ≥ 0``, i.e. ``psi.forward[0] ≥ 0``.
    """

    psi: "Diffeo"
    then: "Term"
    orelse: "Term"
    span: Span | None = _span()

    def __new__(cls, psi, then, orelse, span=None):
        t = _new(cls.__base__)
        t.psi, t.then, t.orelse, t.span, t._hash, t.typed, t.memo = psi, then, orelse, span, None, None, None
        _ifdiffeo(t, psi, then, orelse)
        t.__class__ = cls
        return t


@frozen
class Let:
    """``let name = bound in body``: ``bound`` variable-free, ``name`` a parameter in ``body``."""

    name: str
    bound: "Term"
    body: "Term"
    span: Span | None = _span()

    def __new__(cls, name, bound, body, span=None):
        t = _new(cls.__base__)
        t.name, t.bound, t.body, t.span, t._hash, t.typed, t.memo = name, bound, body, span, None, None, None
        _annotate(t, cls)
        t.__class__ = cls
        return t


@frozen
class Call:
    """A call of ``def name`` of module ``module`` (elaborated form only; see module docstring).

    ``args`` follow the def's argument kinds: a ``var`` argument is a term over variables, a
    ``param`` argument a variable-free term.
    """

    module: str
    name: str
    args: tuple["Term", ...]
    span: Span | None = _span()

    def __new__(cls, module, name, args, span=None):
        t = _new(cls.__base__)
        t.module, t.name, t.args, t.span, t._hash, t.typed, t.memo = module, name, args, span, None, None, None
        _annotate(t, cls)
        t.__class__ = cls
        return t


@frozen
class ImplicitRoot:
    """An implicit root (issue 18: an inverse branch with no closed form).

    It occurs only in an :class:`InverseBranch`'s components and guards: ``equation`` is a smooth
    term over ``Var(variable)`` (bound here), parameters and, for a condition in several variables,
    Ψ̂⁻¹'s other inputs (the other variables' values), ``target`` a term over Ψ̂⁻¹'s inputs and
    parameters, ``lo`` and ``hi`` over parameters and, for a condition split along a variable at
    turning points that move with the others, Ψ̂⁻¹'s other inputs.

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

    def __new__(cls, equation, variable, target, lo, hi, index=None, of=0, slope=None, span=None):
        t = _new(cls.__base__)
        t.equation, t.variable, t.target, t.lo, t.hi = equation, variable, target, lo, hi
        t.index, t.of, t.slope, t.span, t._hash, t.typed, t.memo = index, of, slope, span, None, None, None
        _annotate(t, cls)
        t.__class__ = cls
        return t


#: The classes above as nodes stored in slots (:mod:`langur.core.slots`).
Const, Var, Param, Add, Mul, Prim, Pow, IfGe0, IfDiffeo, Let, Call, ImplicitRoot = _slotted(
    (Const, Var, Param), (Add, Mul), (Prim, Pow), (IfGe0, IfDiffeo, Let, Call, ImplicitRoot))


class TooManyRoots(Exception):
    """An indexed :class:`ImplicitRoot` met more sign changes than its ``of`` (the completion
    split the domain into that many pieces at most), or sign changes it cannot certify it counted
    all of; ``root``: that node, when known, and ``span`` its place in the source, the condition's
    (issue 18).

    The engines remember what they compiled by equal terms, whose spans do not count: the node met
    may be an equal program's, loaded earlier in the process.  An engine's public entry names the
    program's own place (:func:`~langur.core.structural.refusals_located`)."""

    def __init__(self, message: str, root: "ImplicitRoot | None" = None):
        super().__init__(message)
        self.root = root
        self.span: Span | None = None if root is None else root.span


Term = Union[Const, Var, Param, Add, Mul, Prim, Pow, IfGe0, IfDiffeo, Let, Call, ImplicitRoot]


@frozen
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

    def __init__(self, components, guards=()):  # (frozen: the fields written directly, faster)
        d = self.__dict__
        d["components"], d["guards"] = components, guards


@frozen
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

    def __init__(self, variables, forward, inputs, branches, solved_for=None, name=None, nonzero=(), span=None):
        d = self.__dict__  # (frozen: the fields written directly, faster)
        d["variables"], d["forward"], d["inputs"], d["branches"] = variables, forward, inputs, branches
        d["solved_for"], d["name"], d["nonzero"], d["span"] = solved_for, name, nonzero, span

    @property
    def condition(self) -> "Term":
        """π₀Ψ̂."""
        return self.forward[0]


def keep_solved(psi: Diffeo, found) -> None:
    """Keep on ``psi`` what the front end solved to make it, for :func:`kept_solved` to read back
    (``syntax.affine.complete`` keeps its condition's shape solved and constant term, which a loop's
    template asks for again, issue 15).  A memo, not a field: never compared nor hashed, and not
    pickled (a ``Diffeo`` pickles no ``_`` key of its ``__dict__``, :mod:`.sharing`)."""
    psi.__dict__["_solved"] = found


def kept_solved(psi: Diffeo):
    """What :func:`keep_solved` kept on ``psi``, or ``None``."""
    return psi.__dict__.get("_solved")


_TERMS = (Const, Var, Param, Add, Mul, Prim, Pow, IfGe0, IfDiffeo, Let, Call, ImplicitRoot)

for _cls in _TERMS:
    _sharing(_cls, term=True)
for _cls in (InverseBranch, Diffeo):
    _sharing(_cls)


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


def _annotate(t, cls: type) -> None:
    """Compute and keep the attributes of ``t``, being built as a ``cls`` (an ``IfGe0``, ``Let``,
    ``Call`` or ``ImplicitRoot``: the nodes without arithmetic of their own), from its children's
    (:mod:`langur.core.attributes`)."""
    if cls is IfGe0:
        kids = (t.cond, t.then, t.orelse)
    elif cls is Let:
        kids = (t.bound, t.body)
    elif cls is Call:
        kids = tuple(t.args)
    else:  # ImplicitRoot
        kids = (t.equation, t.target, t.lo, t.hi) if t.slope is None else (t.equation, t.target, t.lo, t.hi, t.slope)
    fv = fp = pv = _EMPTY
    for c in kids:
        fv, fp, pv = _join(fv, c.shape[FV]), _join(fp, c.shape[FP]), _join(pv, c.shape[PSI_VARS])
    size, deep = 1, 0
    for c in kids:
        size += c.shape[SIZE]
        if c.shape[DEPTH] > deep:
            deep = c.shape[DEPTH]
    if cls is Let:
        bound, body, name = t.bound, t.body, t.name
        fp = _join(bound.shape[FP], body.shape[FP] - {name} if name in body.shape[FP] else body.shape[FP])
    elif cls is ImplicitRoot:  # binds its variable in its equation (and slope)
        eq, x, slope = t.equation, t.variable, t.slope
        own = eq.shape[FV] if slope is None else _join(eq.shape[FV], slope.shape[FV])
        fv = _join(_join(own - {x} if x in own else own, t.target.shape[FV]), _join(t.lo.shape[FV], t.hi.shape[FV]))
    smooth = cls is not IfGe0 and cls is not Call and all(c.shape[SMOOTH] for c in kids)
    calls = cls is Call or any(c.shape[CALLS] for c in kids)
    t.small = v = False if not fv and not fp else None
    t.small_all = v is not False and all(c.small_all for c in kids)
    scoped = all(c.shape[SCOPED] for c in kids)
    ops = binders = dfp = _EMPTY
    for c in kids:
        ops, binders, dfp = _join(ops, c.shape[OPS]), _join(binders, c.shape[BINDERS]), _join(dfp, c.shape[DFP])
    if cls is IfGe0:
        scoped = scoped and not t.cond.shape[FV]
    elif cls is Let:
        scoped = scoped and not bound.shape[FV]
        binders = _join(binders, _names(name))
        dfp = _join(bound.shape[DFP], body.shape[DFP] - {name} if name in body.shape[DFP] else body.shape[DFP])
    elif cls is ImplicitRoot:  # its bracket may move with Δ (issue 18)
        scoped = scoped and not eq.shape[BINDERS] and (slope is None or not slope.shape[BINDERS])
    t.shape = (fv, fp, smooth, calls, size, deep + 1, pv, scoped, ops, binders, dfp)


