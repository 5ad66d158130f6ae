"""Compile a core term once into a vectorized numpy evaluator with forward-mode tangents (§9).

:func:`compile_term` turns a core term into a *unit*: a Python closure ``fn(point, linking) ->
(value, d)`` that evaluates the term on whole arrays of points at once (no Python loop per sample),
plus the term's *slot table* (its diffeomorphic conditionals and calls in pre-order, for linking).
Separate compilation (§9) splits what the closure reads (:mod:`langur.operational.point`): the
:class:`Point` it is evaluated at (fresh for every evaluation) and its :class:`Linking` (where the
unit sits in a linked program, fixed when the program is linked; :data:`UNLINKED` for a unit run on
its own).  What is computed once per term is in :mod:`~langur.operational.sharing`, dual-number
arithmetic in :mod:`~langur.operational.dual`, implicit roots in :mod:`~langur.operational.roots`.

``d`` is the derivative part of a dual number; ``None`` stands for an exact zero (so terms that do
not depend on the direction cost nothing).  What ``d`` means depends on the point's mode:

* ``VALUE``   — ``d`` is always ``None``: ⟦t⟧ only (Fig. 7).
* ``TANGENT`` — forward-mode derivative in the direction given by ``point.dparams`` (γ') and
  ``point.dvars`` (a direction in the variables, used for Jacobians of inverse branches): the
  regular part of ⦇t⦈ with every delta dropped, i.e. standard AD, the paper's Dˢ (Fig. 1d, 2c).
* ``DELTA``   — ``d`` is G_k(t), the coefficient of δ_k in ⦇t⦈ *per unit* of D_γ π₀Ψ̂_k·γ', where
  ``k = point.site[i]`` is the site owning point ``i``.  It obeys Fig. 8 with every ⦇z⦈ = 0: sums
  add, products G(t)·⟦s⟧ + G(s)·⟦t⟧, primitives f'(⟦t⟧)·G(t), conditionals select, and at site k
  itself ``⟦s⟧ − ⟦r⟧`` is added.  (E_k = (D_γ π₀Ψ̂_k·γ')·G_k because E_k is linear in site k's
  seed; the factor is computed from the site's canonical condition by the sampler.)

Numerical conventions: Const("pi") is π; primitives outside their domain give NaN (log x for
x ≤ 0, t^k with k < 0 at t = 0, sqrt/asin/acos/atanh outside their domains); callers wrap
evaluation in ``np.errstate(all="ignore")``.  Variable-free subterms evaluate to scalars, so a
``param`` argument evaluated once by a linked call and the same term substituted by the inliner
run exactly the same floating-point operations (bit-identical linking, Theorem 9.1).
"""

from __future__ import annotations

import math

import numpy as np

from .. import lazy
from ..core import (
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Term,
    Var,
    free_vars,
)
from ..primitives import REGISTRY
from .consts import const_value
from .dual import power, power_derivative, select
from .point import DELTA, Fn, Linking, Point, Unit
from .sharing import KEYS, Sharing, constant, evaluated_once

# Implicit roots (issue 18) and their interval tapes, imported when a program has one: an affine
# program's conditions are completed in closed form (start-up of a one-shot ``langur eval``, issue 15).
interval = lazy.module("langur.operational.interval")
roots = lazy.module("langur.operational.roots")

# -- the compiler: one match over the core AST, Fig. 8's order -----------------------------------

def compile_term(t: Term, local: frozenset[str] | None = None) -> Unit:
    """Compile ``t`` once; the result evaluates ⟦t⟧ and ⦇t⦈'s parts on arrays of points.

    ``local``: for a def body, its param arguments; any other parameter it reads (its module's
    declared params) is then looked up among the program's parameters (``point.root``), so a
    linked call binds only its arguments.  ``None``: every parameter is in ``point.params``."""
    with np.errstate(all="ignore"):  # constants are folded now (a NaN is a value, as when evaluated)
        ctx = Context([], local, Sharing(t))
        fn = compile_subterm(t, ctx)
    return Unit(fn, ctx.slots)


