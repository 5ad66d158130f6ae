"""The parser's inline transformer (LANGUAGE.md §6): one method per (aliased) rule of
``grammar.lark``, called on every reduction, builds the surface AST of :mod:`langur.syntax.surface`.

No parse tree is built and nothing recurses in Python however deep the input nests
(:mod:`langur.syntax.parser` drives the tables; :mod:`langur.syntax.lalr` without lark, lark itself
for a syntax error).  Every node gets an exact :class:`~langur.diagnostics.Span` (1-based lines and
columns, ``end_col`` exclusive).  Intermediate results are :class:`~langur.syntax.chains.Reduced`
(a node with the span of its source text and its depth; long sums and products as
:mod:`langur.syntax.chains`' balanced chains).  The limits checked here: a term nests at most
:data:`MAX_DEPTH` levels (E105); a number literal has at most :data:`MAX_DIGITS` digits, an exponent
within ±\\ :data:`MAX_EXPONENT` and a value within the range of doubles (E106: the Monte Carlo
engine computes in doubles).
"""

from __future__ import annotations

import sys
from fractions import Fraction

from ..core import INT_FRACTIONS, int_fraction
from ..diagnostics import LangurError, Span, SpanSlots, error
from .chains import CHAIN_BALANCE as _BALANCE
from .chains import FIRST as _FIRST
from .chains import LEVEL as _LEVEL
from .chains import MAX_DEPTH
from .chains import Built as _Built
from .chains import Chain as _Chain
from .chains import Reduced as _R
from .surface import (
    Apply,
    BinOp,
    Component,
    DefArg,
    DefDecl,
    DiffeoApp,
    DiffeoDecl,
    Fields,
    Ident,
    IfCmp,
    IfGe0S,
    IfLogic,
    ImportItem,
    ImportName,
    Interval,
    Iverson,
    LetIn,
    Logic,
    Loop,
    Name,
    Neg,
    NestedInt,
    Num,
    ParamDecl,
    ParamItem,
    ProgramS,
    Vector,
)

#: Longest number literal, in digits (E106).
MAX_DIGITS = 1000
#: Largest absolute decimal exponent of a number literal (E106).
MAX_EXPONENT = 1000

#: Integer literals this short are read directly (no exponent, within a double's range: 10³⁰⁰ < 1.8·10³⁰⁸).
_SHORT = 300
_FLOAT_MAX = Fraction(sys.float_info.max)
_FLOAT_MIN = Fraction(sys.float_info.min)  # the smallest normal double: below it precision is lost
#: The literals ``0`` … ``127`` (as written without leading zeros) and their values, the shared
#: ``INT_FRACTIONS`` (a literal's value is then one lookup).
_SMALL_INTS = dict(zip(map(str, range(len(INT_FRACTIONS))), INT_FRACTIONS))


class _Comparisons:
    """A comparison chain inside brackets, before it becomes an Iverson bracket (an intermediate
    result of the parse, never compared: a plain class, not a dataclass, whose creation cost
    ~0.5 ms of every start)."""

    __slots__ = ("ops", "terms")

    def __init__(self, terms: list, ops: tuple[str, ...]) -> None:
        self.terms, self.ops = terms, ops


def _shorten(text: str) -> str:
    return text if len(text) <= 24 else text[:20] + "..."


_CMP = {"<=": "<=", "≤": "<=", ">=": ">=", "≥": ">=", "<": "<", ">": ">"}


# ----------------------------------------------------------------------------------------------
# Positions.  Intermediate results are `_R` (a node with the span of its source text including
# any parentheses around it, and its depth); tokens carry their own positions.


def _start(x) -> tuple[int, int]:
    if type(x) is tuple:  # a token (lalr.TOKEN: lark's too, given to the callbacks so by _FromLark)
        return x[2], x[3]
    if isinstance(x, _R):
        return x.line, x.col
    return x.span.line, x.span.col  # a node (Ident, ParamDecl, …)


