"""The printer (langur.syntax.printer): exact texts for hand-built terms, and round trips.

* surface: ``parse_term(print_term(t)) == t`` for random surface terms, with random layout;
* core: ``desugar(parse(print_core(t))) == t`` for random core terms (no diffeos, variable-free
  conditions) and for completed conditions, through ``langur.frontend.core_term_from_text``;
* programs: every example loaded, printed with ``print_program`` and loaded again gives the
  same core program (body, variables, box).

Expected strings are written by hand from the grammar's precedences (LANGUAGE.md §6).
"""

from fractions import Fraction

import pytest
from grammar_strategies import module_texts, term_texts
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from paths import DEGENERATE, EXAMPLES

from langur import core as C
from langur.core import Add, Const, Diffeo, IfDiffeo, IfGe0, InverseBranch, Let, Mul, Param, Pow, Prim, Var
from langur.primitives import PRIMITIVES
from langur.syntax import folding
from langur.syntax.parser import parse_module, parse_term
from langur.syntax.printer import decimal, print_core, print_diffeo, print_program, print_term

x, y, a, b = Var("x"), Var("y"), Param("a"), Param("b")


def k(v):
    return Const(Fraction(v))


# ---------------------------------------------------------------------------------------------
# Exact texts.


@pytest.mark.parametrize(
    "value, text",
    [
        (Fraction(0), "0"),
        (Fraction(5), "5"),
        (Fraction(1, 2), "0.5"),
        (Fraction(1, 1000), "0.001"),
        (Fraction(123, 8), "15.375"),
        (Fraction(1, 3), None),
        (Fraction(1, 10**40), "1e-40"),
        (Fraction(10**30), "1e30"),
        (Fraction(12345, 10**30), "12345e-30"),
    ],
)
def test_decimal(value, text):
    assert decimal(value) == text
    if text is not None:
        assert parse_term(text).value == value  # the text reads back exactly


@pytest.mark.parametrize(
    "term, text",
    [
        (k(Fraction(1, 3)), "(1 / 3)"),
        (k(Fraction(-1, 2)), "-0.5"),
        (Const("pi"), "pi"),
        (C.sub(x, a), "x - a"),
        (C.sub(x, C.sub(y, a)), "x - (y - a)"),
        (C.sub(C.sub(x, y), a), "x - y - a"),
        (C.div(x, Mul(y, a)), "x / (y * a)"),
        (Mul(C.div(x, y), a), "x / y * a"),
        (Pow(Add(x, k(1)), Fraction(2)), "(x + 1) ^ 2"),
        (Pow(x, Fraction(-1)), "x ^ -1"),
        (Pow(x, Fraction(1, 3)), "x ^ (1 / 3)"),
        (Pow(k(-2), Fraction(2)), "(-2) ^ 2"),
        (C.neg(Pow(x, Fraction(2))), "-x ^ 2"),
        (Pow(C.neg(x), Fraction(2)), "(-x) ^ 2"),
        (C.neg(k(2)), "-1 * 2"),  # not "-2": that is the literal Const(-2)
        (C.neg(C.neg(x)), "-(-x)"),
        (Mul(x, k(Fraction(1, 3))), "x * (1 / 3)"),
        (Add(x, k(-2)), "x + -2"),
        (Prim("exp", C.neg(Mul(x, x))), "exp(-(x * x))"),
        (IfGe0(C.sub(a, k(1)), x, k(0)), "ifge0 a - 1 then x else 0"),
        (Add(k(1), Let("z", a, Mul(Param("z"), x))), "1 + (let z = a in z * x)"),
        (Let("z", Let("w", a, Param("w")), Param("z")), "let z = (let w = a in w) in z"),
        (
            IfGe0(a, IfGe0(b, k(1), k(2)), IfGe0(b, k(3), k(4))),
            "ifge0 a then (ifge0 b then 1 else 2) else ifge0 b then 3 else 4",
        ),
        (C.Call("m", "f", (x, a)), "m.f(x, a)"),
    ],
)
def test_print_core_exact(term, text):
    assert print_core(term) == text


