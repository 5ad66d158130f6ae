"""Loop and vector sugar (issue 12): §9's finite loop ``sum i in A..B: t`` / ``prod i in A..B: t``,
unrolled, and small fixed-size vectors ``(a, b, c)`` with ``+ - * /``, ``dot``, ``cross`` and
``.x .y .z .w``, desugared to reals in the one desugaring place.

Values are computed by hand (in the comments) and checked through the exact engine; desugared
forms against the hand-written equivalent program's core term (identical: spans do not count);
every new diagnostic at its line and column; the bound on unrolling on hostile input; the printer
round trip of the new forms."""

from __future__ import annotations

import math
import time
from fractions import Fraction as F

import pytest
from paths import EXAMPLES

from langur import operational
from langur.cli import main
from langur.core import Add, Mul, subterms
from langur.diagnostics import LangurError
from langur.exact import exact_deriv, exact_eval
from langur.frontend import core_term_from_text, load, load_text
from langur.syntax import surface as S
from langur.syntax.loops import MAX_COPIES
from langur.syntax.parser import parse_term
from langur.syntax.printer import print_term


def value(src: str, **at) -> float:
    loaded = load_text(src, "t.lgr")
    return exact_eval(loaded.program, loaded.param_values(at)).value


def deriv(src: str, wrt: str, **at):
    loaded = load_text(src, "t.lgr")
    return exact_deriv(loaded.program, loaded.param_values(at), {wrt: 1}, check=False)


def errors(src: str) -> list[tuple[str, int, int]]:
    """The diagnostics of ``src`` as (code, line, col)."""
    with pytest.raises(LangurError) as e:
        load_text(src, "t.lgr")
    return [(d.code, d.span.line, d.span.col) for d in e.value.diagnostics]


def at(src: str, needle: str, line: int | None = None) -> tuple[int, int]:
    """(line, col) of the first ``needle`` on line ``line`` of ``src`` (1-based; default: the first
    line that has it)."""
    lines = src.splitlines()
    line = line or next(i for i, text in enumerate(lines, 1) if needle in text)
    return line, lines[line - 1].index(needle) + 1


def core(text: str, variables=("x", "y"), params=("a", "b", "c")):
    return core_term_from_text(text, variables, params)


# ----------------------------------------------------------------------------------------------
# Loops: values.


@pytest.mark.parametrize("src, expected", [
    # [x <= 1/4] + [x <= 2/4] + [x <= 3/4] over [0, 1]: 1/4 + 2/4 + 3/4
    ("int ([0, 1]) sum i in 1..3: [x <= i / 4] d(x)", 1.5),
    # the index in an exponent: ∫ 1 + x + x² + x³ = 1 + 1/2 + 1/3 + 1/4
    ("int ([0, 1]) sum i in 0..3: x ^ i d(x)", 25 / 12),
    # ∫ (x + 1)(x + 2)(x + 3) = ∫ x³ + 6x² + 11x + 6 = 1/4 + 2 + 11/2 + 6
    ("int ([0, 1]) prod i in 1..3: (x + i) d(x)", 13.75),
    # the outer index bounds the inner loop: 1 + 2 + 3 copies of 1
    ("int ([0, 1]) sum i in 1..3: sum j in 1..i: 1 d(x)", 6.0),
    # empty ranges: a sum is 0, a product 1
    ("int ([0, 1]) (sum i in 3..1: x) + (prod i in 3..1: x) d(x)", 1.0),
    # bounds are arithmetic of literals: 2 - 1 .. 2 * 2 - 1 is 1..3
    ("int ([0, 1]) sum i in 2 - 1..2 * 2 - 1: x d(x)", 1.5),
    # the index in a condition on constants: copies 1 and 2 give x, copy 3 gives 0: 2 · 1/2
    ("int ([0, 1]) sum i in 1..3: if i <= 2 then x else 0 d(x)", 1.0),
    # the index as a def's param argument: the first example again
    ("def f(x: var, k: param) = [x <= k]\nint ([0, 1]) sum i in 1..3: f(x, i / 4) d(x)", 1.5),
    # a let inside the body rebinds the index's name: ∑ over three copies of 1/2 · 1
    ("int ([0, 1]) sum i in 1..3: let i = 0.5 in i d(x)", 1.5),
    # negative bounds: x^2 · (-1 + 0 + 1) = 0 plus x · 3 → 3/2
    ("int ([0, 1]) sum i in -1..1: (i * x ^ 2 + x) d(x)", 1.5),
])
def test_loop_values(src, expected):
    assert value(src) == pytest.approx(expected, abs=1e-12)


