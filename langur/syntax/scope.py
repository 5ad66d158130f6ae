"""Scopes of the desugarer: what a name in a term is (LANGUAGE.md §6, "A name in a term is …").

The typing judgement Δ; Γ ⊢ t : real (§5.1–5.2, Fig. 6): Δ the variables of integration in scope,
Γ the parameters, disjoint.  Where each comes from:

* a program's body: Δ = its variables; Γ = the module's declared params and ``let``-bound names;
* a ``def`` body: Δ = its ``var`` arguments; Γ = its ``param`` arguments, the module's declared
  params (shared by name with the program that inlines it) and ``let``-bound names;
* a ``diffeo`` declaration: Δ = its variables (forward) or its inputs (inverse); Γ = its params;
* a domain bound: Δ = ∅ (bounds are variable-free).

:class:`Scope` holds Δ and Γ with the numeric box used for completion, the indices of the §9 loops
being unrolled and the ``let``-bound vectors; :class:`Env` what a module's terms can call (defs by
their :class:`DefSig`, diffeos by their :class:`DiffeoSig`).  The desugarer
(:mod:`langur.syntax.desugar`) reads them; the elaborator (:mod:`langur.syntax.elaborate`) and the
front end (:mod:`langur.frontend`) build them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field, replace
from fractions import Fraction

from ..core import Diffeo, int_fraction
from ..primitives import ALL_PRIMITIVES, PRIMITIVES
from ..records import FACTORY, frozen, record
from .vectors import Vec, VecName

#: Function names that are not primitives but sugar (LANGUAGE.md §6).
SUGAR_FUNCTIONS = ("abs", "min", "max", "atan2", "dot", "cross")
#: Names a declaration may not take.
RESERVED = frozenset(PRIMITIVES) | frozenset(ALL_PRIMITIVES) | frozenset(SUGAR_FUNCTIONS) | {"pi"}


@frozen
class DefSig:
    """A def's signature: where it lives and its arguments' kinds (what a call site needs)."""

    module: str
    name: str
    args: tuple[tuple[str, str], ...]

    def __init__(self, module, name, args):
        d = self.__dict__
        d["module"], d["name"], d["args"] = module, name, args


@frozen
class DiffeoSig:
    """A checked ``diffeo`` declaration with its parameters' names in declaration order."""

    diffeo: Diffeo
    params: tuple[str, ...]

    def __init__(self, diffeo, params):
        d = self.__dict__
        d["diffeo"], d["params"] = diffeo, params


@record
class Env:
    """What a module's terms can call: defs and diffeos (local and imported), by local name."""

    module: str
    defs: dict[str, DefSig] = field(default_factory=dict)
    diffeos: dict[str, DiffeoSig] = field(default_factory=dict)
    poisoned: set[str] = field(default_factory=set)  # names whose declaration failed: no cascades
    bodies: dict[tuple[str, str], object] = field(default_factory=dict)  # (module, def) -> CoreDef

    def __init__(self, module, defs=FACTORY, diffeos=FACTORY, poisoned=FACTORY, bodies=FACTORY):
        self.module = module
        self.defs = {} if defs is FACTORY else defs
        self.diffeos = {} if diffeos is FACTORY else diffeos
        self.poisoned = set() if poisoned is FACTORY else poisoned
        self.bodies = {} if bodies is FACTORY else bodies



_new = object.__new__


@frozen
class Scope:
    """Δ (``variables``, in order), Γ (``gamma``), the numeric box for completion, and where we are."""

    variables: tuple[str, ...]
    gamma: frozenset[str]
    box: tuple[tuple[str, float, float], ...] = ()
    where: str = "this term"
    in_program: bool = True  # extend declared diffeos to all variables (program bodies)
    hidden_vars: frozenset[str] = frozenset()  # variables not allowed here (domain bounds)
    consts: Mapping[str, Fraction] = field(default_factory=dict)  # loop indices and their values (§9)
    vectors: Mapping[str, VecName] = field(default_factory=dict)  # let-bound vectors (vectors.VecName)

    def __init__(self, variables, gamma, box=(), where="this term", in_program=True, hidden_vars=frozenset(),
                 consts=FACTORY, vectors=FACTORY):
        d = self.__dict__
        d["variables"], d["gamma"], d["box"], d["where"] = variables, gamma, box, where
        d["in_program"], d["hidden_vars"] = in_program, hidden_vars
        d["consts"] = {} if consts is FACTORY else consts
        d["vectors"] = {} if vectors is FACTORY else vectors

    def with_param(self, name: str) -> Scope:
        """``name`` bound by a real ``let``: it hides an index or vector of that name, and the vectors
        whose components mention the outer ``name`` can no longer be substituted here (T233)."""
        vecs = {n: (replace(b, shadowed_by=name) if name in b.params and b.shadowed_by is None else b)
                for n, b in self.vectors.items() if n != name}
        consts = {n: v for n, v in self.consts.items() if n != name}
        return replace(self, gamma=self.gamma | {name}, consts=consts, vectors=vecs)

    def with_index(self, name: str, value: int) -> Scope:
        """``name`` the index of a loop, the number ``value`` in this copy of its body (§9).  (Copied
        field by field, as ``dataclasses.replace`` would with these two changed, without its walk
        over the fields: every first copy of a loop's body, and every copy not built from it.)"""
        vecs = {n: b for n, b in self.vectors.items() if n != name} if self.vectors else {}
        new = _new(Scope)
        d = new.__dict__
        d.update(self.__dict__)
        d["consts"], d["vectors"] = {**self.consts, name: int_fraction(value)}, vecs
        return new

    def with_vector(self, name: str, vec: Vec) -> Scope:
        """``name`` bound to the vector ``vec`` by a ``let``."""
        consts = {n: v for n, v in self.consts.items() if n != name}
        return replace(self, consts=consts, vectors={**self.vectors, name: VecName.of(vec)})


__all__ = ["RESERVED", "SUGAR_FUNCTIONS", "DefSig", "DiffeoSig", "Env", "Scope"]
