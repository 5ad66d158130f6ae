"""Nested quadrature at tangency points (issue 13, tang13): where a deeper region appears or
vanishes as an outer variable moves (the disc ``y² + z² ≤ a`` at y = ±√a), the inner integral
behaves like √(distance) and the middle level's Gauss–Kronrod subdivided some twenty times there;
the nested discs of the seed-1 campaign (programs 686–689) timed out in ⟦p⟧ alone.  Now the
middle level integrates such pieces after t = c + (d − c)·u², and the cylinders' crossing y = ±x
is found as a simple root.

References by hand, independent of the engine:

* the Steinmetz solid x² + z² ≤ a, y² + z² ≤ a: volume (16/3)·a^{3/2}, D_a = 8·√a (inside the box
  [−1, 1]³ for a < 1);
* a quarter ball x² + y² + z² ≤ a in [−1, 1] × [0, 1] × [0, 2]: volume π·a^{3/2}/3, D_a = (π/2)·√a;
* program 689 of the seed-1 campaign (the nested discs): the y-integral by hand (the odd part
  vanishes, the sine part integrates to 0 over the symmetric z-range), leaving twice the area of
  the disc x² + z² ≤ a for x ≥ a − 1.

The quarter ball was not slow before (its tangency is at the outer level, z = 0 a box end): it
checks that the substitution, which now applies there too, keeps the value within its bound.
Each computation runs under a CPU budget (:func:`langur.timebox.run_with_timeout`): the old code
spent minutes on each (the Steinmetz solid's value did not finish in 600 s at load 10).
"""

from __future__ import annotations

import math

import sympy as sp

from langur import denote
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load_text
from langur.fuzz import compare
from langur.symbolic import quadrature
from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature.kinks import _breakpoints, _kink_functions
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem
from langur.timebox import run_with_timeout

A = 0.53
#: CPU seconds each computation may take (a few with the substitution; minutes before it)
BUDGET = 60.0

STEINMETZ = ("param a = 0.53\n"
             "int ([-1, 1], [-1, 1], [-1, 1]) [x ^ 2 + z ^ 2 <= a] * [y ^ 2 + z ^ 2 <= a] d(x, y, z)\n")
QUARTER_BALL = "param a = 0.53\nint ([-1, 1], [0, 1], [0, 2]) [x ^ 2 + y ^ 2 + z ^ 2 <= a] d(x, y, z)\n"
# program 689 of `langur.fuzz.campaign.generated(1000, 1)`
DISCS = ("param a = 0.53\nint ([a - 1, 1], [-1, 1], [-1, 1])\n"
         "  2 * (if x ^ 2 + z ^ 2 <= a then (if y ^ 2 + z ^ 2 <= a then y + 0.5 else 0.5) else sin(z + a * y))\n"
         "d(x, y, z)\n")


def _forget():
    _DONE.clear()
    denote._remembered.clear()


def _steinmetz_problem():
    x, y, z, a = sp.symbols("x y z a")
    piece = Piece((Condition(a - x ** 2 - z ** 2), Condition(a - y ** 2 - z ** 2)), sp.Integer(1))
    _DONE.clear()
    return piece_problem(piece, [x, y, z], [(-1, 1), (-1, 1), (-1, 1)], {a: sp.Rational("0.53")})


def test_steinmetz_solid_by_the_nested_quadrature():
    """The two cylinders' intersection, one problem of the nested quadrature at its usual
    tolerances: (16/3)·a^{3/2} within the bound it reports."""
    prob = _steinmetz_problem()
    val, err = run_with_timeout(lambda: integrate_problem(prob), BUDGET, cpu=True)
    hand = 16 / 3 * A ** 1.5
    assert prob.converged and abs(val - hand) <= err, (val, hand, err)
    assert err < 1e-7


def test_the_cylinders_crossing_is_found_on_both_sides():
    """At the middle level (y, for a fixed x) the inner interval's ends cross at y = ±x: the
    resultant is (x² − y²)², whose double roots ``numpy.roots`` found as a pair 10⁻⁸ apart or as a
    complex pair it dropped (y = +x was missing); the square-free part gives each once, exactly."""
    prob = _steinmetz_problem()
    prob.kinks[1], prob.kink_vary[1] = _kink_functions(prob, 1)
    for x0 in (-0.6, -0.2, 0.3, 0.45):
        _, kinks = _breakpoints(prob, 1, (x0,), True)
        kinks |= _breakpoints(prob, 1, (x0,), False)[1]
        for want in (-abs(x0), abs(x0)):
            assert any(abs(k - want) <= 1e-15 for k in kinks), (x0, sorted(kinks))
        ks = sorted(kinks)
        assert all(b - a > 1e-6 for a, b in zip(ks, ks[1:])), ks  # no near-double pair


def test_steinmetz_solid_value_and_derivative_through_the_engine():
    """⟦p⟧ and D_a⟦p⟧ by quadrature (no closed form sought): (16/3)·a^{3/2} and 8·√a."""
    prog = load_text(STEINMETZ).program
    _forget()
    den = run_with_timeout(lambda: denote_program(prog, {"a": A}, symbolic=False), BUDGET, cpu=True)
    assert den.error is not None and abs(float(den.value) - 16 / 3 * A ** 1.5) <= den.error, den
    der = run_with_timeout(lambda: ddenote_program(prog, {"a": A}, {"a": 1}, symbolic=False), BUDGET, cpu=True)
    assert der.error is not None and abs(float(der.value) - 8 * math.sqrt(A)) <= der.error, der


def test_quarter_ball_value_and_derivative():
    prog = load_text(QUARTER_BALL).program
    _forget()
    den = run_with_timeout(lambda: denote_program(prog, {"a": A}, symbolic=False), BUDGET, cpu=True)
    assert den.error is not None and abs(float(den.value) - math.pi * A ** 1.5 / 3) <= den.error, den
    der = run_with_timeout(lambda: ddenote_program(prog, {"a": A}, {"a": 1}, symbolic=False), BUDGET, cpu=True)
    assert der.error is not None and abs(float(der.value) - math.pi / 2 * math.sqrt(A)) <= der.error, der


def test_the_campaigns_nested_discs():
    """Program 689 of the seed-1 campaign as a campaign unit computes it (the outermost level
    loosened): ⟦p⟧ = 2·∫_{a−1}^{√a} 2√(a − x²) dx and D_a⟦p⟧ = 2·(π/2 − asin((a − 1)/√a)
    − 2√(a − (a − 1)²)) (the box's end x = a − 1 moves with a), each within its reported bound."""
    prog = load_text(DISCS).program
    r = math.sqrt(A)

    def area(x):
        return x * math.sqrt(A - x * x) + A * math.asin(x / r)

    value = 2 * (area(r) - area(A - 1))
    slope = 2 * (math.pi / 2 - math.asin((A - 1) / r) - 2 * math.sqrt(A - (A - 1) ** 2))
    _forget()
    with quadrature.outer_tolerance(compare.OUTER_LOOSENESS):
        den = run_with_timeout(lambda: denote_program(prog, {"a": A}, symbolic=False), BUDGET, cpu=True)
        der = run_with_timeout(lambda: ddenote_program(prog, {"a": A}, {"a": 1}, symbolic=False), BUDGET,
                               cpu=True)
    assert den.error is not None and abs(float(den.value) - value) <= den.error, (den.value, value, den.error)
    assert der.error is not None and abs(float(der.value) - slope) <= der.error, (der.value, slope, der.error)
