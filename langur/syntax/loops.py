"""The finite loop of §9 ("a finite looping construct that is syntactic sugar and is unrolled"):
``sum i in A..B: t`` and ``prod i in A..B: t``, helpers of the desugarer (``langur.syntax.desugar``,
the one desugaring place, which unrolls the loop in :meth:`Desugarer.loop
<langur.syntax.unrolling.Unrolling.loop>`).

* The bounds ``A`` and ``B`` are integer constants: number literals and arithmetic of them and of
  the indices of enclosing loops (:func:`bounds`, T224 otherwise).  The loop has ``B - A + 1``
  copies of its body, none when ``B < A`` (then a sum is 0 and a product 1).
* In the ``k``-th copy the index is the number ``k`` (a ``Const``), so it may occur in exponents,
  in bounds of inner loops, in conditions and as a def's param argument.
* The copies after the first are built from it (:mod:`langur.syntax.template`: its index leaves
  replaced, its conditions completed again) when its desugaring does not read the index as a
  number; they are the same terms as desugaring each copy gives.
* The copies are combined into a balanced tree (:func:`balanced`), of the same shape as the
  parser gives a written-out sum or product (``langur.syntax.chains``): ``sum i in 1..3: t`` is
  exactly ``t1 + t2 + t3``, and a sum of 100,000 copies nests 17 levels, not 100,000.
* Unrolling is bounded (T225): a module's loops write out at most :data:`MAX_COPIES` copies of loop
  bodies and :data:`MAX_NODES` surface nodes in all, checked before a loop is unrolled, so
  ``sum i in 1..1000000000: …`` is refused at once.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from fractions import Fraction

from ..core import Add, Const, Mul, Term
from ..diagnostics import Span
from ..records import record
from .chains import CHAIN_BALANCE
from .folding import is_one, is_zero
from .surface import BinOp, Name, Neg, Num, STerm

#: Most copies of loop bodies that the loops of one module may write out (T225).
MAX_COPIES = 100_000
#: Most surface nodes that the loops of one module may write out, copies times body size (T225):
#: about what a source of MAX_SIGNIFICANT (1,000,000) characters can write out by hand.
MAX_NODES = 500_000
#: Constant expressions (loop bounds, exponents) are computed exactly as long as every
#: intermediate numerator and denominator has at most this many bits; beyond, they are not taken
#: as constants (``((10^64)^64)^64)^64`` would be 16 million digits, one level more a hang).
MAX_BITS = 4096


class TooLarge(Exception):
    """A constant expression whose exact value needs more than :data:`MAX_BITS` bits."""


class BoundError(Exception):
    """A loop bound that is not an integer constant: where and why (T224)."""

    def __init__(self, span: Span | None, why: str):
        super().__init__(why)
        self.span = span
        self.why = why


def _bits(v: Fraction) -> int:
    return max(v.numerator.bit_length(), v.denominator.bit_length())


def constant(st: STerm, consts: Mapping[str, Fraction]) -> Fraction | None:
    """The value of a constant rational surface expression over the loop indices ``consts``
    (number literals, indices, ``+ - * /`` and ``^`` with a small integer exponent), or None;
    :class:`TooLarge` when a value would need more than :data:`MAX_BITS` bits."""
    value = _constant(st, consts)
    if value is not None and _bits(value) > MAX_BITS:
        raise TooLarge(getattr(st, "span", None))
    return value


def _constant(st: STerm, consts: Mapping[str, Fraction]) -> Fraction | None:
    match st:
        case Num(v):
            return v
        case Name(n):
            return consts.get(n)
        case Neg(a):
            v = constant(a, consts)
            return None if v is None else -v
        case BinOp(op, a, b):
            x, y = constant(a, consts), constant(b, consts)
            if x is None or y is None:
                return None
            if op == "+":
                return x + y
            if op == "-":
                return x - y
            if op == "*":
                return x * y
            if op == "/":
                return None if y == 0 else x / y
            if op == "^":
                if y.denominator != 1 or abs(y) > 64 or (x == 0 and y < 0):
                    return None
                if _bits(x) * abs(y) > 2 * MAX_BITS:
                    raise TooLarge(st.span)
                return x ** int(y)
    return None


def _first_name(st: STerm) -> Name | None:
    """The first name in ``st`` (to say which name makes a bound non-constant)."""
    stack = [st]
    while stack:
        u = stack.pop()
        if isinstance(u, Name):
            return u
        stack.extend(reversed([c for c in children(u)]))
    return None


def bounds(lo: STerm, hi: STerm, consts: Mapping[str, Fraction]) -> tuple[int, int]:
    """The integer values of a loop's bounds (T224 through :class:`BoundError` otherwise;
    :class:`TooLarge`, T225, for a value beyond :data:`MAX_BITS` bits)."""
    out = []
    for st in (lo, hi):
        span = getattr(st, "span", None)
        v = constant(st, consts)
        if v is None:
            name = _first_name(st)
            if name is not None and name.name not in consts:
                why = f"`{name.name}` is not the index of an enclosing loop (a parameter, variable or let-bound name)"
                raise BoundError(name.span or span, why)
            raise BoundError(span, "not a constant expression of literals and loop indices (or a division by 0)")
        if v.denominator != 1:
            raise BoundError(span, f"its value {v} is not an integer")
        out.append(int(v))
    return out[0], out[1]


def children(st) -> list:
    """The surface subterms of a surface node (every field that is a node or a tuple of nodes)."""
    out = []
    for name in _fields(type(st)):
        v = getattr(st, name)
        if isinstance(v, tuple):
            out.extend(x for x in v if _is_node(x))
        elif _is_node(v):
            out.append(v)
    return out


_FIELDS: dict[type, tuple[str, ...]] = {}
_NODES: dict[type, bool] = {}


def _fields(cls: type) -> tuple[str, ...]:
    """A surface node class's fields but its span (looked up once per class)."""
    found = _FIELDS.get(cls)
    if found is None:
        found = _FIELDS[cls] = tuple(f.name for f in dataclasses.fields(cls) if f.name != "span")
    return found


