"""The parse per token, second cut (issue 15, branch parse25): what the parser makes without a
Python ``__init__`` call is what the classes' constructors make.

* ``Span`` is a frozen, slotted record; the parser fills a ``SpanSlots`` and assigns it the class
  ``Span``: the result is a ``Span`` in every respect (type, fields, equality, hash, repr, frozen,
  pickling, ``dataclasses.replace``, ``match``).
* ``Num``, ``Name`` and a chain's ``BinOp`` are made as ``surface.Fields`` given their class: the same
  ``__dict__`` (keys in the order of the fields) as their constructor's, frozen all the same.
* A token is a tuple of ``lalr.TOKEN`` (lark's token's attributes); lark's tokens reach the callbacks
  as such tuples (``parser._FromLark``), so that both parsers give the same trees.
* A chain of at most ``CHAIN_BALANCE`` operands is built link by link as it is reduced
  (``chains.Built``): checked against trees built here from the operands' positions, the grammar's
  left-nested shape with each ``BinOp`` spanning its first operand to its last; E105 where a chain is
  too deep is raised where and when it was (spans computed here by hand).
"""

from __future__ import annotations

import copy
import dataclasses
import pickle
import random
import re
from fractions import Fraction

import pytest
from paths import REPO
from test_lalr import _tree  # (surface trees as nested tuples, spans included)

from langur.core import INT_FRACTIONS
from langur.diagnostics import LangurError, Span, SpanSlots
from langur.syntax import chains, lalr, larkload, parser
from langur.syntax.surface import BinOp, Fields, Name, Neg, Num

FILES = sorted(p for p in REPO.rglob("*.lgr") if ".venv" not in p.parts)


def _walk(x):
    """Every object reachable from a surface tree through fields, tuples and lists."""
    yield x
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        for f in dataclasses.fields(x):
            yield from _walk(getattr(x, f.name))
    elif isinstance(x, (tuple, list)):
        for v in x:
            yield from _walk(v)


def _made(path, line, col, end_line, end_col) -> Span:
    s = SpanSlots()
    s.path, s.line, s.col, s.end_line, s.end_col = path, line, col, end_line, end_col
    s.__class__ = Span
    return s


# -- Span ----------------------------------------------------------------------------------------


def test_a_span_made_from_its_slots_is_a_span():
    made, built = _made("p.lgr", 3, 4, 5, 6), Span("p.lgr", 3, 4, 5, 6)
    assert type(made) is Span and made == built and not made != built
    assert hash(made) == hash(built) == hash(("p.lgr", 3, 4, 5, 6))  # (records: the fields' tuple)
    assert repr(made) == "Span(path='p.lgr', line=3, col=4, end_line=5, end_col=6)" == repr(built)
    assert str(made) == "p.lgr:3:4"
    assert made != Span("p.lgr", 3, 4, 5, 7) and made != ("p.lgr", 3, 4, 5, 6)
    assert [f.name for f in dataclasses.fields(made)] == ["path", "line", "col", "end_line", "end_col"]
    match made:
        case Span(path, line, col):
            assert (path, line, col) == ("p.lgr", 3, 4)
        case _:
            pytest.fail("a span does not match its class pattern")


def test_a_span_is_frozen_and_slotted():
    for s in (_made("p", 1, 1, 1, 2), Span("p", 1, 1, 1, 2)):
        assert not hasattr(s, "__dict__")
        with pytest.raises(dataclasses.FrozenInstanceError):
            s.line = 2
        with pytest.raises(dataclasses.FrozenInstanceError):
            del s.col
        assert s.line == 1 and s.col == 1


def test_a_span_survives_pickle_copy_and_replace():
    s = _made("dir/p.lgr", 7, 1, 9, 12)
    for other in (pickle.loads(pickle.dumps(s)), copy.copy(s), copy.deepcopy(s)):
        assert type(other) is Span and other == s and hash(other) == hash(s)
    moved = dataclasses.replace(s, line=8)
    assert type(moved) is Span and (moved.path, moved.line, moved.col, moved.end_line, moved.end_col) == \
        ("dir/p.lgr", 8, 1, 9, 12)


def test_every_span_of_a_parse_is_a_span():
    """No ``SpanSlots`` (nor any other class) is left in a tree: every span the parser made is a
    ``Span``, equal to the one its constructor makes from its fields."""
    seen = 0
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        try:
            module = parser.parse_module(text, str(path))
        except LangurError:
            continue
        for x in _walk(module):
            for name in ("span", "name_span"):
                s = getattr(x, name, None) if dataclasses.is_dataclass(x) else None
                if s is not None:
                    assert type(s) is Span
                    assert s == Span(s.path, s.line, s.col, s.end_line, s.end_col)
                    seen += 1
            assert type(x) is not SpanSlots and type(x) is not Fields
    assert seen > 1000


# -- surface nodes made from their fields ----------------------------------------------------------


