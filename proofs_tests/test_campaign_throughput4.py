"""Campaign throughput, fourth pass (issue 13): the quadrature's kinks computed once per shape of
problem with the parameters as symbols, and the linter's contradictory systems decided without
``sp.solve`` — each checked against an independent reference.

* A disc ``[(x − a)² + y² ≤ r²]`` cut by the box: its kink ``x = a ± r`` (where the region in y
  appears) is found from one parametric computation at two values of ``a``, and both integrals
  agree with the circular-segment area by mpmath; the second point computes no new kinks.
* ``_contradictory``'s verdicts against sympy's ``solve`` followed by :func:`_solve_points`'s own
  verification (the solutions it keeps), on systems of box faces and transcendental zero sets.
"""

from __future__ import annotations

import mpmath
import sympy as sp

from langur.lint import algebra
from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature.kinks import _KINKS
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem


def _segment_area(a: float, r: float) -> float:
    # ∫_0^1 ∫_0^1 [(x − a)² + y² ≤ r²] dy dx = ∫ min(1, sqrt(r² − (x − a)²)) over |x − a| ≤ r, 0 ≤ x ≤ 1
    mpmath.mp.dps = 30
    a, r = mpmath.mpf(str(a)), mpmath.mpf(str(r))
    lo, hi = max(mpmath.mpf(0), a - r), min(mpmath.mpf(1), a + r)
    return float(mpmath.quad(lambda t: mpmath.sqrt(max(mpmath.mpf(0), r * r - (t - a) ** 2)), [lo, a, hi]))


def test_parametric_kinks_hold_at_every_parameter_point():
    x, y, a = sp.symbols("x y a")
    r = sp.Rational(2, 5)
    piece = Piece((Condition(r ** 2 - (x - a) ** 2 - y ** 2),), sp.Integer(1))
    box = [(0, 1), (0, 1)]
    _DONE.clear()
    _KINKS.clear()
    for value in (0.37, 0.41):
        at = {a: sp.Rational(str(value))}
        prob = piece_problem(piece, [x, y], box, at)
        val, err = integrate_problem(prob)
        assert abs(val - _segment_area(value, 0.4)) <= err + 1e-12
        kinks = [root for _, roots in prob.kinks[0] if roots is not None for root in roots()]
        assert any(abs(k - (value + 0.4)) < 1e-12 for k in kinks)  # x = a + r, where y's region vanishes
        assert any(abs(k - (value - 0.4)) < 1e-12 for k in kinks)
        if value == 0.37:
            shapes = {k for k in _KINKS if k[0] == "sym"}
            assert shapes  # the kinks were computed with a as a symbol
        else:
            assert {k for k in _KINKS if k[0] == "sym"} == shapes  # and reused at the second point


def _sympy_verdict(eqs, unknowns) -> bool:
    """No common zero, by sympy's solve and the verification _solve_points applies to it."""
    others = set().union(*(e.free_symbols for e in eqs)) - set(unknowns)
    kept = []
    for sol in sp.solve(eqs, unknowns, dict=True):
        if not sol or any(v.has(sp.I) for v in sol.values()):
            continue
        free = set(unknowns) - set(sol)
        if all(algebra.vanishes(e.subs(sol), others | free) for e in eqs):
            kept.append(sol)
    return not kept


def test_contradictory_systems_agree_with_sympy():
    x, y, z = sp.symbols("x y z")
    R = sp.Rational
    systems = [
        ([x + R(53, 100), 1 - x, -sp.tanh(x - R(47, 100)) - R(3, 10)], (x, y)),  # parallel faces
        ([R(1, 10) - (x - R(37, 100)) ** 2, -y + sp.sin(x) + R(37, 100), R(37, 50) - 2 * x], (x, y)),
        ([x - sp.sin(y) - R(37, 100), x, 2 - x], (x, y)),
        ([1 - x, z, 1 - z, R(153, 100) - sp.sqrt(x + 2)], (x, y, z)),
        ([x - R(1, 2), y - sp.sin(x)], (x, y)),  # consistent: one point
        ([x, x ** 2 + y ** 2 - 1], (x, y)),  # consistent: two points
        ([x - 1, y, x ** 2 + y ** 2 - 1], (x, y)),  # fixed unknowns on the circle: consistent
        ([x + y - 1, sp.sin(x) - y], (x, y)),  # affine part leaves a line: not decided here
    ]
    decided = 0
    for eqs, unknowns in systems:
        mine = algebra._contradictory(list(eqs), unknowns)
        if mine:
            decided += 1
            assert _sympy_verdict(list(eqs), unknowns), eqs
        assert algebra._solve_points(list(eqs), unknowns) == [] if mine else True
    assert decided == 4
    assert not algebra._contradictory([x - 1, y, x ** 2 + y ** 2 - 1], (x, y))
    assert algebra._solve_points([x - 1, y, x ** 2 + y ** 2 - 1], (x, y)) == [{x: 1, y: 0}]
