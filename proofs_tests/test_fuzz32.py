"""`langur fuzz --poles` and `--huge` (fuzz32, langur/strategies/poles.py): conditions with a moving
pole, products of moving factors, such conditions nested in an `if`, terms spelled with neutral
elements, and programs over huge boxes.  Each kind is drawn with its option and never without it
(seed 1's thousand default programs are main's: test_fuzz30's digest); every drawn program loads
and prints back to its AST; each builder registers the zero sets its condition changes sign on
(the pole's too); one program of each kind has its value and derivatives computed by hand, which
both engines must give; the front end no longer raises an internal error on a product with a
cubed moving factor (`[(y - a)^3 * (y - 1) >= 0]`, found by this round's draws:
bench/history/2026-11-29.md#fuzz32."""

import math
import re
from fractions import Fraction as F

import pytest
from hypothesis import HealthCheck, find, given, settings
from hypothesis.errors import NoSuchExample
from scipy.special import erf
from test_fuzz28 import by_hand_in_both_engines

from langur import exact as api
from langur import strategies as ls
from langur.cli import main
from langur.frontend import load_text
from langur.strategies import conditions as C
from langur.strategies import poles as P
from langur.syntax.parser import parse_module

FIND = settings(max_examples=3000, database=None, deadline=None, suppress_health_check=list(HealthCheck))
FAST = settings(max_examples=60, derandomize=True, database=None, deadline=None,
                suppress_health_check=list(HealthCheck))

_BODY = re.compile(r"^  (.*)$", re.M)


def _body(g) -> str:
    return " ".join(_BODY.findall(g.text)) + " " + " ".join(
        line for line in g.text.splitlines() if line.startswith("def "))


#: Each kind by what its text shows (the body, and a def's).
KINDS = {
    "moving pole": lambda g: bool(re.search(r"\[[^\]]*\) / \([^\]]*[<>]", _body(g))),
    "reciprocal": lambda g: "[1 / (" in _body(g),
    "product of three": lambda g: bool(re.search(r"\[\([^\]]*\) \* \([^\]]*\) \* \([^\]]*[<>]=? 0\]", _body(g))),
    "a factor cubed": lambda g: bool(re.search(r"\) \^ 3 \* \(", _body(g))),
    "nested": lambda g: bool(re.search(r"if \([^\]]*\) [/*] \(.* then .*\[", _body(g))),
    "x * 1": lambda g: " * 1)" in _body(g) or " * 1 " in _body(g) or "(1 * " in _body(g),
    "0 * (1 / pole)": lambda g: "0 * (1 / (" in _body(g),
    "t - -k": lambda g: " - -0.5" in _body(g),
}


@pytest.mark.parametrize("kind", sorted(KINDS))
def test_each_kind_is_drawn_only_with_poles(kind):
    g = find(ls.programs(poles=True), KINDS[kind], settings=FIND)
    g.load()
    with pytest.raises(NoSuchExample):
        find(ls.programs(), KINDS[kind], settings=settings(FIND, max_examples=300))


def test_huge_boxes_are_drawn_only_with_huge():
    def huge(g):
        return "10000000000" in g.text or "1000000 " in g.text or "1000000]" in g.text
    g = find(ls.programs(huge=True), huge, settings=FIND)
    assert g.load().program is not None
    with pytest.raises(NoSuchExample):
        find(ls.programs(wide=True, poles=True), huge, settings=settings(FIND, max_examples=300))


@FAST
@given(ls.programs(poles=True, huge=True))
def test_every_drawn_program_loads_and_round_trips(g):
    loaded = g.load()
    assert loaded.program is not None
    again = parse_module(g.text, "main.lgr")
    assert (again.items, again.program) == (g.module.items, g.module.program)


def _scope(choices, variables=("x", "y")) -> C.Scope:
    """A scope whose draws take ``choices`` in turn (an index or a value of a ``sampled_from``)."""
    it = iter(choices)

    def draw(strategy):
        return next(it)
    return C.Scope(draw, variables, {"a": 0.37, "b": 0.61}, ["a", "b"], poles=True)


def test_a_moving_pole_registers_its_root_and_its_pole():
    # level k = 1/4 (both factors affine then); moving(): first variable x, its coefficient 1, y left
    # out, CMP, P = a, offset 0; the pole y - (b - 0.2)
    s = _scope([F(1, 4), "x", 1, 0, "<=", "a", 0,
                "y", 0, 1, ">=", "b", F(-1, 5), ">="])
    P.ratio(s)
    assert len(s.zero_sets) == 2
    root, pole = s.zero_sets
    # the root: x - a - (y - (b - 0.2))/4 = 0, the pole: y = b - 0.2
    assert root.g({"x": 0.37 + 0.1, "y": 0.61 - 0.2 + 0.4}) == pytest.approx(0, abs=1e-12)
    assert pole.g({"x": 0.0, "y": 0.61 - 0.2}) == pytest.approx(0, abs=1e-12)
    assert root.g({"x": 0.0, "y": 0.41}) != pytest.approx(0)


