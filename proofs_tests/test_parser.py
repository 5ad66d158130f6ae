"""The parser of `.lgr` files (LANGUAGE.md §6): every form, exact spans, exact error codes and
positions, encodings, huge and deeply nested inputs.

Expected ASTs are written by hand from the grammar of LANGUAGE.md §6; expected positions are
counted by hand in the source strings (1-based lines and columns, end column exclusive).
"""

import operator
import random
import sys
import time
from fractions import Fraction

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from paths import DEGENERATE, EXAMPLES

from langur.diagnostics import LangurError, Span
from langur.frontend import load_text
from langur.syntax.parser import MAX_DEPTH, parse_bytes, parse_module, parse_term
from langur.syntax.surface import (
    Apply,
    BinOp,
    DefArg,
    DefDecl,
    DiffeoApp,
    DiffeoDecl,
    Ident,
    IfCmp,
    IfGe0S,
    ImportItem,
    ImportName,
    Interval,
    Iverson,
    LetIn,
    Name,
    Neg,
    Num,
    ParamDecl,
    ParamItem,
    ProgramS,
)

EXAMPLE_FILES = sorted(EXAMPLES.glob("*.lgr")) + sorted(DEGENERATE.glob("*.lgr"))


def N(v):
    return Num(Fraction(v))


x, y, a, b = Name("x"), Name("y"), Name("a"), Name("b")


def I(name):
    return Ident(name)


def err(fn, text):
    with pytest.raises(LangurError) as e:
        fn(text)
    (d,) = e.value.diagnostics
    return d


# ---------------------------------------------------------------------------------------------
# Every shipped example parses.


def test_examples_exist():
    assert len(EXAMPLE_FILES) >= 14


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_every_example_parses(path):
    m = parse_bytes(path.read_bytes(), str(path))
    assert m.path == str(path)
    # files with `int` have a program; the def-only modules do not
    assert (m.program is not None) == ("\nint " in "\n" + path.read_text())


def test_renderer_example_structure():
    m = parse_module((EXAMPLES / "renderer.lgr").read_text(), "renderer.lgr")
    imp, par, dif = m.items
    assert imp == ImportItem(I("shader"), (ImportName(I("shade"), None),))
    assert par == ParamItem((ParamDecl(I("c"), Fraction(-1)),))
    assert dif == DiffeoDecl(
        I("half_plane"),
        (I("x"), I("y")),
        (I("c"),),
        (BinOp("+", BinOp("+", x, y), Name("c")), y),
        (I("u"), I("v")),
        (BinOp("-", BinOp("-", Name("u"), Name("v")), Name("c")), Name("v")),
    )
    assert m.program == ProgramS(
        (Interval(N(0), N(1)), Interval(N(0), N(1))),
        IfGe0S(DiffeoApp("half_plane", (x, y), (Name("c"),)), Apply("shade", (x, y, Name("c"))), N(0)),
        (I("x"), I("y")),
    )


def test_risk_example_defaults_are_exact():
    m = parse_module((EXAMPLES / "risk.lgr").read_text())
    imp, par = m.items
    assert imp.names == (ImportName(I("normal"), None), ImportName(I("window"), None))
    assert [(d.name.name, d.default) for d in par.decls] == [("a", -1), ("b", 4), ("mu", 1)]
    assert m.program.domain == (Interval(Neg(N(10)), N(10)),)


def test_densities_example():
    m = parse_module((EXAMPLES / "densities.lgr").read_text())
    normal, window = m.items
    assert normal.args == (DefArg(I("x"), "var"), DefArg(I("m"), "param"))
    # exp(-0.5 * ((x - m) / 5) ^ 2): ^ binds tighter than *, unary minus applies to 0.5
    assert normal.body == Apply(
        "exp",
        (BinOp("*", Neg(N(Fraction(1, 2))), BinOp("^", BinOp("/", BinOp("-", x, Name("m")), N(5)), N(2))),),
    )
    assert window.body == Iverson((a, x, b), ("<=", "<="))


# ---------------------------------------------------------------------------------------------
# Every form of §6.


def test_empty_and_comment_only_files_are_empty_modules():
    for text in ["", "\n\n", "# nothing\n", "   # a\n\t# b"]:
        m = parse_module(text)
        assert m.items == () and m.program is None


