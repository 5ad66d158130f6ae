"""The type system (paper Fig. 6 and Fig. 11, LANGUAGE.md §2): accept and reject cases for every
rule, each rejection with its documented T2xx code, located at the offending source text."""

from __future__ import annotations

from fractions import Fraction as F
from pathlib import Path

import pytest

from langur import typesys as ty
from langur.core import (
    Add,
    Diffeo,
    IfDiffeo,
    IfGe0,
    InverseBranch,
    Let,
    Param,
    Program,
    Var,
    const,
    sub,
)
from langur.diagnostics import LangurError
from langur.frontend import load_text
from langur.syntax.diffeo import complete


def codes(src: str) -> list[str]:
    try:
        load_text(src, "t.lgr")
    except LangurError as e:
        return [d.code for d in e.diagnostics]
    return []


def first(src: str):
    with pytest.raises(LangurError) as info:
        load_text(src, "t.lgr")
    return info.value.diagnostics[0]


REJECT = [
    # (code, source, (line, col) of the diagnostic)
    ("T201", "int ([0, 1]) x + q d(x)", (1, 18)),
    ("T201", "def f(x: var) = x * y\nint ([0, 1]) f(x) d(x)", (1, 21)),  # a def body sees only its arguments
    ("T202", "int ([0, 1]) foo(x) d(x)", (1, 14)),
    ("T202", "diffeo s(x; ) = (x) inverse (u) = (u)\nint ([0, 1]) s(x) d(x)", (2, 14)),  # diffeo as a function
    ("T202", "def f(x: var) = x\nint ([0, 1]) ifge0 f(x; ) then 1 else 0 d(x)", (2, 20)),  # def as ⌊Ψ⌋
    ("T202", "int ([0, 1]) asinh(x) d(x)", (1, 14)),  # not a primitive (asin became one: issue 19)
    ("T203", "int ([0, 1]) exp(x, x) d(x)", (1, 14)),
    ("T203", "int ([0, 1]) min(x) d(x)", (1, 14)),
    ("T203", "def f(x: var) = x\nint ([0, 1]) f(x, x) d(x)", (2, 14)),
    ("T203", "diffeo s(x; c) = (x + c) inverse (u) = (u - c)\nint ([0, 1]) ifge0 s(x; ) then 1 else 0 d(x)", (2, 20)),
    ("T203", "int ([0, 1], [0, 1]) x d(x)", (1, 6)),
    ("T204", "param a = 1\ndef f(x: var) = x\nint ([0, 1]) f(a) * x d(x)", (3, 16)),
    ("T205", "def f(x: var, a: param) = x * a\nint ([0, 1]) f(x, x) d(x)", (2, 19)),
    ("T205", "diffeo s(x; c) = (x + c) inverse (u) = (u - c)\nint ([0, 1], [0, 1]) ifge0 s(x; y) then 1 else 0 d(x, y)",
     (2, 33)),
    ("T206", "int ([0, 1]) let z = 2 * x in z d(x)", (1, 22)),
    # (in one variable these are completed on their monotone pieces, issue 18: test_turning_points.py;
    # x + sin(3x) + y + sin(3y) and x^3 - x + y^3 - y by a split along y: test_split_along.py)
    ("T207", "param a = 0.5\nint ([0, 1], [0, 1]) [sin(3 * x) + sin(3 * y) + 1 / (x + y - 1) >= a] d(x, y)", (2, 23)),
    ("T207", "param a = 0.5\nint ([0, 1], [0, 1]) if x^3 - x * y + y^3 - y + 1 / (x - y) >= a then 1 else 0 d(x, y)",
     (2, 25)),
    ("T207", "param a = 0.5\nint ([-1, 1]) [sin(1 / x) >= a] d(x)", (2, 16)),
    ("T209", "int x d(x)", (1, 1)),
    ("T209", "int [0 <= x <= 1] * y d(x, y)", (1, 1)),
    ("T209", "int [0 <= x] * exp(-x) d(x)", (1, 1)),
    ("T210", "int ([0, b]) x d(x)", (1, 10)),
    ("T210", "int ([0, 1]) let z = q in z * x d(x)", (1, 22)),
    ("T210", "def f(x: var, a: param) = x * a\nint ([0, 1]) f(x, q) d(x)", (2, 19)),
    ("T211", "param a, a\nint ([0, 1]) x d(x)", (1, 10)),
    ("T211", "def f(x: var) = x\ndef f(x: var) = 2 * x\nint ([0, 1]) f(x) d(x)", (2, 5)),
    ("T211", "diffeo s(x; ) = (x) inverse (u) = (u)\ndiffeo s(x; ) = (x) inverse (u) = (u)", (2, 8)),
    ("T211", "param f\ndef f(x: var) = x", (2, 5)),
    ("T211", "def f(x: var, x: param) = x", (1, 15)),
    ("T211", "def exp(x: var) = x", (1, 5)),
    ("T211", "int ([0, 1], [0, 1]) 1 d(x, x)", (1, 29)),
    ("T211", "diffeo s(x, x; ) = (x, x) inverse (u, v) = (u, v)", (1, 13)),
    ("T212", "param x\nint ([0, 1]) x d(x)", (2, 18)),
    ("T212", "int ([0, 1]) let x = 1 in x d(x)", (1, 18)),
    ("T212", "param a\ndef f(a: var) = a", (2, 7)),
    ("T212", "diffeo s(x; x) = (x) inverse (u) = (u)", (1, 10)),
    ("T213", "int ([0, 1]) x ^ x d(x)", (1, 18)),
    ("T213", "param a = 2\nint ([0, 1]) x ^ a d(x)", (2, 18)),
    ("T214", "diffeo s(x, y; ) = (x + y) inverse (u, v) = (u, v)", (1, 8)),
    ("T214", "diffeo s(x; ) = (x) inverse (u, v) = (u)", (1, 8)),
    ("T215", "diffeo s(x; c) = (x + c) inverse (u) = (u + c)", (1, 8)),
    ("T215", "diffeo r(x, y; ) = (x + y, y) inverse (u, v) = (u + v, v)", (1, 8)),
    ("T216", "diffeo s(x, y; ) = (x + y, 2 * x + 2 * y) inverse (u, v) = (u, v)", (1, 8)),
    ("T216", "diffeo c(x; ) = (x ^ 3) inverse (u) = (u ^ (1 / 3))", (1, 8)),
    ("T217", ("diffeo r(x, y; ) = (x + y, y) inverse (u, v) = (u - v, v)\n"
              "int ([0, 1], [0, 1]) ifge0 r(x, x; ) then 1 else 0 d(x, y)"), (2, 33)),
    ("T217", "diffeo s(x; ) = (x) inverse (u) = (u)\nint ([0, 1]) ifge0 s(2 * x; ) then 1 else 0 d(x)", (2, 22)),
    ("T217", "param a\ndiffeo s(x; ) = (x) inverse (u) = (u)\nint ([0, 1]) ifge0 s(a; ) then 1 else 0 d(x)", (3, 22)),
    ("T221", "def f(x: var) = g(x)\ndef g(x: var) = f(x)\nint ([0, 1]) f(x) d(x)", None),
    ("T221", "def f(x: var) = f(x)", (1, 1)),
    ("T222", "diffeo s(x; ) = ([x >= 0]) inverse (u) = (u)", (1, 18)),
]


