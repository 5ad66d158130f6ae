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

The class is one, its methods in three modules: this one (the sugar table, names, powers, calls,
``let``, vectors), :mod:`langur.syntax.conditionals` (conditions: ``ifge0``, comparisons, Iverson
brackets' conditions, completion, kinks, declared diffeos) and :mod:`langur.syntax.unrolling`
(§9's loops).  What a name in a term is — Δ, Γ, a module's defs and diffeos — is
:mod:`langur.syntax.scope`'s.  Def calls are left as ``Call(module, name, args)`` links (separate compilation, §9);
``langur.syntax.inline.inline`` removes them.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
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
    neg,
    product,
    sub,
    subterms,
)
from ..diagnostics import Diagnostic, Span
from ..primitives import ALL_PRIMITIVES, PRIMITIVES
from . import kinks, loops, template, vectors
from .conditionals import Conditionals, compare, join
from .folding import divided, minus, negated, plus, power, times
from .scope import SUGAR_FUNCTIONS, Env, Scope
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
from .unrolling import Unrolling
from .vectors import Vec

_ZERO, _ONE, _MINUS_ONE = INT_FRACTIONS[0], INT_FRACTIONS[1], MINUS_ONE


class Desugarer(Conditionals, Unrolling):
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
                # (t + 0, t − 0, t·1, 1·t, t / 1 fold; t·0 and 0·t where t is defined everywhere: syntax/folding.py)
                if op == "+":
                    return plus(left, right, span)  # (the span by position: a keyword costs a node ~1 k instructions)
                if op == "-":
                    return minus(left, right, span)
                if op == "*":
                    return times(left, right, span)
                if op == "/":
                    return divided(left, right, span)
                raise ValueError(f"unknown operator {op}")
            case Num(v):
                # a decimal literal, read exactly
                return Const(v, span)
            case Neg(Num(v)):
                # a negative literal is Const(-k)
                return Const(-v, span)
            case Neg(a):
                # unary −t is (−1)·t (−0 is 0); −u of a vector is each component's
                arg = self.value(a, sc)
                if isinstance(arg, Vec):
                    return vectors.negate(arg)
                return negated(arg, span)
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
                                                Const(_ZERO), sc, span, join(terms[i], terms[i + 1]), built=True)
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
                return self.conditional(cond, self.term(then, sc), self.term(orelse, sc), sc, span, join(left, right),
                                        built=True)
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
        return power(base, k, st.span)  # (t ^ 1 is t)

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
                return self.conditional(a, a, negated(a), sc, span)
            return Prim(name, a, span=span)
        if name in ("min", "max"):
            if len(st.args) != 2:
                return self.fail(ty.reject_arity(where, f"`{name}`", 2, len(st.args)), span)
            t, s = (self.term(a, sc) for a in st.args)
            # min(t, s) is ifge0 t − s then s else t;  max(t, s) is ifge0 t − s then t else s
            then, orelse = (s, t) if name == "min" else (t, s)
            return self.conditional(minus(t, s), then, orelse, sc, span, built=True)
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


def constant_value(st: STerm, consts: Mapping[str, Fraction] | None = None) -> Fraction | None:
    """The value of a constant rational surface expression (an exponent), or None; ``consts`` are
    the loop indices in scope (§9)."""
    return loops.constant(st, consts or {})


def is_smooth(t: Term) -> bool:
    """No conditionals, lets or calls: a term sympy can treat as a smooth function."""
    return not any(isinstance(u, (IfGe0, IfDiffeo, Let, Call)) for u in subterms(t))


__all__ = ["Desugarer", "constant_value", "is_smooth"]