def test_param_forms():
    m = parse_module("param a = -1, b = 4, mu\nparam t=0.25")
    assert m.items == (
        ParamItem(
            (ParamDecl(I("a"), Fraction(-1)), ParamDecl(I("b"), Fraction(4)), ParamDecl(I("mu"), None))
        ),
        ParamItem((ParamDecl(I("t"), Fraction(1, 4)),)),
    )


def test_diffeo_forms():
    m = parse_module(
        "diffeo s(x;) = (x + 1) inverse (u) = (u - 1)\ndiffeo r(x, y; c, e) = (x, y) inverse (u, v) = (u, v)"
    )
    s, r = m.items
    assert (
        s.params == () and s.forward == (BinOp("+", x, N(1)),) and s.inverse == (BinOp("-", Name("u"), N(1)),)
    )
    assert r.params == (I("c"), I("e")) and r.inputs == (I("u"), I("v"))


def test_def_forms():
    m = parse_module("def one() = 1\ndef f(x: var, a: param) = x * a")
    assert m.items == (
        DefDecl(I("one"), (), N(1)),
        DefDecl(I("f"), (DefArg(I("x"), "var"), DefArg(I("a"), "param")), BinOp("*", x, a)),
    )


def test_import_forms():
    (item,) = parse_module("from m import f as g, h").items
    assert item == ImportItem(I("m"), (ImportName(I("f"), I("g")), ImportName(I("h"), None)))


def test_program_with_and_without_domain():
    p = parse_module("int x d(x)").program
    assert p == ProgramS(None, x, (I("x"),))
    p = parse_module("int ([0, 1], [a, b + 1]) x * y d(x, y)").program
    assert p.domain == (Interval(N(0), N(1)), Interval(a, BinOp("+", b, N(1))))
    # a parenthesized integrand is not a domain; an Iverson bracket in parentheses neither
    assert parse_module("int (x + 1) * 2 d(x)").program.body == BinOp("*", BinOp("+", x, N(1)), N(2))
    assert parse_module("int ([x >= 0]) d(x)").program == ProgramS(
        None, Iverson((x, N(0)), (">=",)), (I("x"),)
    )
    assert parse_module("int ([0, 1]) ([x >= 0]) d(x)").program.domain == (Interval(N(0), N(1)),)


def test_let_extends_right():
    assert parse_term("let z = 1 in z + 2") == LetIn("z", N(1), BinOp("+", Name("z"), N(2)))
    assert parse_term("1 + (let z = 2 in z) * 3") == BinOp(
        "+", N(1), BinOp("*", LetIn("z", N(2), Name("z")), N(3))
    )


def test_let_is_not_an_operand_without_parentheses():
    d = err(parse_term, "1 + let z = 2 in z")
    assert (d.code, d.span.line, d.span.col) == ("E102", 1, 5)
    assert d.message.startswith("unexpected 'let'; expected an operand")  # not "a term": 'let' is one
    assert "parentheses" in d.message


def test_ifge0_condition_forms():
    # a declared diffeo applied: the semicolon makes it a DiffeoApp
    assert parse_term("ifge0 h(x, y; c) then 1 else 0") == IfGe0S(
        DiffeoApp("h", (x, y), (Name("c"),)), N(1), N(0)
    )
    assert parse_term("ifge0 h(x;) then 1 else 0").cond == DiffeoApp("h", (x,), ())
    # without the semicolon it is a call, i.e. a plain term
    assert parse_term("ifge0 h(x, y) then 1 else 0").cond == Apply("h", (x, y))
    assert parse_term("ifge0 x - a then 1 else 0").cond == BinOp("-", x, a)
    # else extends right; nesting in then needs no parentheses
    assert parse_term("ifge0 x then ifge0 y then 1 else 2 else 3 + 4") == IfGe0S(
        x, IfGe0S(y, N(1), N(2)), BinOp("+", N(3), N(4))
    )


def test_if_cmp():
    assert parse_term("if x + 1 >= a then 1 else 2 * x") == IfCmp(
        BinOp("+", x, N(1)), ">=", a, N(1), BinOp("*", N(2), x)
    )


def test_iverson_chains_and_unicode_comparisons():
    assert parse_term("[a <= x < b]") == Iverson((a, x, b), ("<=", "<"))
    assert parse_term("[a ≤ x ≥ b > y]") == Iverson((a, x, b, y), ("<=", ">=", ">"))


