"""Conditions people write (issue 18): ``abs``, ``min`` and ``max`` inside a condition over the
variables are split at their kinks by the desugarer (``Desugarer.conditional``): the condition
becomes nested conditionals on the sign of the kink's argument, each branch completed on its own.

The split must add no derivative of its own: its delta at the kink has weight (then − else) = 0
because abs/min/max are continuous.  Each case checks the exact derivative D⟦p⟧ and the Monte
Carlo one against central finite differences of the value computed here, independently, by
``scipy.integrate.quad`` of a numpy integrand written by hand — at parameters where the
condition's roots lie inside the domain, partly outside, and nowhere.
"""

import math

import pytest
from hypothesis import HealthCheck, given, settings
from scipy.integrate import quad

from langur import frontend
from langur.core import IfDiffeo, children
from langur.ddenote import ddenote_program
from langur.diagnostics import LangurError
from langur.fuzz.compare import compare_text
from langur.fuzz.generate import programs
from langur.operational import estimate_derivative
from langur.syntax.conditionals import MAX_PIECES
from langur.syntax.printer import print_core
from langur.transversality import check_program

H = 1e-4  # central differences of the quadrature: O(h²) ≈ 1e-8 where the value is smooth


def _quad(f, lo, hi, points):
    pts = sorted(p for p in points if lo < p < hi)
    v, err = quad(f, lo, hi, points=pts or None, epsabs=1e-13, epsrel=1e-13, limit=200)
    return v


def window(a):  # ∫₀¹ [|x − a| ≤ 0.2]·eˣ dx
    return _quad(lambda x: float(abs(x - a) <= 0.2) * math.exp(x), 0, 1, [a - 0.2, a + 0.2, a])


def clipped(a):  # ∫₀¹ [max(x, 0.5) − a ≥ 0]·x dx
    return _quad(lambda x: float(max(x, 0.5) - a >= 0) * x, 0, 1, [a, 0.5])


def corner(a):  # ∫₀¹∫₀¹ [min(x, y) − a ≥ 0]·(x + y²) dy dx
    return _quad(lambda x: _quad(lambda y: float(min(x, y) - a >= 0) * (x + y * y), 0, 1, [a, x]), 0, 1, [a])


def square(a):  # ∫₋₁¹∫₋₁¹ [max(|x|, |y|) ≤ a]·(1 + x + x·y²) dy dx
    return _quad(lambda x: _quad(lambda y: float(max(abs(x), abs(y)) <= a) * (1 + x + x * y * y), -1, 1,
                                 [-a, a, 0]), -1, 1, [-a, a, 0])


CASES = [
    # (name, program, value by quadrature, parameter points: roots inside, partly outside, none)
    ("window", "param a = 0.5\nint ([0, 1]) [abs(x - a) <= 0.2] * exp(x) d(x)\n", window, [0.5, 0.1, 0.9, 1.5]),
    ("clipped", "param a = 0.7\nint ([0, 1]) [max(x, 0.5) - a >= 0] * x d(x)\n", clipped, [0.7, 0.3, 1.4]),
    ("corner", "param a = 0.3\nint ([0, 1], [0, 1]) [min(x, y) - a >= 0] * (x + y^2) d(x, y)\n", corner,
     [0.3, 0.8, -0.5]),
    ("square", "param a = 0.5\nint ([-1, 1], [-1, 1]) [max(abs(x), abs(y)) <= a] * (1 + x + x * y^2) d(x, y)\n",
     square, [0.5, 0.9, 1.3]),
]


def _load(text):
    return frontend.load_text(text, "case.lgr")


@pytest.mark.parametrize("name, text, value, points", CASES, ids=[c[0] for c in CASES])
def test_split_derivatives_match_finite_differences(name, text, value, points):
    program = _load(text).program
    for a in points:
        fd = (value(a + H) - value(a - H)) / (2 * H)
        exact = ddenote_program(program, {"a": a}, {"a": 1})
        assert abs(exact.value - fd) <= 1e-6 + exact.error, (a, exact.value, fd)
        mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=4000, seed=3)
        assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-6, (a, mc.value, mc.stderr, fd)


