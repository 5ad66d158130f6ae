"""Per-node attributes of core terms (issue 15), computed once when a node is built.

Every pass of the front end asks the same questions of a term — its free variables and parameters,
whether it is smooth or calls a def, its size and depth, its exact value when it is a constant — and
a walk per question per pass costs Python's price per node each time.  A term is immutable, so each
answer is computed once, bottom-up, when the node is built (its children already carry theirs) and
kept in its ``__dict__`` under a name starting with ``_`` (never compared, hashed nor pickled:
unpickling recomputes them, ``__setstate__`` in :mod:`langur.core.terms`).  The functions of
:mod:`langur.core.structural` (``free_vars``, ``free_params``, ``smooth``, ``has_calls``,
``tree_size``, ``depth``, ``small_value``, ``all_small``, ``diffeo_variables``) read them.

Also kept, for typing (``langur.typesys.well_typed``): the premises of Fig. 6's rules that do not
depend on the context Δ; Γ (``_scoped``: conditions of ``ifge0``, bounds of ``let``, a diffeo's
own terms are where they must be, exponents are rational), the primitives used (``_ops``), the
names ``let`` binds (``_binders``) and the parameters of the diffeos' inverse branches, guards and
``nonzero`` terms (``_dfp``, beside ``free_params``): then ``Δ; Γ ⊢ t`` holds when these and the
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


def _unary(d: dict, a, small, scoped: bool, op: str | None) -> None:
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


def _diffeo_summary(psi) -> tuple:
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
            ops, dfp = _join(ops, u._ops), _join(dfp, _join(u._fp, u._dfp))
            if scoped and not (u._scoped and not u._binders and u._fv <= us):
                scoped = False
        found = d["_summary"] = ((inputs, n), ops, dfp, scoped)
    return found[1:]


def _ifdiffeo(d: dict, psi, a: dict, b: dict) -> None:
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
        if not (f._scoped and not f._binders and f._fv <= xs):
            return False
    for z in psi.nonzero:
        if not (z._scoped and not z._binders and not z._fv):
            return False
    return True  # (the branches' premise: _branch_summary)