def compile_pure(terms) -> tuple[list[Fn], bool]:
    """:func:`compile_term`'s closures of several terms without sites or calls (a zero set's
    condition and inverse branches, a box's bounds: run unlinked), each compiled on its own, all
    under one ``errstate``; and whether they all give the same doubles run on Python floats as on
    numpy arrays of one point (:attr:`Sharing.numbers`)."""
    with np.errstate(all="ignore"):
        sharings = [Sharing(t) for t in terms]
        fns = [compile_subterm(t, Context([], None, sh)) for t, sh in zip(terms, sharings)]
    return fns, all(sh.numbers for sh in sharings)


class Context:
    """What compiling a subterm needs besides the subterm: the unit's slot table (``slots``, its
    diffeomorphic conditionals and calls in pre-order), a def body's param arguments (``local``,
    :func:`compile_term`) and the unit's shared subterms (``sharing``)."""

    __slots__ = ("local", "slots", "sharing")

    def __init__(self, slots: list, local, sharing: Sharing):
        self.slots = slots
        self.local = local
        self.sharing = sharing

    def bind(self, name: str) -> Context:
        return self if self.local is None else Context(self.slots, self.local | {name}, self.sharing)


def compile_subterm(t: Term, ctx: Context) -> Fn:
    """The closure of the subterm ``t`` (a constant folded, a shared subterm compiled once); every
    rule's recursion goes through this module's global of this name, which is what
    :mod:`langur.fuzz.coverage` wraps and :mod:`langur.fuzz.mutants` replaces."""
    if type(t) is not Const:
        c = constant(t)
        if c is not None:
            # a constant: its value computed now, by the same operations its closures would run
            return _constant(c)
    sharing = ctx.sharing
    if sharing.shared(t):
        key = (id(t), ctx.local)
        fn = sharing.compiled.get(key)
        if fn is None:
            fn = sharing.compiled[key] = evaluated_once(_compile_node(t, ctx), next(KEYS), sharing.refs[id(t)])
        return fn
    return _compile_node(t, ctx)


def _compile_node(t: Term, ctx: Context) -> Fn:
    # (each rule's closure is made by a function of its own below: the closures' variables are then
    # that function's, not cells this function would make at every call, one per variable of every case;
    # the frequent nodes' fields are read after the match, not bound by it: a class pattern that binds
    # fields makes a set of their names at every match)
    match t:
        case Const():
            # Fig. 7/8, constant: ⟦c⟧ = c, ⦇c⦈ = 0
            return _constant(const_value(t))
        case Var():
            # Fig. 7/8, variable: ⟦x⟧ = ρ(x), ⦇x⦈ = 0 (a direction in the variables only for Jacobians)
            return _variable(t.name)
        case Param():
            # Fig. 7/8, parameter: ⟦z⟧ = γ(z), ⦇z⦈ = γ'(z)
            if ctx.local is not None and t.name not in ctx.local:
                return _module_parameter(t.name)
            return _parameter(t.name)
        case Add():
            # Fig. 8, sum: ⦇t + s⦈ = ⦇t⦈ + ⦇s⦈
            left, right = t.left, t.right
            cl, cr = constant(left), constant(right)  # (a constant operand is folded into the closure)
            return _add(compile_subterm(left, ctx) if cl is None or cr is not None else None,
                        compile_subterm(right, ctx) if cr is None else None, cl, cr)
        case Mul():
            # Fig. 8, product: ⦇t·s⦈ = ⦇t⦈·T⟦s⟧ + ⦇s⦈·T⟦t⟧
            left, right = t.left, t.right
            cl, cr = constant(left), constant(right)  # (a constant operand is folded into the closure)
            return _mul(compile_subterm(left, ctx) if cl is None or cr is not None else None,
                        compile_subterm(right, ctx) if cr is None else None, cl, cr)
        case IfGe0(cond, then, orelse):
            # Fig. 8, conditional on parameters: ⦇s⦈ if ⟦t⟧(·,γ) ≥ 0 else ⦇r⦈
            ctx.sharing.numbers = False
            return _ifge0(compile_subterm(cond, ctx), compile_subterm(then, ctx), compile_subterm(orelse, ctx))
        case IfDiffeo():
            # Fig. 8, diffeomorphic conditional: (⦇s⦈ if π₀Ψ̂ ≥ 0 else ⦇r⦈) + δ(π₀Ψ̂)·D_γπ₀Ψ̂·γ'·(⟦s⟧−⟦r⟧)
            slot = len(ctx.slots)
            ctx.slots.append(("site", None, ()))
            ctx.sharing.numbers = False
            fc = compile_subterm(t.psi.forward[0], Context([], ctx.local, ctx.sharing))
            return _ifdiffeo(slot, fc, compile_subterm(t.then, ctx), compile_subterm(t.orelse, ctx))
        case Let(name, bound, body):
            # Fig. 8, let: ⦇s⦈(ρ, γ[z ↦ ⟦t⟧], γ'[z ↦ ⦇t⦈])
            return _let(name, compile_subterm(bound, ctx), compile_subterm(body, ctx.bind(name)))
        case Prim(op, arg):
            # extension (§1): smooth primitive, chain rule ⦇f(t)⦈ = f'(⟦t⟧)·⦇t⦈
            ctx.sharing.numbers = False
            return _primitive(compile_subterm(arg, ctx), REGISTRY[op])
        case Pow(base, k):
            # extension (§1): constant power, ⦇t^k⦈ = k·⟦t⟧^(k−1)·⦇t⦈
            if k not in _EXACT_POWERS:
                ctx.sharing.numbers = False
            return _power(compile_subterm(base, ctx), k)
        case Call(module, name, args):
            # §9, separate compilation: a link to a separately compiled def (see link.py)
            slot = len(ctx.slots)
            ctx.sharing.numbers = False
            ctx.slots.append(("call", (module, name), tuple(isinstance(a, Var) for a in args)))
            return _compile_call(slot, module, name, args, ctx)
        case ImplicitRoot(equation, variable, target, lo, hi, index, of, slope):
            # issue 18, implicit root (a Ψ̂⁻¹ component): x* in [lo, hi] with f(x*) = ⟦target⟧;
            # ⦇x*⦈ = (⦇target⦈ − ∂f/∂γ·γ') / ∂f/∂x at x* (implicit function theorem)
            ctx.sharing.numbers = False
            parts = (compile_subterm(equation, ctx), variable, compile_subterm(target, ctx),
                     compile_subterm(lo, ctx), compile_subterm(hi, ctx))
            if index is None:
                return roots.compile_root(*parts)
            others = tuple(sorted(free_vars(equation) - {variable}))  # Ψ̂⁻¹'s other inputs it moves with
            return roots.compile_sign_change(*parts, index, of,
                                              None if slope is None else interval.tape_of([equation, slope], True),
                                              t, others, equation)
    raise TypeError(f"not a core term: {t!r}")


