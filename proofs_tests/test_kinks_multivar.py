"""Kinks in conditions over one to three variables (issue 18): ``abs``, ``min``, ``max`` split at
their kinks by the desugarer, the pieces completed by the variable they are affine in.

Each program's derivative is checked, for the exact engine and for Monte Carlo, against a value
computed here independently: by hand (areas and volumes of squares, cubes, diamonds, windows, and
their derivatives in closed form), or by central finite differences of ``scipy.integrate.quad``
of the value where the set leaves the box — at parameters where the set is inside the box, partly
outside it, and empty.  The linter is checked on the same programs: no finding at these regular
parameter values (the kink's own zero set carries no delta, and a piece meets other zero sets only
where it is in force, ``langur.lint.ancestry``), while genuinely non-transverse programs (a window
of width 0, a square whose edges lie on the box, a tangent disc) are still reported.
"""

import math

import numpy as np
import pytest
from scipy.integrate import quad

from langur import frontend
from langur.ddenote import ddenote_program
from langur.diagnostics import LangurError
from langur.lint.fix import fix
from langur.operational import estimate_derivative
from langur.syntax.printer import print_core
from langur.transversality import check_program

H = 1e-4  # central differences of a quadrature accurate to ~1e-12: error O(h²) ≈ 1e-8


def _quad(f, lo, hi, points):
    pts = sorted(p for p in points if lo < p < hi)
    return quad(f, lo, hi, points=pts or None, epsabs=1e-13, epsrel=1e-13, limit=200)[0]


def diamond_value(a):  # ∫₋₁¹∫₋₁¹ [|x| + |y| ≤ a]·eˣ dy dx = ∫ eˣ·2·min(1, a − |x|)⁺ dx
    return _quad(lambda x: math.exp(x) * 2 * min(1.0, max(0.0, a - abs(x))), -1, 1, [0, a, -a, a - 1, 1 - a])


def corner_z_value(a):  # ∫₀¹∫₀¹∫₀¹ [min(x, y) − a ≥ 0]·z dz dy dx = (1 − a)²·½ on [0, 1]
    return _quad(lambda x: _quad(lambda y: float(min(x, y) >= a) * 0.5, 0, 1, [a, x]), 0, 1, [a])


def _d(value):
    return lambda a: (value(a + H) - value(a - H)) / (2 * H)


CASES = [
    # (name, program, d/da by hand or by finite differences, points: inside, partly outside, empty/all)
    ("window-nested", "param a = 0.5\nint ([-1, 1]) [abs(abs(x) - a) <= 0.2] * exp(x) d(x)\n",
     # |x| ∈ [a − 0.2, a + 0.2] ∩ [0, 1]: 2·(sinh(hi) − sinh(lo)), both ends moving with a
     lambda a: 2 * (math.cosh(a + 0.2) * (-0.2 < a < 0.8) - math.cosh(a - 0.2) * (0.2 < a < 1.2)),
     [0.5, 0.1, 0.9, 1.5, -0.5]),
    ("sum-of-abs", "param a = 1.2\nint ([-1, 2]) [abs(x) + abs(x - 1) <= a] * exp(x) d(x)\n",
     # |x| + |x − 1| ≤ a is x ∈ [(1 − a)/2, (1 + a)/2] for a ≥ 1 (empty below, flat bottom [0, 1] at a = 1)
     lambda a: 0.5 * (math.exp((1 + a) / 2) + math.exp((1 - a) / 2)) if 1 < a < 3 else 0.0,
     [1.2, 2.5, 0.8, 3.5]),
    ("corner-2d", "param a = 0.3\nint ([0, 1], [0, 1]) [min(x, y) - a >= 0] d(x, y)\n",
     lambda a: -2 * (1 - a) if 0 < a < 1 else 0.0, [0.3, 0.8, -0.5, 1.5]),
    ("corner-3d", "param a = 0.3\nint ([0, 1], [0, 1], [0, 1]) [min(min(x, y), z) - a >= 0] d(x, y, z)\n",
     lambda a: -3 * (1 - a) ** 2 if 0 < a < 1 else 0.0, [0.3, -0.5, 1.5]),
    ("corner-2d-in-3", "param a = 0.3\nint ([0, 1], [0, 1], [0, 1]) [min(x, y) - a >= 0] * z d(x, y, z)\n",
     _d(corner_z_value), [0.3, -0.5, 1.5]),
    ("square", "param a = 0.5\nint ([-1, 1], [-1, 1]) [max(abs(x), abs(y)) <= a] d(x, y)\n",
     lambda a: 8 * a if 0 < a < 1 else 0.0, [0.5, 0.9, 1.3, -0.4]),
    ("cube", "param a = 0.5\nint ([-1, 1], [-1, 1], [-1, 1]) [max(max(abs(x), abs(y)), abs(z)) <= a] d(x, y, z)\n",
     lambda a: 24 * a * a if 0 < a < 1 else 0.0, [0.5, 1.3, -0.4]),
    ("diamond", "param a = 0.5\nint ([-1, 1], [-1, 1]) [abs(x) + abs(y) <= a] * exp(x) d(x, y)\n",
     # inside the box: 4·(cosh a − 1), so 4·sinh a; past a = 1 the box cuts it: quadrature
     lambda a: 4 * math.sinh(a) if 0 < a <= 1 else _d(diamond_value)(a), [0.5, 1.5, -0.3, 2.5]),
    # the kinks x = 0 and y = 0 lie on the domain's bounds (no finding: a kink has no delta)
    ("diamond-quadrant", "param a = 0.5\nint ([0, 1], [0, 1]) [abs(x) + abs(y) <= a] d(x, y)\n",
     lambda a: a if 0 < a < 1 else (2 - a if 1 < a < 2 else 0.0), [0.5, 1.5, -0.3, 2.5]),
]