def test_loop_value_does_not_depend_on_an_unused_parameter():
    src = "param a = 0.3\nint ([0, 1]) sum i in 1..3: [x <= i / 4] + 0 * a d(x)"
    for a in (-2.0, 0.3, 7.0):
        assert value(src, a=a) == pytest.approx(1.5, abs=1e-12)


def test_loop_derivative_has_one_delta_per_copy():
    # f(a) = ∑_{i=1..3} ∫₀¹ [x <= a·i/4] = ∑ a·i/4 while a·i/4 ∈ [0, 1]; at a = 1/2: 0.75, and
    # f'(a) = ∑ i/4 = 1.5, all of it from the three jumps (standard AD says 0)
    src = "param a = 0.5\nint ([0, 1]) sum i in 1..3: [x <= a * i / 4] d(x)"
    assert value(src) == pytest.approx(0.75, abs=1e-12)
    d = deriv(src, "a")
    assert d.value == pytest.approx(1.5, abs=1e-12)
    assert d.boundary == pytest.approx(1.5, abs=1e-12) and d.standard_ad == 0


# ----------------------------------------------------------------------------------------------
# Loops: desugared form.


def test_a_loop_is_its_copies_written_out():
    assert core("sum i in 1..3: [x <= i / 4]") == core("[x <= 1 / 4] + [x <= 2 / 4] + [x <= 3 / 4]")
    assert core("prod i in 0..2: (x + i) ^ i") == core("(x + 0) ^ 0 * (x + 1) ^ 1 * (x + 2) ^ 2")
    assert core("sum i in 1..2: sum j in i..2: a * i * j") == core("a * 1 * 1 + a * 1 * 2 + a * 2 * 2")
    assert core("sum i in 5..4: x") == core("0") and core("prod i in 5..4: x") == core("1")


def test_a_long_loop_is_the_balanced_tree_of_the_written_out_sum():
    # the parser regroups a written-out chain of more than 32 operands into a balanced tree; the
    # loop builds the same tree, so 1000 copies nest 10 levels, not 1000
    n = 1000
    looped = core(f"sum i in 1..{n}: x * i")
    assert looped == core(" + ".join(f"x * {i}" for i in range(1, n + 1)))
    depth, stack = 0, [(looped, 1)]
    while stack:
        t, d = stack.pop()
        depth = max(depth, d)
        if isinstance(t, Add | Mul):
            stack += [(t.left, d + 1), (t.right, d + 1)]
    assert depth <= 12  # ⌈log₂ 1000⌉ = 10 levels of +, then x * i


def test_loop_sizes_up_to_the_bound_are_accepted():
    t = core(f"sum i in 1..{MAX_COPIES}: i")
    leaves = [u for u in subterms(t) if not isinstance(u, Add)]
    assert len(leaves) == MAX_COPIES  # every copy is there (the constants 1 … 100000 are distinct)


# ----------------------------------------------------------------------------------------------
# Loops: errors.


def test_a_bound_that_is_a_parameter_is_refused_at_it():
    src = "param n = 3\nint ([0, 1]) sum i in 1..n: x d(x)"
    assert errors(src) == [("T224", *at(src, "n:", 2))]


@pytest.mark.parametrize("src, needle", [
    ("int ([0, 1]) sum i in 1..2.5: x d(x)", "2.5"),  # not an integer
    ("int ([0, 1]) sum i in 1..x: x d(x)", "x:"),  # a variable
    ("int ([0, 1]) (let n = 2 in sum i in 1..n: x) d(x)", "n:"),  # a let-bound name
    ("int ([0, 1]) sum i in 1..3 / 0: x d(x)", "3 / 0"),  # a division by zero
    ("int ([0, 1]) sum i in 1..j: sum j in 1..2: x d(x)", "j:"),  # an index not (yet) bound
])
def test_bounds_that_are_not_integer_constants(src, needle):
    assert errors(src) == [("T224", *at(src, needle))]


def test_a_huge_loop_is_refused_at_once_at_its_range():
    src = "int ([0, 1]) sum i in 1..1000000000: x d(x)"
    start = time.process_time()
    assert errors(src) == [("T225", *at(src, "1..1000000000"))]
    assert time.process_time() - start < 2


@pytest.mark.parametrize("src, code, needle", [
    ("int ([0, 1]) sum i in 1..10^64: x d(x)", "T225", "1..10^64"),
    # a bound of 10^262144 is not even computed (more than 4096 bits)
    ("int ([0, 1]) sum i in 1..((10^64)^64)^64: x d(x)", "T225", "1..("),
    # the same guard protects exponents, which are constant expressions too: this one would have
    # 10^16,777,216 as its value, and one more ^64 would never finish
    ("int ([0, 1]) x ^ ((((10^64)^64)^64)^64) d(x)", "T231", "(((10"),  # the span of the parenthesized term
])
def test_huge_constants_are_refused_without_computing_them(src, code, needle):
    start = time.process_time()
    assert errors(src) == [(code, *at(src, needle))]
    assert time.process_time() - start < 2


