"""Singular integrands: poles on edges, at corners, inside, moving with parameters, in 1–3
variables, and integrable singularities as controls (issue 9, part B).

Each entry: ``(name, program text, value verdict, derivative verdict, hand value, heavy)``.
Verdicts: ``"D"`` the integral does not exist, ``"I"`` it does, ``"?"`` the analysis may say
either (it is honestly undecided, X312).  The derivative verdict is about ⦇p⦈ in the program's
parameter (None without one).  Hand values (None where there is no short one) are derived in the
comments.  ``heavy``: the exact engine needs many seconds (3-D quadrature), so the command test
runs the Monte Carlo engine only.
"""

import math

SQRT2_LOG = math.log(1 + math.sqrt(2))  # ∫∫_[0,1]² dx dy / √(x²+y²) = 2·log(1 + √2)


def program(params: str, domain: str, body: str, variables: str) -> str:
    return (f"param {params}\n" if params else "") + f"int ({domain}) {body} d({variables})\n"


CORPUS = [
    # --- one variable --------------------------------------------------------------------------
    ("pole2_end", program("", "[0, 1]", "1 / x^2", "x"), "D", None, None, False),
    ("pole1_end", program("", "[0, 1]", "1 / x", "x"), "D", None, None, False),
    ("pole1_inside", program("", "[-1, 1]", "1 / x", "x"), "D", None, None, False),
    ("pole2_inside", program("", "[-1, 1]", "1 / x^2", "x"), "D", None, None, False),
    ("pole_times_param", program("a = 1", "[-1, 1]", "a / x", "x"), "D", "D", None, False),
    ("principal_value", program("a = 0.5", "[-1, 1]", "[x <= a] / x", "x"), "D", "D", None, False),
    ("moving_pole_inside", program("a = 0.5", "[0, 1]", "1 / (x - a)", "x"), "D", "D", None, False),
    # ∫₀¹ dx/(x − 2) = log|−1| − log|−2| = −log 2; the pole x = 2 is outside the domain
    ("moving_pole_outside", program("a = 2", "[0, 1]", "1 / (x - a)", "x"), "I", "I", -math.log(2), False),
    ("moving_double_pole", program("a = 0.5", "[0, 1]", "1 / (x - a)^2", "x"), "D", "D", None, False),
    ("inverse_sqrt", program("", "[0, 1]", "1 / sqrt(x)", "x"), "I", None, 2.0, False),  # [2√x]₀¹
    ("log_at_end", program("", "[0, 1]", "log(x)", "x"), "I", None, -1.0, False),  # [x log x − x]₀¹
    ("inverse_sqrt_abs", program("", "[-1, 1]", "1 / sqrt(abs(x))", "x"), "I", None, 4.0, False),
    # ∫₀¹ log|x − ½| = 2·∫₀^½ log u du = 2·(½ log ½ − ½) = log ½ − 1; ⦇·⦈ in a is −1/(x − a)
    ("log_abs_moving", program("a = 0.5", "[0, 1]", "log(abs(x - a))", "x"), "I", "D",
     math.log(0.5) - 1, False),
    ("cube_root_pole", program("", "[0, 1]", "1 / x^(1/3)", "x"), "I", None, 1.5, False),  # [3/2 x^(2/3)]
    ("pole_at_upper_end", program("", "[0, 1]", "1 / (1 - x)", "x"), "D", None, None, False),
    ("tan_pole", program("", "[0, 2]", "tan(x)", "x"), "D", None, None, False),  # cos(π/2) = 0
    ("inverse_log", program("", "[0.5, 2]", "1 / log(x)", "x"), "D", None, None, False),  # log x ~ x − 1
    # sin(x)/x is bounded (removable at 0): ∫₋₁¹ = 2·Si(1) = 2·0.946083070367183
    ("removable", program("", "[-1, 1]", "sin(x) / x", "x"), "I", None, 2 * 0.946083070367183, False),
    ("exp_over_pole", program("a = 0.3", "[0, 1]", "exp(x) / (x - a)", "x"), "D", "D", None, False),
    ("jump_then_pole", program("a = 0.5", "[0, 1]", "[x >= a] / (x - a)", "x"), "D", "D", None, False),
    # ∫_a^1 (x − a)^(−1/2) = 2√(1 − a) = √2; ⦇·⦈ has (x − a)^(−3/2)/2 and δ(x − a)·(x − a)^(−1/2)
    ("jump_then_root_pole", program("a = 0.5", "[0, 1]", "if x >= a then 1 / sqrt(x - a) else 0", "x"),
     "I", "D", math.sqrt(2), False),
    # ∫₀¹ √|x − ½| = 2·(2/3)(½)^(3/2); ⦇·⦈ puts δ(x − a) on (2a − 2x)/(2√(x − a)): 0/0 there
    ("root_of_abs", program("a = 0.5", "[0, 1]", "sqrt(abs(x - a))", "x"), "I", "D",
     (4 / 3) * 0.5 ** 1.5, False),
    ("vanishing_param", program("a = 0", "[-1, 1]", "1 / (x^2 + a^2)", "x"), "D", None, None, False),
    ("expanded_square", program("a = 0.5", "[0, 1]", "1 / (x^2 - 2*x*a + a^2)", "x"), "D", "D", None, False),
    # undefined on a set of positive measure: log of a negative number (LANGUAGE.md §1)
    ("log_negative", program("", "[-1, 1]", "log(x)", "x"), "D", None, None, False),
    # --- two variables -------------------------------------------------------------------------
    ("r2_corner", program("", "[0, 1], [0, 1]", "1 / (x^2 + y^2)", "x, y"), "D", None, None, False),
    ("r1_corner", program("", "[0, 1], [0, 1]", "1 / sqrt(x^2 + y^2)", "x, y"), "I", None, 2 * SQRT2_LOG, True),
    ("r2_inside", program("", "[-1, 1], [-1, 1]", "1 / (x^2 + y^2)", "x, y"), "D", None, None, False),
    ("r1_inside", program("", "[-1, 1], [-1, 1]", "1 / sqrt(x^2 + y^2)", "x, y"), "I", None, 8 * SQRT2_LOG, True),
    # ∫∫_[0,1]² 1/(x + y) = ∫₀¹ log((x + 1)/x) dx = 2 log 2
    ("sum_corner", program("", "[0, 1], [0, 1]", "1 / (x + y)", "x, y"), "I", None, 2 * math.log(2), False),
    ("sum_squared_corner", program("", "[0, 1], [0, 1]", "1 / (x + y)^2", "x, y"), "D", None, None, False),
    ("pole_on_edge", program("", "[0, 1], [0, 1]", "1 / x", "x, y"), "D", None, None, False),
    ("root_pole_on_edge", program("", "[0, 1], [0, 1]", "1 / sqrt(x)", "x, y"), "I", None, 2.0, False),
    ("diagonal", program("", "[0, 1], [0, 1]", "1 / (x - y)", "x, y"), "D", None, None, False),
    # ∫∫ |x − y|^(−1/2) = 2·∫₀¹ ∫₀ˣ (x − y)^(−1/2) dy dx = 2·∫₀¹ 2√x dx = 8/3
    ("root_diagonal", program("", "[0, 1], [0, 1]", "1 / sqrt(abs(x - y))", "x, y"), "I", None, 8 / 3, False),
    # |x|/(x² + y²) ≤ 1/r: integrable; ∫₀¹ atan(1/x) dx = π/4 + log(2)/2
    ("numerator_vanishes", program("", "[0, 1], [0, 1]", "x / (x^2 + y^2)", "x, y"), "I", None,
     math.pi / 4 + math.log(2) / 2, False),
    ("moving_circle", program("a = 0.5", "[0, 1], [0, 1]", "1 / (x^2 + y^2 - a^2)", "x, y"), "D", "D", None, False),
    # ∫_{quarter disk of radius a} (a² − r²)^(−1/2) = (π/2)·∫₀^a r (a² − r²)^(−1/2) dr = (π/2)·a
    # (a conditional: the bracket form [x^2 + y^2 <= a^2] / sqrt(…) evaluates sqrt outside the
    # disk too, where it is undefined, LANGUAGE.md §3: no integral, X311, test_guard27)
    ("rim_root_pole", program("a = 0.5", "[0, 1], [0, 1]",
                              "if x^2 + y^2 <= a^2 then 1 / sqrt(a^2 - x^2 - y^2) else 0", "x, y"),
     "I", "D", math.pi * 0.5 / 2, True),
    # ∫∫_[0,1]² log(x² + y²) = log 2 + π/2 − 3
    ("log_corner", program("", "[0, 1], [0, 1]", "log(x^2 + y^2)", "x, y"), "I", None,
     math.log(2) + math.pi / 2 - 3, False),
    # anisotropic (α = 1 almost everywhere, 2 along the y axis): integrable, honestly undecided
    ("anisotropic", program("", "[0, 1], [0, 1]", "1 / (x + y^2)", "x, y"), "?", None, None, True),
    ("moving_line", program("a = 0.25", "[0, 1], [0, 1]", "1 / (x - y - a)", "x, y"), "D", "D", None, False),
    ("moving_edge", program("a = 0.5", "[0, 1], [0, 1]", "1 / (x - a)", "x, y"), "D", "D", None, False),
    # ∫∫_{y > x} (y − x)^(−1/2) = ∫₀¹ 2√(1 − x) dx = 4/3 (a conditional, as rim_root_pole)
    ("wedge_root_pole", program("", "[0, 1], [0, 1]", "if y >= x then 1 / sqrt(y - x) else 0", "x, y"), "I", None,
     4 / 3, False),
    ("tan_line", program("", "[0, 1], [0, 1]", "tan(x + y)", "x, y"), "D", None, None, False),
    # Σ_k ∫∫ (xy)^k = Σ 1/(k + 1)² = π²/6: a simple pole at the corner (1, 1) of ℝ²
    ("basel", program("", "[0, 1], [0, 1]", "1 / (1 - x*y)", "x, y"), "I", None, math.pi ** 2 / 6, True),
    ("basel_squared", program("", "[0, 1], [0, 1]", "1 / (1 - x*y)^2", "x, y"), "D", None, None, False),
    ("sqrt_negative", program("", "[-1, 1], [0, 1]", "sqrt(x - y)", "x, y"), "D", None, None, False),
    # --- three variables -----------------------------------------------------------------------
    # ∫_{octant of the unit ball} r^−2 = (4π/8)·∫₀¹ dr = π/2
    ("ball_r2", program("", "[0, 1], [0, 1], [0, 1]", "[x^2 + y^2 + z^2 <= 1] / (x^2 + y^2 + z^2)", "x, y, z"),
     "I", None, math.pi / 2, True),
    ("r3_corner", program("", "[0, 1], [0, 1], [0, 1]", "1 / (x^2 + y^2 + z^2)^(3/2)", "x, y, z"),
     "D", None, None, False),
    ("r2_edge", program("", "[0, 1], [0, 1], [0, 1]", "1 / (x^2 + y^2)", "x, y, z"), "D", None, None, False),
    ("pole_on_face", program("", "[0, 1], [0, 1], [0, 1]", "1 / x", "x, y, z"), "D", None, None, False),
    ("r1_edge", program("", "[0, 1], [0, 1], [0, 1]", "1 / sqrt(x^2 + y^2)", "x, y, z"), "I", None,
     2 * SQRT2_LOG, True),
    ("sum3_corner", program("", "[0, 1], [0, 1], [0, 1]", "1 / (x + y + z)", "x, y, z"), "I", None, None, True),
    ("moving_plane", program("a = 0.5", "[0, 1], [0, 1], [0, 1]", "1 / (x - a)", "x, y, z"), "D", "D", None, False),
    ("log3", program("", "[0, 1], [0, 1], [0, 1]", "log(x*y*z)", "x, y, z"), "I", None, -3.0, True),
    ("r2_corner_3d", program("", "[0, 1], [0, 1], [0, 1]", "1 / (x^2 + y^2 + z^2)", "x, y, z"), "I", None, None,
     True),
]