def test_a_reciprocal_registers_where_it_equals_its_level():
    s = _scope([0, "x", 1, 0, "<=", "a", 0, F(2), ">="])  # 1/(x - a) >= 2: x = a + 1/2
    P.reciprocal(s)
    level, pole = s.zero_sets
    assert level.g({"x": 0.37 + 0.5, "y": 0.0}) == pytest.approx(0, abs=1e-12)
    assert pole.g({"x": 0.37, "y": 0.0}) == pytest.approx(0, abs=1e-12)


A, B, C_ = 0.3, 0.4, 0.25
HAND = {
    # x ≤ a or x > b on [0, 2]: a + 2 − b
    "moving pole, 1-D": ("param a = 0.5, b = 1.3\nint ([0, 2]) [(x - a) / (x - b) >= 0] d(x)\n",
                         0.5 + 2 - 1.3, {"a": 1, "b": -1}),
    # (2x − a − b)/((x − a)(x − b)) ≥ 0 on (a, (a+b)/2] and (b, 2]: 2 − (a + b)/2
    "two poles": ("param a = 0.5, b = 1.3\nint ([0, 2]) [1 / (x - b) + 1 / (x - a) >= 0] d(x)\n",
                  2 - 0.9, {"a": -0.5, "b": -0.5}),
    # y > −b: x ≥ a + c(y + b); y < −b: x ≤ a + c(y + b): 2 − 2ab − c(1 + b²)
    "moving pole, level c": (f"param a = {A}, b = {B}, c = {C_}\n"
                             "int ([-1, 1], [-1, 1]) [(x - a) / (y + b) >= c] d(x, y)\n",
                             2 - 2 * A * B - C_ * (1 + B * B),
                             {"a": -2 * B, "b": -2 * A - 2 * B * C_, "c": -(1 + B * B)}),
    # the sign of (x − a)³(y − b) is that of (x − a)(y − b): 2 + 2ab
    "a factor cubed": ("param a = 0.5, b = 0.5\nint ([-1, 1], [-1, 1]) [(x - a) ^ 3 * (y - b) >= 0] d(x, y)\n",
                       2.5, {"a": 1, "b": 1}),
    # 1/(x − b) ≥ 1 ⇔ b < x ≤ b + 1: on [0, 1], 1 − b
    "reciprocal": ("param b = 0.5\nint ([0, 1]) [1 / (x - b) >= 1] d(x)\n", 0.5, {"b": -1}),
    # x ≥ a, weight x + 1 (x * 1, a - 0, x - -1 folded): (1 − a²)/2 + 1 − a
    "neutral elements": ("param a = 0.3\nint ([0, 1]) [x * 1 - (a - 0) >= 0] * (x - -1) d(x)\n",
                         (1 - A * A) / 2 + 1 - A, {"a": -(A + 1)}),
    # 0 * (1/(x + 2)) is 0 on the box (not folded: 1/(x + 2) is undefined at −2): 1 − a.  With the
    # pole on the jump, [x + 0 * (1 / (x - a)) >= a], the engines disagree (exact −1, Monte Carlo
    # nan: bench/history/2026-11-29.md#fuzz32
    "0 * (1 / pole)": ("param a = 0.3\nint ([0, 1]) [x + 0 * (1 / (x + 2)) >= a] d(x)\n", 1 - A, {"a": -1}),
}


@pytest.mark.parametrize("kind", sorted(HAND))
def test_each_kind_by_hand_in_both_engines(kind):
    text, value, derivs = HAND[kind]
    by_hand_in_both_engines(text, f"{kind}.lgr", value, derivs, 1e-8, 1e-9)


def test_a_huge_box_by_hand_in_the_exact_engine():
    # ∫_{−10⁶}^{a} exp(−x²) dx = √π/2 (1 + erf a); ∂a = exp(−a²)
    text = "param a = 0.5\nint ([-1000000, 1000000]) [x <= a] * exp(-x ^ 2) d(x)\n"
    loaded = load_text(text, path="huge.lgr")
    params = loaded.param_values({})
    assert api.exact_eval(loaded.program, params).value == pytest.approx(math.sqrt(math.pi) / 2 * (1 + erf(0.5)), abs=1e-8)
    assert api.exact_deriv(loaded.program, params, {"a": 1}).value == pytest.approx(math.exp(-0.25), abs=1e-8)


def test_a_cubed_moving_factor_in_one_variable_loads():
    # main: the front end's split asked an implicit root at a probe point where the cube's triple
    # root is a degenerate turning point: TooManyRoots escaped as an internal error (check, eval,
    # deriv).  [(y − a)³(y − 1) ≥ 0] is [y ≤ a] + [y ≥ 1] on [0, 2]: a + 1, ∂a = 1.
    by_hand_in_both_engines("param a = 0.25\nint ([0, 2]) [(y - a) ^ 3 * (y - 1) >= 0] d(y)\n", "cube.lgr",
                            1.25, {"a": 1}, 1e-8, 1e-9)


def test_the_help_names_the_new_options(capsys):
    with pytest.raises(SystemExit):
        main(["fuzz", "--help"])
    text = " ".join(capsys.readouterr().out.split())
    for what in ("--poles", "moving pole", "products of moving factors", "x*1", "0*(1/(x - a))", "--huge",
                 "[-1e10, 1e10]"):
        assert what in text, what