def test_the_split_point_carries_no_delta():
    # ∫₀¹ [|x − a| ≤ 0.2] eˣ dx = e^{a+0.2} − e^{a−0.2} for a in [0.2, 0.8]: D = the same, and the
    # kink x = a (split) adds nothing — the two deltas at a ± 0.2 are the whole boundary term
    program = _load(CASES[0][1]).program
    d = ddenote_program(program, {"a": 0.5}, {"a": 1})
    assert abs(d.value - (math.exp(0.7) - math.exp(0.3))) < 1e-12
    mc = estimate_derivative(program, {"a": 0.5}, {"a": 1}, samples=1000, seed=0)
    assert abs(mc.boundary.value - (math.exp(0.7) - math.exp(0.3))) < 1e-12 and mc.regular.value == 0


def _repeated(t, decided=()):
    """A conditional nested in a branch of a conditional on the same condition (a wasted split)."""
    if isinstance(t, IfDiffeo):
        c = t.psi.condition
        return c in decided or _repeated(t.then, decided + (c,)) or _repeated(t.orelse, decided + (c,))
    return any(_repeated(u, decided) for u in children(t))


def test_the_split_is_visible_in_the_core_program():
    program = _load(CASES[0][1]).program
    assert "ifge0 x - a then [0.2 - (x - a) >= 0] else" in print_core(program.integrand)  # (brackets: fold31)
    # the square: the sign of x and of y is decided once on each path
    square_ = _load(CASES[3][1]).program
    assert "ifge0 x then (ifge0 y then (ifge0 x - y then" in print_core(square_.integrand)
    assert not _repeated(square_.integrand)


def test_roots_merging_at_the_kink_are_reported_not_differentiated():
    # [|x − a| ≤ b]: the window's two ends merge at the kink x = a when b = 0, where the value 2b
    # (b ≥ 0; 0 below) has a corner: the linter reports it and the exact engine says undefined
    text = "param a = 0.5, b = 0.2\nint ([0, 1]) [abs(x - a) <= b] d(x)\n"
    loaded = _load(text)
    assert not [f for f in check_program(loaded.program, loaded.params) if f.severity == "error"]
    at_zero = check_program(loaded.program, loaded.params, at={"a": 0.5, "b": 0.0})
    assert "X305" in [f.code for f in at_zero]
    d = ddenote_program(loaded.program, {"a": 0.5, "b": 0.2}, {"b": 1})
    assert abs(d.value - 2) < 1e-12


@pytest.mark.parametrize("cond, says", [
    # (in one variable these are completed on their monotone pieces: test_turning_points.py; x^3 - x + y^3 - y − a
    # is split along y at ±sqrt(3)/3: test_split_along.py; exp(x) + x + exp(y) + y − a, monotone in each, is
    # completed by an implicit root: test_implicit_multivar.py; x^3 - x + y^3 - y + x*y − a is split along y at
    # turning points that move with x: test_split_along_moving.py); a pole inside the box is not split:
    ("x^3 - x + y^3 - y + x * y + 1/(x + y + 0.5) - a >= 0", "it is continuous in y on"),
])
def test_a_refused_condition_says_what_would_make_it_acceptable(cond, says):
    with pytest.raises(LangurError) as info:
        frontend.load_text(f"param a = 0.5\nint ([-2, 2], [-2, 2]) [{cond}] d(x, y)\n", "t.lgr")
    d = info.value.diagnostics[0]
    assert d.code == "T207" and says in d.message


def test_random_programs_with_kinks_in_conditions_agree():
    # the fuzzer's strategy with kinks=True draws abs/min/max inside conditions; a small seeded
    # campaign: both engines agree on each such program (compare_text: 5 standard errors)
    seen = []

    @settings(max_examples=12, derandomize=True, database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(programs(light=True, kinks=True, max_summands=1, max_factors=2))
    def one(p):
        if any(s in p.text for s in ("[abs(", "[max(", "[min(")) and p.text not in seen and len(seen) < 3:
            seen.append(p.text)
            r = compare_text(p.text, samples=4000, seed=0, timeout=20)
            assert not r.failed, (p.text, r.status)

    one()
    assert seen


def test_too_many_kinks_in_one_condition_are_refused_not_split():
    # nested kinks double the written-out condition at each level: past MAX_SPLIT_SIZE it is written
    # as a product of brackets instead (syntax/kinks.py, test_kinks_multivar.py), and past MAX_PIECES
    # pieces in all it is refused (T207)
    t = "x - a"
    for _ in range(8):
        t = f"abs({t}) - 0.1"
    with pytest.raises(LangurError) as info:
        frontend.load_text(f"param a = 0.3\nint ([-1, 1]) [{t} <= 0.05] d(x)\n", "t.lgr")
    d = info.value.diagnostics[0]
    assert d.code == "T207" and f"more than {MAX_PIECES} pieces" in d.message
