"""What a unit computes once (§9, compiling a term once): the subterms shared in a term's DAG,
evaluated once per point, and the variable-free subterms, folded at compile time by the very
floating-point operations their closures would run (bit-identical linking, Theorem 9.1)."""

from __future__ import annotations

import itertools
from operator import attrgetter

from ..core import (
    CALLS,
    FP,
    FV,
    PSI_VARS,
    SIZE,
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
    keep_memo,
)
from ..primitives import REGISTRY
from .consts import const_value
from .dual import power
from .point import Fn

#: Keys of shared subterms in :attr:`Point.memo`, unique across every compiled unit (units
#: compiled apart may be evaluated at one point).
KEYS = itertools.count()
#: A term of at most this many nodes written out (``tree_size``) is compiled as a tree, without
#: looking for its shared subterms: evaluated as a tree it costs at most that many nodes per point,
#: and the same numbers (sharing only saves evaluations); most conditions and inverse branches of
#: zero sets are this small, and the walk that counts references costs about what it could save.
SMALL_TERM = 16


class Sharing:
    """The subterms of a term that occur more than once in it (a DAG: substituted lets, inlined
    calls and vectors share their subterms; the ray tracer's completed conic has ~10,000 nodes
    written out and ~900 distinct ones) and contain no site nor call: those are compiled once and
    evaluated once per :class:`Point` (:func:`evaluated_once`), with the same floating-point operations
    as written out.  Sites and calls are never shared: each occurrence owns its slot."""

    def __init__(self, t: Term):
        self.refs: dict[int, int] = {}
        self.compiled: dict[tuple, Fn] = {}
        #: whether every closure compiled with it gives the same doubles run on Python floats as on
        #: numpy arrays of one point: only sums, products, constants, variables, parameters and the
        #: powers 0, ±1, 2 (IEEE 754 rounds them correctly in every implementation; numpy's loops
        #: for the primitives and other powers may differ from its scalar ones in the last bit).
        #: The compiler clears it where it meets anything else (a zero set's point in one variable
        #: is then computed on numbers, sample.py).
        self.numbers = True
        self.keep = t  # the term stays alive, so the ids above stay its own
        if t.shape[SIZE] > SMALL_TERM:
            self._count(t)

    def _count(self, root: Term) -> None:
        refs = self.refs
        refs[id(root)] = 1
        stack = [root]
        pop, push, leaves, children = stack.pop, stack.append, _LEAVES, _CHILDREN
        while stack:  # each distinct node expanded once (its children's references counted)
            t = pop()
            for c in children[type(t)](t):
                if type(c) in leaves:
                    continue  # never shared
                shape = c.shape
                if not (shape[FV] or shape[FP] or shape[CALLS]) and constant(c) is not None:
                    continue  # folded when compiled: never asked whether it is shared
                k = id(c)
                n = refs.get(k)
                if n is None:
                    refs[k] = 1
                    push(c)
                else:
                    refs[k] = n + 1

    def shared(self, t: Term) -> bool:
        # pure: no site nor call below (the kept attributes: no diffeomorphic conditional, no call)
        return self.refs.get(id(t), 0) > 1 and not t.shape[PSI_VARS] and not t.shape[CALLS]


#: (a set: ``type(c) in`` it is one hashed lookup, where a tuple compares the class with each in turn)
_LEAVES = frozenset((Const, Var, Param))

#: The subterms a unit evaluates (a conditional's condition, not the rest of its Ψ̂), by the node's
#: exact class (the node classes have no subclasses): :class:`Sharing` asks it of every node of every
#: unit compiled (a table of field getters: no Python call for a sum or a product).
_CHILDREN = {
    Add: attrgetter("left", "right"),
    Mul: attrgetter("left", "right"),
    IfDiffeo: lambda t: (t.psi.forward[0], t.then, t.orelse),
    Pow: lambda t: (t.base,),
    Prim: lambda t: (t.arg,),
    IfGe0: attrgetter("cond", "then", "orelse"),
    Let: attrgetter("bound", "body"),
    Call: lambda t: tuple(t.args),
    ImplicitRoot: attrgetter("equation", "target", "lo", "hi"),
    Const: lambda t: (),
    Var: lambda t: (),
    Param: lambda t: (),
}


_NOT_YET = object()


def constant(t: Term):
    """:func:`_fold` of ``t`` when it has no variable, parameter or call (kept on the node: a
    number that only depends on the term), else None."""
    shape = t.shape
    if shape[FV] or shape[FP] or shape[CALLS]:
        return None
    memo = t.memo
    if memo is None:
        memo = {}
        keep_memo(t, memo)
    v = memo.get("folded", _NOT_YET)
    if v is _NOT_YET:
        v = memo["folded"] = _fold(t)
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


def evaluated_once(f: Fn, key: int, uses: int) -> Fn:
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