def test_nested_loops_past_the_bound_are_refused_once_at_the_inner_loop():
    src = "int ([0, 1]) sum i in 1..1000: sum j in 1..1000: x d(x)"  # 10⁶ copies of x
    start = time.process_time()
    assert errors(src) == [("T225", *at(src, "1..1000: x"))]
    assert time.process_time() - start < 10


def test_a_large_body_counts_its_nodes():
    # 50,000 copies are allowed, but not of a body of 21 nodes (over 500,000 nodes written out)
    src = "int ([0, 1]) sum i in 1..50000: (" + " + ".join(["x"] * 10) + ") d(x)"
    assert [c for c, *_ in errors(src)] == ["T225"]


def test_a_body_error_is_reported_once_not_once_per_copy():
    src = "int ([0, 1]) sum i in 1..50: x * q d(x)"
    assert errors(src) == [("T201", *at(src, "q"))]


@pytest.mark.parametrize("src, code, needle", [
    ("int ([0, 1]) sum x in 1..2: x d(x)", "T212", "x in"),  # the index is a variable's name
    ("int ([0, 1]) sum pi in 1..2: x d(x)", "T211", "pi"),
])
def test_index_names_that_clash(src, code, needle):
    assert errors(src) == [(code, *at(src, needle))]


def test_sum_and_prod_are_reserved_words():
    with pytest.raises(LangurError) as e:
        parse_term("let sum = 1 in sum")
    (d,) = e.value.diagnostics
    assert (d.code, d.span.col) == ("E102", 5) and "reserved word" in d.message
    with pytest.raises(LangurError) as e:
        parse_term("1 + sum i in 1..2: i")  # a loop is a term: parenthesize it in arithmetic
    assert "parentheses" in e.value.diagnostics[0].message


# ----------------------------------------------------------------------------------------------
# Vectors: desugared form (identical to the hand-written reals).


@pytest.mark.parametrize("vec, reals", [
    ("(a, b).x", "a"),
    ("(a, b, c).z", "c"),
    ("(a, b, c, 1).w", "1"),
    ("dot((a, b), (x, y))", "a * x + b * y"),
    ("dot((a, b, c), (x, y, 1))", "a * x + b * y + c * 1"),
    ("((a, b) + (x, y)).y", "b + y"),
    ("((a, b) - (x, y)).x", "a - x"),
    ("(2 * (a, b)).y", "2 * b"),
    ("((a, b) * x).x", "a * x"),
    ("((a, b) / 3).y", "b / 3"),
    ("(-(a, b)).y", "-b"),
    ("cross((a, b, c), (x, y, 1)).x", "b * 1 - c * y"),
    ("cross((a, b, c), (x, y, 1)).y", "c * x - a * 1"),
    ("cross((a, b, c), (x, y, 1)).z", "a * y - b * x"),
    ("let o = (a, b) in o.x + o.y", "a + b"),
    ("let o = (1, 2, 3) in dot(o, o)", "1 * 1 + 2 * 2 + 3 * 3"),
    ("let p = (x, y) in dot(p, p)", "x * x + y * y"),  # a vector's components may mention variables
    ("let k = 2 in ((k, a) * k).x", "let k = 2 in k * k"),  # a real let around a vector
    ("((a, b) + (1, 1)).x ^ 2", "(a + 1) ^ 2"),  # .x binds tighter than ^
    ("sum i in 1..2: (i * (a, b)).y", "1 * b + 2 * b"),  # loops and vectors together
])
def test_vectors_desugar_to_the_reals_written_by_hand(vec, reals):
    assert core(vec) == core(reals)


def test_a_vector_never_reaches_the_core_language():
    src = "param a = 1\nint ([0, 1]) let u = (a, 2 * a) in dot(u, u) * x d(x)"
    # (a² + 4a²) · ∫ x = 5/2 at a = 1
    assert value(src) == pytest.approx(2.5, abs=1e-12)
    # d/da 5a²/2 = 5a = 5
    assert deriv(src, "a").value == pytest.approx(5.0, abs=1e-12)