def test_precedence_and_associativity():
    assert parse_term("-x^2") == Neg(BinOp("^", x, N(2)))
    assert parse_term("x^-1") == BinOp("^", x, Neg(N(1)))
    assert parse_term("2^-x^2") == BinOp("^", N(2), Neg(BinOp("^", x, N(2))))
    assert parse_term("x^y^2") == BinOp("^", x, BinOp("^", y, N(2)))
    assert parse_term("a - b - x") == BinOp("-", BinOp("-", a, b), x)
    assert parse_term("a / b / x") == BinOp("/", BinOp("/", a, b), x)
    assert parse_term("a + b * x ^ 2") == BinOp("+", a, BinOp("*", b, BinOp("^", x, N(2))))
    assert parse_term("a * -b") == BinOp("*", a, Neg(b))
    assert parse_term("--x") == Neg(Neg(x))
    assert parse_term("(((x)))") == x


def test_numbers_are_exact():
    assert parse_term("0.5") == N(Fraction(1, 2))
    assert parse_term("1e-3") == N(Fraction(1, 1000))
    assert parse_term("2.5E+2") == N(250)
    assert parse_term(".25") == N(Fraction(1, 4))
    assert parse_term("3.") == N(3)
    assert parse_term("0.1").value == Fraction(1, 10)  # not the binary float 0.1
    assert parse_term("123456789012345678901234567890").value == 123456789012345678901234567890


def test_number_edge_cases():
    assert parse_term("007").value == 7
    assert parse_term("12.5e-2").value == Fraction(1, 8)
    assert parse_term("1e" + "0" * 10_000 + "1").value == 10  # long exponent, small value: fine
    d = err(parse_term, "1e1001")
    assert (d.code, d.span.col, d.span.end_col) == ("E106", 1, 7)
    # The range of doubles, both ends, exactly at the boundary (sys.float_info.max and .min).
    assert parse_term("1.7976931348623157e308").value == Fraction("1.7976931348623157e308")
    assert parse_term("2.2250738585072014e-308").value == Fraction("2.2250738585072014e-308")
    assert parse_term("0e999").value == 0 and parse_term("0.0").value == 0
    for text, what in [("1e999", "too large"), ("1.8e308", "too large"), ("1e-400", "too small"),
                       ("2.2e-308", "too small"), ("9" * 400, "too large")]:
        d = err(parse_term, text)
        assert d.code == "E106" and what in d.message and (d.span.col, d.span.end_col) == (1, 1 + len(text)), text


@settings(max_examples=100, deadline=None)
@given(st.from_regex(r"\A(?:[0-9]{1,12}(?:\.[0-9]{0,8})?|\.[0-9]{1,8})(?:[eE][+-]?[0-9]{1,3})?\Z"))
def test_numbers_agree_with_fractions_parser(text):
    # Fraction's own decimal parser is the independent oracle; doubles bound the range (E106)
    exact = Fraction(text)
    if exact and not Fraction(sys.float_info.min) <= exact <= Fraction(sys.float_info.max):
        assert err(parse_term, text).code == "E106"
    else:
        assert parse_term(text).value == exact


def test_crlf_line_endings():
    m = parse_module("param a = 1\r\nint x\r\n d(x)\r\n", "crlf.lgr")
    assert m.program.variables[0].span == Span("crlf.lgr", 3, 4, 3, 5)


def test_calls_and_pi_are_plain_names():
    assert parse_term("exp(x) + pi + max(a, b) + f()") == BinOp(
        "+", BinOp("+", BinOp("+", Apply("exp", (x,)), Name("pi")), Apply("max", (a, b))), Apply("f", ())
    )


def test_d_is_a_soft_keyword():
    # `d` is a name everywhere except right after the integrand
    p = parse_module("int d * d(x) d(d)").program
    assert p.body == BinOp("*", Name("d"), Apply("d", (x,)))
    assert p.variables == (I("d"),)
    assert parse_module("param d = 1\ndef f(d: var) = d").items[1].args == (DefArg(I("d"), "var"),)


