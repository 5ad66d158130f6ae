"""The transversality checker (paper Def. 7.2, §7.3; LANGUAGE.md §5): langur.transversality.

Expected classifications come from the paper and from each degenerate example's own comment
(``examples/degenerate/*.lgr``); tangency and triple points are computed by hand below.
"""

from fractions import Fraction

import pytest
import sympy as sp
from paths import DEGENERATE, EXAMPLES

from langur import transversality as tv
from langur.commands._prove import Prover
from langur.core import Add, Diffeo, IfDiffeo, InverseBranch, Mul, Param, Program, Var, const, sub
from langur.frontend import load, load_text
from langur.lint import algebra, classify


def check_file(path, at=None):
    return tv.check_loaded(load(str(path)), at=at)


def check_text(text, at=None, name="t.lgr"):
    return tv.check_loaded(load_text(text, name), at=at, sources={name: text})


def codes(findings):
    return sorted((f.code, f.severity) for f in findings)


# ---------------------------------------------------------------------------------------------
# Hand-built core terms (no front end): what multiplies


def ge(a: str) -> Diffeo:
    """[x ≥ a] in one variable: Ψ̂(x) = x − a, inverse x = a + u0."""
    return Diffeo(
        ("x",),
        (sub(Var("x"), Param(a)),),
        ("u0",),
        (InverseBranch((Add(Param(a), Var("u0")),)),),
        solved_for="x",
    )


def ind(psi):
    return IfDiffeo(psi, const(1), const(0))


def program(body):
    return Program(body, ("x",), ((const(0), const(1)),))


def test_products_of_a_product_and_of_a_sum():
    prod = tv.collect(program(Mul(ind(ge("a")), ind(ge("a")))))
    assert [sorted(p.ids) for p in prod.products] == [[0, 1]]
    summ = tv.collect(program(Add(ind(ge("a")), ind(ge("a")))))
    assert sorted(sorted(p.ids) for p in summ.products) == [[0], [1]]


def test_nesting_and_powers_multiply():
    nested = tv.collect(program(IfDiffeo(ge("a"), ind(ge("b")), const(0))))
    # the outer condition multiplies the inner one (then-branch) and nothing (else-branch 0)
    assert sorted(sorted(p.ids) for p in nested.products) == [[0], [0, 1]]
    from langur.core import Pow, Prim

    squared = tv.collect(program(Pow(ind(ge("a")), Fraction(2))))
    (p,) = squared.products
    assert p.ids == {0} and {i for i, _ in p.squared} == {0}
    exp = tv.collect(program(Prim("exp", ind(ge("a")))))
    assert {i for p in exp.products for i, _ in p.squared} == {0}
    linear = tv.collect(program(Pow(ind(ge("a")), Fraction(1))))
    assert all(not p.squared for p in linear.products)


def test_hand_built_coincidence_and_sum():
    params = {"a": Fraction(1, 2)}
    assert codes(tv.check_program(program(Mul(ind(ge("a")), ind(ge("a")))), params)) == [("X301", "error")]
    assert tv.check_program(program(Add(ind(ge("a")), ind(ge("a")))), params) == []
    # [x ≥ a]·[x ≥ b]: coincident exactly when a = b (LANGUAGE.md §5)
    found = tv.check_program(
        program(Mul(ind(ge("a")), ind(ge("b")))), {"a": Fraction(1, 5), "b": Fraction(3, 5)}
    )
    assert codes(found) == [("X304", "warning")] and "when a = b" in found[0].message


# ---------------------------------------------------------------------------------------------
# The shared examples, classified as their comments say


def test_coincident_is_an_error_pointing_at_both():
    (f,) = check_file(DEGENERATE / "coincident.lgr")
    assert (f.code, f.severity) == ("X301", "error")
    # the second [x >= a] (col 25) is the primary position, the first (col 14) the related one
    assert (f.span.line, f.span.col) == (5, 25)
    assert [(r.line, r.col) for r in f.related] == [(5, 14)]
    assert "5:14" in f.message and "x = a" in f.message and "twice" in f.message


def test_nested_is_an_error():
    (f,) = check_file(DEGENERATE / "nested.lgr")
    assert (f.code, f.severity) == ("X301", "error")
    assert f.span.line == 4 and f.related and f.related[0].line == 4


