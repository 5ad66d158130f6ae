"""Desugaring (LANGUAGE.md §6, the sugar table): each row checked against the core term built by
hand, def inlining against hand-inlined programs, and the printer round trip
``desugar(parse(print(t))) == t``."""

from __future__ import annotations

from fractions import Fraction as F

import pytest
import sympy as sp

from langur.core import (
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Var,
    const,
    neg,
    sub,
    subterms,
)
from langur.diagnostics import LangurError
from langur.frontend import core_term_from_text, load_text
from langur.sympy_bridge import to_sympy
from langur.syntax.diffeo import complete

x, y = Var("x"), Var("y")
ONE, ZERO = const(1), const(0)


def program(src: str):
    return load_text(src, "t.lgr").program


def ind(cond, variables, box=()):
    """[cond ≥ 0] as LANGUAGE.md §6 says: ifge0 cond then 1 else 0, completed over ``variables``."""
    return IfDiffeo(complete(cond, variables, box), ONE, ZERO)


def term(text, variables=("x",), params=("a", "b")):
    return core_term_from_text(text, variables, params)


def test_domain_becomes_indicator_products_and_the_box():
    p = program("param theta = 0.5\nint ([0, 1]) [x <= theta] d(x)")
    lo, hi = ind(x, ("x",)), ind(sub(ONE, x), ("x",))  # [x >= 0]'s x - 0 is x (syntax/folding.py)
    assert p.body == Mul(Mul(lo, hi), ind(sub(Param("theta"), x), ("x",)))
    assert p.box == ((ZERO, ONE),)


def test_domain_with_parametric_bounds_in_two_variables():
    p = program("param a = 0, b = 1\nint ([a, b], [-1, 2 * b]) x * y d(x, y)")
    xy = ("x", "y")
    a, b = Param("a"), Param("b")
    minus1, twob = const(-1), Mul(const(2), b)
    # [y − (−1) ≥ 0] is [y + 1 ≥ 0] (syntax/folding.py: t − (−s) = t + s; bench/history/2026-11-29.md#diag32
    factors = [ind(sub(x, a), xy), ind(sub(b, x), xy), ind(Add(y, const(1)), xy), ind(sub(twob, y), xy)]
    expected = Mul(Mul(Mul(factors[0], factors[1]), factors[2]), factors[3])
    assert p.body == Mul(expected, Mul(x, y))
    assert p.box == ((a, b), (minus1, twob))
    assert [u.psi.solved_for for u in subterms(p.body) if isinstance(u, IfDiffeo)] == ["x", "x", "y", "y"]


@pytest.mark.parametrize("text,cond", [
    ("[x >= a]", sub(x, Param("a"))),
    ("[x > a]", sub(x, Param("a"))),
    ("[x <= a]", sub(Param("a"), x)),
    ("[x < a]", sub(Param("a"), x)),
])
def test_iverson_brackets(text, cond):
    assert term(text) == ind(cond, ("x",))


def test_chains_are_products():
    a, b = Param("a"), Param("b")
    assert term("[a <= x <= b]") == Mul(ind(sub(x, a), ("x",)), ind(sub(b, x), ("x",)))
    assert term("[a <= x < b <= 2]") == Mul(Mul(ind(sub(x, a), ("x",)), ind(sub(b, x), ("x",))),
                                            IfGe0(sub(const(2), b), ONE, ZERO))


def test_if_compare_and_plain_conditionals():
    a = Param("a")
    assert term("if x < a then 1 else x") == IfDiffeo(complete(sub(a, x), ("x",)), ONE, x)
    assert term("if a >= 1 then x else 0") == IfGe0(sub(a, ONE), x, ZERO)
    assert term("ifge0 a then x else 0") == IfGe0(a, x, ZERO)
    assert term("ifge0 x - a then 1 else 0") == ind(sub(x, a), ("x",))
    assert term("[a >= b]") == IfGe0(sub(Param("a"), Param("b")), ONE, ZERO)


def test_abs_min_max():
    a = Param("a")
    d = sub(x, a)
    assert term("abs(x - a)") == IfDiffeo(complete(d, ("x",)), d, neg(d))
    assert term("min(x, a)") == IfDiffeo(complete(sub(x, a), ("x",)), a, x)
    assert term("max(x, a)") == IfDiffeo(complete(sub(x, a), ("x",)), x, a)
    assert term("max(a, b)") == IfGe0(sub(a, Param("b")), a, Param("b"))


