"""Compile a core term once into a vectorized numpy evaluator with forward-mode tangents (§9).

:func:`compile_term` turns a core term into a *unit*: a Python closure ``fn(point, linking) ->
(value, d)`` that evaluates the term on whole arrays of points at once (no Python loop per sample),
plus the term's *slot table* (its diffeomorphic conditionals and calls in pre-order, for linking).
Separate compilation (§9) splits what the closure reads: the :class:`Point` it is evaluated at
(fresh for every evaluation) and its :class:`Linking` (where the unit sits in a linked program,
fixed when the program is linked; :data:`UNLINKED` for a unit run on its own).

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

import hashlib
import itertools
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

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
    TooManyRoots,
    Var,
    free_vars,
)
from ..primitives import REGISTRY
from .consts import const_value
from .interval import tape_of
from .signchanges import certified_brackets

VALUE, TANGENT, DELTA = 0, 1, 2
NAN = float("nan")


@dataclass(frozen=True, slots=True)
class Linking:
    """Where a unit sits in a linked program (§9, linking): the global id of its first site
    (``base``), its slot → site offset table (``offsets``; None: slot = offset) and the linked
    defs its calls go to (``units``: (module, def) → (fn, offsets, argument names))."""

    base: int = 0
    offsets: list | None = None
    units: dict | None = None


#: A unit run on its own: no calls to resolve, its sites numbered by its own slots.
UNLINKED = Linking()


@dataclass(frozen=True, slots=True)
class Point:
    """The evaluation point (§9: what a separately compiled unit reads when run): ρ (``vars``), a
    direction in the variables ρ' (``dvars``), γ (``params``), γ' (``dparams``), the mode, in
    DELTA mode the site owning each point (``site``, with the ids present in ``sites``), and the
    program's own (γ, γ') (``root``) that a def's body reads for its module's declared params
    (None at the program's top level, where they are ``params``, ``dparams``)."""

    vars: dict
    params: dict
    dvars: dict = field(default_factory=dict)
    dparams: dict = field(default_factory=dict)
    mode: int = VALUE
    site: np.ndarray | None = None
    sites: frozenset = frozenset()
    root: tuple | None = None
    #: values of the shared subterms already evaluated at this point (see :func:`_shared`)
    memo: dict = field(default_factory=dict, compare=False, repr=False)

    def values(self) -> Point:
        """The same point and parameters without any derivative (conditions are values only)."""
        if self.mode == VALUE:
            return self
        found = self.memo.get(_VALUES)  # made once per point (every condition reads it)
        if found is None:
            found = self.memo[_VALUES] = Point(self.vars, self.params, root=self.root and (self.root[0], {}))
        return found

    def bind(self, name: str, v, d) -> Point:
        """``γ[z ↦ v]``, ``γ'[z ↦ d]`` (Fig. 8, let)."""
        dp = self.dparams
        if d is not None or name in dp:
            dp = dict(dp)
            if d is None:
                del dp[name]
            else:
                dp[name] = d
        return Point(self.vars, {**self.params, name: v}, self.dvars, dp, self.mode, self.site, self.sites,
                     self.root or (self.params, self.dparams))


#: The key of :meth:`Point.values`'s point in :attr:`Point.memo` (the shared subterms' keys are ints).
_VALUES = "values"

Fn = Callable[[Point, Linking], tuple]


@dataclass
class Unit:
    """A compiled term: ``fn`` and its slots in pre-order: ``("site", None, ())`` or
    ``("call", (module, def), which arguments are plain variables)``."""

    fn: Fn
    slots: list


# -- constant powers: value and derivative, NaN outside the domain (primitives: langur.primitives)

def power(a, k: Fraction):
    """a^k for a constant rational k; NaN where undefined (0 to a negative power, fractional
    power of a negative number)."""
    if k == 1:
        return a
    if k == 2:
        return a * a
    if k == 0:
        return np.where(np.isnan(a), NAN, 1.0)
    if k == -1:
        out = 1.0 / np.where(a == 0, NAN, a)
    elif k == Fraction(1, 2):
        out = np.sqrt(a)
    else:
        out = np.power(np.where(a == 0, NAN, a) if k < 0 else a, float(k))
    return out


def power_derivative(a, k: Fraction, v):
    """d/da a^k = k·a^(k−1)."""
    if k == 1:
        return 1.0
    if k == 2:
        return 2.0 * a
    if k == 0:
        return 0.0
    if k == -1:
        return -(v * v)
    return float(k) * power(a, k - 1)


def full(v, n: int) -> np.ndarray:
    """``v`` (a scalar, None for 0, or an array of n values) as an array of n floats."""
    if type(v) is np.ndarray and v.shape == (n,):
        return v
    return np.full(n, 0.0 if v is None else v, dtype=float)


# -- dual-number helpers ------------------------------------------------------------------------

def _dadd(da, db):
    if da is None:
        return db
    if db is None:
        return da
    return da + db


def _dmul(da, b, db, a):
    """⦇t·s⦈ = ⦇t⦈·⟦s⟧ + ⦇s⦈·⟦t⟧ (Fig. 8, product)."""
    if da is None:
        return None if db is None else db * a
    if db is None:
        return da * b
    return da * b + db * a


def _select(c, ds, dr):
    if ds is None and dr is None:
        return None
    return np.where(c, 0.0 if ds is None else ds, 0.0 if dr is None else dr)


# -- the compiler: one match over the core AST, Fig. 8's order -----------------------------------

def compile_term(t: Term, local: frozenset[str] | None = None) -> Unit:
    """Compile ``t`` once; the result evaluates ⟦t⟧ and ⦇t⦈'s parts on arrays of points.

    ``local``: for a def body, its param arguments; any other parameter it reads (its module's
    declared params) is then looked up among the program's parameters (``point.root``), so a
    linked call binds only its arguments.  ``None``: every parameter is in ``point.params``."""
    ctx = _Ctx([], local, _Sharing(t))
    with np.errstate(all="ignore"):  # constants are folded now (a NaN is a value, as when evaluated)
        fn = _compile(t, ctx)
    return Unit(fn, ctx.slots)


class _Ctx:
    __slots__ = ("local", "slots", "sharing")

    def __init__(self, slots: list, local, sharing: _Sharing):
        self.slots = slots
        self.local = local
        self.sharing = sharing

    def bind(self, name: str) -> _Ctx:
        return self if self.local is None else _Ctx(self.slots, self.local | {name}, self.sharing)


#: Keys of shared subterms in :attr:`Point.memo`, unique across every compiled unit (units
#: compiled apart may be evaluated at one point).
_KEYS = itertools.count()


class _Sharing:
    """The subterms of a term that occur more than once in it (a DAG: substituted lets, inlined
    calls and vectors share their subterms; the ray tracer's completed conic has ~10,000 nodes
    written out and ~900 distinct ones) and contain no site nor call: those are compiled once and
    evaluated once per :class:`Point` (:func:`_shared`), with the same floating-point operations
    as written out.  Sites and calls are never shared: each occurrence owns its slot."""

    def __init__(self, t: Term):
        self.refs: dict[int, int] = {}
        self.compiled: dict[tuple, Fn] = {}
        self.keep = t  # the term stays alive, so the ids above stay its own
        self._count(t)

    def _count(self, root: Term) -> None:
        refs = self.refs
        refs[id(root)] = 1
        stack = [root]
        while stack:  # each distinct node expanded once (its children's references counted)
            for c in _children(stack.pop()):
                if type(c) in _LEAVES:
                    continue  # never shared
                n = refs.get(id(c))
                if n is None:
                    refs[id(c)] = 1
                    stack.append(c)
                else:
                    refs[id(c)] = n + 1

    def shared(self, t: Term) -> bool:
        # pure: no site nor call below (the kept attributes: no diffeomorphic conditional, no call)
        return self.refs.get(id(t), 0) > 1 and not t._psi_vars and not t._calls


_LEAVES = (Const, Var, Param)


def _children(t: Term) -> tuple:
    """The subterms a unit evaluates (a conditional's condition, not the rest of its Ψ̂), by the
    node's exact class (the node classes have no subclasses): :class:`_Sharing` asks it of every
    node of every unit compiled."""
    tt = type(t)
    if tt is Add or tt is Mul:
        return (t.left, t.right)
    if tt is IfDiffeo:
        return (t.psi.forward[0], t.then, t.orelse)
    if tt is Pow:
        return (t.base,)
    if tt is Prim:
        return (t.arg,)
    if tt is IfGe0:
        return (t.cond, t.then, t.orelse)
    if tt is Let:
        return (t.bound, t.body)
    if tt is Call:
        return tuple(t.args)
    if tt is ImplicitRoot:
        return (t.equation, t.target, t.lo, t.hi)
    return ()


def _compile(t: Term, ctx: _Ctx) -> Fn:
    if type(t) is not Const:
        c = _constant(t)
        if c is not None:
            # a constant: its value computed now, by the same operations its closures would run
            return lambda pt, lk: (c, None)
    sharing = ctx.sharing
    if sharing.shared(t):
        key = (id(t), ctx.local)
        fn = sharing.compiled.get(key)
        if fn is None:
            fn = sharing.compiled[key] = _shared(_compile_node(t, ctx), next(_KEYS), sharing.refs[id(t)])
        return fn
    return _compile_node(t, ctx)


_NOT_YET = object()


def _constant(t: Term):
    """:func:`_fold` of ``t`` when it has no variable, parameter or call (kept on the node: a
    number that only depends on the term), else None."""
    if t._fv or t._fp or t._calls:
        return None
    d = t.__dict__
    v = d.get("_folded", _NOT_YET)
    if v is _NOT_YET:
        v = d["_folded"] = _fold(t)
    return v


def _fold(t: Term):
    """The value of a constant term (no variable, parameter or call) built of constants, sums,
    products, powers and primitives, computed by exactly the floating-point operations of the
    closures :func:`_compile_node` would build for it (so evaluating it once at compile time gives
    the very numbers every evaluation would: a variable-free subterm evaluates to a scalar); None
    for any other term."""
    match t:
        case Const():
            return const_value(t)
        case Add(a, b) | Mul(a, b):
            x = _fold(a)
            if x is None:
                return None
            y = _fold(b)
            if y is None:
                return None
            return x + y if type(t) is Add else x * y
        case Pow(a, k):
            x = _fold(a)
            return None if x is None else power(x, k)
        case Prim(op, a):
            x = _fold(a)
            return None if x is None else REGISTRY[op].value(x)
    return None


def _shared(f: Fn, key: int, uses: int) -> Fn:
    """``f`` evaluated once per point: a shared pure subterm reads nothing but the point.  Its
    value is kept for the term's ``uses`` references and then dropped, so a point holds at once
    only the shared values still to be read (not every one: arrays of a million samples each).
    A reference not reached (a branch not taken) keeps the value until the point goes; one
    reached more often than counted evaluates ``f`` again, to the same numbers."""
    def shared(pt, lk):
        memo = pt.memo
        hit = memo.get(key)
        if hit is None:
            out = f(pt, lk)
            memo[key] = [out, uses - 1]
            return out
        hit[1] -= 1
        if hit[1] <= 0:
            del memo[key]
        return hit[0]
    return shared


def _compile_node(t: Term, ctx: _Ctx) -> Fn:
    match t:
        case Const():
            # Fig. 7/8, constant: ⟦c⟧ = c, ⦇c⦈ = 0
            c = const_value(t)
            return lambda pt, lk: (c, None)
        case Var(name):
            # Fig. 7/8, variable: ⟦x⟧ = ρ(x), ⦇x⦈ = 0 (a direction in the variables only for Jacobians)
            return lambda pt, lk: (pt.vars[name], pt.dvars.get(name))
        case Param(name):
            # Fig. 7/8, parameter: ⟦z⟧ = γ(z), ⦇z⦈ = γ'(z)
            if ctx.local is not None and name not in ctx.local:
                return lambda pt, lk: (pt.root[0][name], pt.root[1].get(name))
            return lambda pt, lk: (pt.params[name], pt.dparams.get(name))
        case Add(left, right):
            # Fig. 8, sum: ⦇t + s⦈ = ⦇t⦈ + ⦇s⦈
            f, g = _compile(left, ctx), _compile(right, ctx)
            cl, cr = _constant(left), _constant(right)
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
                return a + b, _dadd(da, db)
            return add
        case Mul(left, right):
            # Fig. 8, product: ⦇t·s⦈ = ⦇t⦈·T⟦s⟧ + ⦇s⦈·T⟦t⟧
            f, g = _compile(left, ctx), _compile(right, ctx)
            cl, cr = _constant(left), _constant(right)
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
                return a * b, _dmul(da, b, db, a)
            return mul
        case IfGe0(cond, then, orelse):
            # Fig. 8, conditional on parameters: ⦇s⦈ if ⟦t⟧(·,γ) ≥ 0 else ⦇r⦈
            fc, fs, fr = _compile(cond, ctx), _compile(then, ctx), _compile(orelse, ctx)

            def ifge0(pt, lk):
                c, _ = fc(pt.values(), lk)
                if np.ndim(c) == 0:
                    return fs(pt, lk) if c >= 0 else fr(pt, lk)
                s, ds = fs(pt, lk)
                r, dr = fr(pt, lk)
                m = c >= 0
                return np.where(m, s, r), _select(m, ds, dr)
            return ifge0
        case IfDiffeo(psi, then, orelse):
            # Fig. 8, diffeomorphic conditional: (⦇s⦈ if π₀Ψ̂ ≥ 0 else ⦇r⦈) + δ(π₀Ψ̂)·D_γπ₀Ψ̂·γ'·(⟦s⟧−⟦r⟧)
            slot = len(ctx.slots)
            ctx.slots.append(("site", None, ()))
            fc = _compile(psi.forward[0], _Ctx([], ctx.local, ctx.sharing))
            fs, fr = _compile(then, ctx), _compile(orelse, ctx)

            def ifdiffeo(pt, lk):
                c, _ = fc(pt.values(), lk)
                m = c >= 0
                s, ds = fs(pt, lk)
                r, dr = fr(pt, lk)
                d = _select(m, ds, dr)
                if pt.mode == DELTA:
                    gid = lk.base + (slot if lk.offsets is None else lk.offsets[slot])
                    if gid in pt.sites:
                        jump = np.where(pt.site == gid, s - r, 0.0)
                        d = jump if d is None else d + jump
                return np.where(m, s, r), d
            return ifdiffeo
        case Let(name, bound, body):
            # Fig. 8, let: ⦇s⦈(ρ, γ[z ↦ ⟦t⟧], γ'[z ↦ ⦇t⦈])
            fb, fbody = _compile(bound, ctx), _compile(body, ctx.bind(name))

            def let(pt, lk):
                v, d = fb(pt, lk)
                return fbody(pt.bind(name, v, d), lk)
            return let
        case Prim(op, arg):
            # extension (§1): smooth primitive, chain rule ⦇f(t)⦈ = f'(⟦t⟧)·⦇t⦈
            f, prim = _compile(arg, ctx), REGISTRY[op]

            def primitive(pt, lk):
                a, da = f(pt, lk)
                v = prim.value(a)
                return v, (None if da is None else prim.derivative(a, v) * da)
            return primitive
        case Pow(base, k):
            # extension (§1): constant power, ⦇t^k⦈ = k·⟦t⟧^(k−1)·⦇t⦈
            f = _compile(base, ctx)

            def pow_(pt, lk):
                a, da = f(pt, lk)
                v = power(a, k)
                return v, (None if da is None else power_derivative(a, k, v) * da)
            return pow_
        case Call(module, name, args):
            # §9, separate compilation: a link to a separately compiled def (see link.py)
            slot = len(ctx.slots)
            ctx.slots.append(("call", (module, name), tuple(isinstance(a, Var) for a in args)))
            return _compile_call(slot, module, name, args, ctx)
        case ImplicitRoot(equation, variable, target, lo, hi, index, of, slope):
            # issue 18, implicit root (a Ψ̂⁻¹ component): x* in [lo, hi] with f(x*) = ⟦target⟧;
            # ⦇x*⦈ = (⦇target⦈ − ∂f/∂γ·γ') / ∂f/∂x at x* (implicit function theorem)
            parts = (_compile(equation, ctx), variable, _compile(target, ctx), _compile(lo, ctx), _compile(hi, ctx))
            if index is None:
                return _compile_root(*parts)
            others = tuple(sorted(free_vars(equation) - {variable}))  # Ψ̂⁻¹'s other inputs it moves with
            return _compile_sign_change(*parts, index, of, None if slope is None else tape_of([equation, slope], True),
                                        t.span, others, equation)
    raise TypeError(f"not a core term: {t!r}")


#: Halvings of an implicit root's bracket: past double precision for brackets up to 2^10 wide.
ROOT_HALVINGS = 64 + 10
def _bisect(f, t, a, b):
    """Vectorized bisection of ``f − t`` on brackets ``[a, b]`` where it changes sign (NaN where it
    does not)."""
    a0, b0 = a, b
    a, b = a.copy(), b.copy()
    fa, fb = f(a) - t, f(b) - t
    rising = fa < fb
    ok = (np.sign(fa) * np.sign(fb) <= 0) & ~np.isnan(fa) & ~np.isnan(fb)
    for _ in range(ROOT_HALVINGS):
        m = 0.5 * (a + b)
        below = (f(m) - t < 0) == rising
        a, b = np.where(below, m, a), np.where(below, b, m)
    return np.where(ok, np.where(fa == 0, a0, np.where(fb == 0, b0, 0.5 * (a + b))), NAN)


def _root_tangent(fe: Fn, x: str, value, dt, pt: Point, lk: Linking):
    """⦇x*⦈ = (⦇target⦈ − ∂f/∂γ·γ' − ∂f/∂u·u') / ∂f/∂x at x* (implicit function theorem; u: the
    other inputs of Ψ̂⁻¹ the equation mentions, for a condition in several variables)."""
    vals = pt.values()
    at = {**vals.vars, x: value}
    fx = fe(Point(at, vals.params, dvars={x: 1.0}, mode=TANGENT, root=vals.root), lk)[1]
    others = {k: d for k, d in pt.dvars.items() if k != x}
    ftheta = fe(Point(at, pt.params, dvars=others, dparams=pt.dparams, mode=TANGENT, root=pt.root), lk)[1]
    num = _dadd(dt, None if ftheta is None else -ftheta)
    return None if num is None else num / fx


def _compile_root(fe: Fn, x: str, ft: Fn, flo: Fn, fhi: Fn) -> Fn:
    """The implicit root, vectorized: bisection of ``f − target`` on each point's bracket (``f`` is
    monotone there and changes sign when the branch's guard holds; NaN where it does not)."""
    def root(pt, lk):
        vals = pt.values()
        t, dt = ft(pt, lk)
        lo, hi = flo(vals, lk)[0], fhi(vals, lk)[0]
        t, a, b = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (t, lo, hi)))
        value = _bisect(lambda at: fe(Point({**vals.vars, x: at}, vals.params, root=vals.root), lk)[0], t, a, b)
        return value, (None if pt.mode == VALUE else _root_tangent(fe, x, value, dt, pt, lk))
    return root