def test_tangent_is_a_measure_zero_warning_at_the_hand_computed_point():
    # y = x² + a and y = 2x² + a meet where x² = 0: the point (0, a), normals (−2x, 1), (4x, −1)
    # are dependent exactly there.
    (f,) = check_file(DEGENERATE / "tangent.lgr")
    assert (f.code, f.severity) == ("X302", "warning")
    assert "(x, y) = (0, a)" in f.message
    assert "measure zero" in f.message or "null set" in f.message
    assert "Theorem 8.1" in f.message


def test_three_lines_is_a_measure_zero_warning():
    # x = a, y = a and x + y = 2a meet at (a, a): three normals in ℝ² are dependent.
    (f,) = check_file(DEGENERATE / "three_lines.lgr")
    assert (f.code, f.severity) == ("X303", "warning")
    assert "(x, y) = (a, a)" in f.message and len(f.related) == 2


def test_boundary_names_the_bad_set_and_is_an_error_at_it():
    (f,) = check_file(DEGENERATE / "boundary.lgr")  # default theta = 1 lies in the set
    assert (f.code, f.severity) == ("X304", "warning")
    assert "theta ∈ {0, 1}" in f.message
    (g,) = check_file(DEGENERATE / "boundary.lgr", at={"theta": 1.0})
    assert (g.code, g.severity) == ("X305", "error")
    (h,) = check_file(DEGENERATE / "boundary.lgr", at={"theta": 0.0})
    assert (h.code, h.severity) == ("X305", "error") and "x >= 0" in h.message
    assert check_file(DEGENERATE / "boundary.lgr", at={"theta": 0.5}) == []


def test_equal_params_names_the_bad_set_and_is_an_error_at_it():
    (f,) = check_file(DEGENERATE / "equal_params.lgr")
    assert (f.code, f.severity) == ("X304", "warning") and "when a = b" in f.message
    (g,) = check_file(DEGENERATE / "equal_params.lgr", at={"a": 0.3, "b": 0.3})
    assert (g.code, g.severity) == ("X305", "error")
    # a = b = 5: the common jump x = 5 lies outside the domain [0, 1]: no error, the set is named
    (h,) = check_file(DEGENERATE / "equal_params.lgr", at={"a": 5.0, "b": 5.0})
    assert (h.code, h.severity) == ("X304", "warning")


@pytest.mark.parametrize(
    "name",
    [
        "fig1.lgr",
        "fig9.lgr",
        "renderer.lgr",
        "risk.lgr",
        "densities.lgr",
        "shader.lgr",
        "lin_shader.lgr",
        "quad_shader.lgr",
    ],
)
def test_the_other_examples_are_clean(name):
    assert check_file(EXAMPLES / name) == []


def test_def_call_sites_are_the_primary_position():
    # The two calls are one shared subterm once inlined (§9): its condition multiplies itself
    # through the product, reported at the call, with the def body's condition named.
    text = "def w(x: var, a: param) = [x >= a]\nparam a = 0.5\nint ([0, 1]) w(x, a) * w(x, a) d(x)"
    (f,) = check_text(text)
    assert f.code == "X301"
    assert (f.span.line, f.span.col) == (3, 14) and (f.related[0].line, f.related[0].col, f.related[0].end_col) == (3, 14, 31)
    assert "1:27" in f.message and "`w(x, a) * w(x, a)`" in f.message


def test_a_def_called_with_other_arguments_is_not_shared():
    text = "def w(x: var, a: param) = [x >= a]\nparam a = 0.5, b = 0.25\nint ([0, 1]) w(x, a) * w(x, b) d(x)"
    assert [f.code for f in check_text(text)] == ["X304"]  # two conditions, coincident only when a = b


# ---------------------------------------------------------------------------------------------
# Every code on small programs


@pytest.mark.parametrize(
    "text",
    [
        "param t = 0.5\nint ([0, 1]) [x < t]^2 d(x)",  # power
        "param a = 0.5\nint ([0, 1]) exp([x >= a]) d(x)",  # primitive
        "param t = 0.5\nint ([0, 1]) [x >= t] * [x < t] d(x)",  # opposite sides
        "param a = 0.25\nint ([0, 1]) let s = 2*a in [x >= s] * [2*x >= 4*a] d(x)",  # through let
        "param c = 0.1\nint ([0, 1], [0, 1]) [x + y >= c] * [2*x + 2*y - 2*c >= 0] d(x, y)",
        "param a = 0.5\nint ([0, 1]) ifge0 x - a then 0 else (ifge0 a - x then 1 else 0) d(x)",
    ],
)
def test_x301_coincidence(text):
    found = check_text(text)
    assert ("X301", "error") in codes(found)


