"""Issue 15 (exact16q): the quadrature cross-check's crossings of two conditions of degree 1 in the
eliminated variable (the stylization kernel's half-planes and box sides) without sympy's
``resultant`` and ``sqf_part``, and no resultant for a pair free of the variable kept.

The reference is the old computation itself, run here by sympy's public functions: the square-free
part in ``w`` of ``sympy.resultant(e1, e2, v)`` (``kinks._square_free_part``, which calls
``sympy.sqf_part``), compared by ``srepr`` (the same expression tree, so the same compiled kink
function and the same breakpoints, bit for bit).
"""

from __future__ import annotations

import itertools
import math
import random

import pytest
import sympy as sp
from scipy import integrate as si

import langur.symbolic.quadrature.kinks as kinks
from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem

ax, ay, bx, by, cx, cy, px, py, h, x, y = sp.symbols("ax ay bx by cx cy px py h x y", real=True)
a, b, c, d, u = sp.symbols("a b c d u", real=True)

#: The stylization kernel's half-planes and box sides (examples/stylize/quadratic.lgr), in y.
STYLIZE = [(-bx + cx) * (-by + y) - (-bx + x) * (-by + cy), (ax - cx) * (-cy + y) - (ay - cy) * (-cx + x),
           (-ax + bx) * (-ay + y) - (-ax + x) * (-ay + by), -py + y, h + py - y]


def _reference(e1: sp.Expr, e2: sp.Expr, v: sp.Symbol, w: sp.Symbol) -> sp.Expr:
    """The old answer: sympy's resultant, then its square-free part in ``w`` (or the resultant)."""
    return kinks._square_free_part(sp.sympify(sp.resultant(e1, e2, v)), w)[0]


@pytest.fixture(autouse=True)
def _fresh_memos(monkeypatch):
    for name in ("_PAIRS", "_SQUARE_FREE", "_CROSSES"):
        monkeypatch.setattr(kinks, name, {})


def _forbid_resultant(monkeypatch):
    def forbidden(*args, **kwargs):
        raise AssertionError("sympy's resultant or sqf_part asked for two affine conditions")
    monkeypatch.setattr(kinks.sp, "resultant", forbidden)
    monkeypatch.setattr(kinks.sp, "sqf_part", forbidden)


def test_stylize_pairs_without_resultant(monkeypatch):
    pairs = [(e1, e2) for e1, e2 in itertools.permutations(STYLIZE, 2)
             if x in e1.free_symbols or x in e2.free_symbols]
    want = {pair: _reference(*pair, y, x) for pair in pairs}
    # the triangle's corners (x = ax, bx, cx) and its edges met by the box's sides in y
    assert {want[STYLIZE[0], STYLIZE[1]], want[STYLIZE[1], STYLIZE[2]], want[STYLIZE[0], STYLIZE[2]]} \
        == {x - cx, x - ax, x - bx}
    _forbid_resultant(monkeypatch)
    for (e1, e2), r in want.items():
        got = kinks._crossing(e1, e2, y, x)
        assert sp.srepr(got) == sp.srepr(r), (e1, e2)


def _random_poly(rng: random.Random, symbols: list, degree: int, terms: int) -> sp.Expr:
    out = sp.Integer(0)
    for _ in range(terms):
        m = sp.Integer(rng.choice([-3, -2, -1, 1, 1, 2, 5]))
        for _ in range(rng.randint(0, degree)):
            m *= rng.choice(symbols)
        out += m
    return out


def _random_pairs(rng: random.Random, n: int):
    """Conditions A·y + C·x + D (A, C, D random polynomials in some of a, b, c, d, u), some times a
    common factor (a content: 2, −1, a, a − u, 1 − 3au) or expanded; and a few others: rational
    coefficients (ℚ[…], left to sympy), x² (a resultant of degree 2 in x, left to sympy), no x."""
    pool = [a, b, c, d, u]
    for _ in range(n):
        others = pool[: rng.randint(1, 5)]
        common = rng.choice([1, 1, 1, 2, -1, others[0], others[0] - others[-1], 1 - 3 * others[0] * others[-1]])

        def affine(others=others, common=common):
            e = (_random_poly(rng, others, 2, rng.randint(1, 3)) * y + _random_poly(rng, others, 1, rng.randint(1, 3)) * x
                 + _random_poly(rng, others, 2, rng.randint(0, 3)))
            return common * e if rng.random() < 0.5 else e
        e1, e2 = affine(), affine()
        kind = rng.random()
        if kind < 0.1:
            e1 = sp.expand(e1)
        elif kind < 0.2:
            e2 = e2 + sp.Rational(1, 3) * x
        elif kind < 0.3:
            e2 = e2 + x ** 2
        elif kind < 0.35:
            e1 = e1.xreplace({x: 1})
        yield e1, e2


