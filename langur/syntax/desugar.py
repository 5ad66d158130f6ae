"""Desugaring: the surface AST (``langur.syntax.surface``) to the core language (``langur.core``).

This is the ONE place where LANGUAGE.md §6's sugar table is implemented; :meth:`Desugarer.value`
is one ``match`` with a case per row.  It includes §9's finite loop (``sum i in A..B: t``, unrolled;
helpers in :mod:`langur.syntax.loops`) and small fixed-size vectors (``(a, b, c)``, ``dot``,
``cross``, ``u.x``; helpers in :mod:`langur.syntax.vectors`), which :meth:`Desugarer.value`
evaluates to a :class:`~langur.syntax.vectors.Vec` of core terms: :meth:`Desugarer.term`, where a
real is expected, refuses a vector (T226), so no vector reaches the core language.  Typing rules
that concern names and sugar (unbound names, argument kinds, arity, ``let``, conditions over
variables, …) are applied here, on the surface AST, through the ``reject_*`` helpers of
:mod:`langur.typesys` (which documents every T2xx code).

Scopes (LANGUAGE.md §6, "A name in a term is …"):

* a program's body: Δ = its variables; Γ = the module's declared params and ``let``-bound names;
* a ``def`` body: Δ = its ``var`` arguments; Γ = its ``param`` arguments, the module's declared
  params (shared by name with the program that inlines it) and ``let``-bound names;
* a ``diffeo`` declaration: Δ = its variables (forward) or its inputs (inverse); Γ = its params;
* a domain bound: Δ = ∅ (bounds are variable-free).

Conditions over variables become ``IfDiffeo``: a declared diffeo application is instantiated
(``langur.syntax.diffeo.instantiate``); any other condition is completed automatically
(``langur.syntax.diffeo.complete``) over *all* of Δ.  In a program body a declared diffeo is
extended by the identity to all the program's variables; in a ``def`` body it stays over its
application's variables (the inliner renames and extends it at each call site).
A condition over variables that calls defs of its own module is completed with those calls
expanded (it is completed as a whole); calling an imported def there is a T207 (the module's
elaborated form would depend on the imported body, not just its signature).
Def calls are left as ``Call(module, name, args)`` links (separate compilation, §9);
``langur.syntax.inline.inline`` (re-exported here as :func:`inline`) removes them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import field, replace
from fractions import Fraction

from .. import typesys as ty
from ..core import (
    INT_FRACTIONS,
    MINUS_ONE,
    PI,
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
    Term,
    Var,
    free_vars,
    int_fraction,
    map_children,
    neg,
    product,
    smooth,
    sub,
    subterms,
    tree_size,
)
from ..diagnostics import Diagnostic, LangurError, Span
from ..modules import ElaboratedModule
from ..primitives import ALL_PRIMITIVES, PRIMITIVES
from ..records import FACTORY, frozen, record
from . import kinks, loops, template, vectors
from .completion import complete, diffeo
from .inline import expand_calls, inline
from .surface import (
    Apply,
    BinOp,
    Component,
    DiffeoApp,
    IfCmp,
    IfGe0S,
    IfLogic,
    Iverson,
    LetIn,
    Logic,
    Loop,
    Name,
    Neg,
    NestedInt,
    Num,
    STerm,
    Vector,
)
from .vectors import Vec, VecName

#: Function names that are not primitives but sugar (LANGUAGE.md §6).
SUGAR_FUNCTIONS = ("abs", "min", "max", "atan2", "dot", "cross")
#: The conditions of a module split at their kinks (abs/min/max over the variables) have at most
#: this many pieces in all (nested kinks double them at each level: the bound keeps the work bounded).
MAX_PIECES = 128
#: A condition with kinks is split only when written out as a tree it has at most this many nodes
#: (the cube [max(max(abs(x), abs(y)), abs(z)) <= a] has 867; four nested abs over 10000).
MAX_SPLIT_SIZE = 1000


class _TooManyPieces(Exception):
    pass
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
_ZERO, _ONE, _MINUS_ONE = INT_FRACTIONS[0], INT_FRACTIONS[1], MINUS_ONE


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


def _put(t: Term, old: Term, new: Term) -> Term:
    """``t`` with the subterm ``old`` (by identity) replaced by ``new``."""
    if t is old:
        return new
    return map_children(t, lambda c: _put(c, old, new))


def _decided(t: Term, cond: Term, holds: bool) -> Term:
    """``t`` where ``cond ≥ 0`` is known to hold (or not): each conditional over the variables on
    ``cond`` replaced by its then-branch (else-branch), which it takes there."""
    t = map_children(t, lambda c: _decided(c, cond, holds))
    if isinstance(t, IfDiffeo) and t.psi.condition == cond:
        return t.then if holds else t.orelse
    return t


class Desugarer:
    """Desugars terms of one module; collects diagnostics instead of stopping at the first."""

    def __init__(self, env: Env, errors: list[Diagnostic] | None = None):
        self.env = env
        self.errors: list[Diagnostic] = errors if errors is not None else []
        #: What unrolling loops has written out so far (T225).
        self.budget = loops.Budget()
        #: While a program's box is not known yet (no domain: it is read off the body, §8.3), the
        #: conditions that cannot be completed without it wait here with their diagnostic.
        self.pending: list[tuple[Diffeo, Diagnostic]] | None = None
        #: How many pieces the conditions split at their kinks have so far (at most MAX_PIECES),
        #: and whether a split is under way.
        self.pieces = 0
        self.splitting = False
        #: The kinks decided on the way to the piece being completed: (kink's condition, ≥ 0?).
        self.sides: list[tuple[Term, bool]] = []
        #: The loops whose first copy is being desugared, by index: what it shows (syntax/template.py).
        self.records: dict[str, template.Record] = {}

    def fail(self, d: Diagnostic, span: Span | None) -> Term:
        self.errors.append(d)
        return Const(Fraction(0), span=span)

    # ------------------------------------------------------------------------------------------
    def term(self, st: STerm, sc: Scope) -> Term:
        """The core term of the real-valued surface term ``st``; a vector here is T226."""
        t = self.value(st, sc)
        if type(t) is not Vec:  # (a core term: no equality test with POISON, two Python calls each)
            return t
        if t == vectors.POISON:
            return Const(Fraction(0), span=getattr(st, "span", None))
        span = getattr(st, "span", None)
        return self.fail(ty.reject_vector(span, len(t.parts)), span)

    def value(self, st: STerm, sc: Scope) -> Term | Vec:
        """The core term of the surface term ``st``, or the vector of core terms it denotes
        (LANGUAGE.md §6, the sugar table)."""
        span = getattr(st, "span", None)
        match st:  # (the most frequent forms first: each case is a class test)
            case Name():
                # a variable, parameter, let-bound name, def argument, or pi
                return self.name(st, sc)
            case BinOp("^"):
                # t ^ k with k a constant rational (T213 otherwise)
                return self.power(st, sc)
            case BinOp(op, a, b):
                # t + s;  t − s is t + (−1)·s;  t · s;  t / s is t · s ^ −1; with vectors: u ± v,
                # s·u, u·s, u / s component-wise
                left, right = self.value(a, sc), self.value(b, sc)
                if isinstance(left, Vec) or isinstance(right, Vec):
                    return self.vector_op(vectors.binop, op, left, right, span, (a.span, b.span))
                if op == "+":
                    return Add(left, right, span)  # (the span by position: a keyword costs a node ~1 k instructions)
                if op == "-":
                    return Add(left, neg(right), span)
                if op == "*":
                    return Mul(left, right, span)
                if op == "/":
                    return Mul(left, Pow(right, _MINUS_ONE, span), span)
                raise ValueError(f"unknown operator {op}")
            case Num(v):
                # a decimal literal, read exactly
                return Const(v, span)
            case Neg(Num(v)):
                # a negative literal is Const(-k)
                return Const(-v, span)
            case Neg(a):
                # unary −t is (−1)·t; −u of a vector is each component's
                arg = self.value(a, sc)
                if isinstance(arg, Vec):
                    return vectors.negate(arg)
                return Mul(Const(_MINUS_ONE), arg, span)
            case Apply("dot" | "cross" as f, args):
                # dot(u, v) is u1·v1 + … + un·vn; cross(u, v) of 3-vectors
                if len(args) != 2:
                    return self.fail(ty.reject_arity(st.name_span or span, f"`{f}`", 2, len(args)), span)
                return self.vector_op(vectors.dot if f == "dot" else vectors.cross, [self.value(u, sc) for u in args],
                                      span, tuple(u.span for u in args))
            case Apply():
                # f(t) primitive; abs/min/max sugar; a def call (left as a Call link)
                return self.apply(st, sc)
            case Vector(parts):
                # (t1, …, tn): the vector of the ti
                return Vec(tuple(self.term(u, sc) for u in parts))
            case Component(u, name):
                # u.x, u.y, u.z, u.w: a component
                return self.vector_op(vectors.component, self.value(u, sc), name, span, u.span, st.name_span)
            case Loop():
                # §9: sum i in A..B: t is t[A/i] + … + t[B/i] (0 when B < A); prod alike (1)
                return self.loop(st, sc)
            case Iverson(terms, ops):
                # [t0 op t1 op t2 …] is the product [t0 op t1]·[t1 op t2]·…
                errors, pieces = len(self.errors), self.pieces
                core = [self.term(t, sc) for t in terms]
                out = product([self.conditional(compare(core[i], op, core[i + 1]), Const(_ONE),
                                                Const(_ZERO), sc, span, join(terms[i], terms[i + 1]))
                               for i, op in enumerate(ops)], span)
                if len(self.errors) > errors and all(kinks.TOO_LARGE in d.message for d in self.errors[errors:]) \
                        and (alt := kinks.lattice(st)) is not None:
                    # too large to split at its kinks: [max(A, B) <= s] is [A <= s & B <= s] (syntax/kinks.py)
                    del self.errors[errors:]
                    self.pieces = pieces
                    return self.term(alt, sc)
                return out
            case Logic(op, parts):
                # [A & B] is [A]·[B]; [A | B] is 1 − (1 − [A])·(1 − [B]); [not A] is 1 − [A]
                one = Const(Fraction(1))
                brackets = [self.term(p_, sc) for p_ in parts]
                if op == "and":
                    return product(brackets, span)
                if op == "not":
                    return sub(one, brackets[0])
                return sub(one, product([sub(one, b) for b in brackets], span))
            case LetIn():
                # let z = t in s, t variable-free (Fig. 6, let)
                return self.let(st, sc)
            case IfGe0S(DiffeoApp() as app, then, orelse):
                # ifge0 ⌊Ψ⌋ then s else r with a declared Ψ
                psi = self.diffeo_app(app, sc)
                s, r = self.term(then, sc), self.term(orelse, sc)
                if psi is None:
                    return Const(Fraction(0), span=span)
                return IfDiffeo(psi, s, r, span=span)
            case IfGe0S(c, then, orelse):
                # ifge0 t then s else r: plain if t is variable-free, else completed ⌊Ψ⌋
                return self.conditional(self.term(c, sc), self.term(then, sc), self.term(orelse, sc), sc, span,
                                        cond_span=getattr(c, "span", None))
            case IfLogic(Logic(op, parts), then, orelse):
                # if A & B then s else r is if A then (if B then s else r) else r; with |, if A then s
                # else (if B then s else r); if not A then s else r is if A then r else s
                s_, r_ = self.term(then, sc), self.term(orelse, sc)
                if op == "not":
                    return self.if_chain(parts[0], r_, s_, sc, span)
                out = s_ if op == "and" else r_
                for part in reversed(parts):
                    out = (self.if_chain(part, out, r_, sc, span) if op == "and"
                           else self.if_chain(part, s_, out, sc, span))
                return out
            case IfCmp(left, op, right, then, orelse):
                # if t CMP s then p else q is ifge0 (t − s) (or s − t) then p else q
                cond = compare(self.term(left, sc), op, self.term(right, sc))
                return self.conditional(cond, self.term(then, sc), self.term(orelse, sc), sc, span, join(left, right))
            case NestedInt():
                # Fig. 11: a term contains no int (T208)
                return self.fail(ty.reject_nested_int(span), span)
        raise TypeError(f"not a surface term: {st!r}")

    # ------------------------------------------------------------------------------------------
    def vector_op(self, f, *args) -> Term | Vec:
        """``f(*args)``, one of :mod:`langur.syntax.vectors`' operations; its error is reported, and
        its value is then :data:`~langur.syntax.vectors.POISON` (no cascade of diagnostics)."""
        if any(a == vectors.POISON or (isinstance(a, list) and vectors.POISON in a) for a in args):
            return vectors.POISON
        try:
            return f(*args)
        except vectors.VectorError as e:
            self.errors.append(e.diagnostic)
            return vectors.POISON

    def loop(self, st: Loop, sc: Scope) -> Term:
        """§9's finite loop, unrolled: one copy of the body per value of the index, combined into a
        balanced sum or product (:mod:`langur.syntax.loops`; T224 for a bound that is not an integer
        constant, T225 past the bound on unrolling)."""
        if self.budget.exhausted:
            return Const(Fraction(0), span=st.span)
        self.unsafe(st.lo, st.hi, sc=sc)  # an enclosing index as a number
        try:
            lo, hi = loops.bounds(st.lo, st.hi, sc.consts)
        except loops.BoundError as e:
            return self.fail(ty.reject_loop_bound(e.span, e.why), st.span)
        except loops.TooLarge:
            self.budget.exhausted = True
            return self.fail(ty.reject_loop_too_large(join(st.lo, st.hi), f"a bound has more than {loops.MAX_BITS} "
                                                      "bits"), st.span)
        where = st.name_span or st.span
        if st.index in sc.variables:
            return self.fail(ty.reject_var_param_clash(where, st.index, "a loop's index has the name of a variable"),
                             st.span)
        if st.index == "pi":
            return self.fail(ty.reject_duplicate(where, "name (reserved constant)", "pi"), st.span)
        refused = self.budget.charge(max(0, hi - lo + 1), loops.size(st.body))
        if refused:
            return self.fail(ty.reject_loop_too_large(join(st.lo, st.hi), refused), st.span)
        before = len(self.errors)
        copies: list[Term] = []
        plan: template.Template | None = None
        charged = (0, 0)  # what desugaring the first copy took of the budget: each instantiated copy takes it too
        for k in range(lo, hi + 1):
            if plan is not None and k == lo + 1:
                # every other copy at once when they all fit the budget and all complete (else one
                # by one, below: a copy that does not complete is desugared, and reports why)
                rest = hi - lo
                if self.budget.again(charged[0] * rest, charged[1] * rest):
                    built = plan.at_all(range(k, hi + 1))
                    if built is not None:
                        copies += built
                        break
                    self.budget.copies -= charged[0] * rest
                    self.budget.nodes -= charged[1] * rest
            if plan is not None:
                if self.budget.again(*charged):
                    copy = plan.at(k)
                    if copy is not None:
                        copies.append(copy)
                        continue
                    self.budget.copies -= charged[0]
                    self.budget.nodes -= charged[1]
                else:
                    plan = None  # past the bound: desugared (and refused) as before
            if k == lo and hi > lo and template.ENABLED:
                # the first copy, watched: the others are built from it when its desugaring allows
                first, plan, charged = self.first_copy(st, sc, k)
                copies.append(first)
            else:
                copies.append(self.term(st.body, sc.with_index(st.index, k)))
            if self.budget.exhausted:
                break
        self.errors[before:] = loops.once(self.errors[before:])  # the copies' diagnostics are the body's
        if self.budget.exhausted:
            return Const(Fraction(0), span=st.span)
        return loops.balanced(copies, st.op, st.span)

    def first_copy(self, st: Loop, sc: Scope, k: int) -> tuple[Term, template.Template | None, tuple[int, int]]:
        """The first copy of a loop's body (index ``k``), desugared while a record watches; the
        template of the others when its desugaring allows (:mod:`langur.syntax.template`), and
        what it took of the budget."""
        record = template.Record(st.index)
        outer = self.records.get(st.index)
        if outer is not None:
            outer.unsafe = True  # an inner loop with the same index: the outer index is not watched here
        self.records[st.index] = record
        errors, pending, pieces = len(self.errors), len(self.pending or ()), self.pieces
        copies, nodes = self.budget.copies, self.budget.nodes
        try:
            body = self.term(st.body, sc.with_index(st.index, k))
        finally:
            if outer is None:
                del self.records[st.index]
            else:
                self.records[st.index] = outer
        charged = (self.budget.copies - copies, self.budget.nodes - nodes)
        if (record.unsafe or len(self.errors) > errors or len(self.pending or ()) != pending
                or self.pieces != pieces or self.budget.exhausted):
            return body, None, charged
        plan = template.Template(body, record, self.complete_again, self.note_completion)
        return body, (plan if plan.usable else None), charged

    def complete_again(self, cond: Term, variables: tuple[str, ...], box) -> Diffeo | None:
        """A copy's condition completed as :meth:`completed` would; None when it is not."""
        try:
            return complete(cond, variables, box)
        except diffeo.CompletionError:
            return None

    def note_completion(self, node: IfDiffeo, cond: Term, variables: tuple[str, ...], box) -> None:
        """Tell the loops being watched that ``node`` completes ``cond`` over ``variables``."""
        for watched in self.records.values():
            watched.completions[id(node)] = (node, cond, variables, box)

    def unsafe(self, *sts: STerm, sc: Scope | None = None) -> None:
        """The desugaring depends on the value of a watched loop index: on every watched one (no
        ``sts``), or on those the surface terms ``sts`` mention (read as numbers)."""
        if not self.records:
            return
        if not sts:
            for record in self.records.values():
                record.unsafe = True
            return
        for st in sts:
            stack = [st]
            while stack:
                u = stack.pop()
                if isinstance(u, Name) and u.name in self.records and (sc is None or u.name in sc.consts):
                    self.records[u.name].unsafe = True
                stack.extend(loops.children(u))

    def name(self, st: Name, sc: Scope) -> Term | Vec:
        n, span = st.name, st.span
        if n in sc.variables:
            return Var(n, span)
        if n in sc.consts:
            # a loop's index: the number it stands for in this copy of the body (§9)
            c = Const(sc.consts[n], span)
            record = self.records.get(n)
            if record is not None:
                record.leaves[id(c)] = c
            return c
        if n in sc.vectors:
            bound = sc.vectors[n]
            if bound.shadowed_by is not None:
                self.errors.append(ty.reject_vector_capture(span, bound.shadowed_by, n))
                return vectors.POISON
            return bound.vec
        if n in sc.gamma:
            return Param(n, span)
        if n == "pi":
            return Const(PI, span=span)
        if n in self.env.poisoned:
            return Const(Fraction(0), span=span)
        if n in self.env.defs or n in self.env.diffeos:
            return self.fail(ty.reject_unbound(span, n, f" (`{n}` is a {'def' if n in self.env.defs else 'diffeo'}, "
                                               "not a value)"), span)
        if n in sc.hidden_vars:
            return self.fail(ty.reject_undeclared_param(span, n, sc.where + f" (`{n}` is a variable of "
                                                        "integration; this position must be variable-free)"), span)
        if sc.where != "this term":
            return self.fail(ty.reject_undeclared_param(span, n, sc.where), span)
        return self.fail(ty.reject_unbound(span, n), span)

    def power(self, st: BinOp, sc: Scope) -> Term:
        base = self.term(st.left, sc)
        self.unsafe(st.right, sc=sc)  # the index as a number
        try:
            k = constant_value(st.right, sc.consts)
        except loops.TooLarge:
            return self.fail(ty.diag(st.right.span, "T231", "constant beyond the range of doubles: this exponent's "
                                     f"exact value has more than {loops.MAX_BITS} bits"), st.span)
        if k is None:
            return self.fail(ty.reject_exponent(getattr(st.right, "span", st.span)), st.span)
        return Pow(base, k, st.span)

    def apply(self, st: Apply, sc: Scope) -> Term:
        name, span = st.name, st.span
        where = st.name_span or span
        if name in self.env.poisoned:
            return Const(Fraction(0), span=span)
        if name in PRIMITIVES or name == "abs":
            if len(st.args) != 1:
                return self.fail(ty.reject_arity(where, f"`{name}`", 1, len(st.args)), span)
            a = self.term(st.args[0], sc)
            if name == "abs":
                # abs(t) is ifge0 t then t else −t
                return self.conditional(a, a, neg(a), sc, span)
            return Prim(name, a, span=span)
        if name in ("min", "max"):
            if len(st.args) != 2:
                return self.fail(ty.reject_arity(where, f"`{name}`", 2, len(st.args)), span)
            t, s = (self.term(a, sc) for a in st.args)
            # min(t, s) is ifge0 t − s then s else t;  max(t, s) is ifge0 t − s then t else s
            then, orelse = (s, t) if name == "min" else (t, s)
            return self.conditional(sub(t, s), then, orelse, sc, span)
        if name == "atan2":
            if len(st.args) != 2:
                return self.fail(ty.reject_arity(where, "`atan2`", 2, len(st.args)), span)
            y, x = (self.term(a, sc) for a in st.args)
            # atan2(y, x) is ifge0 y then acos(x / r) else −acos(x / r), r = sqrt(x² + y²): the
            # branch cut along y = 0, x < 0 (a jump of 2π) is a conditional, so it carries its delta
            angle = Prim("acos", Mul(x, Pow(Prim("sqrt", Add(Pow(x, Fraction(2)), Pow(y, Fraction(2)))), Fraction(-1))),
                         span=span)
            return self.conditional(y, angle, neg(angle), sc, span)
        if name in self.env.defs:
            sig = self.env.defs[name]
            if len(st.args) != len(sig.args):
                return self.fail(ty.reject_arity(where, f"def `{name}`", len(sig.args), len(st.args)), span)
            args = []
            ok = True
            for a, (aname, kind) in zip(st.args, sig.args):
                before = len(self.errors)
                t = self.term(a, sc if kind == "var" else replace(sc, where=f"param argument `{aname}` of `{name}`"))
                used = free_vars(t)
                if len(self.errors) > before:  # already refused (a vector argument, …): no cascade
                    ok = False
                elif kind == "var" and not used:
                    self.errors.append(ty.reject_var_arg_without_variables(getattr(a, "span", span), name, aname))
                    ok = False
                elif kind == "param" and used:
                    self.errors.append(ty.reject_param_arg_with_variables(getattr(a, "span", span), name, aname, used))
                    ok = False
                args.append(t)
            if not ok:
                return Const(Fraction(0), span=span)
            return Call(sig.module, sig.name, tuple(args), span=span)
        if name in self.env.diffeos:
            return self.fail(ty.reject_unknown_function(where, name, ": it is a diffeo, which is applied only as the "
                                                        f"condition of ifge0: `ifge0 {name}(variables; params) then …`"),
                             span)
        if name in ALL_PRIMITIVES:
            return self.fail(ty.reject_unknown_function(where, name, " (an internal primitive, not part of the "
                                                        "surface language)"), span)
        return self.fail(ty.reject_unknown_function(where, name, ": not a primitive (" + ", ".join(PRIMITIVES) +
                                                    ", " + ", ".join(SUGAR_FUNCTIONS) + ") nor a def in scope"), span)

    def let(self, st: LetIn, sc: Scope) -> Term | Vec:
        where = st.name_span or st.span
        bound = self.value(st.bound, replace(sc, where=f"the term bound to `{st.name}`"))
        if st.name in sc.variables:
            self.errors.append(ty.reject_var_param_clash(where, st.name, "let binds the name of a variable"))
        elif st.name == "pi":
            self.errors.append(ty.reject_duplicate(where, "name (reserved constant)", "pi"))
        if isinstance(bound, Vec):
            # a let-bound vector names its components, substituted where it is used
            return self.value(st.body, sc.with_vector(st.name, bound))
        used = free_vars(bound)
        if used:
            self.errors.append(ty.reject_let_with_variables(getattr(st.bound, "span", st.span), st.name, used))
        body = self.value(st.body, sc.with_param(st.name))
        if isinstance(body, Vec):
            # let z = t in (vector): the let around each component
            return Vec(tuple(Let(st.name, bound, b, span=st.span) for b in body.parts))
        return Let(st.name, bound, body, span=st.span)

    def if_chain(self, chain: Iverson, then: Term, orelse: Term, sc: Scope, span) -> Term:
        """``if t0 op0 t1 op1 t2 … then s else r``: one conditional per comparison, nested."""
        core = [self.term(u, sc) for u in chain.terms]
        out = then
        for i in reversed(range(len(chain.ops))):
            out = self.conditional(compare(core[i], chain.ops[i], core[i + 1]), out, orelse, sc, span,
                                   join(chain.terms[i], chain.terms[i + 1]))
        return out

    def conditional(self, cond: Term, then: Term, orelse: Term, sc: Scope, span, cond_span=None) -> Term:
        """``ifge0 cond then … else …``: IfGe0 when ``cond`` is variable-free, else the completed
        IfDiffeo (Fig. 6, conditional / diffeomorphic conditional)."""
        cond = kinks.cancelled(cond) if self.splitting else cond  # a kink split's flat piece
        if not free_vars(cond):
            return IfGe0(cond, then, orelse, span)
        if smooth(cond):  # no conditional and no call inside: completed as it is
            self.count_piece()
            return self.completed(cond, then, orelse, sc, span, cond_span)
        inner = next((u for u in subterms(cond) if isinstance(u, IfGe0) and not free_vars(u.cond)), None)
        if inner is not None:
            # a conditional on the parameters inside a condition over variables ([x < min(t, s)],
            # a bound `if c < 0 then a else b`): constant in the variables, it is lifted out —
            # ifge0 c' then (the condition with its then-branch) else (… with its else-branch)
            return IfGe0(inner.cond,
                         self.conditional(_put(cond, inner, inner.then), then, orelse, sc, span, cond_span),
                         self.conditional(_put(cond, inner, inner.orelse), then, orelse, sc, span, cond_span),
                         span=span)
        kink = next((u for u in subterms(cond) if isinstance(u, IfDiffeo)), None)
        if kink is not None and tree_size(cond) > MAX_SPLIT_SIZE:
            # nested kinks (abs(abs(…) − c)) double the written-out condition at each level
            return self.fail(ty.reject_condition(cond_span or cond.span or span, (
                f"with its kinks (abs, min, max over the variables) written out it has more than {MAX_SPLIT_SIZE} "
                "nodes: write it as a product or sum of simpler conditions ([max(A, B) <= s] is "
                "[A <= s & B <= s], [min(A, B) <= s] is [A <= s | B <= s]: brackets that compare a min, max "
                "or abs with a term are rewritten so by themselves)")), span)
        if kink is not None:
            self.unsafe()  # the split compares conditions
            # a conditional over the variables inside a condition (abs, min, max: [abs(x - a) <= 0.2])
            # splits the condition at the kink: ifge0 ⌊Ψ_k⌋ then (the condition with the kink's
            # then-branch) else (… with its else-branch), each branch completed on its own.  The
            # split's delta has weight (then − else) at the kink, which is 0 for a continuous
            # abs/min/max (both branches agree there): the split adds no derivative
            # (every conditional on the kink's condition in it takes the same branch: no repeated split)
            # (at most MAX_PIECES pieces in all the module's conditions: each split doubles them)
            c = kink.psi.condition
            top, self.splitting = not self.splitting, True
            self.sides.append((c, True))  # which piece: for the messages of a piece refused (T207)
            try:
                yes = self.conditional(_decided(cond, c, True), then, orelse, sc, span, cond_span)
                self.sides[-1] = (c, False)
                no = self.conditional(_decided(cond, c, False), then, orelse, sc, span, cond_span)
                return IfDiffeo(kink.psi, yes, no, span=span)
            except _TooManyPieces:
                if not top:
                    raise
                return self.fail(ty.reject_condition(cond_span or cond.span or span, (
                    f"split at their kinks (abs, min, max over the variables) the conditions have more than "
                    f"{MAX_PIECES} pieces in all: write this one as a product or sum of simpler conditions")), span)
            finally:
                self.sides.pop()
                if top:
                    self.splitting = False
        self.count_piece()
        if any(isinstance(u, Call) for u in subterms(cond)):
            self.unsafe()
            # a condition is completed as a whole: expand the defs it calls first
            cond, errs = expand_calls(cond, lambda m, n: self.env.bodies.get((m, n)), sc.variables, sc.box)
            if errs:
                self.errors.extend(errs)
                return Const(Fraction(0), span=span)
        return self.completed(cond, then, orelse, sc, span, cond_span)

    def count_piece(self) -> None:
        """One more piece of a condition split at its kinks (at most MAX_PIECES in all)."""
        if self.splitting:
            self.pieces += 1
            if self.pieces > MAX_PIECES:
                raise _TooManyPieces

    def completed(self, cond: Term, then: Term, orelse: Term, sc: Scope, span, cond_span) -> Term:
        """``ifge0 ⌊Ψ⌋ then … else …`` with Ψ the completion of ``cond`` over the variables (a
        pending one while the program's box is not known yet)."""
        try:
            psi = complete(cond, sc.variables, sc.box)
        except diffeo.CompletionError as e:
            why = kinks.on_piece(str(e), self.sides)
            if not sc.in_program and "bounded" in why:
                why += "; inside a def or diffeo the variables' domain is unknown: write this condition in the program"
            diagnostic = ty.reject_condition(cond_span or cond.span or span, why)
            if self.pending is None:
                return self.fail(diagnostic, span)
            psi = Diffeo(sc.variables, (cond,), (), ())  # completed by complete_pending
            self.pending.append((psi, diagnostic))
            self.unsafe()
            return IfDiffeo(psi, then, orelse, span=span)
        node = IfDiffeo(psi, then, orelse, span)
        if self.records:
            self.note_completion(node, cond, sc.variables, sc.box)
        return node

    def complete_pending(self, t: Term, variables: tuple[str, ...], box) -> Term:
        """``t`` with the conditions left pending completed over the program's ``box`` (a periodic
        condition needs its argument's range); those that still fail are reported (T207)."""
        pending, self.pending = dict((id(psi), d) for psi, d in self.pending or ()), None
        if not pending:
            return t

        def go(u: Term) -> Term:
            u = map_children(u, go)
            if not (isinstance(u, IfDiffeo) and id(u.psi) in pending):
                return u
            if box:
                try:
                    return replace(u, psi=complete(u.psi.forward[0], variables, box))
                except diffeo.CompletionError as e:
                    return self.fail(ty.reject_condition(pending[id(u.psi)].span, str(e)), u.span)
            return self.fail(pending[id(u.psi)], u.span)

        return go(t)

    def diffeo_app(self, app: DiffeoApp, sc: Scope) -> Diffeo | None:
        self.unsafe()  # a declared Ψ instantiated with its arguments' values
        where = app.name_span or app.span
        if app.name in self.env.poisoned:
            return None
        if app.name not in self.env.diffeos:
            detail = ": it is a def, not a diffeo" if app.name in self.env.defs else ": no diffeo of that name in scope"
            self.errors.append(ty.reject_unknown_function(where, app.name, detail))
            return None
        sig = self.env.diffeos[app.name]
        n, m = len(sig.diffeo.variables), len(sig.params)
        if len(app.variables) != n or len(app.params) != m:
            self.errors.append(ty.diag(where, "T203", f"diffeo `{app.name}` takes {n} variable(s) and {m} "
                                       f"parameter(s), got {len(app.variables)} and {len(app.params)}"))
            return None
        names: list[str] = []
        for v in app.variables:
            if not (isinstance(v, Name) and v.name in sc.variables):
                self.errors.append(ty.reject_diffeo_args(getattr(v, "span", where), app.name,
                                                         "this argument is not a variable of integration"))
                return None
            if v.name in names:
                self.errors.append(ty.reject_diffeo_args(v.span, app.name, f"`{v.name}` is passed twice"))
                return None
            names.append(v.name)
        params = []
        for p, pname in zip(app.params, sig.params):
            t = self.term(p, replace(sc, where=f"parameter `{pname}` of diffeo `{app.name}`"))
            used = free_vars(t)
            if used:
                self.errors.append(ty.reject_param_arg_with_variables(getattr(p, "span", where), app.name, pname, used))
                return None
            params.append(t)
        psi = diffeo.instantiate(sig.diffeo, sig.params, tuple(names), tuple(params),
                                 sc.variables if sc.in_program else None)
        return replace(psi, span=app.span)


