"""fold31: the desugarer writes out no ``x * 1``, ``1 * -a``, ``y * 0``, ``t + 0``, ``t - 0`` (``syntax/folding.py``).

Each source of them (a comparison with 0, a domain's end 0, a loop's copy at index 0 or 1, vectors
written out, a kink's piece, a def's or a declared diffeo's parameter given 0 or 1) against the core
term written by hand; the folds that are NOT sound stay (``0 · (1/x)``, ``0 · sqrt(x)`` are undefined
where the other factor is); values computed by hand through both engines; a loop's instantiated
copies against the per-copy desugaring with indices of both signs; and no such sub-term in the core
of any example (62 ``- 0`` before).
"""

from __future__ import annotations

import math
from fractions import Fraction

import pytest
from paths import EXAMPLES

from langur import core as C
from langur import operational
from langur.exact import ExactUndefined, exact_deriv, exact_eval
from langur.frontend import clear_load_cache, core_term_from_text, load, load_text
from langur.syntax import folding, template
from langur.syntax.printer import print_core, print_program


def _const(t, v) -> bool:
    return type(t) is C.Const and type(t.value) is Fraction and t.value == v


def artefacts(t) -> list[str]:
    """The sub-terms ``s * 1``, ``1 * s`` (but ``1 / s``), ``s * 0``, ``0 * s``, ``s + 0``, ``0 + s``, ``s - 0``,
    ``s ^ 1`` of ``t`` and of its completed conditions (each distinct node once), printed."""
    out, seen, stack = [], set(), [t]
    while stack:
        u = stack.pop()
        if id(u) in seen:
            continue
        seen.add(id(u))
        if type(u) is C.IfDiffeo:
            stack.append(u.psi.forward[0])
        if type(u) is C.Add and type(u.right) is C.Mul and _const(u.right.left, -1):
            # s - r: the subtraction itself (its (-1)·1 in s - 1 is no artefact), and s - 0
            if _const(u.right.right, 0) or _const(u.left, 0):
                out.append(print_core(u))
            stack.extend((u.left, u.right.right))
            continue
        if type(u) is C.Mul and (_const(u.right, 1) or _const(u.right, 0) or _const(u.left, 0)
                                 or _const(u.left, 1) and not (type(u.right) is C.Pow and u.right.exponent == -1)):
            out.append(print_core(u))
        if type(u) is C.Add and (_const(u.left, 0) or _const(u.right, 0)):
            out.append(print_core(u))
        if type(u) is C.Pow and u.exponent == 1:
            out.append(print_core(u))
        stack.extend(C.children(u))
    return out


def core(text: str, variables=("x", "y"), params=("a", "b")) -> str:
    t = core_term_from_text(text, variables, params)
    assert artefacts(t) == [], print_core(t)
    return print_core(t)


# ---------------------------------------------------------------------------------------------
# Each source, against the term written by hand.


@pytest.mark.parametrize("text, printed", [
    # a comparison with 0: [t >= 0] is ifge0 t (was t - 0); 0 <= t alike; 0 >= t is -t
    ("[x * y - a >= 0]", "[x * y - a >= 0]"),
    ("[0 <= x]", "[x >= 0]"),
    ("[0 >= x + a]", "[-(x + a) >= 0]"),
    # a loop's copies at index 0 and 1: x * 0 is 0 (dropped from the sum), x * 1 is x, x - 0 is x, x ^ 1 is x
    ("sum i in 0..3: x * i", "x + x * 2 + x * 3"),
    ("sum i in 0..2: (x - i) ^ 2", "x ^ 2 + (x - 1) ^ 2 + (x - 2) ^ 2"),
    ("sum i in 0..3: a ^ i * x ^ i", "1 + a * x + a ^ 2 * x ^ 2 + a ^ 3 * x ^ 3"),  # a^0 x^0 is 1: both defined everywhere
    ("prod i in 1..3: x + a * i", "(x + a) * (x + a * 2) * (x + a * 3)"),
    ("sum i in 0..2: [x >= a * i]", "[x >= 0] + [x - a >= 0] + [x - a * 2 >= 0]"),
    ("sum i in -1..1: i * a * x", "-a * x + a * x"),  # (the copy at -1 as before: (-1)·a, printed -a)
    # vectors written out
    ("dot((x, y, 0), (a, 1, 0))", "x * a + y"),
    ("cross((x, y, 0), (1, a, 0)).z", "x * a - y"),
    ("cross((x, y, 0), (1, a, 0)).x + 2", "2"),  # y * 0 - 0 * a is 0
    ("((x, y, 0) - (a, b, 0)).z + x", "x"),  # 0 - 0 is 0
    ("dot(2 * (x, 0), (1, y))", "2 * x"),  # 2 * 0 is 0, 0 * y is 0: dropped
    ("-((0, x)).x + a", "a"),  # -0 is 0
    # min/max/abs: the kink's condition t - s, and a piece where the kink's branch put in is 0
    ("max(x, 0)", "ifge0 x then x else 0"),
    ("[max(x, 0) >= a]", "ifge0 x then [x - a >= 0] else [-a >= 0]"),
    # literals the user wrote fold too (exact): x * 1, t + 0, 1 * t, t / 1, 1 ^ k
    ("x * 1 + 0 + 1 * a + y / 1 + 1 ^ 3", "x + a + y + 1"),
])
def test_each_source_is_folded(text, printed):
    assert core(text) == printed


