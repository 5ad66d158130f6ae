"""Per-node attributes of core terms (issue 15), computed once when a node is built.

Every pass of the front end asks the same questions of a term — its free variables and parameters,
whether it is smooth or calls a def, its size and depth, its exact value when it is a constant — and
a walk per question per pass costs Python's price per node each time.  A term is immutable, so each
answer is computed once, bottom-up, when the node is built (its children already carry theirs) and
kept on the node (never compared, hashed nor pickled: a pickled node is rebuilt by its
constructor, which recomputes them).  Those that depend on the node's shape only — its classes,
names, primitives, exponents and diffeos, not the values of its constants — are kept together as
one tuple, ``t.shape``, read at the indices :data:`FV` … :data:`DFP` (a loop's copies share their
template's tuple, :mod:`langur.core.shapes`; a parent reads a child's in one access); its small
value as ``t.small`` and ``t.small_all``.  The functions of :mod:`langur.core.structural`
(``free_vars``, ``free_params``, ``smooth``, ``has_calls``, ``tree_size``, ``depth``,
``small_value``, ``all_small``, ``diffeo_variables``) read them.

``t.shape`` is public, like the node's fields (read only: a node is frozen), and so are the indices
(exported by :mod:`langur.core`): code outside the core that reads an entry in a loop over every node
(the Monte Carlo engine's link, its sharing pass, the type system's ``well_typed``, the front end's
loop template) reads ``t.shape[SMOOTH]`` or unpacks the tuple in place, one attribute access, where
a call of ``smooth(t)`` would cost a Python call per node.  ``t.small`` and ``t.small_all`` are
public for the same reason (``small_value(t)`` and ``all_small(t)``, read in place by the front
end's linear forms, ``syntax.affine``, and its loop template).

Also kept, for typing (``langur.typesys.well_typed``): the premises of Fig. 6's rules that do not
depend on the context Δ; Γ (``SCOPED``: conditions of ``ifge0``, bounds of ``let``, a diffeo's
own terms are where they must be, exponents are rational), the primitives used (``OPS``), the
names ``let`` binds (``BINDERS``) and the parameters of the diffeos' inverse branches, guards and
``nonzero`` terms (``DFP``, beside ``free_params``): then ``Δ; Γ ⊢ t`` holds when these and the
free variables and parameters fit the context, without a walk.

Here: the arithmetic of those attributes, from the children's to the parent's.  It names no node
class — the constructors of :mod:`langur.core.terms` call it with their children's attributes (a
diffeomorphic conditional's Ψ̂ and its inverse branches are read by their fields), and the generic
constructor there (``_annotate``) computes the same attributes for the other nodes.
"""

from __future__ import annotations

import sys
from fractions import Fraction

from ..memo import remember

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

#: ``Fraction(i)`` for the integers 0 … 127, made once at import (≈ 0.6 M instructions): most literals
#: of a program and most indices of a loop's copies are small integers, and ``Fraction``'s
#: constructor is Python code (≈ 4.8 k instructions a call) where this is one subscript (issue 15).
#: A ``Fraction`` is immutable: sharing one is invisible.
INT_FRACTIONS: tuple[Fraction, ...] = tuple(Fraction(i) for i in range(128))
#: ``Fraction(-1)``, one object: the factor of every negation (``core.neg``, the desugarer's ``t − s``
#: and ``−t``), which :func:`_binary_value` recognizes by identity (issue 15).
MINUS_ONE = Fraction(-1)
#: Their identities (the tables keep them alive): a ``Const`` of one of them is small (``Const``).
_INT_IDS = frozenset(map(id, INT_FRACTIONS + (MINUS_ONE,)))
_ZERO_F, _ONE_F = INT_FRACTIONS[0], INT_FRACTIONS[1]


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