@pytest.mark.parametrize("code,src,where", REJECT, ids=[f"{c}-{i}" for i, (c, _, _) in enumerate(REJECT)])
def test_rejected_with_its_code_and_location(code, src, where):
    d = first(src)
    assert d.code == code, d.format()
    assert d.span is not None and d.span.path == "t.lgr"
    if where is not None:
        assert (d.span.line, d.span.col) == where, d.format()
    assert code in ty.CODES


ACCEPT = [
    "param a = 1\nint ([0, 1]) x * a + pi d(x)",                                   # variable, parameter, constant
    "param a = 1\nint ([0, 1]) let z = 2 * a in let w = z + 1 in w * x d(x)",        # let over params
    "param a = 1\nint ([0, 1]) let a = 2 in a * x d(x)",                            # let may shadow a param
    "param a = 0.5\nint ([0, 1]) ifge0 a - 0.25 then x else 1 d(x)",                # plain conditional
    "param a = 0.5\nint ([0, 1]) ifge0 x - a then x else 1 d(x)",                   # completed condition
    "param a = 0.5\nint ([0, 1]) [x ^ 2 >= a] * exp(x) ^ -1 * x ^ 0.5 d(x)",        # constant exponents
    "param a = 0.5\ndef f(x: var, a: param) = x * a\nint ([0, 1]) f(2 * x + a, a + 1) d(x)",  # argument kinds
    "param a = 0.5\ndef f(x: var, a: param) = x * a\nint ([0, 1]) f(x, 2) d(x)",    # param arg may shadow
    ("param c = 0\ndiffeo r(x, y; c) = (x + y + c, y) inverse (u, v) = (u - v - c, v)\n"
     "int ([0, 1], [0, 1]) ifge0 r(y, x; 2 * c + 1) then 1 else 0 d(x, y)"),         # declared diffeo
    "diffeo e(x; ) = (exp(x)) inverse (u) = (log(u))\nint ([0, 1]) ifge0 e(x; ) then 1 else 0 d(x)",
    "param t = 0.5\nint [0 <= x <= 1] * [0 <= y <= x] * [sin(x) >= t] d(x, y)",     # box from indicators
    "def f(x: var) = g(x) + 1\ndef g(x: var) = x\nint ([0, 1]) f(x) d(x)",          # defs used before declared
    "param a = 1",                                                                  # no program
]


@pytest.mark.parametrize("src", ACCEPT)
def test_accepted(src):
    assert codes(src) == []


def test_all_errors_are_reported_not_just_the_first():
    found = codes("int ([0, 1]) q + r + exp(x, x) + (let z = x in z) d(x)")
    assert found == ["T201", "T201", "T203", "T206"]