def test_a_domain_from_0_is_x_not_x_minus_0():
    p = load_text("param a = 0.5\nint ([0, 1], [0, 2]) [x <= a] d(x, y)\n", "d.lgr").program
    lower = [iv.lower.psi.forward[0] for iv in p.domain]
    assert lower == [C.Var("x"), C.Var("y")]
    assert artefacts(p.body) == []


def test_a_def_called_with_1_and_0_inlines_to_x():
    text = "def f(x: var, k: param, c: param) = k * x + c\nparam a = 0.5\nint ([0, 1]) [f(x, 1, 0) >= a] * f(x, a, 0) d(x)\n"
    p = load_text(text, "def.lgr").program
    assert print_program(p).splitlines()[-1] == "int ([0, 1]) [x - a >= 0] * (a * x) d(x)"
    assert artefacts(p.body) == []


def test_a_declared_diffeo_given_1_folds_in_its_instance():
    text = ("param a = 0.5\ndiffeo sh(x; c, k) = (k * x - c) inverse (u) = ((u + c) / k)\n"
            "int ([0, 1]) ifge0 sh(x; a, 1) then 1 else 0 d(x)\n")
    loaded = load_text(text, "sh.lgr")
    lines = print_program(loaded.program, loaded.params).splitlines()
    assert "diffeo sh(x; a) = (x - a) inverse (u0) = (u0 + a)" in lines
    again = load_text("\n".join(lines) + "\n", "again.lgr")  # the printer's round trip
    assert again.program.body == loaded.program.body
    assert exact_eval(loaded.program, {"a": 0.5}).value == pytest.approx(0.5, abs=1e-15)  # ∫₀¹ [x ≥ a] = 1 − a


# ---------------------------------------------------------------------------------------------
# A factor 0 absorbs only what is defined everywhere (0 · (1/0) is undefined).


@pytest.mark.parametrize("text, folds", [
    ("0 * exp(x)", True), ("sin(x * y) * 0", True), ("0 * [x >= a]", True), ("0 * (x + a) ^ 3", True),
    ("0 * (a / 4)", True), ("0 / 4", True), ("0 * atan(x)", True),
    ("0 * (1 / x)", False), ("0 * sqrt(x)", False), ("log(x + 2) * 0", False), ("0 * x ^ (1 / 3)", False),
    ("0 / a", False), ("0 * (a / b)", False), ("(1 / x) ^ 0", False), ("sqrt(x) ^ 0", False),
])
def test_a_zero_factor_absorbs_only_a_term_defined_everywhere(text, folds):
    t = core_term_from_text(text, ("x", "y"), ("a", "b"))
    assert _const(t, 0 if "^ 0" not in text else 1) is folds, print_core(t)


def test_an_undefined_integrand_stays_undefined():
    # 0 · sqrt(x) on [-1, 1]: sqrt is undefined on [-1, 0), so is the product; folding it to 0 would
    # give 0 (both engines say: no value)
    loaded = load_text("int ([-1, 1]) 0 * sqrt(x) d(x)\n", "u.lgr")
    mc = operational.estimate_value(loaded, {}, samples=1000, seed=0)
    assert math.isnan(mc.value)
    with pytest.raises(ExactUndefined, match="sqrt"):
        exact_eval(loaded.program, {})


# ---------------------------------------------------------------------------------------------
# Values: by hand, both engines.


def test_a_loop_from_0_values_by_hand():
    # ∫₀¹ Σ_{i=0..3} i·x·[x ≥ a·i/4] dx = Σ_i i·(1 − (a·i/4)²)/2 at a = 1/2: 63/128 + 120/128 + 165/128;
    # d/da = −Σ_i i³·a/16 = −36·a/16 = −9/8 (the delta at x = a·i/4, weight i·x·i/4)
    loaded = load_text("param a = 0.5\nint ([0, 1]) sum i in 0..3: [x >= a * i / 4] * x * i d(x)\n", "l.lgr")
    assert "* 0" not in print_program(loaded.program)
    assert exact_eval(loaded.program, {"a": 0.5}).value == pytest.approx(348 / 128, abs=1e-14)
    d = exact_deriv(loaded.program, {"a": 0.5}, {"a": 1})
    assert d.value == pytest.approx(-9 / 8, abs=1e-14)
    mc = operational.estimate_derivative(loaded, {"a": 0.5}, {"a": 1.0}, samples=20_000, seed=3)
    assert abs(mc.value - (-9 / 8)) <= 5 * max(mc.stderr, 1e-12)
    v = operational.estimate_value(loaded, {"a": 0.5}, samples=20_000, seed=3)
    assert abs(v.value - 348 / 128) <= 5 * v.stderr