def test_random_affine_pairs_match_sympy():
    rng = random.Random(16)
    checked = shortcut = 0
    for e1, e2 in _random_pairs(rng, 45):
        for f1, f2 in ((e1, e2), (e2, e1)):
            if not (kinks._crosses(f1, y) and kinks._crosses(f2, y)):
                continue
            want = _reference(f1, f2, y, x)
            shortcut += kinks._linear_crossing(f1, f2, y, x) is not None
            kinks._PAIRS.clear()
            got = kinks._crossing(f1, f2, y, x)
            assert sp.srepr(got) == sp.srepr(want), (f1, f2, got, want)
            checked += 1
    assert checked >= 80 and shortcut >= 50  # (most pairs go the new way; the others through sympy)


def test_shortcut_declines_what_it_does_not_cover():
    # rational coefficients (the domain ℚ[…]), a resultant of degree 2 in x, a float, degree 2 in y
    assert kinks._linear_crossing(a * y + x / 3, y - b, y, x) is None
    assert kinks._linear_crossing(a * y + x ** 2, y - b, y, x) is None
    assert kinks._linear_crossing(a * y + sp.Float("0.5") * x, y - b, y, x) is None
    assert kinks._linear_crossing(y ** 2 - x, y - b, y, x) is None
    for e1, e2 in ((a * y + x / 3, y - b), (a * y + x ** 2, y - b), (y ** 2 - x, y - b)):
        assert sp.srepr(kinks._crossing(e1, e2, y, x)) == sp.srepr(_reference(e1, e2, y, x))


class _Cond:
    def __init__(self, e):
        self.expr = self.sym = e


class _Problem:
    """What :func:`kinks._crossings` reads of a problem: its variables and the next level's conditions."""

    def __init__(self, conds):
        self.syms, self.at, self._conds = [x, y], dict.fromkeys([ax, ay, bx, by, cx, cy, px, py, h], 0.5), conds

    def here(self, level):
        return self._conds


def test_pair_free_of_the_kept_variable_not_asked(monkeypatch):
    asked = []
    crossing = kinks._crossing

    def spy(e1, e2, v, w):
        asked.append((e1, e2))
        return crossing(e1, e2, v, w)
    monkeypatch.setattr(kinks, "_crossing", spy)
    problem = _Problem([_Cond(e) for e in STYLIZE])
    out = kinks._crossings(problem, 0, parametric=True)
    # the box's two sides in y are free of x: their resultant (h) is too, and was dropped anyway
    assert (STYLIZE[3], STYLIZE[4]) not in asked and len(asked) == 9
    want = []
    for e1, e2 in itertools.combinations(STYLIZE, 2):
        r = _reference(e1, e2, y, x)
        if x in r.free_symbols:
            want.append(r)
    assert [sp.srepr(r) for r in out] == [sp.srepr(r) for r in want]



def test_kinks_with_polynomial_roots_are_not_compiled(monkeypatch):
    # the lens of test_quadrature_speed: [y ≥ x²]·[(1 + x)/2 − y ≥ 0]·eˣ·cos y over [−1, 1]×[0, 2];
    # its kinks in x (the parabola's vertex, the crossings x = −1/2 and x = 1) have polynomial roots
    compiled = []
    lambdify = kinks._lambdify

    def spy(symbols, expr, at):
        compiled.append(sp.sympify(expr))
        return lambdify(symbols, expr, at)
    monkeypatch.setattr(kinks, "_lambdify", spy)
    monkeypatch.setattr(kinks, "_KINKS", {})
    px, py = sp.symbols("x y")
    piece = Piece((Condition(py - px ** 2), Condition((1 + px) / 2 - py)), sp.exp(px) * sp.cos(py))
    _DONE.clear()
    prob = piece_problem(piece, [px, py], [(-1, 1), (0, 2)], {})
    val, err = integrate_problem(prob)
    found = sorted(r for _, roots in prob.kinks[0] if roots is not None for r in roots())
    assert any(abs(r + 0.5) < 1e-12 for r in found) and any(abs(r - 1) < 1e-12 for r in found)
    assert all(f is None for f, roots in prob.kinks[0] if roots is not None) and compiled == []
    # the value: ∫_{−1/2}^{1} eˣ (sin((1 + x)/2) − sin(x²)) dx by scipy, independently of the kinks
    ref = si.quad(lambda t: math.exp(t) * (math.sin((1 + t) / 2) - math.sin(t * t)), -0.5, 1, epsabs=1e-13)[0]
    assert abs(val - ref) <= err + 1e-12
