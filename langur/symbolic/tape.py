"""A large rational closed form walked over its distinct subtrees (issue 15): the two walks of
:mod:`langur.symbolic.rational`, each written once over an :class:`~langur.symbolic.arithmetic.Arithmetic`.

A form of rationals, symbols, +, ·, integer powers and ``Abs`` (the closed forms of ⟦p⟧ that
:mod:`langur.symbolic.local` builds for large problems, checked by Theorem 8.1) is either flattened
once into a list of operations (:class:`Tape`: the values at a point and the slope along a
tangent, forward mode) or walked recursively over its distinct subtrees (:func:`node_walk`).
The values of subtrees at a point are remembered per arithmetic for the last :data:`VALUE_POINTS`
points (:func:`point_memo`), shared by both walks.
"""

from __future__ import annotations

import sympy as sp

from langur.memo import remember


class NotRational(Exception):
    """The form is not one of rationals, symbols, +, ·, integer powers and ``Abs``, or a symbol has
    no rational value at the point (or, in :data:`~langur.symbolic.exactpairs.EXACT`, the form is undefined there)."""


_RAT, _SYM, _ADD, _MUL, _POW, _ABS = range(6)
#: Flattened closed forms (:class:`Tape`) by form, or the exception met flattening it.
TAPES: dict = {}


class Tape:
    """A form of rationals, symbols, +, ·, integer powers and ``Abs`` as a list of operations over
    its distinct subtrees, children before parents (the form itself last): ``(kind, operand
    indices, payload)`` with the payload a rational's integer pair, a symbol, or a power's
    exponent; and its values by arithmetic and point."""

    def __init__(self, expr):
        index: dict = {}
        self.ops: list = []
        self.nodes: list = []  # (the subtree of each operation)
        stack = [(expr, False)]
        while stack:
            node, done = stack.pop()
            if node in index:
                continue
            if done:
                index[node] = len(self.ops)
                self.ops.append(self._op(node, index))
                self.nodes.append(node)
                continue
            stack.append((node, True))
            stack.extend((a, False) for a in operands(node) if a not in index)
        self._values: dict = {}  # arithmetic -> point key -> values

    @staticmethod
    def _op(node, index):
        if isinstance(node, sp.Rational):
            return _RAT, (), (int(node.p), int(node.q))
        if isinstance(node, sp.Symbol):
            return _SYM, (), node
        if isinstance(node, sp.Add):
            return _ADD, tuple(index[a] for a in node.args), None
        if isinstance(node, sp.Mul):
            return _MUL, tuple(index[a] for a in node.args), None
        if isinstance(node, sp.Pow):
            return _POW, (index[node.base],), int(node.exp)
        return _ABS, (index[node.args[0]],), None

    @classmethod
    def of(cls, expr) -> "Tape":
        tape = TAPES.get(expr)
        if tape is None:
            try:
                tape = cls(expr)
            except NotRational as exc:
                tape = exc
            remember(TAPES, expr, tape, 64)
        if isinstance(tape, Exception):
            raise tape
        return tape

    def values(self, point: dict, arith) -> list:
        """The value of every operation at ``point`` in ``arith`` (remembered for the last few
        points), sharing the values of subtrees at the point with the recursive walk
        (:func:`point_memo`): the Theorem 8.1 check differentiates ⟦p⟧'s closed form and
        evaluates ⦇p⦈'s and its cell's relations at the same points, and they share their
        subtrees (a polygon's vertices and their powers, the weights' coefficients)."""
        memo = self._values.get(arith)
        if memo is None:
            memo = self._values[arith] = {}
        key = point_key(point)
        vals = memo.get(key)
        if vals is None:
            const, read, total, product = arith.const, arith.read, arith.total, arith.product
            power, magnitude = arith.power, arith.magnitude
            vals = []
            at = vals.__getitem__
            known = point_memo(arith, point)
            for node, (kind, args, k) in zip(self.nodes, self.ops):
                v = known.get(node)
                if v is None:
                    if kind == _RAT:
                        v = const(*k)
                    elif kind == _SYM:
                        if k not in point:
                            raise NotRational()
                        v = read(point[k])
                    elif kind == _ADD:
                        v = total(map(at, args))
                    elif kind == _MUL:
                        v = product(map(at, args))
                    elif kind == _POW:
                        v = power(vals[args[0]], k)
                    else:
                        v = magnitude(vals[args[0]])
                    known[node] = v
                vals.append(v)
            remember(memo, key, vals, VALUE_POINTS)
        return vals

    def slope(self, vals: list, tangent: dict, arith):
        """The derivative along ``tangent`` in ``arith`` (forward mode over the values ``vals``,
        ``None`` standing for an exact 0)."""
        read, add, mul, power, sign, neg, scale = (arith.read, arith.add, arith.mul, arith.power, arith.sign,
                                                   arith.neg, arith.scale)
        zero, one = arith.zero, arith.one
        d: list = []
        for kind, args, k in self.ops:
            if kind == _RAT:
                out = None
            elif kind == _SYM:
                out = read(tangent.get(k, 0))
            elif kind == _ADD:
                out = None
                for j in args:
                    dj = d[j]
                    if dj is not None:
                        out = dj if out is None else add(out, dj)
            elif kind == _MUL:
                out = None
                last = -1
                for i, j in enumerate(args):
                    if d[j] is not None:
                        last = i
                # Σᵢ dᵢ·Πⱼ≠ᵢ vⱼ as d ← d·vᵢ + v·dᵢ, v ← v·vᵢ (v: the product so far, None for 1;
                # needed up to the last dᵢ ≠ 0)
                v = None
                for i in range(last + 1):
                    j = args[i]
                    if out is not None:
                        out = mul(out, vals[j])
                    dj = d[j]
                    if dj is not None:
                        term = dj if v is None else mul(v, dj)
                        out = term if out is None else add(out, term)
                    if i < last:
                        v = vals[j] if v is None else mul(v, vals[j])
                if out is not None:
                    for i in range(last + 1, len(args)):
                        out = mul(out, vals[args[i]])
            elif kind == _POW:
                db = d[args[0]]
                # (k·xᵏ⁻¹·dx; x¹'s slope is dx, also at x = 0)
                out = None if db is None else mul(scale(one if k == 1 else power(vals[args[0]], k - 1), k), db)
            else:
                da = d[args[0]]
                out = da if da is None or sign(vals[args[0]]) > 0 else neg(da)
            if out is not None and out == zero:
                out = None
            d.append(out)
        return d[-1] or zero