def _load(text):
    return frontend.load_text(text, "case.lgr")


@pytest.mark.parametrize("name, text, derivative, points", CASES, ids=[c[0] for c in CASES])
def test_exact_and_monte_carlo_match_the_independent_derivative(name, text, derivative, points):
    program = _load(text).program
    for a in points:
        want = derivative(a)
        exact = ddenote_program(program, {"a": a}, {"a": 1})
        assert abs(exact.value - want) <= 1e-6 + exact.error, (a, exact.value, want)
        mc = estimate_derivative(program, {"a": a}, {"a": 1}, samples=3000, seed=5)
        assert abs(mc.value - want) <= 5 * mc.stderr + 1e-6, (a, mc.value, mc.stderr, want)
        assert abs(mc.value - exact.value) <= 5 * mc.stderr + 1e-6 + exact.error


@pytest.mark.parametrize("name, text, derivative, points", CASES, ids=[c[0] for c in CASES])
def test_no_false_alarm_at_regular_parameter_values(name, text, derivative, points):
    loaded = _load(text)
    for a in points[:2]:  # inside, partly outside: no zero set degenerates there
        found = check_program(loaded.program, loaded.params, at={"a": a})
        assert not found, (a, [(f.code, f.message) for f in found])


def test_the_flat_piece_of_a_sum_of_abs_is_a_condition_on_the_parameters():
    # between the kinks 0 and 1, |x| + |x − 1| = 1: that piece is `ifge0 a − 1` (Fig. 6, conditional),
    # not a condition over x (which could not be completed: x cancels)
    core = print_core(_load(CASES[1][1]).program.integrand)
    assert "[-1 + a >= 0]" in core  # (a bracket prints as one since fold31)


def test_pieces_meet_the_box_only_where_they_are_in_force():
    # [|x| + |y − a| ≤ 0.5] at a = 0.5: the piece y − x ≥ 0 (x ≥ 0, y < a) is the line y = x, which
    # passes through the corners (−1, −1) and (1, 1) of the box — outside the piece (x < 0, y > a):
    # no three zero sets of the program meet there (before: four X303); the diamond's top vertex
    # (0, 1) does lie on the bound y = 1, but there only the kink x = 0 (no delta) joins them
    loaded = _load("param a = 0.5\nint ([-1, 1], [-1, 1]) [abs(x) + abs(y - a) <= 0.5] * exp(x) d(x, y)\n")
    assert not check_program(loaded.program, loaded.params, at={"a": 0.5})


