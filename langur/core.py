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
import operator
import sys
import threading
from dataclasses import field, replace
from fractions import Fraction
from typing import Callable, TypeVar, Union

from .diagnostics import Span
from .memo import remember
from .records import frozen

T = TypeVar("T")

PI = "pi"  # the one named constant: Const(PI) is π


def _span() -> Span | None:
    return field(default=None, compare=False, repr=False)  # type: ignore[return-value]


@frozen
class Const:
    """A constant ``c``: an exact rational, or the string ``"pi"`` for π."""

    value: Fraction | str
    span: Span | None = _span()

    def __init__(self, value, span=None):
        d = self.__dict__
        d["value"], d["span"] = value, span
        d.update(_LEAF_ATTRS)
        if id(value) in _INT_IDS:  # (an integer of INT_FRACTIONS: small, without Fraction's properties)
            d["_small"] = value
        elif type(value) is not Fraction:
            d["_small"] = d["_small_all"] = False
        elif value.denominator.bit_length() > SMALL_BITS or value.numerator.bit_length() >= 1000:
            d["_small"] = v = _in_range(value)
            d["_small_all"] = v is not False
        else:
            d["_small"] = value


@frozen
class Var:
    """A variable of integration ``x`` (or an input ``u`` of an inverse diffeomorphism)."""

    name: str
    span: Span | None = _span()

    def __init__(self, name, span=None):
        d = self.__dict__
        d["name"], d["span"] = name, span
        d.update(_LEAF_ATTRS)
        d["_fv"] = _names(name)


@frozen
class Param:
    """A parameter ``z`` (declared, or bound by ``let``)."""

    name: str
    span: Span | None = _span()

    def __init__(self, name, span=None):
        d = self.__dict__
        d["name"], d["span"] = name, span
        d.update(_LEAF_ATTRS)
        d["_fp"] = _names(name)


@frozen
class Add:
    left: "Term"
    right: "Term"
    span: Span | None = _span()

    def __init__(self, left, right, span=None):
        d = self.__dict__
        d["left"], d["right"], d["span"] = left, right, span
        _binary(d, left.__dict__, right.__dict__, False)


@frozen
class Mul:
    left: "Term"
    right: "Term"
    span: Span | None = _span()

    def __init__(self, left, right, span=None):
        d = self.__dict__
        d["left"], d["right"], d["span"] = left, right, span
        _binary(d, left.__dict__, right.__dict__, True)


@frozen
class Prim:
    """A smooth primitive applied to a term: ``op`` names an entry of
    :data:`langur.primitives.REGISTRY`."""

    op: str
    arg: "Term"
    span: Span | None = _span()

    def __init__(self, op, arg, span=None):
        d = self.__dict__
        d["op"], d["arg"], d["span"] = op, arg, span
        _unary(d, arg, False if arg._small is not None else None, True, op)


@frozen
class Pow:
    """``base ^ exponent`` with a constant rational exponent (``t / s`` is ``t · s ^ -1``)."""

    base: "Term"
    exponent: Fraction
    span: Span | None = _span()

    def __init__(self, base, exponent, span=None):
        d = self.__dict__
        d["base"], d["exponent"], d["span"] = base, exponent, span
        _unary(d, base, _small_power(base._small, exponent),
               type(exponent) is Fraction or isinstance(exponent, Fraction), None)


@frozen
class IfGe0:
    """``ifge0 cond then then else orelse`` with a variable-free ``cond`` (Fig. 6, conditional)."""

    cond: "Term"
    then: "Term"
    orelse: "Term"
    span: Span | None = _span()

    def __init__(self, cond, then, orelse, span=None):
        d = self.__dict__
        d["cond"], d["then"], d["orelse"], d["span"] = cond, then, orelse, span
        _annotate(self)