@pytest.mark.parametrize(
    "kw",
    [
        "param",
        "diffeo",
        "inverse",
        "def",
        "from",
        "import",
        "as",
        "int",
        "let",
        "in",
        "ifge0",
        "if",
        "then",
        "else",
        "var",
    ],
)
def test_keywords_are_not_names(kw):
    d = err(parse_term, f"x + {kw}")
    assert d.code in ("E102", "E103")
    d = err(parse_module, f"param {kw} = 1")
    assert (d.code, d.span.col) == ("E102", 7)
    assert f"'{kw}'" in d.message and "expected a name" in d.message


def test_comments():
    m = parse_module("# head\nparam a = 1 # the parameter\nint x # integrand\n d(x) # end")
    assert m.program.body == x


# ---------------------------------------------------------------------------------------------
# Spans.


def test_spans_in_renderer():
    text = (EXAMPLES / "renderer.lgr").read_text()
    m = parse_module(text, "renderer.lgr")
    lines = text.splitlines()
    d = 1 + next(i for i, s in enumerate(lines) if s.startswith("diffeo half_plane"))
    n = 1 + next(i for i, s in enumerate(lines) if s.startswith("int ("))
    # line d: diffeo half_plane(x, y; c) = (x + y + c, y) inverse (u, v) = (u - v - c, v)
    dif = m.items[2]
    assert dif.span == Span("renderer.lgr", d, 1, d, 76)
    assert dif.name.span == Span("renderer.lgr", d, 8, d, 18)
    assert dif.forward[0].span == Span("renderer.lgr", d, 31, d, 40)
    # line n: int ([0, 1], [0, 1]) ifge0 half_plane(x, y; c) then shade(x, y, c) else 0 d(x, y)
    p = m.program
    assert p.span == Span("renderer.lgr", n, 1, n, 82)
    assert p.domain[1].span == Span("renderer.lgr", n, 14, n, 20)
    body = p.body
    assert body.span == Span("renderer.lgr", n, 22, n, 74)
    assert body.cond.span == Span("renderer.lgr", n, 28, n, 47)
    assert body.cond.name_span == Span("renderer.lgr", n, 28, n, 38)
    assert body.then.span == Span("renderer.lgr", n, 53, n, 67)
    assert body.then.name_span == Span("renderer.lgr", n, 53, n, 58)
    assert body.orelse.span == Span("renderer.lgr", n, 73, n, 74)
    assert p.variables[1].span == Span("renderer.lgr", n, 80, n, 81)


def test_spans_cover_parentheses_and_lines():
    t = parse_term("(a + b) *\n  c", "t.lgr")
    assert t.span == Span("t.lgr", 1, 1, 2, 4)  # from '(' to after 'c'
    assert t.left.span == Span("t.lgr", 1, 2, 1, 7)  # a + b, without its parentheses
    t = parse_term("let zz = 1 in zz")
    assert t.name_span == Span("<string>", 1, 5, 1, 7) and t.span == Span("<string>", 1, 1, 1, 17)
    t = parse_term("-x")
    assert t.span == Span("<string>", 1, 1, 1, 3) and t.arg.span == Span("<string>", 1, 2, 1, 3)
    m = parse_module("param a = -1, b\n")
    assert m.items[0].span == Span("<string>", 1, 1, 1, 16)
    assert m.items[0].decls[0].span == Span("<string>", 1, 7, 1, 13)


# ---------------------------------------------------------------------------------------------
# Rejects: code, position, message.