def test_nodes_made_from_fields_are_their_constructors():
    """Every ``Num``, ``Name`` and ``BinOp`` of a parse has the ``__dict__`` its constructor gives it
    (the same keys in the same order, the same values) and stays frozen."""
    counts = {Num: 0, Name: 0, BinOp: 0}
    for path in FILES:
        try:
            module = parser.parse_module(path.read_text(encoding="utf-8"), str(path))
        except LangurError:
            continue
        for x in _walk(module):
            if type(x) in counts:
                counts[type(x)] += 1
                again = type(x)(**vars(x))
                assert list(vars(x).items()) == list(vars(again).items())
                assert list(vars(x)) == [f.name for f in dataclasses.fields(x)]
                assert x == again and hash(x) == hash(again) and repr(x) == repr(again)
    assert all(n > 50 for n in counts.values()), counts
    n = parser.parse_term("x + 1", "t.lgr")
    with pytest.raises(dataclasses.FrozenInstanceError):
        n.op = "-"
    with pytest.raises(dataclasses.FrozenInstanceError):
        n.left.name = "y"


def test_small_literals_are_the_shared_fractions():
    """A literal 0 … 127 written plainly is the shared ``INT_FRACTIONS`` value (``core``'s
    identity test for small constants); written otherwise, or larger, the same value."""
    for text, value, shared in (("0", 0, True), ("7", 7, True), ("127", 127, True), ("128", 128, False),
                                ("007", 7, True), ("1.0", 1, False), ("2e1", 20, False), ("1e-3", Fraction(1, 1000), False)):
        node = parser.parse_term(text)
        assert type(node) is Num and node.value == value and type(node.value) is Fraction
        assert any(node.value is f for f in INT_FRACTIONS) is shared, text


# -- tokens --------------------------------------------------------------------------------------


def test_a_token_tuple_holds_lark_s_token():
    """``lalr.TOKEN`` names every slot of lark's token, and ``lalr.token`` reads them in its order."""
    assert sorted(lalr.TOKEN) == sorted(larkload.Token.__slots__)
    t = larkload.Token("NAME", "abc", start_pos=4, line=2, column=3, end_line=2, end_column=6, end_pos=7)
    assert lalr.token(t) == tuple(getattr(t, k) for k in lalr.TOKEN) == ("NAME", "abc", 2, 3, 2, 6, 4, 7)
    assert type(lalr.token(t)[1]) is str


def test_lark_and_the_driver_give_the_same_trees():
    """The callbacks run under lark (FAST off: lark's tokens given as tuples) and under the driver
    give the same trees, spans and diagnostics, on every file and on broken variants of them."""
    rng = random.Random(25)
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        variants = [text] + [text[:rng.randrange(len(text) + 1)] for _ in range(3)]
        for t in variants:
            out = []
            for fast in (True, False):
                parser.FAST = fast
                try:
                    out.append(("ok", _tree(parser.parse_module(t, "f.lgr"))))
                except LangurError as e:
                    out.append(("error", [d.format() for d in e.diagnostics]))
                finally:
                    parser.FAST = True
            assert out[0] == out[1], path


# -- chains --------------------------------------------------------------------------------------


def _chain_text(rng: random.Random, n: int) -> tuple[str, list]:
    """A sum of ``n`` products of one or two numbers or names: the text, and per sum operand its
    (text, start col, end col, [(op, factor text, start, end), …]) (one line, columns 1-based)."""
    parts, terms, col = [], [], 1
    for i in range(n):
        if i:
            op = rng.choice("+-")
            parts.append(f" {op} ")
            col += 3
        else:
            op = "+"
        factors = []
        for j in range(rng.choice((1, 1, 2))):
            if j:
                fop = rng.choice("*/")
                parts.append(f" {fop} ")
                col += 3
            else:
                fop = "*"
            word = rng.choice(("x", "a1", str(rng.randrange(1, 200)), "2.5"))  # (no 0: divisors)
            factors.append((fop, word, col, col + len(word)))
            parts.append(word)
            col += len(word)
        terms.append((op, factors))
    return "".join(parts), terms


def _leaf(word: str, a: int, b: int):
    s = Span("t.lgr", 1, a, 1, b)
    return Name(word, s) if word[0].isalpha() else Num(Fraction(word), s)


def _expected(terms: list):
    """The grammar's left-nested tree, each BinOp from its first operand's start to its last's end."""
    def product(factors):
        (_, w, a, b), *rest = factors
        node = _leaf(w, a, b)
        for op, w2, _, b2 in rest:
            node = BinOp(op, node, _leaf(w2, _, b2), Span("t.lgr", 1, a, 1, b2))
        return node, a, factors[-1][3]
    node, a, _ = product(terms[0][1])
    for op, factors in terms[1:]:
        right, _, b = product(factors)
        node = BinOp(op, node, right, Span("t.lgr", 1, a, 1, b))
    return node


def test_chains_up_to_the_balance_are_the_grammar_s_trees():
    rng = random.Random(2525)
    for _ in range(300):
        n = rng.randrange(1, chains.CHAIN_BALANCE + 1)
        text, terms = _chain_text(rng, n)
        got = parser.parse_term(text, "t.lgr")
        assert _tree(got) == _tree(_expected(terms)), text