def _is_node(x) -> bool:
    """``x`` is a surface node: a dataclass instance with a span (decided once per class)."""
    cls = type(x)
    found = _NODES.get(cls)
    if found is None:
        found = dataclasses.is_dataclass(x) and hasattr(x, "span")
        if not isinstance(x, type):
            _NODES[cls] = found
    return found


def size(st: STerm) -> int:
    """The number of surface nodes of ``st`` (iteratively: no recursion on its depth; ``children``
    written out, with the lookups by class hoisted, and the classes of most nodes of a term — names,
    numbers, operators, negations — handled first: a loop's body is counted on every load)."""
    n, stack = 0, [st]
    pop, push = stack.pop, stack.append
    fields, nodes = _FIELDS, _NODES
    while stack:
        u = pop()
        n += 1
        cls = type(u)
        if cls is Name or cls is Num:  # (leaves)
            continue
        if cls is BinOp:
            push(u.left)
            push(u.right)
            continue
        if cls is Neg:
            push(u.arg)
            continue
        names = fields.get(cls) or _fields(cls)
        for name in names:
            v = getattr(u, name)
            if type(v) is tuple:
                for x in v:
                    found = nodes.get(type(x))
                    if found or (found is None and _is_node(x)):
                        push(x)
            else:
                found = nodes.get(type(v))
                if found or (found is None and _is_node(v)):
                    push(v)
    return n


@record
class Budget:
    """What the loops of one module have written out so far (T225); once the bound is hit it is
    ``exhausted`` and every later loop is skipped (one diagnostic, no cascade)."""

    copies: int = 0
    nodes: int = 0
    exhausted: bool = False

    def __init__(self, copies=0, nodes=0, exhausted=False):
        self.copies, self.nodes, self.exhausted = copies, nodes, exhausted

    def charge(self, count: int, size: int) -> str | None:
        """Take ``count`` copies of a body of ``size`` surface nodes: None within the bound, else why
        not (and the budget is exhausted)."""
        if self.copies + count <= MAX_COPIES and self.nodes + count * size <= MAX_NODES:
            self.copies += count
            self.nodes += count * size
            return None
        self.exhausted = True
        shown = f"{count:,}" if count < 10**15 else "over 10^15"
        return (f"this loop has {shown} copies of a body of {size:,} nodes; the loops of a module may write out at "
                f"most {MAX_COPIES:,} copies and {MAX_NODES:,} nodes in all (so far {self.copies:,} and "
                f"{self.nodes:,})")


    def again(self, copies: int, nodes: int) -> bool:
        """Take ``copies`` copies and ``nodes`` nodes written out by an instantiated copy of a loop's
        body (what desugaring it again would take, :mod:`langur.syntax.template`) when they fit; else
        take nothing and say False (the copy is then desugared, and refused, as before)."""
        if self.copies + copies <= MAX_COPIES and self.nodes + nodes <= MAX_NODES:
            self.copies += copies
            self.nodes += nodes
            return True
        return False


def once(diagnostics: list) -> list:
    """``diagnostics`` without repetitions (each copy of a loop's body reports the body's errors)."""
    seen: set = set()
    out = []
    for d in diagnostics:
        key = (d.code, d.span, d.message)
        if key not in seen:
            seen.add(key)
            out.append(d)
    return out


def balanced(terms: list[Term], op: str, span: Span | None = None) -> Term:
    """``t1 + … + tn`` (``op`` ``"sum"``) or ``t1 · … · tn`` (``"prod"``) as the parser builds the
    written-out chain: left-nested up to :data:`~langur.syntax.chains.CHAIN_BALANCE` operands,
    halved recursively beyond (depth log₂ n).  An empty sum is 0, an empty product 1; a summand 0
    (a factor 1) is left out (``syntax/folding.py``: a loop's copy at i = 0 of ``x * i``, a vector's
    component ``0 * 0`` in ``dot``)."""
    make: Callable[..., Term] = Add if op == "sum" else Mul
    drop = is_zero if op == "sum" else is_one
    for t in terms:
        if type(t) is Const and drop(t):
            terms = [u for u in terms if not drop(u)]
            break
    if not terms:
        return Const(Fraction(0 if op == "sum" else 1), span=span)
    if len(terms) <= CHAIN_BALANCE:
        out = terms[0]
        for t in terms[1:]:
            out = make(out, t, span)
        return out

    def halve(lo: int, hi: int) -> Term:
        if hi - lo == 1:
            return terms[lo]
        mid = lo + (hi - lo) // 2
        return make(halve(lo, mid), halve(mid, hi), span)

    return halve(0, len(terms))