@pytest.mark.parametrize(
    "text, code, line, col, words",
    [
        ("int ([0,1]) (x + ) d(x)", "E102", 1, 18, ["unexpected ')'", "expected an operand"]),
        ("int ([0,1]) ( ) d(x)", "E102", 1, 15, ["unexpected ')'", "expected a term"]),
        ("int x", "E103", 1, 6, ["end of input", "'d'"]),
        ("int x d(x", "E103", 1, 10, ["end of input", "')'"]),
        ("int x d(x) int y d(y)", "E107", 1, 12, ["'int'", "after the program"]),
        ("int x d(x)\nparam a", "E107", 2, 1, ["'param'"]),
        ("param a = @", "E104", 1, 11, ["'@'"]),
        ("int x ! 2 d(x)", "E104", 1, 7, ["'!'"]),
        ("param θ = 1", "E104", 1, 7, ["'θ'"]),
        ("int x +\n\n  then d(x)", "E102", 3, 3, ["'then'", "expected an operand"]),
        ("int ([0, 1) x d(x)", "E102", 1, 11, ["')'", "expected ']'"]),
        ("int [x <= 1 1] d(x)", "E102", 1, 13, ["number '1'", "a comparison", "']'"]),
        ("int f(x; y) d(x)", "E102", 1, 8, ["';'", "condition of ifge0"]),
        ("int ifge0 x then 1 d(x)", "E102", 1, 20, ["'d'", "expected 'else'"]),
        ("def f(x: real) = x", "E102", 1, 10, ["name 'real'", "'var'", "'param'"]),
        ("diffeo f(x) = (x) inverse (u) = (u)", "E102", 1, 11, ["')'", "';'"]),
        ("param a = b", "E102", 1, 11, ["name 'b'", "a number"]),
        ("param a = 1e5000", "E106", 1, 11, ["exponent"]),
        ("int " + "7" * 1001 + " d(x)", "E106", 1, 5, ["too long"]),
        ("from m import", "E103", 1, 14, ["a name"]),
    ],
    ids=lambda v: v[:30] if isinstance(v, str) else None,
)
def test_rejects(text, code, line, col, words):
    d = err(lambda s: parse_module(s, "f.lgr"), text)
    assert (d.code, d.span.path, d.span.line, d.span.col) == (code, "f.lgr", line, col), d.format()
    for w in words:
        assert w in d.message, d.message
    assert d.format().startswith(f"f.lgr:{line}:{col}: error {code} ")


def test_parse_term_rejects():
    assert err(parse_term, "").code == "E103"
    d = err(parse_term, "x 2")
    assert (d.code, d.span.col) == ("E102", 3) and "expected an operator" in d.message
    assert err(parse_term, "x d(x)").code == "E102"


# ---------------------------------------------------------------------------------------------
# Bytes, encodings, size and depth limits.


def test_bom_is_stripped():
    m = parse_bytes(b"\xef\xbb\xbfparam a = 1\nint x d(x)", "bom.lgr")
    assert m.items[0].decls[0].name.span == Span("bom.lgr", 1, 7, 1, 8)
    assert parse_module("\ufeffint x d(x)").program.body == x


def test_non_utf8_bytes_are_E101_at_the_first_bad_byte():
    # 'é' is two bytes but one column: the bad byte is in column 6 of line 2
    d = err(lambda b: parse_bytes(b, "bad.lgr"), b"param a = 1\nint \xc3\xa9\xff d(x)")
    assert (d.code, d.span.line, d.span.col) == ("E101", 2, 6)
    assert "0xff" in d.message
    d = err(lambda b: parse_bytes(b, "bad.lgr"), b"\x80")
    assert (d.code, d.span.line, d.span.col) == ("E101", 1, 1)


def test_empty_bytes():
    m = parse_bytes(b"", "empty.lgr")
    assert m.items == () and m.program is None


def test_ten_megabytes():
    t0 = time.process_time()
    # 10 MB of comments and white space around a program: parses
    big = ("# " + "c" * 98 + "\n") * 100_000 + "int x d(x)\n"
    assert parse_bytes(big.encode(), "big.lgr").program.body == x
    # 10 MB of tokens: a clean error (E108), quickly
    huge = "param " + ", ".join(f"a{i}" for i in range(1_200_000))
    assert len(huge) > 10_000_000
    assert err(parse_module, huge).code == "E108"
    # a 10 MB number literal
    assert err(parse_module, "int " + "9" * 10_000_000 + " d(x)").code in ("E106", "E108")
    assert time.process_time() - t0 < 20


@pytest.mark.parametrize(
    "text",
    [
        "int " + "(" * 100_000 + "x" + ")" * 100_000 + " d(x)",
        "int " + "let a = 1 in " * 20_000 + "a d(x)",
        "int " + "+".join(["x"] * 100_000) + " d(x)",
        "int " + "-" * 100_000 + "x d(x)",
        "int " + "[" * 50_000 + "x",
        "int " + "f(" * 50_000 + "x" + ")" * 50_000 + " d(x)",
        "int " + "2^" * 30_000 + "x d(x)",
        "int " + "ifge0 x then 1 else " * 10_000 + "0 d(x)",
    ],
    ids=["parens", "lets", "sum", "minus", "brackets", "calls", "powers", "ifge0"],
)
def test_deep_nesting_is_clean(text):
    try:
        m = parse_module(text)
    except LangurError as e:
        assert e.diagnostics[0].code in ("E103", "E105", "E108")
    else:
        assert m.program is not None