# -- the rules' closures (made by _compile_node, one function per rule) ---------------------------

def _constant(c) -> Fn:
    return lambda pt, lk: (c, None)


def _variable(name: str) -> Fn:
    return lambda pt, lk: (pt.vars[name], pt.dvars.get(name))


def _parameter(name: str) -> Fn:
    return lambda pt, lk: (pt.params[name], pt.dparams.get(name))


def _module_parameter(name: str) -> Fn:
    """A def body's read of its module's declared parameter: the program's (γ, γ')."""
    return lambda pt, lk: (pt.root[0][name], pt.root[1].get(name))


#: The constant powers whose value and derivative (:func:`~.dual.power`: ``a``, ``a·a``, ``1/a``, ``1``;
#: ``1``, ``2·a``, ``−v·v``, ``0``) IEEE 754 rounds correctly whatever runs them (:attr:`Sharing.numbers`).
_EXACT_POWERS = (1, 2, -1, 0)


def _unit(c, unit: float) -> bool:
    """Whether the constant ``c`` is exactly ``unit``, −0.0 for a sum, 1.0 for a product: x + (−0.0)
    and x · 1.0 are x bit for bit for every double x (IEEE 754 round to nearest: ±0, ±∞ and NaN
    included), so the operation is left out and the same numbers come out (an affine condition's
    completion ends in ``+ (−1)·0``)."""
    return c == unit and math.copysign(1.0, c) == math.copysign(1.0, unit)


def _add(f: Fn | None, g: Fn | None, cl, cr) -> Fn:
    if cr is not None and _unit(cr, -0.0):
        return f
    if cl is not None and _unit(cl, -0.0):
        return g
    if cr is not None:  # t + c (⦇c⦈ = 0): the same operation, one call fewer
        def add_constant(pt, lk):
            a, da = f(pt, lk)
            return a + cr, da
        return add_constant
    if cl is not None:
        def constant_add(pt, lk):
            b, db = g(pt, lk)
            return cl + b, db
        return constant_add

    def add(pt, lk):
        a, da = f(pt, lk)
        b, db = g(pt, lk)
        # (dual.dadd written out: one call fewer per sum)
        return a + b, (db if da is None else da if db is None else da + db)
    return add