def test_a_disc_written_with_dot():
    # [|p − c|² <= a/16]: the disc of radius √a/4 inside the unit square, area π a/16, d/da = π/16
    src = ("param a = 1\nint ([0, 1], [0, 1]) let c = (0.5, 0.5) in let p = (x, y) in "
           "[dot(p - c, p - c) <= a / 16] d(x, y)")
    assert value(src) == pytest.approx(math.pi / 16, abs=1e-12)
    assert deriv(src, "a").value == pytest.approx(math.pi / 16, abs=1e-12)


def test_a_let_bound_vector_is_shared_not_copied():
    # v_k = v_(k-1) + v_(k-1): v40 = 2^40 (x, 1), 2^40 leaves written out but 41 lets' worth of
    # distinct nodes; the front end (the inliner's depth measure and expansion) and the exact engine
    # work on the shared form: ∫₀¹ [2^40 x <= 2^39] · 2^40 dx = 2^40 / 2
    lets = "".join(f"let v{k} = v{k - 1} + v{k - 1} in " for k in range(1, 41))
    src = f"int ([0, 1]) let v0 = (x, 1) in {lets}[v40.x <= 2^39] * v40.y d(x)"
    start = time.process_time()
    assert value(src) == 2**39
    assert time.process_time() - start < 20


def test_a_vector_chain_too_deep_once_substituted_is_refused_quickly():
    # each cross adds 3 levels where the vector is used: 190 lets nest 573 levels once written out,
    # past the 400 of T230 (the depth measure and the search for a culprit visit shared nodes once)
    lets = "".join(f"let v{k} = cross(v{k - 1}, (1, 2, 3)) in " for k in range(1, 191))
    src = f"int ([0, 1]) let v0 = (x, 1, 2) in {lets}v190.x * x d(x)"
    start = time.process_time()
    assert errors(src) == [("T230", 1, 1)]
    assert time.process_time() - start < 10


# ----------------------------------------------------------------------------------------------
# Vectors: errors, each at its text.


@pytest.mark.parametrize("src, code, needle", [
    # a vector where a real is expected: the integrand, a condition, a def's argument, a loop's body
    ("int ([0, 1]) (x, 1) d(x)", "T226", "(x, 1)"),
    ("int ([0, 1]) [(x, 1) >= 0] d(x)", "T226", "(x, 1)"),
    ("int ([0, 1]) if (x, 1) < 0 then 1 else 0 d(x)", "T226", "(x, 1)"),
    ("def f(u: var) = u\nint ([0, 1]) f((x, x)) d(x)", "T226", "(x, x)"),
    ("int ([0, 1]) sum i in 1..2: (x, i) d(x)", "T226", "(x, i)"),
    ("int ([0, 1]) x * ((1, 2), 3).x d(x)", "T226", "(1, 2)"),
    ("int ([0, 1]) (x, 1) ^ 2 d(x)", "T226", "(x, 1)"),
    ("int ([0, 1]) x * ((1, 2) * (3, 4)).x d(x)", "T226", "(3, 4)"),  # vector times vector
    ("int ([0, 1]) x * (1 / (3, 4)).x d(x)", "T226", "(3, 4)"),  # a real divided by a vector
    ("int ([0, 1]) (let o = (x, 1) in o) d(x)", "T226", "let"),
    ("def f(x: var) = (x, 1)\nint ([0, 1]) f(x) * 2 d(x)", "T226", "(x, 1)"),  # defs return reals
    # a real where a vector is expected
    ("int ([0, 1]) x * (1 + (x, 2)).x d(x)", "T227", "1 +"),
    ("int ([0, 1]) x * dot(2, (1, 2)) d(x)", "T227", "2,"),
    ("int ([0, 1]) x.x d(x)", "T227", "x.x"),
    # sizes
    ("int ([0, 1]) x * ((1, 2) + (1, 2, 3)).x d(x)", "T228", "(1, 2) +"),
    ("int ([0, 1]) x * dot((1, 2), (1, 2, 3)) d(x)", "T228", "dot"),
    ("int ([0, 1]) x * cross((1, 2), (3, 4)).x d(x)", "T229", "cross"),
    ("int ([0, 1]) x * (1, 2).z d(x)", "T232", "z d"),
    ("int ([0, 1]) x * (1, 2, 3).q d(x)", "T232", "q"),
    ("int ([0, 1]) x * dot((1, 2)) d(x)", "T203", "dot"),
])
def test_vector_misuse_is_located(src, code, needle):
    assert errors(src) == [(code, *at(src, needle))]