@pytest.mark.parametrize("text, at, code", [
    # a window of width 0: the kink's zero set and its pieces' coincide for every a
    ("param a = 0.5\nint ([-1, 1]) [abs(x - a) <= 0] d(x)\n", None, "X301"),
    # the square's edges on the box's bounds: the area 4a² stops growing at a = 1 (8 → 0)
    ("param a = 0.5\nint ([-1, 1], [-1, 1]) [max(abs(x), abs(y)) <= a] d(x, y)\n", {"a": 1.0}, "X305"),
    # the flat bottom of |x| + |x − 1| at a = 1: the value jumps from 0 to e − 1
    ("param a = 1.2\nint ([-1, 2]) [abs(x) + abs(x - 1) <= a] * exp(x) d(x)\n", {"a": 1.0}, "X305"),
    # two ends of the nested window meet at the kink x = 0 when a = 0.2
    ("param a = 0.5\nint ([-1, 1]) [abs(abs(x) - a) <= 0.2] * exp(x) d(x)\n", {"a": 0.2}, "X305"),
    # the square's right edge written twice: the same moving zero set x = a in two factors
    ("param a = 0.5\nint ([-1, 1], [-1, 1]) [max(abs(x), abs(y)) <= a] * [x <= a] d(x, y)\n", None, "X301"),
    # the inscribed disc is tangent to the square's edges at a = 0.5
    ("param a = 0.5\nint ([-1, 1], [-1, 1]) [max(abs(x), abs(y)) <= a] * [x^2 + y^2 <= 0.25] d(x, y)\n",
     {"a": 0.5}, "X302"),
])
def test_genuinely_non_transverse_programs_are_still_reported(text, at, code):
    loaded = _load(text)
    codes = [f.code for f in check_program(loaded.program, loaded.params, at=at)]
    assert code in codes, codes


def test_the_reported_square_has_a_corner_in_its_value():
    # the square at a = 1 (X305 above) is a true alarm: the one-sided derivatives 8a and 0 differ
    program = _load(CASES[5][1]).program
    left = ddenote_program(program, {"a": 1 - 1e-3}, {"a": 1}).value
    right = ddenote_program(program, {"a": 1 + 1e-3}, {"a": 1}).value
    assert abs(left - 8 * (1 - 1e-3)) < 1e-9 and right == 0  # the one-sided derivatives differ


def test_two_kinks_meeting_are_no_coincidence():
    # |x − a| + |x + a| = max(2|x|, 2|a|): its kinks x = ±a meet at a = 0, but neither carries a
    # delta (the split's branches agree there), so nothing is counted twice: the value
    # ∫_{−0.75}^{0.75} eˣ dx does not depend on a for |a| < 0.75, and at a = 0 there is no finding
    loaded = _load("param a = 0.3\nint ([-1, 1]) [abs(x - a) + abs(x + a) <= 1.5] * exp(x) d(x)\n")
    for a in (0.0, 0.3):
        assert not check_program(loaded.program, loaded.params, at={"a": a})
        exact = ddenote_program(loaded.program, {"a": a}, {"a": 1})
        assert abs(exact.value) <= 1e-9 + exact.error
        mc = estimate_derivative(loaded.program, {"a": a}, {"a": 1}, samples=2000, seed=1)
        assert abs(mc.value) <= 5 * mc.stderr + 1e-9
    # where the flat part |x| ≤ |a| reaches the level 1.5 the set vanishes at once: reported
    assert "X305" in [f.code for f in check_program(loaded.program, loaded.params, at={"a": 0.75})]


def _nested(n):
    t = "x - a"
    for _ in range(n):
        t = f"abs({t}) - 0.1"
    return f"param a = 0.3\nint ([-1, 1]) [{t} <= 0.05] d(x)\n"


def test_a_condition_too_large_to_split_is_a_product_of_brackets():
    # four nested abs: written out at its kinks the condition has over 10000 nodes (refused before);
    # as brackets, [abs(t) - 0.1 <= 0.05] is [t <= 0.15 & -t <= 0.15] and so on down: the set is
    # |x − a| ≤ 0.05 + 4·0.1 (each level's lower bound holds everywhere), so on [−1, 1] the value
    # is 0.9 while the window is inside (a = 0.3) and 1 − (a − 0.45) once it leaves (a = 0.7)
    loaded = _load(_nested(4))
    for a, want in ((0.3, 0.0), (0.7, -1.0)):
        exact = ddenote_program(loaded.program, {"a": a}, {"a": 1})
        assert abs(exact.value - want) <= 1e-9 + exact.error
        mc = estimate_derivative(loaded.program, {"a": a}, {"a": 1}, samples=2000, seed=2)
        assert abs(mc.value - want) <= 5 * mc.stderr + 1e-9
        # the brackets' pieces whose zero sets lie where they are not in force are no coincidence
        assert not check_program(loaded.program, loaded.params, at={"a": a})


def test_the_four_cube():
    # [max(max(|x|, |y|), max(|z|, |w|)) <= a]: a product of 8 affine brackets, volume (2a)⁴, so
    # d/da = 64a³ (Monte Carlo here; the exact engine agrees, 8 at a = 0.5, in ~25 s)
    loaded = _load("param a = 0.5\nint ([-1, 1], [-1, 1], [-1, 1], [-1, 1]) "
                   "[max(max(abs(x), abs(y)), max(abs(z), abs(w))) <= a] d(x, y, z, w)\n")
    for a in (0.5, 0.8):
        mc = estimate_derivative(loaded.program, {"a": a}, {"a": 1}, samples=3000, seed=5)
        assert abs(mc.value - 64 * a ** 3) <= 5 * mc.stderr