def _mul(f: Fn | None, g: Fn | None, cl, cr) -> Fn:
    if cr is not None and _unit(cr, 1.0):  # (⦇t⦈·1.0 is ⦇t⦈ too)
        return f
    if cl is not None and _unit(cl, 1.0):
        return g
    if cr is not None:  # t · c (⦇c⦈ = 0): ⦇t⦈·c
        def mul_constant(pt, lk):
            a, da = f(pt, lk)
            return a * cr, (None if da is None else da * cr)
        return mul_constant
    if cl is not None:
        def constant_mul(pt, lk):
            b, db = g(pt, lk)
            return cl * b, (None if db is None else db * cl)
        return constant_mul

    def mul(pt, lk):
        a, da = f(pt, lk)
        b, db = g(pt, lk)
        # (dual.dmul written out: one call fewer per product)
        if da is None:
            return a * b, (None if db is None else db * a)
        return a * b, (da * b if db is None else da * b + db * a)
    return mul


def _ifge0(fc: Fn, fs: Fn, fr: Fn) -> Fn:
    def ifge0(pt, lk):
        c, _ = fc(pt.values(), lk)
        if np.ndim(c) == 0:
            return fs(pt, lk) if c >= 0 else fr(pt, lk)
        s, ds = fs(pt, lk)
        r, dr = fr(pt, lk)
        m = c >= 0
        return np.where(m, s, r), select(m, ds, dr)
    return ifge0


def _ifdiffeo(slot: int, fc: Fn, fs: Fn, fr: Fn) -> Fn:
    def ifdiffeo(pt, lk):
        c, _ = fc(pt.values(), lk)
        m = c >= 0
        s, ds = fs(pt, lk)
        r, dr = fr(pt, lk)
        d = None if ds is None and dr is None else select(m, ds, dr)
        if pt.mode == DELTA:
            gid = lk.base + (slot if lk.offsets is None else lk.offsets[slot])
            if gid in pt.sites:
                jump = np.where(pt.site == gid, s - r, 0.0)
                d = jump if d is None else d + jump
        return np.where(m, s, r), d
    return ifdiffeo


def _let(name: str, fb: Fn, fbody: Fn) -> Fn:
    def let(pt, lk):
        v, d = fb(pt, lk)
        return fbody(pt.bind(name, v, d), lk)
    return let


def _primitive(f: Fn, prim) -> Fn:
    def primitive(pt, lk):
        a, da = f(pt, lk)
        v = prim.value(a)
        return v, (None if da is None else prim.derivative(a, v) * da)
    return primitive


def _power(f: Fn, k) -> Fn:
    def pow_(pt, lk):
        a, da = f(pt, lk)
        v = power(a, k)
        return v, (None if da is None else power_derivative(a, k, v) * da)
    return pow_


def _compile_call(slot: int, module: str, name: str, args, ctx: Context) -> Fn:
    """A linked call: param arguments evaluated once in the caller (a value and its tangent, as a
    ``let`` would), var arguments renamed (they must be plain variables, see link.py)."""
    arg_fns = []
    for a in args:
        if isinstance(a, Var):
            arg_fns.append(("var", a.name))
        else:
            arg_fns.append(("term", compile_subterm(a, ctx)))

    def call(pt, lk):
        fn, offsets, arg_names = lk.units[(module, name)]
        vars_, dvars, params, dparams = {}, {}, {}, {}
        for (how, a), argname in zip(arg_fns, arg_names):
            if how == "var":
                vars_[argname] = pt.vars[a]
                if a in pt.dvars:
                    dvars[argname] = pt.dvars[a]
            else:
                v, d = a(pt, lk)
                params[argname] = v
                if d is not None:
                    dparams[argname] = d
        base = lk.base + (slot if lk.offsets is None else lk.offsets[slot])
        return fn(Point(vars_, params, dvars, dparams, pt.mode, pt.site, pt.sites,
                        pt.root or (pt.params, pt.dparams)), Linking(base, offsets, lk.units))
    return call