#: The certified sign changes of the last few (equation, points) met, each bisected: the k-th sign
#: changes of one equation are one node per k (and each is read by several branches and guards),
#: all found by one certification (kept with the equation itself, whose id is part of the key; the
#: points by a digest of their table, so a large batch is not held twice).
_SIGN_CHANGES: dict = {}


def _compile_sign_change(fe: Fn, x: str, ft: Fn, flo: Fn, fhi: Fn, index: int, of: int, tape, span,
                         others: tuple[str, ...] = (), equation: Term | None = None) -> Fn:
    """The ``index``-th sign change of ``f − target`` on ``[lo, hi]`` (``hi`` when there are
    fewer; :class:`~langur.core.TooManyRoots` when more than ``of``, or when they cannot be
    certified): each sign change certified in a bracket (:mod:`langur.operational.signchanges`,
    ``tape`` encloses f and ∂f/∂x), once per distinct parameter point, and bisected there.
    ``others``: the other inputs of Ψ̂⁻¹ ``f`` mentions (turning points that move with the other
    variables of a condition split along ``x``): part of each point, and a cell left uncertified
    on a null set of them is decided by its ends (``lenient``)."""
    def sign_change(pt, lk):
        vals = pt.values()
        if tape is None:
            raise TooManyRoots("a turning point that moves with the parameters has no ∂²/∂x² to certify that none "
                               "is missed (an implicit root without its slope): Langur cannot evaluate it", span)
        t, dt = ft(pt, lk)
        (lo, _), (hi, dhi) = flo(vals, lk), fhi(pt, lk)
        columns = [t, lo, hi] + [vals.vars[u] for u in others] + [v for v in vals.params.values() if np.ndim(v)]
        n = max([np.size(c) for c in columns])
        table = np.stack([np.broadcast_to(np.asarray(c, dtype=float).reshape(-1), (n,)) if np.size(c) > 1
                          else np.full(n, float(np.asarray(c).reshape(-1)[0])) for c in columns], axis=1)
        rows, back = np.unique(table, axis=0, return_inverse=True)
        back = back.reshape(-1)
        first = np.unique(back, return_index=True)[1]  # one sample row per distinct point
        params = {k: (np.broadcast_to(np.asarray(v, dtype=float).reshape(-1), (n,))[first] if np.ndim(v) else v)
                  for k, v in vals.params.items()}
        tr, lor, hir = rows[:, 0], rows[:, 1], rows[:, 2]
        moving = {u: rows[:, 3 + i] for i, u in enumerate(others)}

        def at_rows(r):
            return {k: (v[r] if np.ndim(v) else v) for k, v in params.items()}

        def value(at, r):
            at_vars = {x: at, **{u: v[r] for u, v in moving.items()}}
            return np.broadcast_to(fe(Point(at_vars, at_rows(r), root=vals.root), lk)[0], np.shape(at))

        key = (id(equation), x, rows.shape, hashlib.blake2b(rows.tobytes(), digest_size=20).digest(),
               tuple((k, float(v)) for k, v in sorted(vals.params.items()) if not np.ndim(v)))
        found = _SIGN_CHANGES.get(key)
        if found is None or found[0] is not equation:
            r, a, b = certified_brackets(value, tape, x, tr, lor, hir, params, span, what=f"∂/∂{x}", others=moving,
                                         lenient=bool(others))
            counts = np.bincount(r, minlength=len(tr))
            if np.any(counts > of):
                raise TooManyRoots(f"{int(counts.max())} turning points on the domain at these parameter values, more "
                                   f"than the {of} the condition was split for: Langur cannot differentiate it here; "
                                   "split the variable's domain (a sum of integrals over sub-intervals, each with at "
                                   "most that many turning points)", span)
            roots = _bisect(lambda at: value(at, r), tr[r], a, b)  # every sign change of every row at once
            found = (equation, r, counts, roots)
            if len(_SIGN_CHANGES) >= 8:
                _SIGN_CHANGES.pop(next(iter(_SIGN_CHANGES)))
            _SIGN_CHANGES[key] = found
        _, r, counts, roots = found
        value_rows = hir.copy()
        has = counts > index
        if has.any():
            start = np.concatenate([[0], np.cumsum(counts)[:-1]])
            pick = start[has] + index  # the (index+1)-th bracket of each row that has one
            value_rows[r[pick]] = roots[pick]
        value = value_rows[back] if n > 1 or np.ndim(t) or np.ndim(lo) or np.ndim(hi) else value_rows[0]
        if pt.mode == VALUE:
            return value, None
        inside = has[back] if np.ndim(value) else bool(has[0])
        d = _root_tangent(fe, x, value, dt, pt, lk)
        if d is None and dhi is None:
            return value, None
        return value, np.where(inside, 0.0 if d is None else d, 0.0 if dhi is None else dhi)
    return sign_change


def _compile_call(slot: int, module: str, name: str, args, ctx: _Ctx) -> Fn:
    """A linked call: param arguments evaluated once in the caller (a value and its tangent, as a
    ``let`` would), var arguments renamed (they must be plain variables, see link.py)."""
    arg_fns = []
    for a in args:
        if isinstance(a, Var):
            arg_fns.append(("var", a.name))
        else:
            arg_fns.append(("term", _compile(a, ctx)))

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
