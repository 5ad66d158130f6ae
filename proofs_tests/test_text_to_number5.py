"""Loading cheaper at small n (issue 15, branch front5): the parser's fast paths against independent
references.

* ``syntax/lalr.py``'s driver skips the callbacks of unit rules that return their child and matches
  white space and comments together with the next token: its trees, spans included, are lark's own
  parser's (``Lark.parse`` with the same callbacks) on texts with ignored runs everywhere, and it
  finishes by itself (never :data:`lalr.FAILED`, which would hand the text to lark) for a whole
  term, whose start rule ends in a unit reduction.
* ``builder.Builder.number`` reads short integer literals directly: the same Fraction as Python's
  own decimal reading, and the E106 bounds kept for long ones.
* ``Span`` and the surface nodes with a written-out ``__init__`` take their fields as the generic
  record ``__init__`` does (by position, by name, defaults) and compare as before.
* ``loops.size`` counts the nodes that a plain walk over the dataclass fields counts.
"""

from __future__ import annotations

import dataclasses
import random
from fractions import Fraction

import pytest

from langur.diagnostics import LangurError, Span
from langur.syntax import chains, lalr, loops, parser, surface
from langur.syntax.parser import parse_bytes, parse_term


def _lark(text: str, start: str):
    """Lark's own LALR parser over the same grammar and callbacks (the reference)."""
    with parser._LOCK:
        lark = parser._parser()
        parser._BUILDER.path = "<t>"
        return lark.parse(text, start=start)


def _driver(text: str, start: str):
    with parser._LOCK:
        parser._parser()
        parser._BUILDER.path = "<t>"
        return parser._DRIVER(text, start)


def _tree(x):
    """A parse result as nested tuples with every span (the records' equality ignores spans)."""
    if isinstance(x, chains.Reduced):
        return ("R", _tree(x.node), x.line, x.col, x.end_line, x.end_col, x.depth)
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return (type(x).__name__,) + tuple(_tree(getattr(x, f.name)) for f in dataclasses.fields(x))
    if isinstance(x, (list, tuple)):
        return tuple(_tree(y) for y in x)
    return x


_IGNORED = [" ", "  ", "\t", "\n", "\r\n", "\f", "\n\n  ", " # a comment\n", "# c\n\t", "#\n", " \n # x\n\n"]


def _spread(tokens: list[str], rng: random.Random) -> str:
    out = [rng.choice(_IGNORED) if rng.random() < 0.5 else ""]
    for t in tokens:
        out.append(t)
        out.append(rng.choice(_IGNORED) if rng.random() < 0.7 else " ")
    if rng.random() < 0.5:
        out.append("# trailing comment without a newline")
    return "".join(out)


_PROGRAM = ("param a = 1 , b = -2 def f ( x : var , c : param ) = x * c + 1 / 3 int ( [ -1 , 1 ] , [ 0 , a ] ) "
            "( sum i in 10 .. 12 : [ x + 1 / i + a - 1 >= 0 ] * ( 1 / i + a - 1 + x ) ) + f ( y , b ) ^ 2 "
            "- ( let z = 2 in z * x ) + [ x <= y & y <= 1 ] d ( x , y )").split(" ")


def test_driver_trees_are_larks_with_ignored_text_anywhere():
    rng = random.Random(5)
    for _ in range(60):
        text = _spread(_PROGRAM, rng)
        ours = _driver(text, "start")
        assert ours is not lalr.FAILED, text
        assert _tree(ours) == _tree(_lark(text, "start")), text


@pytest.mark.parametrize("text", ["x", "1 / i + a - 1 + x", "  (x)  # c", "-x ^ 2", "[x <= 1] * exp(x)",
                                  "sum i in 1..3: i * x", "if x <= 1 then 2 else 3"])
def test_a_whole_term_is_parsed_by_the_driver_itself(text):
    # start rule `term`: its last reduction is the unit rule `term: sum` (skipped by the driver),
    # after which the end must still be recognised
    ours = _driver(text, "term")
    assert ours is not lalr.FAILED
    assert _tree(ours) == _tree(_lark(text, "term"))
    assert parse_term(text) == parse_term(text)  # (and through the public entry)


def test_syntax_errors_still_fall_back_to_lark():
    for text in ["int x + d(x)", "int (x +) d(x)", "int x @ d(x)", "int x d(x) extra"]:
        assert _driver(text, "start") is lalr.FAILED
        with pytest.raises(LangurError):
            parse_bytes(text.encode(), "<t>")


def test_integer_literals_read_as_python_reads_them():
    rng = random.Random(15)
    texts = ["0", "7", "007", "10", "1" + "0" * 299, "9" * 300, "9" * 301, "1" + "0" * 307, "0" * 500 + "12"]
    texts += ["".join(rng.choice("0123456789") for _ in range(rng.randint(1, 40))) for _ in range(200)]
    for text in texts:
        module = parse_bytes(f"int ([0, 1]) {text} * x d(x)\n".encode(), "<t>")
        assert module.program.body.left.value == Fraction(text), text
    for text in ["1" + "0" * 400, "1" * 1001]:  # beyond doubles, or too many digits: E106 as before
        with pytest.raises(LangurError) as e:
            parse_bytes(f"int ([0, 1]) {text} * x d(x)\n".encode(), "<t>")
        assert e.value.diagnostics[0].code == "E106"


_WRITTEN_OUT = [Span, surface.Num, surface.Name, surface.BinOp, surface.Neg, surface.Apply, surface.Iverson,
                surface.Loop, surface.Ident]


@pytest.mark.parametrize("cls", _WRITTEN_OUT, ids=lambda c: c.__name__)
def test_written_out_inits_take_fields_as_records_do(cls):
    assert "__init__" in cls.__dict__
    fields = dataclasses.fields(cls)
    values = [object() for _ in fields]
    by_position = cls(*values)
    by_name = cls(**{f.name: v for f, v in zip(fields, values)})
    for f, v in zip(fields, values):
        assert getattr(by_position, f.name) is v and getattr(by_name, f.name) is v
    required = [f for f in fields if f.default is dataclasses.MISSING]
    short = cls(*values[:len(required)])
    for f in fields[len(required):]:
        assert getattr(short, f.name) == f.default  # (None: every defaulted field is a span)
    with pytest.raises(TypeError):
        cls(*values[:len(required) - 1])
    with pytest.raises(dataclasses.FrozenInstanceError):
        setattr(by_position, fields[0].name, 1)
    assert by_position == by_name and hash(by_position) == hash(by_name)


def _count(st) -> int:
    """Surface nodes below and including ``st``: recursion over the dataclass fields (the reference)."""
    def nodes(v):
        if isinstance(v, tuple):
            return sum(nodes(x) for x in v)
        if dataclasses.is_dataclass(v) and not isinstance(v, type) and hasattr(v, "span") and not isinstance(v, Span):
            return _count(v)
        return 0
    return 1 + sum(nodes(getattr(st, f.name)) for f in dataclasses.fields(st) if f.name != "span")


def test_loop_body_size_is_the_plain_count():
    text = ("def g(x: var) = (x, 2 * x).y + cross((x, 1, 2), (1, x, 3)).z\n"
            "int ([0, 1]) sum i in 1..3: prod j in 1..2: [x <= i / 4 & x >= 0] * g(x) ^ 2 + max(x, 1 / j) d(x)\n")
    module = parse_bytes(text.encode(), "<t>")
    terms = [module.program.body, module.items[0].body]
    terms += [module.program.body.body, module.program.body.body.body]
    for t in terms:
        assert loops.size(t) == _count(t) > 1