def _completed(cond, v, inverse):
    return Diffeo((v,), (cond,), ("u0",), (InverseBranch((inverse,)),), solved_for=v)


def test_ifdiffeo_prints_its_condition():
    psi = _completed(C.sub(x, a), "x", Add(Var("u0"), a))
    assert print_core(IfDiffeo(psi, k(1), k(0))) == "[x - a >= 0]"  # a bracket prints as one
    assert print_core(IfDiffeo(psi, x, k(0))) == "ifge0 x - a then x else 0"
    named = Diffeo(
        ("x", "y"),
        (Add(x, y), y),
        ("u", "v"),
        (InverseBranch((C.sub(Var("u"), Var("v")), Var("v"))),),
        name="rot",
    )
    t = IfDiffeo(named, x, k(0))
    assert print_core(t) == "ifge0 x + y then x else 0"  # without a declaration: the condition
    assert print_core(t, {named: "rot"}) == "ifge0 rot(x, y;) then x else 0"


def test_print_diffeo():
    psi = Diffeo(
        ("x",), (C.sub(Pow(x, Fraction(2)), a),), ("u0",),
        (InverseBranch((Pow(Add(Var("u0"), a), Fraction(1, 2)),), (Add(Var("u0"), a),)),
         InverseBranch((C.neg(Pow(Add(Var("u0"), a), Fraction(1, 2))),), (Add(Var("u0"), a),))),
        solved_for="x",
    )  # fmt: skip
    assert print_diffeo(psi) == (
        "completed for x: (x; a) ↦ (x ^ 2 - a); "
        "inverse (u0) ↦ ((u0 + a) ^ 0.5) where u0 + a >= 0 | (-(u0 + a) ^ 0.5) where u0 + a >= 0"
    )
    rot = Diffeo(("x", "y"), (Add(Add(x, y), Param("c")), y), ("u", "v"),
                 (InverseBranch((C.sub(C.sub(Var("u"), Var("v")), Param("c")), Var("v"))),), name="half_plane",
                 nonzero=(Param("c"),))  # fmt: skip
    assert print_diffeo(rot) == (
        "declared half_plane: (x, y; c) ↦ (x + y + c, y); inverse (u, v) ↦ (u - v - c, v); needs c ≠ 0"
    )


def test_printing_is_iterative():
    t = x
    for _ in range(100_000):
        t = Add(t, k(1))
    text = print_core(t)
    assert text.startswith("x + 1 + 1") and text.count("+") == 100_000
    t = x
    for _ in range(5_000):
        t = C.neg(t)
    assert print_core(t) == "-(" * 4_999 + "-x" + ")" * 4_999  # deeper than the recursion limit


# ---------------------------------------------------------------------------------------------
# Surface round trips.

EXAMPLE_FILES = sorted(EXAMPLES.glob("*.lgr")) + sorted(DEGENERATE.glob("*.lgr"))


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(term_texts())
def test_surface_term_round_trip(pair):
    t, text = pair
    assert parse_term(text) == t
    assert parse_term(print_term(t)) == t


@settings(max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(module_texts())
def test_surface_module_round_trip(pair):
    m, text = pair
    assert parse_module(text) == m


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: p.name)
def test_example_surface_round_trip(path):
    from langur.syntax.printer import print_module_surface

    m = parse_module(path.read_text())
    assert parse_module(print_module_surface(m)) == m


# ---------------------------------------------------------------------------------------------
# Core round trips through the desugarer (langur.frontend).

frontend = pytest.importorskip("langur.frontend")

VARIABLES = ("x", "y")
PARAMS = ("a", "b")
LETS = ("z", "w")

terminating = st.builds(lambda m, e: Fraction(m, 10**e), st.integers(-(10**6), 10**6), st.integers(0, 4))


