"""Chains of one precedence level, built into balanced trees (parser, E105).

The LALR parser reduces ``t1 + t2 + … + tn`` through the grammar's left recursion, one link at a
time; :class:`Chain` collects the links and builds the tree once, when the chain is first used, so
that a sum or product of any length nests only as deep as its balanced tree.  :class:`Reduced` is
what every term rule of the parser returns: the surface node, its source extent and its depth.
"""

from __future__ import annotations

from ..diagnostics import Span, SpanSlots
from .surface import BinOp

#: Deepest term nesting accepted (E105).
MAX_DEPTH = 200


class Reduced:
    """A term rule's result: ``node``, the extent of its source text (``line``, ``col``,
    ``end_line``, ``end_col``, parentheses included) and ``depth``.  Made field by field, without an
    ``__init__`` (``r = Reduced()`` then one store a field: a Python ``__init__`` call cost more
    than the stores, parse25)."""

    __slots__ = ("col", "depth", "end_col", "end_line", "line", "node")


#: Chains of at most this many operands keep the grammar's left-nested shape; longer ones are
#: regrouped into balanced trees, so that E105 counts real nesting only (``t1 + … + t10000`` is
#: accepted; its tree is 14 levels deep).
CHAIN_BALANCE = 32

LEVEL = {"+": "sum", "-": "sum", "*": "product", "/": "product"}


class Built(Reduced):
    """A chain of at most :data:`CHAIN_BALANCE` operands at one ``level``, its tree built link by
    link as the parser reduces them (``node``, ``depth``: the grammar's left-nested tree, as
    :class:`Chain` builds it), its links kept in ``items`` as :class:`Chain` keeps them, in case it
    grows longer.  Only while nothing can be pending: no operand a :class:`Chain` (whose ``node``
    may raise E105 when first read) and the tree within :data:`MAX_DEPTH`; otherwise the parser
    makes a :class:`Chain` of its items (issue 15, parse25: no call of ``append``, ``node``,
    ``depth``, ``_build`` per chain).  Made field by field, as :class:`Reduced`."""

    __slots__ = ("items", "level")


#: A chain's first operand's operator (as :class:`Chain` records it).
FIRST = {"sum": "+", "product": "*"}


class Chain(Reduced):
    """``t1 op t2 op … tn`` at one precedence level (``+``/``-`` or ``*``/``/``), collected link by
    link as the LALR parser reduces the grammar's left recursion, and built into a tree when first
    used (iteratively: no recursion on the chain's length).

    Up to :data:`CHAIN_BALANCE` operands the tree is the grammar's own, left-nested.  Longer sums
    are split in halves, ``L - (t + u - v)`` for ``L - t - u + v`` (the right half's signs flipped:
    the same value); longer products become ``(∏ factors) / (∏ divisors)``, each a balanced product
    (the same value where the original is defined, and defined exactly where it is: a divisor is
    never moved into a numerator)."""

    __slots__ = ("_depth", "_node", "builder", "items", "level")

    def __init__(self, builder, level: str, first: Reduced):
        self.builder = builder
        self.level = level
        self.items: list[tuple[str, Reduced]] = [("+" if level == "sum" else "*", first)]
        self.line, self.col = first.line, first.col
        self.end_line, self.end_col = first.end_line, first.end_col
        self._node = None
        self._depth = None

    def append(self, op: str, right: Reduced) -> None:
        self.items.append((op, right))
        self.end_line, self.end_col = right.end_line, right.end_col
        self._node = self._depth = None

    @property
    def depth(self) -> int:  # type: ignore[override]
        if self._depth is None:
            self._build()
        return self._depth

    @property
    def node(self):  # type: ignore[override]
        if self._node is None:
            self._build()
            if self._depth > MAX_DEPTH:
                raise self.builder.too_deep(self.builder.span(self, self))
        return self._node

    def _span(self, first: Reduced, last: Reduced) -> Span:
        return self.builder.span(first, last)

    def _build(self) -> None:
        items = self.items
        if len(items) <= CHAIN_BALANCE:
            (_, first), *rest = items
            node, depth = first.node, first.depth
            path, line, col = self.builder.path, first.line, first.col
            for op, r in rest:  # (the span from `first` to `r`, both Reduced: builder.span written out)
                s = SpanSlots()  # (a Span made without a Python call: see SpanSlots)
                s.path = path
                s.line = line
                s.col = col
                s.end_line = r.end_line
                s.end_col = r.end_col
                s.__class__ = Span
                node = BinOp(op, node, r.node, s)
                d = r.depth
                depth = 1 + (depth if depth > d else d)
            self._node, self._depth = node, depth
        elif self.level == "sum":
            self._node, self._depth = self._balanced([(op == "-", r) for op, r in items], "+", "-")
        else:
            factors = [(False, r) for op, r in items if op == "*"]
            divisors = [(False, r) for op, r in items if op == "/"]
            node, depth = self._balanced(factors, "*", "/")
            if divisors:
                den, den_depth = self._balanced(divisors, "*", "/")
                node, depth = BinOp("/", node, den, self._span(self, self)), 1 + max(depth, den_depth)
            self._node, self._depth = node, depth

    def _balanced(self, items: list[tuple[bool, Reduced]], plus: str, minus: str):
        """A balanced tree of ``items`` (inverted?, operand), the first not inverted; recursion
        depth log₂ of the length."""
        if len(items) == 1:
            return items[0][1].node, items[0][1].depth
        mid = len(items) // 2
        left, right = items[:mid], items[mid:]
        inverted = right[0][0]
        if inverted:  # L - t - u + v = L - (t + u - v)
            right = [(not inv, r) for inv, r in right]
        ln, ld = self._balanced(left, plus, minus)
        rn, rd = self._balanced(right, plus, minus)
        span = self._span(left[0][1], right[-1][1])
        return BinOp(minus if inverted else plus, ln, rn, span), 1 + max(ld, rd)