def operands(node) -> tuple:
    """The operands :class:`Tape` flattens (:class:`NotRational` for any other node)."""
    if isinstance(node, (sp.Rational, sp.Symbol)):
        return ()
    if isinstance(node, (sp.Add, sp.Mul, sp.Abs)):
        return node.args
    if isinstance(node, sp.Pow) and node.exp.is_Integer:
        return (node.base,)
    raise NotRational()


def node_walk(arith):
    """``value_at(e, memo, point)``: ``e`` at ``point`` in ``arith``, recursively over its
    distinct subtrees (their values remembered in ``memo``); :class:`NotRational` when ``e`` is
    not a form of rationals, symbols, +, ·, integer powers and ``Abs`` or a symbol has no value,
    the arithmetic's failure where it cannot decide.  (The arithmetic's operations are bound once,
    here, and the memo and the point once per call: a sum's or a product's operands are walked as
    the arithmetic folds them.)"""
    const, read, total, product = arith.const, arith.read, arith.total, arith.product
    power, magnitude = arith.power, arith.magnitude

    def value_at(e, memo: dict, point: dict):
        known = memo.get

        def value_of(e):
            hit = known(e)
            if hit is not None:
                return hit
            if isinstance(e, sp.Rational):
                out = const(int(e.p), int(e.q))
            elif isinstance(e, sp.Symbol):
                if e not in point:
                    raise NotRational()
                out = read(point[e])
            elif isinstance(e, sp.Add):
                out = total(map(value_of, e.args))
            elif isinstance(e, sp.Mul):
                out = product(map(value_of, e.args))
            elif isinstance(e, sp.Pow) and e.exp.is_Integer:
                out = power(value_of(e.base), int(e.exp))
            elif isinstance(e, sp.Abs):
                out = magnitude(value_of(e.args[0]))
            else:
                raise NotRational()
            memo[e] = out
            return out
        return value_of(e)
    return value_at


#: Points whose values of subtrees are kept, per arithmetic.
VALUE_POINTS = 8


def point_key(point: dict):
    return frozenset(point.items())


def point_memo(arith, point: dict) -> dict:
    """The remembered values of subtrees at ``point`` in ``arith`` (a new dict for a new point; the
    few most recent points are kept, a point's dict dropped with it)."""
    key = point_key(point)
    memo = arith.points.pop(key, None)  # (moved to the end: the oldest point is dropped first)
    return remember(arith.points, key, {} if memo is None else memo, VALUE_POINTS)


__all__ = ["TAPES", "VALUE_POINTS", "NotRational", "Tape", "node_walk", "operands", "point_key", "point_memo"]