# The indices of ``t.shape``:
FV = 0  #: free variables (a frozenset of names)
FP = 1  #: free parameters
SMOOTH = 2  #: no ``ifge0``, no call (bool)
CALLS = 3  #: calls a def (bool)
SIZE = 4  #: nodes, written out as a tree
DEPTH = 5  #: depth (a diffeo's condition counted for a completed one)
PSI_VARS = 6  #: the variable lists of its diffeos (``diffeo_variables``)
SCOPED = 7  #: typing's premises that do not depend on Δ; Γ hold (above)
OPS = 8  #: the primitives used
BINDERS = 9  #: the names ``let`` binds
DFP = 10  #: the parameters of its diffeos' inverse branches, guards and ``nonzero`` terms
#: The slots a term keeps them in (:mod:`langur.core.slots`).
_KEPT = ("shape", "small", "small_all")
_SHAPE_NAMES = ("_fv", "_fp", "_smooth", "_calls", "_size", "_depth", "_psi_vars", "_scoped", "_ops", "_binders", "_dfp")


def kept_attributes(t) -> dict:
    """Every attribute ``t`` keeps, by name (``_fv`` … ``_dfp`` for the entries of ``shape``,
    ``small``, ``small_all``): for reading them all at once, as tests and tools do (the passes
    read one at its index)."""
    out = dict(zip(_SHAPE_NAMES, t.shape))
    out["small"], out["small_all"] = t.small, t.small_all
    return out

#: ``shape`` of a constant (a variable's has its name as FV, a parameter's as FP).
_LEAF_SHAPE = (_EMPTY, _EMPTY, True, False, 1, 1, _EMPTY, True, _EMPTY, _EMPTY, _EMPTY)


_VAR_SHAPES: dict[str, tuple] = {}
_PARAM_SHAPES: dict[str, tuple] = {}


def _var_shape(name: str) -> tuple:
    """``shape`` of ``Var(name)``, one tuple per name (a parent whose children share theirs skips
    nothing, but a leaf is built without making a tuple, issue 15)."""
    s = _VAR_SHAPES.get(name)
    if s is None:
        s = remember(_VAR_SHAPES, name, (_names(name), *_LEAF_SHAPE[FP:]), 4096, at_once=True)
    return s


def _param_shape(name: str) -> tuple:
    """``shape`` of ``Param(name)``, one tuple per name."""
    s = _PARAM_SHAPES.get(name)
    if s is None:
        s = remember(_PARAM_SHAPES, name, (_EMPTY, _names(name), *_LEAF_SHAPE[SMOOTH:]), 4096, at_once=True)
    return s


def _binary(t, a, b, mul: bool) -> None:
    """The attributes of ``t + s`` or ``t · s`` (``t``) from those of ``t`` (``a``) and ``s`` (``b``):
    the sets joined, the flags combined, size and depth counted."""
    sa, sb = a.shape, b.shape
    if sb is _LEAF_SHAPE or sa is _LEAF_SHAPE:  # a constant (a negation's −1, a product by a number)
        fa, pa, sma, ca, za, da, psa, sca, oa, ba, dfa = sa if sb is _LEAF_SHAPE else sb
        t.shape = (fa, pa, sma, ca, za + 2, da + 1, psa, sca, oa, ba, dfa)  # (the constant's depth is 1)
        _binary_value(t, a, b, mul)
        return
    fa, pa, sma, ca, za, da, psa, sca, oa, ba, dfa = sa
    fb, pb, smb, cb, zb, db, psb, scb, ob, bb, dfb = sb
    if not (psb or ob or bb or dfb):  # (most terms: no diffeo, primitive nor let on the right)
        t.shape = (fa if (not fb or fa is fb) else (fb if not fa else _join(fa, fb)),
                    pa if (not pb or pa is pb) else (pb if not pa else _join(pa, pb)),
                    sma and smb, ca or cb, 1 + za + zb, 1 + (da if da > db else db), psa, sca and scb, oa, ba, dfa)
        _binary_value(t, a, b, mul)
        return
    t.shape = (fa if (not fb or fa is fb) else (fb if not fa else _join(fa, fb)),
                pa if (not pb or pa is pb) else (pb if not pa else _join(pa, pb)),
                sma and smb, ca or cb, 1 + za + zb, 1 + (da if da > db else db),
                psa if (not psb or psa is psb) else (psb if not psa else _join(psa, psb)),
                sca and scb,
                oa if (not ob or oa is ob) else (ob if not oa else _join(oa, ob)),
                ba if (not bb or ba is bb) else (bb if not ba else _join(ba, bb)),
                dfa if (not dfb or dfa is dfb) else (dfb if not dfa else _join(dfa, dfb)))
    _binary_value(t, a, b, mul)


