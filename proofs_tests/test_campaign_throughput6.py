"""Campaign throughput, sixth pass (issue 13): in the nested quadrature, the breakpoints of a
level that do not depend on the outer variables (roots of a condition on that variable alone,
Psi hints free of the outer variables, kinks in that variable alone) are found once per problem
instead of once per outer abscissa.  Checked against independent references:

* a 3-D box cut by ``[tanh(z − a) ≤ 0.1]`` (a root found by the grid search, the same at every
  (x, y)) and the simplex ``[x + y + z ≤ s]`` (a root that moves): the volume by hand,
  ``(s³ − (s − t)³)/6`` with ``t = a + atanh(0.1)``;
* the breakpoints :func:`quadrature.nested._nested` uses at an abscissa (fixed, found once, plus moving)
  are exactly those every condition's root finder and every kink function gives there — the
  pre-change computation, written out here;
* a shear ``x + y − c`` (Psi hints that move with x) and a Psi of one variable (hints that do
  not) against the area by hand;
* roots that depend on some of the outer variables only (``x² + z² ≤ r²`` at z's level inside x
  and y) remembered by those (:func:`quadrature.problem._by_outer`): a half cylinder against πr²/2 · 3/2.
"""

from __future__ import annotations

import math

import sympy as sp

from langur.symbolic.pieces import Branch, Condition, Piece, Psi
from langur.symbolic.quadrature.kinks import _breakpoints
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem
from langur.symbolic.quadrature.problem import _by_outer, _depends
from langur.symbolic.quadrature.roots import _roots


def _problem(piece, variables, box, at):
    _DONE.clear()
    return piece_problem(piece, variables, box, at)


def _all_breakpoints(p, level, prefix):
    """Every condition's roots, hints and kinks of ``level`` at ``prefix`` (no memo)."""
    lo, hi = p.bounds[level]
    pts, kinks = {lo, hi}, set()
    for c, finder in p.finders(level):
        found = finder(*prefix) if finder is not None else _roots(lambda t, c=c: c.f(*prefix, t), lo, hi)
        pts.update(r for r in found if lo < r < hi)
        if c.hints is not None:
            pts.update(r for r in c.hints(*prefix) if lo < r < hi)
    for kf, roots in p.kinks[level]:
        found = roots(*prefix) if roots is not None else _roots(lambda t, kf=kf: kf(*prefix, t), lo, hi)
        kinks.update(r for r in found if lo < r < hi)
    return pts, kinks


def test_box_cut_by_a_fixed_transcendental_condition_and_a_moving_plane():
    x, y, z, a, s = sp.symbols("x y z a s")
    piece = Piece((Condition(sp.Rational(1, 10) - sp.tanh(z - a)), Condition(s - x - y - z)), sp.Integer(1))
    for av, sv in (("0.3", "0.8"),):
        prob = _problem(piece, [x, y, z], [(0, 1), (0, 1), (0, 1)], {a: sp.Rational(av), s: sp.Rational(sv)})
        val, err = integrate_problem(prob)
        t, sf = float(av) + math.atanh(0.1), float(sv)
        assert t < sf <= 1  # the section at height z is the triangle x + y ≤ s − z ≤ 1
        exact = (sf ** 3 - (sf - t) ** 3) / 6  # ∫_0^t (s − z)²/2 dz
        assert abs(val - exact) <= err + 1e-12
        # the tanh condition's root was found once for the innermost level, not per (x, y)
        fixed_pts, _ = prob.fixed[2]
        assert len(fixed_pts) == 1 and abs(next(iter(fixed_pts)) - t) <= 1e-12
        for prefix in ((0.1, 0.2), (0.35, 0.05), (0.0, 0.7)):
            moving, kinks = _breakpoints(prob, 2, prefix, True)
            fixed = prob.fixed[2]
            assert ({*prob.bounds[2], *fixed[0], *moving}, kinks | fixed[1]) == _all_breakpoints(prob, 2, prefix)