@frozen
class IfDiffeo:
    """``ifge0 ⌊Ψ⌋ then then else orelse`` (Fig. 6, diffeomorphic conditional).

    The condition is ``π₀Ψ̂ ≥ 0``, i.e. ``psi.forward[0] ≥ 0``.
    """

    psi: "Diffeo"
    then: "Term"
    orelse: "Term"
    span: Span | None = _span()

    def __init__(self, psi, then, orelse, span=None):
        d = self.__dict__
        d["psi"], d["then"], d["orelse"], d["span"] = psi, then, orelse, span
        _ifdiffeo(d, psi, then.__dict__, orelse.__dict__)


@frozen
class Let:
    """``let name = bound in body``: ``bound`` variable-free, ``name`` a parameter in ``body``."""

    name: str
    bound: "Term"
    body: "Term"
    span: Span | None = _span()

    def __init__(self, name, bound, body, span=None):
        d = self.__dict__
        d["name"], d["bound"], d["body"], d["span"] = name, bound, body, span
        _annotate(self)


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

    def __init__(self, module, name, args, span=None):
        d = self.__dict__
        d["module"], d["name"], d["args"], d["span"] = module, name, args, span
        _annotate(self)


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

    def __init__(self, equation, variable, target, lo, hi, index=None, of=0, slope=None, span=None):
        d = self.__dict__
        d["equation"], d["variable"], d["target"], d["lo"], d["hi"] = equation, variable, target, lo, hi
        d["index"], d["of"], d["slope"], d["span"] = index, of, slope, span
        _annotate(self)


class TooManyRoots(Exception):
    """An indexed :class:`ImplicitRoot` met more sign changes than its ``of`` (the completion
    split the domain into that many pieces at most), or sign changes it cannot certify it counted
    all of; ``span``: the condition's place in the source (issue 18)."""

    def __init__(self, message: str, span: Span | None = None):
        super().__init__(message)
        self.span = span


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