def test_teg_issue_25_square_of_a_difference():
    # ½∫₀¹([x<a] − [x<t])²: the squares [x<a]², [x<t]² are coincident for every value;
    # the cross term [x<a][x<t] only when a = t.
    found = check_text("param a = 0.3, t = 0.6\nint ([0, 1]) 0.5 * ([x < a] - [x < t])^2 d(x)")
    assert codes(found) == [("X301", "error"), ("X301", "error"), ("X304", "warning")]
    assert "when a = t" in [f for f in found if f.code == "X304"][0].message


def test_summands_do_not_multiply():
    assert check_text("param a = 0.5\nint ([0, 1]) [x >= a] + [x >= a] d(x)") == []


def test_x302_osculating_circles():
    # x²+y² = 1 and (x−a)²+y² = (1−a)² are tangent at (1, 0) for every a (hand computation:
    # the normals (2x, 2y), (2(x−a), 2y) are dependent iff a·y = 0).
    (f,) = check_text(
        "param a = 0.5\nint ([-2, 2], [-2, 2]) [x^2 + y^2 <= 1] * [(x - a)^2 + y^2 <= (1 - a)^2] d(x, y)"
    )
    assert f.code == "X302" and "(x, y) = (1, 0)" in f.message


def test_transverse_circles_are_clean():
    assert (
        check_text(
            "param r = 0.5\nint ([-1, 1], [-1, 1]) [x^2 + y^2 <= r] * [(x - 0.2)^2 + y^2 <= r] d(x, y)"
        )
        == []
    )


def test_x306_and_x305_parameter_coefficient():
    (f,) = check_text("param t = 2\nint ([0, 1]) [t*x >= 1] d(x)")
    assert (f.code, f.severity) == ("X306", "warning") and "t = 0" in f.message
    (g,) = check_text("param t = 2\nint ([0, 1]) [t*x >= 1] d(x)", at={"t": 0.0})
    assert (g.code, g.severity) == ("X305", "error")


def test_x307_primitive_outside_its_domain():
    f, g = sorted(check_text("param a = 1\nint ([-1, 1]) a * log(x) d(x)"), key=lambda f: f.code)
    assert (f.code, f.severity) == ("X307", "warning") and "log(x)" in f.message
    assert (g.code, g.severity) == ("X311", "error")  # undefined on [-1, 0): no integral
    assert check_text("param a = 1\nint ([-1, 1]) if x > 0 then log(x) else 0 d(x)") == []
    assert check_text("int ([0, 1]) log(x + 1) d(x)") == []
    g, h = sorted(check_text("int ([-1, 1]) 1 / x d(x)"), key=lambda f: f.code)
    assert g.code == "X307" and "divides by zero" in g.message
    assert (h.code, h.severity) == ("X311", "error")  # and ∫₋₁¹ dx/x does not exist


def test_x308_static_coincidence_is_harmless():
    (f,) = check_text("int ([0, 1]) [x >= 0.5] * [x >= 0.5] d(x)")
    assert (f.code, f.severity) == ("X308", "warning")


def test_x310_when_sympy_cannot_decide(monkeypatch):
    def undecided(*a, **k):
        raise algebra.Undecided("sympy took longer than 2 s")

    monkeypatch.setattr(classify, "bad_parameters", undecided)
    found = check_text("param a = 0.3, b = 0.6\nint ([0, 1]) [x >= a] * [x >= b] d(x)")
    assert found and {f.code for f in found} == {"X310"}


# ---------------------------------------------------------------------------------------------
# Helpers


def test_describe_set():
    a, b, th = sp.symbols("a b theta", real=True)
    assert algebra.describe_set([{th: sp.Integer(1)}, {th: sp.Integer(0)}]) == "theta ∈ {0, 1}"
    assert algebra.describe_set([{a: b}]) == "a = b"
    assert algebra.describe_set([{a: sp.Integer(0)}, {a: b}]) == "a = 0 or a = b"