def test_arithmetic_sugar():
    assert term("-2") == Const(F(-2))
    assert term("-x") == Mul(const(-1), x)
    assert term("x - 0.5") == Add(x, Mul(const(-1), Const(F(1, 2))))
    assert term("x / a") == Mul(x, Pow(Param("a"), F(-1)))
    assert term("x ^ -0.5") == Pow(x, F(-1, 2))
    assert term("x ^ (1 / 3)") == Pow(x, F(1, 3))
    assert term("-x ^ 2") == Mul(const(-1), Pow(x, F(2)))
    assert term("sqrt(pi)") == Prim("sqrt", Const("pi"))
    assert term("let z = a in z * x") == Let("z", Param("a"), Mul(Param("z"), x))


def test_def_inlining_equals_hand_inlined_program():
    lib = "param b = 1\ndef f(x: var, a: param) = [x >= a] * a\n"
    called = program(lib + "int ([0, 1], [0, 1]) f(y, 2 * b) d(x, y)")
    direct = program("param b = 1\nint ([0, 1], [0, 1]) [y >= 2 * b] * (2 * b) d(x, y)")
    assert called.body == direct.body


def test_var_argument_that_is_not_a_variable_recompletes_the_condition():
    called = program("param a = 0.5\ndef w(x: var, a: param) = [x >= a]\nint ([0, 1]) w(2 * x + 1, a) d(x)")
    direct = program("param a = 0.5\nint ([0, 1]) [2 * x + 1 >= a] d(x)")
    assert called.body == direct.body


def test_declared_diffeo_in_a_def_is_renamed_and_extended_at_the_call():
    decl = "param c = 0\ndiffeo r(p, q; k) = (p + q + k, q) inverse (u, v) = (u - v - k, v)\n"
    called = program(decl + "def g(s: var, t: var, k: param) = ifge0 r(s, t; k) then 1 else 0\n"
                     "int ([0, 1], [0, 1], [0, 1]) g(z, x, c + 1) d(x, y, z)")
    direct = program(decl + "int ([0, 1], [0, 1], [0, 1]) ifge0 r(z, x; c + 1) then 1 else 0 d(x, y, z)")
    assert called.body == direct.body
    (psi,) = {u.psi for u in subterms(direct.body) if isinstance(u, IfDiffeo) and u.psi.name == "r"}
    assert psi.variables == ("x", "y", "z")
    assert psi.forward == (Add(Add(Var("z"), x), Add(Param("c"), ONE)), x, y)


def test_declared_diffeo_in_a_def_rejects_a_non_variable_argument():
    src = ("diffeo r(p; ) = (p) inverse (u) = (u)\ndef g(s: var) = ifge0 r(s; ) then 1 else 0\n"
           "int ([0, 1]) g(2 * x) d(x)")
    with pytest.raises(LangurError) as info:
        load_text(src, "t.lgr")
    (d,) = info.value.diagnostics
    assert d.code == "T217" and (d.span.line, d.span.col) == (3, 14)


def test_every_diffeo_is_over_the_program_variables_after_inlining():
    src = ("param a = 0.5\ndef f(x: var) = [x >= a] * [x ^ 2 <= a]\n"
           "int ([0, 1], [0, 1], [0, 1]) f(y) * f(x + z) d(x, y, z)")
    p = program(src)
    found = [u.psi for u in subterms(p.body) if isinstance(u, IfDiffeo)]
    assert len(found) == 6 + 4
    assert all(psi.variables == ("x", "y", "z") for psi in found)


def test_let_in_a_def_does_not_capture_an_argument():
    p = program("param b = 2\ndef g(x: var, a: param) = let b = 1 in a * b * x\nint ([0, 1]) g(x, b) d(x)")
    lets = [u for u in subterms(p.body) if isinstance(u, Let)]
    assert len(lets) == 1 and lets[0].name != "b"
    assert sp.simplify(to_sympy(lets[0]) - sp.Symbol("b", real=True) * sp.Symbol("x", real=True)) == 0


def test_elaborated_form_keeps_calls_and_inlined_form_has_none(tmp_path):
    (tmp_path / "lib.lgr").write_text("param m = 3\ndef f(x: var) = x * m\n")
    (tmp_path / "main.lgr").write_text("from lib import f as g\nparam a = 1\nint ([0, 1]) g(x) * a d(x)\n")
    from langur.frontend import load

    loaded = load(str(tmp_path / "main.lgr"))
    calls = [u for u in subterms(loaded.main.program.body) if isinstance(u, Call)]
    assert calls == [Call("lib", "f", (x,))]
    assert not any(isinstance(u, Call) for u in subterms(loaded.program.body))
    # the imported def's own param is a parameter of the program, after the main module's
    assert loaded.params == {"a": F(1), "m": F(3)}
    assert loaded.main.imports == {"g": ("lib", "f")}