def _binary_value(t, a, b, mul: bool) -> None:
    """The attributes of ``t + s`` or ``t · s`` (``t``) that depend on the values of its constants
    (``small``, ``small_all``), from those of ``t`` (``a``) and ``s`` (``b``)."""
    x, y = a.small, b.small
    if x is None or y is None:
        v = False if x is False or y is False else None
    elif x is False or y is False:
        v = False
    elif mul:  # (x, y small: a product by 1 or a sum with 0 is the other, already in range)
        if x is _ONE_F:  # (the shared objects first, by identity: no call of Fraction's Python code)
            v = y
        elif y is _ONE_F:
            v = x
        elif x is MINUS_ONE:  # a negation: −y, small as y is (the range is symmetric)
            v = y if y is _ZERO_F else -y
        else:
            v = y if x.numerator == x.denominator else (x if y.numerator == y.denominator else _in_range(x * y))
    elif x is _ZERO_F:
        v = y
    elif y is _ZERO_F:
        v = x
    else:
        v = y if not x else (x if not y else _in_range(x + y))
    t.small = v
    t.small_all = v is not False and a.small_all and b.small_all


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


def _unary(t, a, small, scoped: bool, op: str | None) -> None:
    """The attributes of ``f(t)`` or ``t ^ k`` (``t``) from those of ``t`` (``a``), with its small
    value, whether its own premise holds (a rational exponent) and its primitive."""
    fv, fp, sm, c, z, d, ps, sc, o, bi, df = a.shape
    t.shape = (fv, fp, sm, c, z + 1, d + 1, ps, scoped and sc, o if op is None else _join(o, _names(op)), bi, df)
    t.small = small
    t.small_all = small is not False and a.small_all


_INTERNED_SETS: dict = {}


def _interned_set(items: tuple) -> frozenset:
    s = _INTERNED_SETS.get(items)
    if s is None:
        s = remember(_INTERNED_SETS, items, frozenset(items), 4096, at_once=True)
    return s


def _diffeo_summary(psi) -> tuple:
    """What a diffeomorphic conditional's attributes take from its Ψ̂ (kept on the Diffeo, which
    several conditionals may share): its condition's parameters, its variables (as a set, and as
    the one variable list of ``diffeo_variables``), the depth its condition counts for, whether
    its own premises hold (``_diffeo_scoped``), the primitives and parameters of all its terms."""
    d = psi.__dict__
    found = d.get("_summary")
    if found is None and len(psi.forward) == 1 and not psi.nonzero and len(psi.branches) == 1:
        # (a condition completed over one variable, the most frequent: the loops below written out)
        shape = psi.forward[0].shape
        fp, ops = shape[FP], shape[OPS]
        dfp = _join(fp, shape[DFP])
        b_ops, b_dfp, b_scoped = _branch_summary(psi.branches[0], psi.inputs, len(psi.variables))
        found = d["_summary"] = (fp, _interned_set(psi.variables), _interned_set((psi.variables,)),
                                 shape[DEPTH] if psi.name is None else 1, _diffeo_scoped(psi) and b_scoped,
                                 _join(ops, b_ops), _join(dfp, b_dfp))
    elif found is None:
        fp = ops = dfp = _EMPTY
        for f in psi.forward:
            fp = _join(fp, f.shape[FP])
        for u in psi.forward + psi.nonzero:
            ops, dfp = _join(ops, u.shape[OPS]), _join(dfp, _join(u.shape[FP], u.shape[DFP]))
        scoped = _diffeo_scoped(psi)
        for b in psi.branches:  # (a branch shared by several Diffeos is summarized once)
            b_ops, b_dfp, b_scoped = _branch_summary(b, psi.inputs, len(psi.variables))
            ops, dfp, scoped = _join(ops, b_ops), _join(dfp, b_dfp), scoped and b_scoped
        found = d["_summary"] = (fp, _interned_set(psi.variables), _interned_set((psi.variables,)),
                                 psi.forward[0].shape[DEPTH] if psi.name is None else 1, scoped, ops, dfp)
    return found