def test_vectors_values_by_hand():
    # p = (x, y, 0), n = (a, 1, 0): [dot(p, n) >= a]·dot(p, p) = [a·x + y ≥ a]·(x² + y²) on [0, 1]²;
    # at a = 1/2 the region is y ≥ (1 − x)/2: ∫₀¹ ∫_{(1−x)/2}^1 (x² + y²) dy dx = 49/72 by hand:
    # ∫₀¹ x²(1 − (1−x)/2) + (1 − ((1−x)/2)³)/3 dx = 5/24 + 1/3 − 1/96 ... = 49/72 − (see below)
    text = "param a = 0.5\nint ([0, 1], [0, 1]) let p = (x, y, 0) in let n = (a, 1, 0) in [dot(p, n) >= a] * dot(p, p) d(x, y)\n"
    loaded = load_text(text, "v.lgr")
    assert artefacts(loaded.program.body) == []
    # ∫₀¹ x²·(1 + x)/2 dx = (1/3 + 1/4)/2 = 7/24;  ∫₀¹ (1 − ((1 − x)/2)³)/3 dx = (1 − 1/32)/3 = 31/96
    hand = 7 / 24 + 31 / 96
    assert exact_eval(loaded.program, {"a": 0.5}).value == pytest.approx(hand, abs=1e-14)
    mc = operational.estimate_value(loaded, {"a": 0.5}, samples=20_000, seed=1)
    assert abs(mc.value - hand) <= 5 * mc.stderr


# ---------------------------------------------------------------------------------------------
# A loop's copies: those built from the template are those desugaring gives, indices of both signs.


@pytest.mark.parametrize("body, lo, hi", [
    ("[x + i/3 >= a] * (x - i) ^ 2", -3, 4),
    ("[x * i - 1 + y >= a / 2] * i", -2, 3),
    ("[y - x^2 >= i/8] * (x + i) + 0 * i", -1, 3),
    ("(i * x + 1) * [x >= a] + i ^ 2 * y", 0, 5),
])
def test_instantiated_copies_are_the_desugared_ones(body, lo, hi):
    text = f"param a = 0.5\nint ([0, 1], [0, 1]) (sum i in {lo}..{hi}: {body}) d(x, y)\n"
    out = []
    for enabled in (True, False):
        template.ENABLED = enabled
        clear_load_cache()
        try:
            out.append(load_text(text, "t.lgr"))
        finally:
            template.ENABLED = True
    new, old = out
    assert new.program == old.program
    assert print_program(new.program) == print_program(old.program)
    assert artefacts(new.program.body) == []
    d = {"a": 1.0}
    x = operational.estimate_derivative(new, {"a": 0.5}, d, samples=200, seed=2)
    y = operational.estimate_derivative(old, {"a": 0.5}, d, samples=200, seed=2)
    assert (x.value, x.regular, x.boundary) == (y.value, y.regular, y.boundary)


# ---------------------------------------------------------------------------------------------
# Every example: no such sub-term in its core (program and defs); the printer reads it back.


EXAMPLE_FILES = sorted(EXAMPLES.rglob("*.lgr"))


@pytest.mark.parametrize("path", EXAMPLE_FILES, ids=lambda p: str(p.relative_to(EXAMPLES)))
def test_no_example_has_one_in_its_core(path):
    loaded = load(str(path))
    found = [s for d in loaded.main.defs.values() for s in artefacts(d.body)]
    if loaded.program is not None:
        found += artefacts(loaded.program.body)
    assert found == []


def test_folding_constructors_are_the_identities_they_claim():
    x, a = C.Var("x"), C.Param("a")
    zero, one = C.Const(Fraction(0)), C.Const(Fraction(1))
    assert folding.plus(x, zero) is x and folding.plus(zero, x) is x
    assert folding.minus(x, zero) is x and folding.minus(zero, x) == C.Mul(C.Const(Fraction(-1)), x)
    assert folding.times(x, one) is x and folding.times(one, a) is a
    assert folding.times(x, zero) is zero and folding.times(zero, C.Pow(x, Fraction(-1))) != zero
    assert folding.negated(one) == C.Const(Fraction(-1)) and folding.negated(zero) is zero
    assert folding.power(x, Fraction(1)) is x and folding.power(one, Fraction(-1)) is one
    assert folding.divided(one, x) == C.Mul(one, C.Pow(x, Fraction(-1)))  # 1 / x as written
    assert folding.times(one, C.Pow(x, Fraction(-1))) == C.Mul(one, C.Pow(x, Fraction(-1)))  # (printed 1 / x)
    assert folding.plus(x, a) == C.Add(x, a) and folding.times(x, a) == C.Mul(x, a)


def test_a_def_returning_1_divided_stays_1_over():
    # scene.lgr: shade(x, y, c) = 1 (shader.lgr), inlined in shade(x, y, c) / h^2: 1 / h ^ 2, not (h ^ 2) ^ -1
    loaded = load(str(EXAMPLES / "scene.lgr"))
    assert "then 1 / h ^ 2 else 0" in print_program(loaded.program)