def test_box_from_bounding_indicators():
    p = program("int [0 <= x <= 1] * [0 <= y <= x] * x d(x, y)")
    assert p.box == ((ZERO, ONE), (ZERO, ONE))
    p = program("param a = 0\nint [x >= a] * [x <= a + 1] * (ifge0 2 - y then 0 else 1) * [y <= 3] * x d(x, y)")
    a = sp.Symbol("a", real=True)
    (xlo, xhi), (ylo, yhi) = p.box
    assert sp.simplify(to_sympy(xlo) - a) == 0 and sp.simplify(to_sympy(xhi) - (a + 1)) == 0
    assert (to_sympy(ylo), to_sympy(yhi)) == (2, 3)
    p = program("param a = 1\nint let z = 2 * a in [0 <= x <= z] * x d(x)")
    assert p.box == ((ZERO, Mul(const(2), Param("a"))),)


def test_periodic_condition_without_domain_uses_the_inferred_box():
    p = program("param t = 0.5\nint [0 <= x <= 10] * [sin(x) >= t] d(x)")
    (psi,) = [u.psi for u in subterms(p.body) if isinstance(u, IfDiffeo) and u.psi.solved_for and
              "sin" in repr(u.psi.forward[0])]
    assert len(psi.branches) == 4


ROUND_TRIP = [
    ("param t = 0.5\nint ([0, 1]) [sin(x) >= t] * x d(x)"),
    ("param r = 0.5\nint ([-1, 1], [-1, 1]) [x^2 + y^2 <= r] * exp(-x) d(x, y)"),
    ("param a = 0.5, t = 2\nint ([0, 1], [0, 2]) [t * x >= 1] * abs(x - y) + max(x, a) / (1 + y) d(x, y)"),
    ("param a = 0.5\nint ([0, 1]) let z = a ^ 2 in if x < z then z else -x d(x)"),
    ("param a = 0.5\nint ([0, 1]) ifge0 a - 0.25 then [exp(x) >= a + 1] else x ^ -1.5 d(x)"),
]


@pytest.mark.parametrize("src", ROUND_TRIP)
def test_printed_core_desugars_to_the_same_term(src):
    from langur.syntax.printer import print_core

    loaded = load_text(src, "t.lgr")
    p = loaded.program
    again = core_term_from_text(print_core(p.body), p.variables, loaded.params, box=p.box)
    assert again == p.body


def test_core_term_from_text_reports_unbound_names():
    with pytest.raises(LangurError) as info:
        core_term_from_text("x + q", ("x",), ("a",))
    assert info.value.diagnostics[0].code == "T201"


def test_condition_calling_a_local_def_is_completed_with_the_call_expanded():
    called = program("param a = 0.5\ndef f(x: var) = [g(x) <= a]\ndef g(x: var) = x ^ 2 + 1\n"
                     "int ([-1, 1]) f(x) d(x)")
    direct = program("param a = 0.5\nint ([-1, 1]) [x ^ 2 + 1 <= a] d(x)")
    assert called.body == direct.body


def test_condition_calling_an_imported_def_is_rejected(tmp_path):
    from langur.frontend import load

    (tmp_path / "lib.lgr").write_text("def g(x: var) = x ^ 2\n")
    (tmp_path / "main.lgr").write_text("from lib import g\nparam a = 0.5\nint ([-1, 1]) [g(x) <= a] d(x)\n")
    with pytest.raises(LangurError) as info:
        load(str(tmp_path / "main.lgr"))
    (d,) = info.value.diagnostics
    assert d.code == "T207" and "own module" in d.message and (d.span.line, d.span.col) == (3, 16)


def test_a_callers_let_does_not_capture_the_callees_module_param(tmp_path):
    # lib's `k` is the program's param k (module params are shared by name); the caller's
    # `let k = 2 * k` binds a different k.  By hand at k = 0.3: the call reads
    # [x <= 0.3] * (x + 0.6) + [x <= 0.6] * 0.3 * x, whose integral over [0, 1] is
    # (0.045 + 0.18) + 0.3 * 0.18 = 0.279.  Capturing the callee's k would give 0.648.
    from langur.denote import denote_program
    from langur.frontend import load
    from langur.operational import estimate_value

    (tmp_path / "lib.lgr").write_text("param k = 0.3\ndef f(x: var, c: param) = [x <= k] * (x + c) + [x <= c] * k * x\n")
    (tmp_path / "main.lgr").write_text("from lib import f\nparam k = 0.3\nint ([0, 1]) let k = 2 * k in f(x, k) d(x)\n")
    loaded = load(str(tmp_path / "main.lgr"))
    exact = denote_program(loaded.program, {"k": F(3, 10)})
    assert exact.expr.subs(sp.Symbol("k", real=True), sp.Rational(3, 10)) == sp.Rational(279, 1000)
    # the Monte Carlo engine links the call instead of inlining it: the same reading
    linked = estimate_value(loaded, {"k": 0.3}, samples=4000, seed=3)
    inlined = estimate_value(loaded.program, {"k": 0.3}, samples=4000, seed=3)
    assert linked == inlined