def test_nested_int_is_rejected_by_fig11_at_its_text():
    # Fig. 11: a program integrates a term, and a term contains no int.  The parser accepts `int`
    # where a term is expected only so that typing can say so (T208), located at the inner int.
    d = first("int ([0, 1]) (int ([0, 1]) y d(y)) d(x)")
    assert (d.code, d.span.line, d.span.col, d.span.end_col) == ("T208", 1, 15, 34)
    assert "no nested integration" in d.message and "Fig. 11" in d.message
    # the only error: the outer program's other errors are still all reported
    assert codes("int ([0, 1]) int y d(y) d(x)") == ["T208"]
    assert codes("param a = 1\nint ([0, 1]) q * 2 * int ([0, a]) y d(y) d(x)") == ["T201", "T208"]
    # in a def body, a domain bound, a let-bound term: the same diagnostic where it is written
    src = "def f(x: var) = x + int ([0, 1]) y d(y)\nint ([0, 1]) f(x) d(x)"
    d = first(src)
    assert (d.code, d.span.line, d.span.col) == ("T208", 1, 21)
    d = first("int ([0, int ([0, 1]) y d(y)]) x d(x)")
    assert (d.code, d.span.col) == ("T208", 10)
    d = first("int ([0, 1]) (let z = int ([0, 1]) y d(y) in z * x) d(x)")
    assert (d.code, d.span.col) == ("T208", 23)
    # syntax errors inside or around it are still syntax errors, located as before
    assert codes("int ([0, 1]) (int ([0, 1]) y + d(y)) d(x)")[0] == "E102"
    assert codes("int ([0, 1]) x d(x)\nint ([0, 1]) y d(y)") == ["E107"]


def test_every_code_is_documented():
    # the typing codes are documented once, in the catalogue (langur.codes) and docs/CODES.md
    doc = (Path(__file__).resolve().parent.parent / "docs" / "CODES.md").read_text(encoding="utf-8")
    for code in (c for c in ty.CODES if c.startswith("T")):
        assert ty.CODES[code].summary and f"| {code} |" in doc


# --- Fig. 6 / Fig. 11 on core terms ---------------------------------------------------------------

def core_codes(delta, gamma, t):
    out = []
    ty.type_term(frozenset(delta), frozenset(gamma), t, out)
    return [d.code for d in out]


def test_fig6_variable_and_parameter_rules():
    assert core_codes({"x"}, {"a"}, Add(Var("x"), Param("a"))) == []
    assert core_codes({"x"}, {"a"}, Var("y")) == ["T201"]
    assert core_codes({"x"}, {"a"}, Var("a")) == ["T212"]
    assert core_codes({"x"}, {"a"}, Param("b")) == ["T210"]


def test_fig6_conditional_needs_a_variable_free_condition():
    assert core_codes({"x"}, {"a"}, IfGe0(Param("a"), Var("x"), const(0))) == []
    assert core_codes({"x"}, {"a"}, IfGe0(sub(Var("x"), Param("a")), const(1), const(0))) == ["T207"]


def test_fig6_let_needs_a_variable_free_bound_term_and_binds_a_parameter():
    assert core_codes({"x"}, {"a"}, Let("z", Param("a"), Add(Param("z"), Var("x")))) == []
    assert core_codes({"x"}, {"a"}, Let("z", Var("x"), Param("z"))) == ["T206"]
    assert core_codes({"x"}, {"a"}, Let("x", Param("a"), const(1))) == ["T212"]


def test_fig6_diffeomorphic_conditional():
    psi = complete(sub(Var("x"), Param("a")), ("x",))
    assert core_codes({"x"}, {"a"}, IfDiffeo(psi, const(1), const(0))) == []
    assert "T210" in core_codes({"x"}, set(), IfDiffeo(psi, const(1), const(0)))  # a not in Γ
    assert "T217" in core_codes({"y"}, {"a"}, IfDiffeo(psi, const(1), const(0)))  # x not in Δ
    broken = Diffeo(("x",), (Var("x"),), ("u0",), (InverseBranch((Var("x"),)),))  # branch not over inputs
    assert "T201" in core_codes({"x"}, set(), IfDiffeo(broken, const(1), const(0)))


def test_fig11_program():
    psi = complete(sub(Var("x"), Param("a")), ("x",))
    body = IfDiffeo(psi, const(1), const(0))
    good = Program(body, ("x",), ((const(0), const(1)),))
    assert ty.type_program(good, frozenset({"a"})) == []
    assert [d.code for d in ty.type_program(Program(body, ("x",), ()), frozenset({"a"}))] == ["T209"]
    assert "T212" in [d.code for d in ty.type_program(good, frozenset({"a", "x"}))]
    two = Program(const(1), ("x", "x"), ((const(0), const(1)),) * 2)
    assert "T211" in [d.code for d in ty.type_program(two, frozenset())]
    # after inlining every diffeo is over all the program's variables
    wide = Program(body, ("x", "y"), ((const(0), const(1)),) * 2)
    assert "T217" in [d.code for d in ty.type_program(wide, frozenset({"a"}))]
    assert F(1) == 1