def test_vanishes_and_bad_parameters():
    u, a, b = sp.symbols("u a b", real=True)
    assert algebra.vanishes((u + a) ** 2 - u**2 - 2 * a * u - a**2, [u, a])
    assert not algebra.vanishes(u - a, [u, a])
    # (a − b)·u + (a − b)² vanishes identically in u exactly when a = b
    assert algebra.bad_parameters((a - b) * u + (a - b) ** 2, [u], [a, b]) == [{a: b}]


def test_prove_says_whether_the_derivative_is_wrong():
    # coincident.lgr at a = 0.5: D_a ∫₀¹[x ≥ a] dx = −1; the derivative denotation counts the
    # jump twice: −2 (paper §7.3.1).  three_lines.lgr: Def. 7.2 fails on a null set only.
    loaded = load(str(DEGENERATE / "coincident.lgr"))
    (f,) = tv.check_loaded(loaded)
    res = Prover(loaded.program, tv.point_of(loaded.params, {})).prove(f.params)
    assert res["verdict"] == "wrong"
    assert res["directions"]["a"]["d_denotation"] == pytest.approx(-1.0)
    assert res["directions"]["a"]["derivative_denotation"] == pytest.approx(-2.0)
    loaded = load(str(DEGENERATE / "three_lines.lgr"))
    (f,) = tv.check_loaded(loaded)
    res = Prover(loaded.program, tv.point_of(loaded.params, {})).prove(f.params)
    # Def. 7.2 fails on a null set only: the check must not find the derivative wrong (it is
    # -1.5 = D_a⟦p⟧ at a = 1/4); when the engine cannot decide, the reason is reported.
    assert res["verdict"] in ("right", "unknown")
    if res["verdict"] == "unknown":
        assert res["directions"]["a"]["reason"]


@pytest.mark.parametrize(
    "text",
    [
        "param a = 0.5\nint ([0, 1]) min(x, a) * [x >= a] d(x)",
        "param a = 0.5\nint ([0, 1]) abs(x - a)^2 d(x)",
        "param t = 1\nint ([0, 1]) max(t*x, 1) d(x)",
    ],
)
def test_continuous_conditionals_have_no_delta(text):
    # abs/min/max: the branches agree on the zero set, the jump ⟦s⟧ − ⟦r⟧ is 0 there, so Fig. 8's
    # delta term vanishes and nothing is multiplied by it.
    assert check_text(text) == []


def test_parametric_coincidence_in_two_variables():
    text = "param a = 0.5, b = 0.7\nint ([0, 1], [0, 1]) [x + y >= a] * [x + y >= b] d(x, y)"
    (f,) = check_text(text)
    assert (f.code, "when a = b" in f.message) == ("X304", True)
    # at a = b = 0.6 the common line x + y = 0.6 crosses the square: an error, and nothing more
    (g,) = check_text(text, at={"a": 0.6, "b": 0.6})
    assert (g.code, g.severity) == ("X305", "error")
    # at a = b = 5 the line misses the square: the set is named, no error
    (h,) = check_text(text, at={"a": 5.0, "b": 5.0})
    assert (h.code, h.severity) == ("X304", "warning")


def test_three_planes_through_a_line_in_r3():
    # x = a, x + y = 2a and 2x + y = 3a all contain the line x = y = a: their normals (1,0,0),
    # (1,1,0), (2,1,0) are dependent there (Def. 7.2 with a subfamily of 3 ≤ n = 3).
    text = (
        "param a = 0.25\nint ([0, 1], [0, 1], [0, 1]) [x >= a] * [x + y >= 2*a] * [2*x + y >= 3*a] d(x, y, z)"
    )
    (f,) = check_text(text)
    assert (f.code, f.severity) == ("X302", "warning") and "(x, y) = (a, a) (any z)" in f.message
    # three coordinate planes meet at one point transversally; a fourth plane through it does not
    assert (
        check_text("param a = 0.25\nint ([0, 1], [0, 1], [0, 1]) [x >= a] * [y >= a] * [z >= a] d(x, y, z)")
        == []
    )
    (g,) = check_text(
        "param a = 0.25\nint ([0, 1], [0, 1], [0, 1]) [x >= a] * [y >= a] * [z >= a] * "
        "[x + y + z >= 3*a] d(x, y, z)"
    )
    assert g.code == "X303" and "(x, y, z) = (a, a, a)" in g.message