def test_depth_limit_is_exact():
    ok = "int " + "-" * (MAX_DEPTH - 1) + "x d(x)"  # MAX_DEPTH nodes deep
    assert parse_module(ok).program is not None
    d = err(parse_module, "int " + "-" * MAX_DEPTH + "x d(x)")
    assert (d.code, d.span.col) == ("E105", 5)
    # parentheses alone add no depth
    assert parse_term("(" * 5000 + "x" + ")" * 5000) == x


def test_examples_parse_in_milliseconds():
    texts = [(p.read_text(), str(p)) for p in EXAMPLE_FILES]
    for text, path in texts:  # warm-up (builds the parser once)
        parse_module(text, path)
    t0 = time.process_time()
    for _ in range(10):
        for text, path in texts:
            parse_module(text, path)
    per_file = (time.process_time() - t0) / (10 * len(texts))
    assert per_file < 0.02, per_file


# -- Long chains: parsed iteratively into balanced trees (E105 counts real nesting only) ---------


_OPS = {"+": operator.add, "-": operator.sub, "*": operator.mul, "/": operator.truediv}


def _value(t):
    """The surface term's value, by an explicit stack (an oracle that does not recurse)."""
    out: dict[int, Fraction] = {}
    stack = [(t, False)]
    while stack:
        node, done = stack.pop()
        if isinstance(node, Num):
            out[id(node)] = node.value
        elif isinstance(node, Neg):
            if done:
                out[id(node)] = -out[id(node.arg)]
            else:
                stack += [(node, True), (node.arg, False)]
        elif done:
            a, b = out[id(node.left)], out[id(node.right)]
            out[id(node)] = _OPS[node.op](a, b)
        else:
            stack += [(node, True), (node.left, False), (node.right, False)]
    return out[id(t)]


def _depth(t):
    best, stack = 0, [(t, 1)]
    while stack:
        node, d = stack.pop()
        best = max(best, d)
        for child in (getattr(node, "left", None), getattr(node, "right", None), getattr(node, "arg", None)):
            if child is not None:
                stack.append((child, d + 1))
    return best


@pytest.mark.parametrize("n", [2, 31, 32, 33, 201, 10_000])
@pytest.mark.parametrize("level", ["sum", "product"])
def test_a_long_chain_keeps_its_value_and_balances(n, level):
    rng = random.Random(n)
    ops = ["+", "-"] if level == "sum" else ["*", "/"]
    numbers = [rng.randint(1, 9) for _ in range(n)]
    chosen = [rng.choice(ops) for _ in range(n - 1)]
    text = str(numbers[0]) + "".join(f" {o} {v}" for o, v in zip(chosen, numbers[1:]))
    expected = Fraction(numbers[0])  # left to right, as the grammar reads it
    for o, v in zip(chosen, numbers[1:]):
        expected = _OPS[o](expected, v)
    t = parse_term(text)
    assert _value(t) == expected
    if n <= 32:  # short chains keep the grammar's left-nested shape
        assert _depth(t) == n
    else:
        assert _depth(t) <= 2 + 2 * n.bit_length()
    assert (t.span.col, t.span.end_col) == (1, len(text) + 1)


def test_a_balanced_product_never_moves_a_divisor_into_a_numerator():
    t = parse_term(" * ".join(["x"] * 20) + " / y * z" + " * x" * 20)
    assert isinstance(t, BinOp) and t.op == "/" and t.right == Name("y")


def test_real_nesting_inside_a_long_chain_still_counts():
    deep = "-" * (MAX_DEPTH - 3) + "x"
    assert err(parse_term, " + ".join([deep] * 100)).code == "E105"
    assert parse_term(" + ".join(["-x"] * 100)) is not None


def test_a_ten_thousand_term_sum_loads_as_a_program():
    text = "param a = 0.5\nint ([0, 1]) " + " + ".join(["x * [x <= a]"] * 10_000) + " d(x)\n"
    p = load_text(text, "sum.lgr")
    assert p.program.variables == ("x",)