def test_breakpoints_split_is_exact_at_every_level_of_a_disc_in_a_slab():
    x, y, z, r = sp.symbols("x y z r")
    piece = Piece((Condition(r ** 2 - x ** 2 - z ** 2), Condition(z - sp.Rational(1, 5)),
                   Condition(sp.Rational(3, 4) - y)), x + y)
    prob = _problem(piece, [x, y, z], [(-1, 1), (0, 1), (0, 1)], {r: sp.Rational(7, 10)})
    val, err = integrate_problem(prob)
    # ∫∫_{x² + z² ≤ r², z ≥ 0.2} ∫_0^{3/4} (x + y) dy: the x term vanishes by symmetry, so
    # (3/4)²/2 · area of the disc's cap above z = 0.2 (the circular segment)
    rr, h = 0.7, 0.2
    cap = rr ** 2 * math.acos(h / rr) - h * math.sqrt(rr ** 2 - h ** 2)
    assert abs(val - 0.28125 * cap) <= err + 1e-12
    for level, prefixes in ((1, [(0.3,), (-0.6,)]), (2, [(0.3, 0.4), (-0.65, 0.9)])):
        for prefix in prefixes:
            moving, kinks = _breakpoints(prob, level, prefix, True)
            fixed = prob.fixed[level]
            assert ({*prob.bounds[level], *fixed[0], *moving}, kinks | fixed[1]) == \
                _all_breakpoints(prob, level, prefix)


def test_psi_hints_moving_and_fixed():
    x, y, c, u, v = sp.symbols("x y c u v")
    shear = Psi((x, y), (x + y - c, y), (u, v), (Branch(((x, u - v + c), (y, v))),), solved_for=x)
    # solved for x, the condition's root x = c − y moves with y when y is the outer variable
    piece = Piece((Condition(x + y - c, psi=shear),), sp.Integer(1))
    prob = _problem(piece, [y, x], [(0, 1), (0, 1)], {c: sp.Rational(13, 10)})
    assert prob.conds[0].hints_vary is True
    val, err = integrate_problem(prob)
    assert abs(val - 0.7 ** 2 / 2) <= err + 1e-12  # the triangle above x + y = 1.3
    one = Psi((x,), (x - c,), (u,), (Branch(((x, u + c),)),), solved_for=x)
    piece = Piece((Condition(x - c, psi=one), Condition(y - x)), sp.Integer(1))
    prob = _problem(piece, [y, x], [(0, 1), (0, 1)], {c: sp.Rational(1, 4)})
    assert prob.conds[0].hints_vary is False  # x = c at every y: found once
    val, err = integrate_problem(prob)
    assert abs(val - 0.75 ** 2 / 2) <= err + 1e-12  # c ≤ x ≤ y ≤ 1


def test_roots_remembered_by_the_outer_variables_they_depend_on():
    calls = []

    def roots(x, y):
        calls.append((x, y))
        return [x / 2]

    by_x = _by_outer(roots, (0,), 2)  # at z's level inside x and y, a function of x only
    assert by_x(0.5, 0.1) == [0.25] and by_x(0.5, 0.7) == [0.25] and by_x(0.3, 0.7) == [0.15]
    assert calls == [(0.5, 0.1), (0.3, 0.7)]  # computed once per value of x
    assert _by_outer(roots, (0, 1), 2) is roots  # depends on every outer variable: not remembered
    x, y, z = sp.symbols("x y z")
    assert _depends(x ** 2 + z ** 2, [x, y, z], 2) == (0,)
    assert _depends(y - z, [x, y, z], 2) == (1,)
    assert _depends(None, [x, y, z], 2) == (0, 1)


def test_cylinder_in_a_box_whose_roots_skip_the_middle_variable():
    x, y, z, r = sp.symbols("x y z r")
    # [x² + z² ≤ r²]·(y + 1) on [−1, 1] × [0, 1] × [0, 1]: its roots in z depend on x, not y;
    # ∫₀¹ (y + 1) dy = 3/2 times the area πr²/2 of the half disc z ≥ 0
    piece = Piece((Condition(r ** 2 - x ** 2 - z ** 2),), y + 1)
    prob = _problem(piece, [x, y, z], [(-1, 1), (0, 1), (0, 1)], {r: sp.Rational(3, 5)})
    val, err = integrate_problem(prob)
    assert abs(val - 1.5 * math.pi * 0.36 / 2) <= err + 1e-12
    for prefix in ((0.2, 0.3), (0.2, 0.9), (-0.5, 0.1)):
        moving, kinks = _breakpoints(prob, 2, prefix, True)
        fixed = prob.fixed[2]
        assert ({*prob.bounds[2], *fixed[0], *moving}, kinks | fixed[1]) == _all_breakpoints(prob, 2, prefix)