def test_a_refused_piece_says_which_piece_it_is():
    # |x| + x³ − 2x + y³ − y + xy + 1/(x + y + 0.5) − a: on x ≥ 0 monotone in neither variable and
    # split along neither (a pole inside the box; without it the piece is split along y at turning
    # points that move with x, test_split_along_moving.py; a piece monotone in one would be completed
    # by an implicit root, test_implicit_multivar.py); the T207 says which piece of the split it is
    # and what would make it acceptable
    with pytest.raises(LangurError) as info:
        _load("param a = 0.5\nint ([-1, 1], [-1, 1]) [abs(x) + x^3 - 2*x + y^3 - y + x*y + 1/(x + y + 0.5) - a >= 0] "
              "d(x, y)\n")
    messages = [d.message for d in info.value.diagnostics]
    assert any("on its piece where x >= 0" in m and "monotone in x" in m and "declare a `diffeo`" in m
               for m in messages), messages


def test_check_fix_writes_the_kink_split_where_it_is_a_rewrite():
    # [abs(x − a) <= 0.2]² multiplies the window's ends by themselves (X301, true: ⦇p⦈ counts them
    # twice); --fix writes the transverse rewrite, which is the split written out, and the result
    # is clean and has the window's derivative e^{a+0.2} − e^{a−0.2}
    text = "param a = 0.5\nint ([0, 1]) [abs(x - a) <= 0.2]^2 * exp(x) d(x)\n"
    loaded = _load(text)
    before = [f.code for f in check_program(loaded.program, loaded.params)]
    assert before.count("X301") == 2  # the two ends; the kink x = a itself has no delta
    fixed = fix(text, "case.lgr", loaded)
    assert fixed is not None and "ifge0 x - a then [0.2 - (x - a) >= 0]" in fixed.after  # (brackets as brackets: fold31)
    again = _load(fixed.after)
    assert not check_program(again.program, again.params)
    d = ddenote_program(again.program, {"a": 0.5}, {"a": 1})
    assert abs(d.value - (math.exp(0.7) - math.exp(0.3))) < 1e-12


def test_the_degenerate_set_lists_only_meetings_within_the_pieces():
    # [||x| − 0.3| <= a] on [−1, 1]: its value has corners at a = 0 (the windows open), 0.3 (they
    # merge at the kink x = 0) and 0.7 (they reach the box); the pieces' lines extended past their
    # kinks would also meet x = 0 at a = −0.3 and the box at a = −1.3, where nothing happens
    loaded = _load("param a = 0\nint ([-1, 1]) [abs(abs(x) - 0.3) <= a] * exp(x) d(x)\n")
    found = check_program(loaded.program, loaded.params)
    assert found and all(f.code == "X304" for f in found)
    text = " ".join(f.message for f in found)
    assert "a = 3/10" in text and "a = 7/10" in text and "-3/10" not in text and "-13/10" not in text
    # [|x| − a >= 0] at a = −1: the whole box, a constant value: nothing to report
    loaded = _load("param a = -1\nint ([-1, 1]) [abs(x) - a >= 0] * exp(x) d(x)\n")
    assert not check_program(loaded.program, loaded.params)


def test_a_scaled_bracket_too_large_to_split():
    # 2·abs(…) <= 0.05 is abs(…) <= 0.025 before the bracket form applies; the value's derivative by
    # finite differences of the measure of the set on a fine grid (numpy, independent of Langur)
    def measure(a):
        xs = np.linspace(-1, 1, 400_001)
        inside = 2 * np.abs(np.abs(np.abs(np.abs(xs - a) - 0.1) - 0.1) - 0.1) <= 0.05
        return 2 * float(np.mean(inside))

    loaded = _load("param a = 0.5\nint ([-1, 1]) [2 * abs(abs(abs(abs(x - a) - 0.1) - 0.1) - 0.1) <= 0.05] d(x)\n")
    for a in (0.3, 0.9):
        fd = (measure(a + 1e-3) - measure(a - 1e-3)) / 2e-3
        mc = estimate_derivative(loaded.program, {"a": a}, {"a": 1}, samples=2000, seed=2)
        assert abs(mc.value - fd) <= 5 * mc.stderr + 1e-3, (a, mc.value, fd)