@st.composite
def core_terms(draw, depth=4, lets=(), variable_free=False):
    """Random core terms as the desugarer builds them: no diffeos, variable-free conditions and
    let-bounds, terminating literals (``Const(1/3)`` prints as ``(1 / 3)``, which desugars to
    ``1 · 3^-1``: same value, another tree), sums and products with their 0s and 1s folded
    (``syntax/folding.py``: the desugarer builds no ``x * 1``, ``t + 0``, ``t - 0``)."""
    leaves = [
        st.builds(Const, terminating),
        st.just(Const("pi")),
        st.sampled_from([Param(p) for p in PARAMS + lets]),
    ]
    if not variable_free:
        leaves.append(st.sampled_from([Var(v) for v in VARIABLES]))
    leaf = st.one_of(*leaves)
    if depth == 0 or draw(st.integers(0, 3)) == 0:
        return draw(leaf)
    sub = core_terms(depth - 1, lets, variable_free)
    kind = draw(st.sampled_from(["add", "mul", "sub", "div", "neg", "prim", "pow", "if", "let"]))
    if kind == "add":
        return folding.plus(draw(sub), draw(sub))
    if kind == "mul":
        return folding.times(draw(sub), draw(sub))
    if kind == "sub":
        return folding.minus(draw(sub), draw(sub))
    if kind == "div":
        return folding.divided(draw(sub), draw(sub))
    if kind == "neg":
        return folding.negated(draw(sub))
    if kind == "prim":
        return Prim(draw(st.sampled_from(PRIMITIVES)), draw(sub))
    if kind == "pow":
        exponent = draw(
            st.one_of(terminating, st.sampled_from([Fraction(1, 3), Fraction(-2, 3), Fraction(-1)]))
        )
        return folding.power(draw(sub), exponent)
    if kind == "if":
        cond = draw(core_terms(depth - 1, lets, variable_free=True))
        return IfGe0(cond, draw(sub), draw(sub))
    name = draw(st.sampled_from(LETS))
    bound = draw(core_terms(depth - 1, lets, variable_free=True))
    body = draw(core_terms(depth - 1, tuple(set(lets) | {name}), variable_free))
    return Let(name, bound, body)


def redesugar(t, **kw):
    return frontend.core_term_from_text(print_core(t), variables=VARIABLES, params=PARAMS, **kw)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(core_terms())
def test_core_round_trip(t):
    assert redesugar(t) == t, print_core(t)


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(core_terms())
def test_core_as_an_operand_round_trip(t):
    # check --fix splices print_core(t, operand=True) into any position: as the base of a power in a
    # product it reads back as the whole term in parentheses does (an atom bare, anything else wrapped)
    text = print_core(t, operand=True)
    read = [frontend.core_term_from_text(f"2 * {u} ^ 3", variables=VARIABLES, params=PARAMS)
            for u in (text, f"({print_core(t)})")]
    assert read[0] == read[1], text


@pytest.mark.parametrize(
    "cond",
    [C.sub(x, a), C.sub(a, x), C.sub(y, Add(x, a)), C.sub(Add(x, y), k(1)), C.sub(Pow(x, Fraction(2)), a)],
    ids=["x-a", "a-x", "y-(x+a)", "x+y-1", "x^2-a"],
)
def test_core_round_trip_completed_conditions(cond):
    from langur.syntax.diffeo import complete

    psi = complete(cond, VARIABLES, ())
    t = Mul(IfDiffeo(psi, Add(x, k(1)), k(0)), Let("z", a, IfGe0(Param("z"), y, k(2))))
    assert redesugar(t) == t, print_core(t)


@pytest.mark.parametrize(
    "path", [p for p in EXAMPLE_FILES if "\nint " in "\n" + p.read_text()], ids=lambda p: p.name
)
def test_program_round_trip(path):
    loaded = frontend.load(str(path))
    text = print_program(loaded.program, loaded.params)
    again = frontend.load_text(text, str(path.with_name("printed.lgr")))
    assert again.program.variables == loaded.program.variables
    assert again.program.body == loaded.program.body
    assert again.program.box == loaded.program.box
    assert again.params == loaded.params


def test_a_nested_int_prints_back_to_itself():
    # parsed only to be rejected (T208), but printable like any surface term
    from langur.syntax.parser import parse_term
    from langur.syntax.printer import print_term

    for text in ["2 * int ([0, 1]) y d(y)", "int y ^ 2 d(y)", "int ([0, a], [b, 1]) y * z d(y, z) + 1"]:
        t = parse_term(text)
        assert parse_term(print_term(t)) == t