def join(a: STerm, b: STerm) -> Span | None:
    """The span from the start of ``a`` to the end of ``b`` (a comparison's source text)."""
    sa, sb = getattr(a, "span", None), getattr(b, "span", None)
    if sa is None or sb is None:
        return sa or sb
    return Span(sa.path, sa.line, sa.col, sb.end_line, sb.end_col)


def compare(left: Term, op: str, right: Term) -> Term:
    """The condition of ``[left op right]``: ``left − right`` for ≥ and >, ``right − left`` for ≤ and <."""
    if op in (">=", ">", "≥"):
        return sub(left, right)
    if op in ("<=", "<", "≤"):
        return sub(right, left)
    raise ValueError(f"unknown comparison {op}")


def constant_value(st: STerm, consts: Mapping[str, Fraction] | None = None) -> Fraction | None:
    """The value of a constant rational surface expression (an exponent), or None; ``consts`` are
    the loop indices in scope (§9)."""
    return loops.constant(st, consts or {})


def is_smooth(t: Term) -> bool:
    """No conditionals, lets or calls: a term sympy can treat as a smooth function."""
    return not any(isinstance(u, (IfGe0, IfDiffeo, Let, Call)) for u in subterms(t))


__all__ = [
    "DefSig",
    "Desugarer",
    "DiffeoSig",
    "ElaboratedModule",
    "Env",
    "LangurError",
    "Scope",
    "compare",
    "constant_value",
    "inline",
    "is_smooth",
]
