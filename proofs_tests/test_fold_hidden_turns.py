"""Two turns of a fold curve closer than the fold grid's cell (``quadrature.foldcurve``, issue 18).

The outer kinks of a delta through an implicit root in two coordinates (``folds``) are where the
fold curve turns: :func:`_kink_functions` finds them from sympy's critical points, and
:func:`_add_fold_turns` / :func:`_add_fold_guards` by the sign changes of the guard at its critical
points on a grid of :data:`FOLD_TURN_GRID` cells in the outer variable, so that they do not hang on
sympy.  A tiny closed loop of the fold curve (the zero set of a condition near a nondegenerate
minimum: ``[z³ − zy + 3(x − 0.3)²(1 + x) + 3(y − 0.5)²(1 + y) ≥ a]`` with a 10⁻⁶ above the minimum)
has its two turns in one cell: the grid saw no sign change, and without sympy's critical points the
outer quadrature saw the inner integral 0 at every abscissa and lost the loop's part (1.3·10⁻³ of
d/da, with an error bound of 1.6·10⁻⁷).  The grid's values are now searched for hidden pairs like
:func:`_roots`' (extremum by bounded Brent, then brentq on its sides).  The reference is by hand:
∫∫ over {A(y − y₀)² + B(z − z₀)² ≤ ε} of (ε − A(y − y₀)² − B(z − z₀)²)^(−1/2) = 2π√ε / √(AB).
"""

from __future__ import annotations

import math

import pytest
import sympy as sp

from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature import kinks
from langur.symbolic.quadrature.foldcurve import FOLD_TURN_GRID, _fold_grid_sign_changes
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import piece_problem

EPS, A, B = 1e-6, 4.0, 1.0
Y0 = (300 + 0.4) / FOLD_TURN_GRID  # inside a cell of [0, 1], both turns too
Z0 = 0.4


def test_a_pair_of_sign_changes_inside_one_cell_is_found():
    half = math.sqrt(EPS / A)
    assert 2 * half < 1.0 / FOLD_TURN_GRID
    found = sorted(_fold_grid_sign_changes(lambda x: ([EPS - A * (x - Y0) ** 2],), 0.0, 1.0))
    assert found == pytest.approx([Y0 - half, Y0 + half], abs=1e-12)
    # a minimum above 0 (no crossing) and a pair of a minimum below 0 (the grid sees it) add nothing
    assert _fold_grid_sign_changes(lambda x: ([(x - Y0) ** 2 + EPS],), 0.0, 1.0) == []
    wide = sorted(_fold_grid_sign_changes(lambda x: ([(x - 0.5) ** 2 - 0.01],), 0.0, 1.0))
    assert wide == pytest.approx([0.4, 0.6], abs=1e-12)


def test_a_loop_of_the_fold_curve_inside_one_cell_is_integrated(monkeypatch):
    # without sympy's critical points (its solve given up), the fold grid alone must find the turns
    monkeypatch.setattr(kinks, "_critical_points", lambda e, v: [])
    y, z = sp.symbols("y z", real=True)
    c = sp.Float(EPS) - sp.Float(A) * (y - sp.Float(Y0)) ** 2 - sp.Float(B) * (z - sp.Float(Z0)) ** 2
    prob = piece_problem(Piece((Condition(c),), 1 / sp.sqrt(c)), [y, z], [(0, 1), (0, 1)], {})
    prob.folds, prob.vweight = True, None  # as a delta through an implicit root (deltaproblems)
    val, err = integrate_problem(prob)
    hand = 2 * math.pi * math.sqrt(EPS) / math.sqrt(A * B)
    assert abs(val - hand) <= err + 1e-9, (val, err, hand)
    assert err < 0.05 * hand  # (the fold's allowances: its weight is 1/√ at the whole loop)