def test_longer_chains_keep_their_value_and_stay_shallow():
    """Past ``CHAIN_BALANCE`` operands a sum is regrouped (chains.Chain, unchanged): the same value,
    depth logarithmic in its length."""
    def value(t, env):
        if type(t) is Num:
            return t.value
        if type(t) is Name:
            return env[t.name]
        if type(t) is Neg:
            return -value(t.arg, env)
        a, b = value(t.left, env), value(t.right, env)
        return a + b if t.op == "+" else a - b if t.op == "-" else a * b if t.op == "*" else a / b

    def depth(t):
        return 1 + max(depth(t.left), depth(t.right)) if type(t) is BinOp else 1

    rng = random.Random(25)
    env = {"x": Fraction(3, 7), "a1": Fraction(-5, 2)}
    for n in (33, 40, 64, 200):
        text, terms = _chain_text(rng, n)
        got = parser.parse_term(text, "t.lgr")
        assert value(got, env) == value(_expected(terms), env)
        assert depth(got) <= 2 * (n.bit_length() + 2)


def test_a_too_deep_chain_is_reported_where_it_was():
    """E105 for a chain whose tree is too deep: at the chain (read inside parentheses or as the
    program's body) or at the term it is an operand of (which counts the depth first); a chain never
    read because the text has a syntax error first gives the syntax error."""
    deep = "(" * 199 + "x" + ")" * 199  # depth 1: parentheses add none
    power = "x^" * 199 + "x"  # depth 200
    col = len("int ([0, 1]) ") + 1

    def error(text):
        with pytest.raises(LangurError) as e:
            parser.parse_module(text, "t.lgr")
        return e.value.diagnostics[0].format()

    assert error(f"int ([0, 1]) {power} + 1 d(x)") == \
        f"t.lgr:1:{col}: error E105 nesting too deep: terms may nest at most 200 levels (parentheses, calls, " \
        "conditionals, lets and powers inside one another; long sums and products count only the depth of " \
        "their balanced tree)"
    # read inside parentheses: at the chain (after "-(", "(", "2 * (")
    assert error(f"int ([0, 1]) -({power} + 1) d(x)").startswith(f"t.lgr:1:{col + 2}: error E105")
    assert error(f"int ([0, 1]) ({power} + 1) d(x)").startswith(f"t.lgr:1:{col + 1}: error E105")
    assert error(f"int ([0, 1]) 2 * ({power} + 1) d(x)").startswith(f"t.lgr:1:{col + 5}: error E105")
    # an operand of a term that counts its operands' depth first: at that term (the bracket)
    assert error(f"int ([0, 1]) [{power} + 1 > 0] d(x)").startswith(f"t.lgr:1:{col}: error E105")
    ok = parser.parse_module(f"int ([0, 1]) {deep} + 1 d(x)", "t.lgr")
    assert type(ok.program.body) is BinOp
    assert error(f"int ([0, 1]) {power} + 1 ) d(x)").startswith(f"t.lgr:1:{col + len(power) + 5}: error E10")


# -- the lexer's pattern -------------------------------------------------------------------------


def test_the_pattern_cuts_as_parse24_s_did():
    """The shipped pattern (parse25: the end of the text an alternative, a comment's run unrolled
    once) cuts every text as parse24's form of it did — ``((?>C*(?:OC*)*))(?:(T)|([\\s\\S]))?`` —
    on random texts over the grammar's characters, comments, line breaks and stray characters,
    whole and between random bounds (the driver's pieces)."""
    data = lalr.load()
    pattern = data["scanner"]["pattern"]
    skip_end = pattern.index("))(?:(")
    c = pattern[4:pattern.index("*")]  # ((?>C* …
    assert c == "[ \t\x0c\r\n]" and pattern.endswith(r"|([\s\S])|\Z)")
    token = pattern[skip_end + len("))(?:("):-len(r")|([\s\S])|\Z)")]
    old = rf"((?>{c}*(?:(?:#[^\n]*){c}*)*))(?:({token})|([\s\S]))?"
    ours, theirs = re.compile(pattern, data["scanner"]["flags"]), re.compile(old, data["scanner"]["flags"])
    rng = random.Random(25)
    pieces = ["x", "ab_1", "12", "1.5e3", ".5", "..", ".", "<=", "≤", ">=", "<", "(", ")", "[", "]", ",", ";",
              "+", "-", "*", "/", "^", "&", "|", " ", "  ", "\t", "\n", "\r\n", "\f", "# c", "#", "# x # y\n",
              "@", "é", "\x0b", "let", "d", "sum"]
    for _ in range(3000):
        text = "".join(rng.choice(pieces) for _ in range(rng.randrange(12)))
        assert ours.findall(text) == theirs.findall(text), text
        a = rng.randrange(len(text) + 1)
        b = rng.randrange(a, len(text) + 1)
        assert ours.findall(text, a, b) == theirs.findall(text, a, b), (text, a, b)