def test_a_vector_under_a_let_that_rebinds_its_names_is_refused():
    # o's component is the outer k; under the inner let k, o would silently mean the inner k
    src = "param a = 1\nint ([0, 1]) x * (let k = a in let o = (k, 2) in let k = 5 in o.x) d(x)"
    assert errors(src) == [("T233", *at(src, "o.x", 2))]
    # rebinding a name the vector does not use is fine
    ok = "param a = 1\nint ([0, 1]) x * (let k = a in let o = (k, 2) in let m = 5 in o.x * m) d(x)"
    assert value(ok) == pytest.approx(2.5, abs=1e-12)


def test_dot_and_cross_are_reserved_names():
    assert [c for c, *_ in errors("def dot(x: var) = x\nint ([0, 1]) x d(x)")] == ["T211"]


def test_component_syntax_errors_say_how_components_are_written():
    with pytest.raises(LangurError) as e:
        parse_term("u.0")
    (d,) = e.value.diagnostics
    assert d.code == "E102" and (d.span.line, d.span.col) == (1, 2) and ".x, .y, .z, .w" in d.message


def test_errors_print_path_line_col_code(capsys, tmp_path):
    bad = tmp_path / "bad.lgr"
    bad.write_text("param n = 2\nint ([0, 1]) x * (1, 2).z + (sum i in 1..n: x) d(x)\n")
    assert main(["check", str(bad)]) != 0
    out = capsys.readouterr()
    text = out.out + out.err
    assert f"{bad}:2:25: error T232" in text
    assert f"{bad}:2:42: error T224" in text
    assert "Traceback" not in text


# ----------------------------------------------------------------------------------------------
# Syntax: lexing and the printer round trip.


def test_dot_dot_is_its_own_token():
    # `1..3` is 1, .., 3 (not the numbers `1.` and `.3`); `1.5..2` is 1.5, .., 2
    loop = parse_term("sum i in 1..3: i")
    assert (loop.lo, loop.hi) == (S.Num(F(1)), S.Num(F(3)))
    loop = parse_term("sum i in 1.5..2: i")
    assert (loop.lo, loop.hi) == (S.Num(F(3, 2)), S.Num(F(2)))


@pytest.mark.parametrize("text", [
    "sum i in 1..3: [x <= i / 4]",
    "prod k in -2..n + 1: sum j in 0..k: x ^ j",
    "1 + (sum i in 1..2: i) * 2",
    "sum i in (let a = 1 in a)..(sum j in 1..2: j): -(1, 2).y",
    "(1, 2, 3)",
    "cross(b - a, (x, y, 0) - a).z",
    "(3).x",
    "(1 / 3).y",
    "u.x ^ 2",
    "-u.x",
    "(-u).x",
    "let o = (1, 2) in dot(o, o)",
    "f((1, 2), (sum i in 1..2: i, 3))",
])
def test_printer_round_trip(text):
    t = parse_term(text)
    printed = print_term(t)
    assert parse_term(printed) == t
    assert print_term(parse_term(printed)) == printed


def test_printer_parenthesizes_a_number_before_a_component():
    t = S.Component(S.Num(F(3)), "x")
    assert print_term(t) == "(3).x" and parse_term(print_term(t)) == t


# ----------------------------------------------------------------------------------------------
# The example: a triangle covering a pixel, with vectors.


def test_triangle_example_value_and_derivative():
    loaded = load(str(EXAMPLES / "triangle.lgr"))
    params = loaded.param_values({})
    # a = (ax, 0.1) = (0.2, 0.1), b = (0.9, 0.3), c = (0.4, 0.8), inside the pixel [0, 1]²: the area
    # |cross(b − a, c − a).z| / 2 = (0.7 · 0.7 − 0.2 · 0.2) / 2 = 0.225
    assert exact_eval(loaded.program, params).value == pytest.approx(0.225, abs=1e-12)
    # d/d ax of ((bx − ax)(cy − ay) − (by − ay)(cx − ax)) / 2 = (−(cy − ay) + (by − ay)) / 2 = −0.25
    d = exact_deriv(loaded.program, params, {"ax": 1}, check=False)
    assert d.value == pytest.approx(-0.25, abs=1e-12)
    assert d.boundary == pytest.approx(-0.25, abs=1e-12) and d.standard_ad == 0
    mc = operational.estimate_derivative(loaded, params, {"ax": 1}, samples=100_000, seed=1)
    assert abs(mc.value - (-0.25)) < 4 * mc.stderr
    # the pixel [1, 2] x [0, 1] is beside the triangle: nothing covered, nothing moves
    beside = loaded.param_values({"px": 1})
    assert exact_eval(loaded.program, beside).value == pytest.approx(0, abs=1e-12)
    assert exact_deriv(loaded.program, beside, {"ax": 1}, check=False).value == pytest.approx(0, abs=1e-12)