def _end(x) -> tuple[int, int]:
    if type(x) is tuple:  # a token
        return x[4], x[5]
    if isinstance(x, _R):
        return x.end_line, x.end_col
    return x.span.end_line, x.span.end_col


class Builder:
    """The inline transformer: one method per (aliased) grammar rule, called on reduction."""

    def __init__(self) -> None:
        self.path = "<string>"

    # -- helpers --
    def span(self, first, last) -> Span:
        # (_start and _end written out for the two kinds met on every term: an intermediate
        # result or the driver's token)
        tf, tl = type(first), type(last)
        if tf is _R or tf is _Built or tf is _Chain:
            l1, c1 = first.line, first.col
        elif tf is tuple:  # a token (lalr.TOKEN)
            l1, c1 = first[2], first[3]
        else:
            l1, c1 = _start(first)
        if tl is _R or tl is _Built or tl is _Chain:
            l2, c2 = last.end_line, last.end_col
        elif tl is tuple:
            l2, c2 = last[4], last[5]
        else:
            l2, c2 = _end(last)
        s = SpanSlots()  # (a Span made without a Python call: see SpanSlots)
        s.path = self.path
        s.line = l1
        s.col = c1
        s.end_line = l2
        s.end_col = c2
        s.__class__ = Span
        return s

    def tok_span(self, t: tuple) -> Span:
        s = SpanSlots()
        s.path = self.path
        s.line = t[2]
        s.col = t[3]
        s.end_line = t[4]
        s.end_col = t[5]
        s.__class__ = Span
        return s

    def term(self, make, first, last, subs) -> _R:
        """Build a term node spanning ``first``..``last`` with subterm results ``subs``."""
        sp = self.span(first, last)
        depth = 0
        for s in subs:  # (the deepest subterm: a loop, not max over a generator, on this hot path)
            d = s.depth
            if d > depth:
                depth = d
        depth += 1
        if depth > MAX_DEPTH:
            raise self.too_deep(sp)
        r = _R()
        r.node = make(sp)
        r.line = sp.line
        r.col = sp.col
        r.end_line = sp.end_line
        r.end_col = sp.end_col
        r.depth = depth
        return r

    def too_deep(self, sp: Span) -> LangurError:
        return error(sp, "E105", f"nesting too deep: terms may nest at most {MAX_DEPTH} levels (parentheses, "
                     "calls, conditionals, lets and powers inside one another; long sums and products "
                     "count only the depth of their balanced tree)")

    def ident(self, t: tuple) -> Ident:
        return Ident(t[1], self.tok_span(t))

    def number(self, t: tuple) -> Fraction:
        """The exact value of a decimal literal (E106 when too long or its exponent too large)."""
        text = t[1]
        if len(text) <= _SHORT and text.isdigit():  # an integer of at most 300 digits: a double's range
            return Fraction(int(text))
        mantissa, _, exp = text.lower().partition("e")
        whole, _, frac = mantissa.partition(".")
        if len(whole) + len(frac) > MAX_DIGITS:
            raise error(self.tok_span(t), "E106", f"number literal too long (more than {MAX_DIGITS} digits)")
        exp_digits = exp.lstrip("+-").lstrip("0")
        if len(exp_digits) > 6 or (exp_digits and int(exp_digits) > MAX_EXPONENT):
            shown = exp if len(exp) <= 12 else exp[:9] + "..."
            raise error(
                self.tok_span(t), "E106", f"number literal's exponent {shown} is beyond ±{MAX_EXPONENT}"
            )
        power = (int(exp_digits) if exp_digits else 0) * (-1 if exp.startswith("-") else 1) - len(frac)
        value = Fraction(int(whole + frac or "0"))
        value = value * 10**power if power >= 0 else value / 10**-power
        if value and not _FLOAT_MIN <= value <= _FLOAT_MAX:
            what = "too large" if value > _FLOAT_MAX else "too small"
            raise error(self.tok_span(t), "E106", f"number literal {_shorten(text)} is {what} for a double-precision "
                        f"number (nonzero magnitudes {sys.float_info.min:.3g} to {sys.float_info.max:.4g}): "
                        "the Monte Carlo engine computes in doubles")
        return value

    # -- module level --
    def start(self, c):
        return c  # items then maybe a program; parse_module builds the ModuleS

    def param_item(self, c):
        decls = tuple(x for x in c if isinstance(x, ParamDecl))
        return ParamItem(decls, self.span(c[0], c[-1]))

    def pdecl(self, c):
        return ParamDecl(self.ident(c[0]), None, self.span(c[0], c[-1]))

    def pdecl_default(self, c):
        return ParamDecl(self.ident(c[0]), self.number(c[2]), self.span(c[0], c[-1]))

    def pdecl_default_neg(self, c):
        return ParamDecl(self.ident(c[0]), -self.number(c[3]), self.span(c[0], c[-1]))

    def diffeo_item(self, c):
        # DIFFEO name ( names ; names? ) = tuple INVERSE ( names ) = tuple
        name, variables = c[1], c[3]
        rest = c[5:]
        params: tuple = ()
        if isinstance(rest[0], list):
            params = tuple(rest[0])
            rest = rest[1:]
        # rest: ) = tuple INVERSE ( names ) = tuple
        forward, inputs, inverse = rest[2], rest[5], rest[8]
        return DiffeoDecl(
            self.ident(name),
            tuple(variables),
            params,
            tuple(r.node for r in forward[1]),
            tuple(inputs),
            tuple(r.node for r in inverse[1]),
            self.span(c[0], inverse[2]),
        )

    def tuple(self, c):
        return (c[0], c[1], c[2])  # ( terms ): kept with its tokens for spans

    def def_item(self, c):
        args = c[3] if len(c) == 7 else ()  # DEF name ( defargs? ) = term
        body = c[-1]
        return DefDecl(self.ident(c[1]), args, body.node, self.span(c[0], body))

    def defargs(self, c):
        return tuple(x for x in c if isinstance(x, DefArg))

    def defarg(self, c):
        return DefArg(self.ident(c[0]), c[2][1], self.span(c[0], c[2]))

    def import_item(self, c):
        names = tuple(x for x in c[3:] if isinstance(x, ImportName))
        return ImportItem(self.ident(c[1]), names, self.span(c[0], c[-1]))

    def impname(self, c):
        alias = self.ident(c[2]) if len(c) == 3 else None
        return ImportName(self.ident(c[0]), alias, self.span(c[0], c[-1]))

    def program(self, c):
        # INT domain? term D ( names )
        domain = c[1] if isinstance(c[1], tuple) else None
        body = c[2] if domain is not None else c[1]
        variables = tuple(c[-2])
        return ProgramS(domain, body.node, variables, self.span(c[0], c[-1]))

    def nested_int(self, c):
        # INT domain? term D ( names ): a term, rejected by the type system (T208)
        domain = c[1] if isinstance(c[1], tuple) else None
        body = c[2] if domain is not None else c[1]
        variables = tuple(c[-2])
        return self.term(lambda sp: NestedInt(domain, body.node, variables, sp), c[0], c[-1], (body,))

    def domain(self, c):
        return tuple(x for x in c if isinstance(x, Interval))

    def interval(self, c):
        return Interval(c[1].node, c[3].node, self.span(c[0], c[-1]))

    def names(self, c):
        return [self.ident(x) for x in c if x[0] != "COMMA"]

    def terms(self, c):
        return [x for x in c if isinstance(x, _R)]

    # (``name`` of a NAME, ``cmp``, ``plain`` and ``cond_term`` give back their one child: the driver's
    # table never reduces by them — ``tables.IDENTITIES``, folded by ``tables.fold_units`` — lark does)
    def name(self, c):
        t = c[0]
        return t if t[0] == "NAME" else ("NAME", *t[1:])  # (`d` where it is a name)

    def cmp(self, c):
        return c[0]

    # -- terms --
    def plain(self, c):
        return c[0]

    def cond_term(self, c):
        return c[0]

    def binop(self, c):
        left, op, right = c
        op = op[1]  # (a token's text)
        level = _LEVEL.get(op)
        if level is None:  # ^: right-associative and bounded by real nesting
            return self.term(lambda sp: BinOp(op, left.node, right.node, sp), left, right, (left, right))
        tl = type(left)
        if tl is _Chain and left.level == level:  # the grammar's left recursion: one more link
            left.append(op, right)
            return left
        items = left.items if tl is _Built and left.level == level else None  # (one more link, or a new chain)
        if tl is not _Chain and type(right) is not _Chain and (items is None or len(items) < _BALANCE):
            # built now (chains.Built): the grammar's left-nested tree, as Chain._build makes it
            d = right.depth
            depth = left.depth
            depth = 1 + (depth if depth > d else d)
            if depth <= MAX_DEPTH:
                s = SpanSlots()  # (from the chain's first operand to `right`)
                s.path = self.path
                s.line = left.line
                s.col = left.col
                s.end_line = right.end_line
                s.end_col = right.end_col
                s.__class__ = Span
                node = Fields()  # (BinOp(op, left.node, right.node, s) without a Python call: see surface.Fields)
                node.op = op
                node.left = left.node
                node.right = right.node
                node.span = s
                node.__class__ = BinOp
                if items is None:
                    b = _Built()
                    b.level = level
                    b.items = [(_FIRST[level], left), (op, right)]
                    b.line = left.line
                    b.col = left.col
                else:
                    b = left
                    items.append((op, right))
                b.node = node
                b.depth = depth
                b.end_line = right.end_line
                b.end_col = right.end_col
                return b
        # built when first read (a chain too long or too deep, or an operand whose node may raise E105)
        if items is None:
            chain = _Chain(self, level, left)
        else:
            chain = _Chain(self, level, items[0][1])
            chain.items = items
        chain.append(op, right)
        return chain

    def neg(self, c):
        arg = c[1]
        return self.term(lambda sp: Neg(arg.node, sp), c[0], arg, (arg,))

    def num(self, c):
        t = c[0]
        value = _SMALL_INTS.get(t[1])  # (0 … 127 written as Python writes them: one lookup)
        if value is None:
            text = t[1]  # (number()'s first case written out: a short integer)
            if len(text) <= _SHORT and text.isdigit():
                value = int_fraction(int(text))
            else:
                value = self.number(t)
        n = Fields()  # (Num(value, span): see leaf)
        n.value = value
        return self.leaf(t, n, Num)

    def var(self, c):
        t = c[0]
        n = Fields()  # (Name(t[1], span): see leaf)
        n.name = t[1]
        return self.leaf(t, n, Name)

    def leaf(self, t: tuple, node: Fields, cls: type) -> _R:
        """The term of the token ``t``: ``node`` (its fields but its span set) made a ``cls`` with
        the token's span, at depth 1 (``term()`` without a Python call of the node's ``__init__``,
        see ``surface.Fields``, nor of the span's, see ``SpanSlots``)."""
        s = SpanSlots()
        s.path = self.path
        s.line = line = t[2]
        s.col = col = t[3]
        s.end_line = end_line = t[4]
        s.end_col = end_col = t[5]
        s.__class__ = Span
        node.span = s
        node.__class__ = cls
        r = _R()
        r.node = node
        r.line = line
        r.col = col
        r.end_line = end_line
        r.end_col = end_col
        r.depth = 1
        return r

    def apply(self, c):
        args = c[2] if isinstance(c[2], list) else []
        nsp = self.tok_span(c[0])
        return self.term(lambda sp: Apply(c[0][1], tuple(a.node for a in args), sp, nsp), c[0], c[-1], args)

    def paren(self, c):
        left, inner, right = c  # ( term ): two tokens around the term
        r = _R()
        r.node = inner.node
        r.line = left[2]
        r.col = left[3]
        r.end_line = right[4]
        r.end_col = right[5]
        r.depth = inner.depth
        return r

    def chain(self, c):
        """``t0 op0 t1 op1 t2 …``: its terms and comparison operators."""
        return _Comparisons([x for x in c if isinstance(x, _R)], tuple(_CMP[x[1]] for x in c[1::2]))

    def iverson(self, c):
        ch = c[1]
        return self.term(lambda sp: Iverson(tuple(t.node for t in ch.terms), ch.ops, sp), c[0], c[-1], ch.terms)

    def _logic(self, op: str, c, first=None, last=None):
        """``Logic(op, …)`` over the comparison chains among ``c``, spanning ``first``..``last``
        (default: the chains themselves)."""
        parts = [self.term(lambda sp, ch=ch: Iverson(tuple(t.node for t in ch.terms), ch.ops, sp),
                           ch.terms[0], ch.terms[-1], ch.terms) for ch in c if isinstance(ch, _Comparisons)]
        return self.term(lambda sp: Logic(op, tuple(p.node for p in parts), sp), first or parts[0],
                         last or parts[-1], parts)

    def _if_logic(self, op: str, c):
        then, orelse = [x for x in c if isinstance(x, _R)][-2:]
        logic = self._logic(op, c)
        return self.term(lambda sp: IfLogic(logic.node, then.node, orelse.node, sp), c[0], orelse,
                         (logic, then, orelse))

    def if_and(self, c):
        return self._if_logic("and", c)

    def if_or(self, c):
        return self._if_logic("or", c)

    def if_not(self, c):
        return self._if_logic("not", c)

    def iverson_and(self, c):
        return self._logic("and", c, c[0], c[-1])

    def iverson_or(self, c):
        return self._logic("or", c, c[0], c[-1])

    def iverson_not(self, c):
        return self._logic("not", c, c[0], c[-1])

    def let(self, c):
        name, bound, body = c[1], c[3], c[5]
        nsp = self.tok_span(name)
        return self.term(
            lambda sp: LetIn(name[1], bound.node, body.node, sp, nsp), c[0], body, (bound, body)
        )

    def loop(self, c):
        # SUM|PROD name IN term DOTDOT term COLON term (§9, the finite loop)
        op, name, lo, hi, body, nsp = c[0][1], c[1], c[3], c[5], c[7], self.tok_span(c[1])
        return self.term(lambda sp: Loop(op, name[1], lo.node, hi.node, body.node, sp, nsp), c[0], body,
                         (lo, hi, body))

    def vector(self, c):
        # ( term , terms ): a vector of at least two components
        parts = [c[1], *c[3]]
        return self.term(lambda sp: Vector(tuple(p.node for p in parts), sp), c[0], c[-1], parts)

    def component(self, c):
        # atom . name
        base, name, nsp = c[0], c[2], self.tok_span(c[2])
        return self.term(lambda sp: Component(base.node, name[1], sp, nsp), base, name, (base,))

    def ifge0(self, c):
        cond, then, orelse = c[1], c[3], c[5]
        return self.term(
            lambda sp: IfGe0S(cond.node, then.node, orelse.node, sp), c[0], orelse, (cond, then, orelse)
        )

    def ifcmp(self, c):
        left, op, right, then, orelse = c[1], _CMP[c[2][1]], c[3], c[5], c[7]
        return self.term(
            lambda sp: IfCmp(left.node, op, right.node, then.node, orelse.node, sp),
            c[0],
            orelse,
            (left, right, then, orelse),
        )

    def diffeo_app(self, c):
        variables = c[2]
        params = c[4] if isinstance(c[4], list) else []
        nsp = self.tok_span(c[0])
        return self.term(
            lambda sp: DiffeoApp(
                c[0][1], tuple(v.node for v in variables), tuple(p.node for p in params), sp, nsp
            ),
            c[0],
            c[-1],
            list(variables) + list(params),
        )



__all__ = ["MAX_DEPTH", "MAX_DIGITS", "MAX_EXPONENT", "Builder"]