def _branch_summary(b, inputs: tuple[str, ...], n: int) -> tuple:
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
            ops, dfp = _join(ops, u.shape[OPS]), _join(dfp, _join(u.shape[FP], u.shape[DFP]))
            if scoped and not (u.shape[SCOPED] and not u.shape[BINDERS] and u.shape[FV] <= us):
                scoped = False
        found = d["_summary"] = ((inputs, n), ops, dfp, scoped)
    return found[1:]


def _ifdiffeo(t, psi, a, b) -> None:
    """The attributes of ``ifge0 ⌊Ψ⌋ then s else r`` (``t``) from Ψ's and those of ``s`` (``a``)
    and ``r`` (``b``)."""
    fp, xs, pv, cond, scoped, ops, dfp = _diffeo_summary(psi)
    if a.shape is _LEAF_SHAPE and b.shape is _LEAF_SHAPE:  # both branches constants ([…] is 1 or 0): the same, joined
        t.shape = (xs, fp, False, False, 3, 1 + (cond if cond > 1 else 1), pv, scoped, ops, _EMPTY, dfp)
        t.small = v = False if not xs and not fp else None
        t.small_all = v is not False and a.small_all and b.small_all
        return
    fv = _join(_join(a.shape[FV], b.shape[FV]), xs)
    fp = _join(_join(a.shape[FP], b.shape[FP]), fp)
    t.shape = (fv, fp, False, a.shape[CALLS] or b.shape[CALLS], 1 + a.shape[SIZE] + b.shape[SIZE], 1 + max(a.shape[DEPTH], b.shape[DEPTH], cond),
                _join(_join(a.shape[PSI_VARS], b.shape[PSI_VARS]), pv), scoped and a.shape[SCOPED] and b.shape[SCOPED],
                _join(_join(a.shape[OPS], b.shape[OPS]), ops), _join(a.shape[BINDERS], b.shape[BINDERS]), _join(_join(a.shape[DFP], b.shape[DFP]), dfp))
    t.small = v = False if not fv and not fp else None
    t.small_all = v is not False and a.small_all and b.small_all


def _diffeo_scoped(psi) -> bool:
    """The premises of Fig. 6's diffeomorphic conditional that do not depend on the context (see
    ``typesys.type_diffeo``): distinct variables, as many components and inputs as variables,
    components over the variables, ``nonzero`` terms variable-free, each of these terms itself
    scoped and binding no name (and, by :func:`_branch_summary`, inverse branches and guards over
    the inputs, scoped, binding no name)."""
    xs, n = frozenset(psi.variables), len(psi.variables)
    if len(xs) != n or len(psi.forward) != n or len(psi.inputs) != n:
        return False
    for f in psi.forward:  # (loops, not all() over generators: every completed condition comes here)
        if not (f.shape[SCOPED] and not f.shape[BINDERS] and f.shape[FV] <= xs):
            return False
    for z in psi.nonzero:
        if not (z.shape[SCOPED] and not z.shape[BINDERS] and not z.shape[FV]):
            return False
    return True  # (the branches' premise: _branch_summary)