def test_transcendental_parameter_set_decided_at_the_point():
    # sin(x) = a meets the bound x = 1 at a = sin(1), x = 0 at a = 0 (solved); at a = 0 an error
    text = "param a = 0.5\nint ([0, 1]) [sin(x) >= a] d(x)"
    assert check_text(text) == []
    (f,) = check_text(text, at={"a": 0.0})
    assert (f.code, f.severity) == ("X305", "error") and "x >= 0" in f.message


def test_a_double_root_for_every_parameter_is_an_error():
    # issue 19: [t²x² − 2tx + 1 > 0] is [(tx − 1)² > 0]: its zero set x = 1/t is a double root for
    # every t (∂/∂x = 2t(tx − 1) vanishes on it), so no derivative exists: X315, an error (it used
    # to pass `check` with a warning at t = 0 only).  A condition that changes sign is not flagged.
    loaded = load_text("param t = 0.7\nint ([-1, 1]) [t^2 * x^2 - 2*t*x + 1 > 0] d(x)\n")
    codes = {(f.code, f.severity) for f in tv.check_loaded(loaded)}
    assert ("X315", "error") in codes
    fine = load_text("param t = 0.7\nint ([-1, 1]) [t^2 * x^2 - 2*t*x + 0.5 > 0] d(x)\n")
    assert "X315" not in {f.code for f in tv.check_loaded(fine)}


def test_a_kink_under_a_factor_that_vanishes_there_is_no_kink():
    # issue 19: [x + k > 0]·[x + l > 0] on [−1, 1] at k = 1, l = 0: the jump of the first sits on the
    # bound x = −1, but there the second factor [x > 0] is 0 (on a neighbourhood): the integral
    # is ∫₀¹ 1 dx = 1 for every k > 0, constant near 1, so no X305.  With l = 2 the second factor is 1
    # at x = −1 and the kink is real (∫ = 1 + min(k, 1) for l ≥ 1: one-sided slopes 1 and 0).
    loaded = load_text("param k = 1, l = 0\nint ([-1, 1]) [x + k > 0] * [x + l > 0] d(x)\n")
    assert "X305" not in {f.code for f in tv.check_loaded(loaded, at={"k": 1.0, "l": 0.0})}
    assert "X305" in {f.code for f in tv.check_loaded(loaded, at={"k": 1.0, "l": 2.0})}


@pytest.mark.parametrize("weight,vanishes", [
    ("sqrt(x - theta)", True), ("sin(x - theta)", True), ("(x - theta)^2", True), ("x - theta + 1", False)])
def test_a_window_closing_where_the_weight_vanishes_is_no_kink(weight, vanishes):
    # issue 19: ∫_θ^v w(x) dx is 0 for v ≤ θ and W(v) − W(θ) above; its derivative in v jumps at
    # v = θ by w(θ).  For w = sqrt(x − θ), sin(x − θ), (x − θ)² that is 0 — the integral is
    # (2/3)(v − θ)^(3/2), 1 − cos(v − θ), (v − θ)³/3, all C¹ — so no X305; for w = x − θ + 1 the
    # slope jumps from 0 to 1: a kink, X305.  The same in two variables, the window in x and the
    # weight constant in y.
    for text in (f"param theta = 0, v = 0\nint ([theta, v]) {weight} d(x)\n",
                 f"param theta = 0, v = 0\nint ([theta, v], [0, 1]) {weight} d(x, y)\n"):
        found = {f.code for f in tv.check_loaded(load_text(text), at={"theta": 0.0, "v": 0.0})}
        assert ("X305" not in found) == vanishes, (text, found)


def test_a_bound_meeting_where_the_weight_is_nonzero_is_a_kink():
    # ∫₀¹ ∫₀^v w dy dx = max(v, 0)·∫₀¹ w dx: a kink at v = 0 unless ∫ w = 0 on the line y = 0
    loaded = load_text("param theta = 0.5, v = 0\nint ([0, 1], [0, v]) (x - theta)^2 d(x, y)\n")
    assert "X305" in {f.code for f in tv.check_loaded(loaded, at={"theta": 0.5, "v": 0.0})}
    loaded = load_text("param theta = 0, v = 0\nint ([0, 1], [0, v]) (y - theta)^2 d(x, y)\n")
    assert "X305" not in {f.code for f in tv.check_loaded(loaded, at={"theta": 0.0, "v": 0.0})}