@frozen
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

    def __init__(self, variable, lo, hi, lower, upper, span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["variable"], d["lo"], d["hi"], d["lower"], d["upper"], d["span"] = variable, lo, hi, lower, upper, span


@frozen
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

    def __init__(self, integrand, variables, box, domain=(), span=None):  # (written out: the generic one costs twice as much)
        d = self.__dict__
        d["integrand"], d["variables"], d["box"], d["domain"], d["span"] = integrand, variables, box, domain, span

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
    leaf = cls.__name__ in ("Const", "Var", "Param")

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
        if leaf:  # one field to compare: no DAG to guard against
            return field_eq(self, other)
        if hash(self) != hash(other):
            return False
        if self.__dict__.get("_size", REPR_LIMIT) < 64:  # small written out: compared as a tree
            return field_eq(self, other)
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


# ----------------------------------------------------------------------------------------------
# Per-node attributes (issue 15).  Every pass of the front end asks the same questions of a term —
# its free variables and parameters, whether it is smooth or calls a def, its size and depth, its
# exact value when it is a constant — and a walk per question per pass costs Python's price per
# node each time.  A term is immutable, so each answer is computed once, bottom-up, when the node
# is built (its children already carry theirs) and kept in its ``__dict__`` under a name starting
# with ``_`` (never compared, hashed nor pickled: unpickling recomputes them, ``__setstate__``).
# The functions below (``free_vars``, ``free_params``, ``smooth``, ``has_calls``, ``tree_size``,
# ``depth``, ``small_value``, ``all_small``, ``diffeo_variables``) read them.
#
# Also kept, for typing (``langur.typesys.well_typed``): the premises of Fig. 6's rules that do not
# depend on the context Δ; Γ (``_scoped``: conditions of ``ifge0``, bounds of ``let``, a diffeo's
# own terms are where they must be, exponents are rational), the primitives used (``_ops``), the
# names ``let`` binds (``_binders``) and the parameters of the diffeos' inverse branches, guards and
# ``nonzero`` terms (``_dfp``, beside ``free_params``): then ``Δ; Γ ⊢ t`` holds when these and the
# free variables and parameters fit the context, without a walk.

#: Exact rational constants up to this magnitude count as small (the range check of constants,
#: T231, is then decided exactly: room to spare below the largest double).
SMALL = Fraction(int(sys.float_info.max) // 2**10)
#: Longest denominator (bits) kept exact: beyond it Fraction arithmetic grows quadratically.
SMALL_BITS = 256
#: Largest |exponent| of a constant power folded exactly.
SMALL_EXPONENT = 64

_EMPTY: frozenset = frozenset()
_SINGLE: dict[str, frozenset] = {}


def _names(name: str) -> frozenset:
    """``frozenset({name})``, one object per name (so that unions of equal sets are no-ops)."""
    s = _SINGLE.get(name)
    if s is None:
        s = remember(_SINGLE, name, frozenset((name,)), 4096, at_once=True)
    return s


def _join(a: frozenset, b: frozenset) -> frozenset:
    if not b or a is b:
        return a
    if not a:
        return b
    return a if b <= a else a | b


_SMALL_INT = int(SMALL)
_MINUS_ONE = Fraction(-1)

#: ``Fraction(i)`` for the integers 0 … 127, made once at import (≈ 0.6 M instructions): most literals
#: of a program and most indices of a loop's copies are small integers, and ``Fraction``'s
#: constructor is Python code (≈ 4.8 k instructions a call) where this is one subscript (issue 15).
#: A ``Fraction`` is immutable: sharing one is invisible.
INT_FRACTIONS: tuple[Fraction, ...] = tuple(Fraction(i) for i in range(128))
#: Their identities (the table keeps them alive): a ``Const`` of one of them is small (``Const``).
_INT_IDS = frozenset(map(id, INT_FRACTIONS))


def int_fraction(i: int) -> Fraction:
    """``Fraction(i)``, read off :data:`INT_FRACTIONS` when ``i`` is in it."""
    return INT_FRACTIONS[i] if 0 <= i < len(INT_FRACTIONS) else Fraction(i)


def _in_range(v: Fraction):
    """``v`` when it is a small rational (``SMALL``, ``SMALL_BITS``), else ``False`` (integer
    arithmetic: ``|n/d| ≤ SMALL`` is ``|n| ≤ SMALL·d``)."""
    n, d = v.numerator, v.denominator
    if d.bit_length() > SMALL_BITS:
        return False
    if n.bit_length() < 1000 or abs(n) <= _SMALL_INT * d:  # 2^1000 < SMALL
        return v
    return False


_LEAF_ATTRS = {"_fv": _EMPTY, "_fp": _EMPTY, "_smooth": True, "_calls": False, "_size": 1, "_depth": 1,
               "_small": None, "_small_all": True, "_psi_vars": _EMPTY,
               "_scoped": True, "_ops": _EMPTY, "_binders": _EMPTY, "_dfp": _EMPTY}


def _binary(d: dict, a: dict, b: dict, mul: bool) -> None:
    """The attributes of ``t + s`` or ``t · s`` (``d``) from those of ``t`` (``a``) and ``s`` (``b``)."""
    x, y = a["_fv"], b["_fv"]
    d["_fv"] = x if (not y or x is y) else (y if not x else _join(x, y))
    x, y = a["_fp"], b["_fp"]
    d["_fp"] = x if (not y or x is y) else (y if not x else _join(x, y))
    d["_smooth"] = a["_smooth"] and b["_smooth"]
    d["_calls"] = a["_calls"] or b["_calls"]
    d["_size"] = 1 + a["_size"] + b["_size"]
    x, y = a["_depth"], b["_depth"]
    d["_depth"] = 1 + (x if x > y else y)
    _binary_value(d, a, b, mul)
    x, y = a["_psi_vars"], b["_psi_vars"]
    d["_psi_vars"] = x if (not y or x is y) else (y if not x else _join(x, y))
    d["_scoped"] = a["_scoped"] and b["_scoped"]
    x, y = a["_ops"], b["_ops"]
    d["_ops"] = x if (not y or x is y) else (y if not x else _join(x, y))
    x, y = a["_binders"], b["_binders"]
    d["_binders"] = x if (not y or x is y) else (y if not x else _join(x, y))
    x, y = a["_dfp"], b["_dfp"]
    d["_dfp"] = x if (not y or x is y) else (y if not x else _join(x, y))


def _binary_value(d: dict, a: dict, b: dict, mul: bool) -> None:
    """The attributes of ``t + s`` or ``t · s`` (``d``) that depend on the values of its constants
    (``_small``, ``_small_all``), from those of ``t`` (``a``) and ``s`` (``b``)."""
    x, y = a["_small"], b["_small"]
    if x is None or y is None:
        v = False if x is False or y is False else None
    elif x is False or y is False:
        v = False
    elif mul:  # (x, y small: a product by 1 or a sum with 0 is the other, already in range)
        v = y if x.numerator == x.denominator else (x if y.numerator == y.denominator else _in_range(x * y))
    else:
        v = y if not x else (x if not y else _in_range(x + y))
    d["_small"] = v
    d["_small_all"] = v is not False and a["_small_all"] and b["_small_all"]


#: The attributes that depend on a term's shape only (its classes, names, primitives, exponents and
#: diffeos), not on the values of its constants: all but ``_small`` and ``_small_all``.
_SHAPE = ("_fv", "_fp", "_smooth", "_calls", "_size", "_depth", "_psi_vars", "_scoped", "_ops", "_binders", "_dfp")
_shape = operator.itemgetter(*_SHAPE)
_SHAPE_SPAN = (*_SHAPE, "span")
_shape_span = operator.itemgetter(*_SHAPE_SPAN)


def same_shape(t: "Term", s: "Term") -> bool:
    """``t`` and ``s`` have the same attributes but those that depend on their constants' values
    (then a node above one of them may be built by :func:`like` from a node above the other)."""
    return _shape(t.__dict__) == _shape(s.__dict__)


def shape_of(t: "Term") -> dict:
    """What :func:`like` keeps of ``t`` (an ``Add``, ``Mul``, ``Pow``, ``Prim`` or ``IfDiffeo``):
    the attributes of its shape, and its exponent or primitive."""
    d = dict(zip(_SHAPE, _shape(t.__dict__)))
    if type(t) is Pow:
        d["exponent"] = t.exponent
    elif type(t) is Prim:
        d["op"] = t.op
    elif type(t) is not Add and type(t) is not Mul and type(t) is not IfDiffeo:
        raise TypeError(f"shape_of: not an Add, Mul, Pow, Prim or IfDiffeo: {t!r}")
    return d


def shape_with_span(t: "Term") -> dict:
    """:func:`shape_of` ``t`` with its span: what :func:`like_binary` and :func:`like_power` copy
    (an ``Add`` or ``Mul``, the most frequent, read in one call)."""
    tt = type(t)
    if tt is Add or tt is Mul:
        return dict(zip(_SHAPE_SPAN, _shape_span(t.__dict__)))
    d = shape_of(t)
    d["span"] = t.span
    return d


def like(cls: type, shape: dict, kids: tuple, span) -> "Term":
    """The node of class ``cls`` with children ``kids`` (in the order of :func:`children`) and
    ``span`` whose other fields and attributes of its shape are ``shape`` (:func:`shape_of` of a
    node whose children had the :func:`same_shape` as ``kids``): only the attributes that depend on
    its constants' values are computed (a loop's copies, issue 15).  Equal, attributes included,
    to the node the constructor builds.

    For an ``IfDiffeo``, ``kids`` is ``(psi, then, orelse)`` and ``psi`` must have what Ψ̂ gives the
    node (``_diffeo_summary``) in common with the Ψ̂ of the node ``shape`` was taken from: the same
    variables and the same shapes of its terms, whatever their constants (an affine completion of
    a condition of the same shape, :func:`langur.syntax.affine.completed`)."""
    new = cls.__new__(cls)
    d = new.__dict__
    d.update(shape)
    d["span"] = span
    if cls is Add or cls is Mul:
        a, b = kids
        d["left"], d["right"] = a, b
        _binary_value(d, a.__dict__, b.__dict__, cls is Mul)
        return new
    if cls is IfDiffeo:
        psi, a, b = kids
        d["psi"], d["then"], d["orelse"] = psi, a, b
        v = d["_small"] = False if not d["_fv"] and not d["_fp"] else None
        d["_small_all"] = v is not False and a._small_all and b._small_all
        return new
    (a,) = kids
    if cls is Pow:
        d["base"] = a
        d["_small"] = v = _small_power(a._small, shape["exponent"])
    else:
        d["arg"] = a
        d["_small"] = v = False if a._small is not None else None
    d["_small_all"] = v is not False and a._small_all
    return new


def like_binary(cls: type, shape: dict, a: "Term", b: "Term") -> "Term":
    """``like(cls, shape, (a, b), span)`` for an ``Add`` or a ``Mul`` whose ``shape`` also holds its
    ``span`` (``dict(shape_of(t), span=…)``): a loop's copies build most of their nodes so, one call
    each (issue 15)."""
    new = _new(cls)
    d = new.__dict__
    d.update(shape)
    d["left"] = a
    d["right"] = b
    a, b = a.__dict__, b.__dict__
    x, y = a["_small"], b["_small"]
    if (x is None or y is None) and x is not False and y is not False:
        # (_binary_value's first case, written out: a copy's nodes over a variable or parameter)
        d["_small"] = None
        d["_small_all"] = a["_small_all"] and b["_small_all"]
    else:
        _binary_value(d, a, b, cls is Mul)
    return new


def like_binary_many(cls: type, shape: dict, lefts: list, rights: list) -> list:
    """``[like_binary(cls, shape, a, b) for a, b in zip(lefts, rights)]`` in one loop (the same node
    of all of a loop's copies at once, issue 15)."""
    out = []
    append = out.append
    mul = cls is Mul
    for a, b in zip(lefts, rights):
        new = _new(cls)
        d = new.__dict__
        d.update(shape)
        d["left"] = a
        d["right"] = b
        a, b = a.__dict__, b.__dict__
        x, y = a["_small"], b["_small"]
        if (x is None or y is None) and x is not False and y is not False:
            d["_small"] = None
            d["_small_all"] = a["_small_all"] and b["_small_all"]
        else:
            _binary_value(d, a, b, mul)
        append(new)
    return out

def like_power(shape: dict, a: "Term", small) -> "Term":
    """``like(Pow, shape, (a,), span)`` whose ``shape`` also holds its ``span``, with the small value
    of ``a ^ k`` given (``small_power(small_value(a), k)``, which a copy may have computed already)."""
    new = _new(Pow)
    d = new.__dict__
    d.update(shape)
    d["base"] = a
    d["_small"] = small
    d["_small_all"] = small is not False and a._small_all
    return new


def like_leaf(c: Const, span) -> Const:
    """``Const(c.value, span=span)``, its attributes copied from ``c`` (a loop's copy reads its
    index at several places: one number, issue 15)."""
    new = _new(Const)
    d = new.__dict__
    d.update(c.__dict__)
    d["span"] = span
    return new


_new = object.__new__


def index_const(value: int, span=None) -> Const:
    """``Const(Fraction(value), span=span)`` for an int ``value`` (a loop's index in one of its
    copies, issue 15): an integer of fewer than 1000 bits is its own small value, so its attributes
    are written without the constructor's tests.  Equal, attributes included, to the constructor's."""
    number = int_fraction(value)
    if value.bit_length() >= 1000:
        return Const(number, span=span)
    new = _new(Const)
    d = new.__dict__
    d["value"], d["span"] = number, span
    d.update(_LEAF_ATTRS)
    d["_small"] = number
    return new


def index_power_small(value: int, n: int):
    """``small_power(small_value(Const(Fraction(value))), n)`` for ints ``value`` and ``n`` (a
    power of a loop's index, ``1/i``), in integer arithmetic: ``_small_power``'s tests and
    ``_in_range`` on the numerator and denominator of ``value ** n`` (issue 15)."""
    if value.bit_length() >= 1000:
        return _small_power(_in_range(Fraction(value)), n)
    if not -SMALL_EXPONENT <= n <= SMALL_EXPONENT or (not value and n <= 0):
        return False
    if n >= 0:
        num, den = value**n, 1
    else:
        den = value**-n
        num, den = (1, den) if den > 0 else (-1, -den)
    if den.bit_length() > SMALL_BITS:
        return False
    if num.bit_length() < 1000 or abs(num) <= _SMALL_INT * den:
        return Fraction(num, den)
    return False


def small_power(x, k):
    """The small value of ``t ^ k`` from ``t``'s (``x``): :func:`small_value` of ``Pow(t, k)``."""
    return _small_power(x, k)


def _small_power(x, k):
    """The small value of ``t ^ k`` from ``t``'s (``x``)."""
    if x is None or x is False:
        return x
    if (type(k) is Fraction or isinstance(k, (int, Fraction))) and k.denominator == 1:
        n = k.numerator  # (integer comparisons: a loop's copies rebuild 1/i, each a Pow)
        if -SMALL_EXPONENT <= n <= SMALL_EXPONENT and (x or n > 0):
            return _in_range(x ** n)
    return False


def _unary(d: dict, a: "Term", small, scoped: bool, op: str | None) -> None:
    """The attributes of ``f(t)`` or ``t ^ k`` (``d``) from those of ``t`` (``a``), with its small
    value, whether its own premise holds (a rational exponent) and its primitive."""
    d["_fv"], d["_fp"], d["_psi_vars"] = a._fv, a._fp, a._psi_vars
    d["_smooth"], d["_calls"], d["_size"], d["_depth"] = a._smooth, a._calls, a._size + 1, a._depth + 1
    d["_small"] = small
    d["_small_all"] = small is not False and a._small_all
    d["_scoped"] = scoped and a._scoped
    d["_ops"] = a._ops if op is None else _join(a._ops, _names(op))
    d["_binders"], d["_dfp"] = a._binders, a._dfp


_INTERNED_SETS: dict = {}


def _interned_set(items: tuple) -> frozenset:
    s = _INTERNED_SETS.get(items)
    if s is None:
        s = remember(_INTERNED_SETS, items, frozenset(items), 4096, at_once=True)
    return s


def _diffeo_summary(psi: "Diffeo") -> tuple:
    """What a diffeomorphic conditional's attributes take from its Ψ̂ (kept on the Diffeo, which
    several conditionals may share): its condition's parameters, its variables (as a set, and as
    the one variable list of ``diffeo_variables``), the depth its condition counts for, whether
    its own premises hold (``_diffeo_scoped``), the primitives and parameters of all its terms."""
    d = psi.__dict__
    found = d.get("_summary")
    if found is None:
        fp = ops = dfp = _EMPTY
        for f in psi.forward:
            fp = _join(fp, f._fp)
        for u in psi.forward + psi.nonzero:
            ops, dfp = _join(ops, u._ops), _join(dfp, _join(u._fp, u._dfp))
        scoped = _diffeo_scoped(psi)
        for b in psi.branches:  # (a branch shared by several Diffeos is summarized once)
            b_ops, b_dfp, b_scoped = _branch_summary(b, psi.inputs, len(psi.variables))
            ops, dfp, scoped = _join(ops, b_ops), _join(dfp, b_dfp), scoped and b_scoped
        found = d["_summary"] = (fp, _interned_set(psi.variables), _interned_set((psi.variables,)),
                                 psi.forward[0]._depth if psi.name is None else 1, scoped, ops, dfp)
    return found


def _branch_summary(b: "InverseBranch", inputs: tuple[str, ...], n: int) -> tuple:
    """The primitives and parameters of an inverse branch's terms, and whether it is scoped for a
    Ψ̂ with these ``inputs`` and ``n`` variables (``_diffeo_scoped``'s premise on branches); kept
    on the branch per ``(inputs, n)``."""
    d = b.__dict__
    found = d.get("_summary")
    if found is None or found[0] != (inputs, n):
        ops = dfp = _EMPTY
        us = frozenset(inputs)
        scoped = len(b.components) == n
        for u in b.components + b.guards:
            ops, dfp = _join(ops, u._ops), _join(dfp, _join(u._fp, u._dfp))
            if scoped and not (u._scoped and not u._binders and u._fv <= us):
                scoped = False
        found = d["_summary"] = ((inputs, n), ops, dfp, scoped)
    return found[1:]


def _ifdiffeo(d: dict, psi: "Diffeo", a: dict, b: dict) -> None:
    """The attributes of ``ifge0 ⌊Ψ⌋ then s else r`` (``d``) from Ψ's and those of ``s`` (``a``)
    and ``r`` (``b``)."""
    fp, xs, pv, cond, scoped, ops, dfp = _diffeo_summary(psi)
    d["_fv"] = fv = _join(_join(a["_fv"], b["_fv"]), xs)
    d["_fp"] = fp = _join(_join(a["_fp"], b["_fp"]), fp)
    d["_psi_vars"] = _join(_join(a["_psi_vars"], b["_psi_vars"]), pv)
    d["_smooth"] = False
    d["_calls"] = a["_calls"] or b["_calls"]
    d["_size"] = 1 + a["_size"] + b["_size"]
    d["_depth"] = 1 + max(a["_depth"], b["_depth"], cond)
    d["_small"] = v = False if not fv and not fp else None
    d["_small_all"] = v is not False and a["_small_all"] and b["_small_all"]
    d["_scoped"] = scoped and a["_scoped"] and b["_scoped"]
    d["_ops"] = _join(_join(a["_ops"], b["_ops"]), ops)
    d["_binders"] = _join(a["_binders"], b["_binders"])
    d["_dfp"] = _join(_join(a["_dfp"], b["_dfp"]), dfp)


def _annotate(t: "Term") -> None:
    """Compute and keep ``t``'s attributes from its children's (see above)."""
    d = t.__dict__
    if type(t) is IfDiffeo:
        _ifdiffeo(d, t.psi, t.then.__dict__, t.orelse.__dict__)
        return
    kids = children(t)
    fv = fp = pv = _EMPTY
    for c in kids:
        fv, fp, pv = _join(fv, c._fv), _join(fp, c._fp), _join(pv, c._psi_vars)
    size, deep = 1, 0
    for c in kids:
        size += c._size
        if c._depth > deep:
            deep = c._depth
    match t:
        case Var(name):
            fv = _names(name)
        case Param(name):
            fp = _names(name)
        case Let(name, bound, body):
            fp = _join(bound._fp, body._fp - {name} if name in body._fp else body._fp)
        case ImplicitRoot(eq, x, target, lo, hi, slope=slope):  # binds its variable in its equation (and slope)
            own = eq._fv if slope is None else _join(eq._fv, slope._fv)
            fv = _join(_join(own - {x} if x in own else own, target._fv), _join(lo._fv, hi._fv))
    d["_fv"], d["_fp"], d["_psi_vars"], d["_size"], d["_depth"] = fv, fp, pv, size, deep + 1
    d["_smooth"] = not isinstance(t, (IfGe0, Call)) and all(c._smooth for c in kids)
    d["_calls"] = isinstance(t, Call) or any(c._calls for c in kids)
    match t:
        case Const(value):
            v = _in_range(value) if type(value) is Fraction else False
        case Var() | Param():
            v = None
        case Add(a, b) | Mul(a, b):
            x, y = a._small, b._small
            if x is False or y is False:
                v = False
            elif x is None or y is None:
                v = None
            else:
                v = _in_range(x + y if isinstance(t, Add) else x * y)
        case Pow(a, k):
            v = _small_power(a._small, k)
        case _:
            v = False if not fv and not fp else None
    d["_small"] = v
    d["_small_all"] = v is not False and all(c._small_all for c in kids)
    scoped = all(c._scoped for c in kids)
    ops = binders = dfp = _EMPTY
    for c in kids:
        ops, binders, dfp = _join(ops, c._ops), _join(binders, c._binders), _join(dfp, c._dfp)
    match t:
        case Prim(op, _):
            ops = _join(ops, _names(op))
        case Pow(_, k):
            scoped = scoped and (type(k) is Fraction or isinstance(k, Fraction))
        case IfGe0(c, _, _):
            scoped = scoped and not c._fv
        case Let(name, bound, body):
            scoped = scoped and not bound._fv
            binders = _join(binders, _names(name))
            dfp = _join(bound._dfp, body._dfp - {name} if name in body._dfp else body._dfp)
        case ImplicitRoot(eq, _, _, lo, hi, slope=slope):  # its bracket may move with Δ (issue 18)
            scoped = scoped and not eq._binders and (slope is None or not slope._binders)
    d["_scoped"], d["_ops"], d["_binders"], d["_dfp"] = scoped, ops, binders, dfp


def _diffeo_scoped(psi: "Diffeo") -> bool:
    """The premises of Fig. 6's diffeomorphic conditional that do not depend on the context (see
    ``typesys.type_diffeo``): distinct variables, as many components and inputs as variables,
    components over the variables, ``nonzero`` terms variable-free, each of these terms itself
    scoped and binding no name (and, by :func:`_branch_summary`, inverse branches and guards over
    the inputs, scoped, binding no name)."""
    xs, n = frozenset(psi.variables), len(psi.variables)
    if len(xs) != n or len(psi.forward) != n or len(psi.inputs) != n:
        return False
    for f in psi.forward:  # (loops, not all() over generators: every completed condition comes here)
        if not (f._scoped and not f._binders and f._fv <= xs):
            return False
    for z in psi.nonzero:
        if not (z._scoped and not z._binders and not z._fv):
            return False
    return True  # (the branches' premise: _branch_summary)


def _setstate(self, state: dict) -> None:  # unpickled: the attributes computed again
    self.__dict__.update(state)
    if type(self) in (Const, Var, Param):
        self.__init__(**state)
    elif type(self) in _TERMS:
        _annotate(self)


for _cls in _TERMS:
    _cls.__setstate__ = _setstate


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
    return Mul(Const(_MINUS_ONE), t)


def product(factors: list[Term], span: Span | None = None) -> Term:
    """``f1·f2·…·fn``, grouped from the left."""
    out = factors[0]
    for f in factors[1:]:
        out = Mul(out, f, span=span)
    return out


def sub(t: Term, s: Term) -> Term:
    return Add(t, neg(s))


def div(t: Term, s: Term) -> Term:
    return Mul(t, Pow(s, _MINUS_ONE))


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


def free_vars(t: Term) -> frozenset[str]:
    """Names of variables occurring in ``t`` (including in diffeomorphic conditions; an implicit
    root binds its variable in its equation)."""
    return t._fv


def free_params(t: Term) -> frozenset[str]:
    """Names of parameters occurring free in ``t`` (``let`` binds its name in its body; a
    diffeomorphic conditional's include its condition's)."""
    return t._fp


def smooth(t: Term) -> bool:
    """No conditional and no call in ``t``: ⟦t⟧ is a smooth expression (where it is defined)."""
    return t._smooth


def has_calls(t: Term) -> bool:
    """Whether ``t`` contains a ``Call``."""
    return t._calls


def tree_size(t: Term) -> int:
    """The number of nodes of ``t`` counted once per path (its size written out as a tree)."""
    return t._size


def depth(t: Term) -> int:
    """The nesting depth of ``t`` (a leaf is 1); a completed condition (``Diffeo.name`` None)
    counts as a child of its conditional, a declared diffeo as a leaf: what the inlined program's
    depth limit (T230, ``langur.syntax.inline``) measures."""
    return t._depth


def small_value(t: Term):
    """The exact value of the constant (variable-free, parameter-free) term ``t`` when rational
    arithmetic on small numbers decides it (every constant a rational of magnitude ≤ ``SMALL``
    with a denominator of at most ``SMALL_BITS`` bits, integer powers up to ``SMALL_EXPONENT``);
    ``None`` when ``t`` is not constant; ``False`` when it is but not decided so (π, primitives,
    fractional powers, large values)."""
    return t._small


def all_small(t: Term) -> bool:
    """Every subterm of ``t`` has a :func:`small_value` that is not ``False``."""
    return t._small_all


def diffeo_variables(t: Term) -> frozenset[tuple[str, ...]]:
    """The variable lists of the diffeomorphic conditionals in ``t``."""
    return t._psi_vars


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

