"""The quadrature's fast paths (issue 13, campaign throughput) against independent references.

* :func:`polynomial_roots` (breakpoints of polynomial conditions: linear and quadratic in closed
  form) against mpmath's ``polyroots`` at 50 digits on seeded random well-conditioned polynomials;
* :func:`_gk21_panel` / :func:`_first_panel` (one vectorized 21-point Gauss–Kronrod panel for
  the innermost integrals) against scipy's ``quad`` (QUADPACK's ``dqagse``): where ``quad`` stops
  after its first panel (21 evaluations) the fast path gives its value and error estimate, and
  where the fast path declines ``quad`` needed more panels; the rule itself against
  numpy's Gauss–Legendre nodes and its exactness on polynomials of degree ≤ 31;
* whole integrals with and without the fast path agree within their error bounds.
"""

from __future__ import annotations

import math
import warnings

import mpmath
import numpy as np
import pytest
import sympy as sp
from scipy import integrate as si

from langur.symbolic import quadrature as q
from langur.symbolic.pieces import Condition, Piece
from langur.symbolic.quadrature import kinks as kink_module
from langur.symbolic.quadrature import nested, pieceproblems
from langur.symbolic.quadrature.gausskronrod import WG, XGK, _first_panel, _gk21_panel
from langur.symbolic.quadrature.kinks import _KINKS
from langur.symbolic.quadrature.nested import integrate_problem
from langur.symbolic.quadrature.pieceproblems import _DONE, piece_problem
from langur.symbolic.quadrature.roots import polynomial_roots


def _reference_roots(cs):
    mpmath.mp.dps = 50
    k = next(i for i, c in enumerate(cs) if c != 0)
    rs = mpmath.polyroots([mpmath.mpf(c) for c in cs[k:]], maxsteps=200, extraprec=200)
    return sorted(float(mpmath.re(r)) for r in rs if abs(mpmath.im(r)) < mpmath.mpf(10) ** -30)


def test_polynomial_roots_match_mpmath():
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(600):
        d = int(rng.integers(1, 5))
        cs = [float(c) for c in rng.normal(size=d + 1) * 10.0 ** rng.integers(-3, 4, size=d + 1)]
        if rng.random() < 0.15:
            cs = [0.0] + cs  # a leading exact zero: one degree less
        nz = [c for c in cs if c != 0]
        if len(nz) >= 3 and len(cs) - cs.index(nz[0]) == 3:
            a, b, c = cs[-3:]
            if abs(b * b - 4 * a * c) < 1e-6 * (b * b + abs(4 * a * c)):
                continue  # near a double root: ill-conditioned for any method
        if len(cs) - cs.index(nz[0]) > 3:
            continue  # numpy.roots as before: not the closed forms under test
        ours, ref = sorted(polynomial_roots(cs)), _reference_roots(cs)
        assert len(ours) == len(ref), (cs, ours, ref)
        for x, y in zip(ours, ref):
            assert abs(x - y) <= 1e-13 * max(1.0, abs(y)), (cs, ours, ref)
        checked += 1
    assert checked > 300


def test_polynomial_roots_edge_cases():
    assert polynomial_roots([0.0, 0.0, 3.0]) == []  # a constant
    assert polynomial_roots([2.0, -1.0]) == [0.5]
    assert sorted(polynomial_roots([1.0, 0.0, -4.0])) == [-2.0, 2.0]
    assert polynomial_roots([1.0, 0.0, 4.0]) == []  # x² + 4: no real root
    assert polynomial_roots([1.0, -2.0, 1.0]) == [1.0, 1.0]  # a double root
    assert polynomial_roots([1.0, 0.0, 0.0]) == [0.0, 0.0]
    assert polynomial_roots([1.0, math.nan, 0.0]) == []
    cubic = sorted(polynomial_roots([1.0, -6.0, 11.0, -6.0]))  # numpy.roots: (x−1)(x−2)(x−3)
    assert np.allclose(cubic, [1.0, 2.0, 3.0], rtol=0, atol=1e-12)


def test_gauss_kronrod_rule():
    gx, gw = np.polynomial.legendre.leggauss(10)
    assert np.allclose(sorted(XGK[1:10:2]), gx[gx > 0], rtol=0, atol=1e-15)
    assert np.allclose(sorted(WG), sorted(gw[gx > 0]), rtol=0, atol=1e-15)
    for deg in range(32):  # Kronrod-21 integrates every polynomial of degree ≤ 31 exactly on [-1, 1]
        def f(t, deg=deg):
            return t ** deg + 0.5 * t
        x = np.array(XGK[:10])
        res, _, _ = _gk21_panel(np.concatenate([f(-x), f(x), [f(0.0)]]), 1.0)
        exact = 0.0 if deg % 2 else 2.0 / (deg + 1)
        assert abs(res - exact) <= 1e-14, deg


def test_first_panel_is_quadpack_first_panel():
    rng = np.random.default_rng(3)
    taken = declined = 0
    for _ in range(400):
        k, c, d = rng.normal(size=3) * [3, 1, 2]

        def f(t, k=k, c=c, d=d):
            return np.exp(k * t) * np.cos(c * t + d) + t ** 2
        a = float(rng.uniform(-2, 1))
        b = a + float(rng.uniform(1e-3, 4))
        eps = float(10.0 ** rng.integers(-13, -7))
        fast = _first_panel(f, (), a, b, eps)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            val, err, info = si.quad(lambda t: float(f(t)), a, b, epsabs=eps, epsrel=eps, limit=100,
                                     full_output=1)[:3]
        if fast is None:
            declined += 1
            assert info["neval"] > 21 or err > max(eps, eps * abs(val))  # more panels, or roundoff (ier 2)
            continue
        taken += 1
        assert info["neval"] == 21
        assert abs(fast[0] - val) <= 1e-14 * max(1.0, abs(val))
        assert abs(fast[1] - err) <= 1e-3 * max(err, eps)  # the estimate: a difference of close sums
    assert taken > 100 and declined > 10


def test_first_panel_declines_non_finite():
    assert _first_panel(lambda t: 1.0 / t, (), -1.0, 1.0 + 1e-9, 1e-10) is None
    assert _first_panel(lambda t: np.sqrt(t), (), -0.5, 1.0, 1e-10) is None  # NaN below 0


@pytest.mark.parametrize("weight, conds", [
    ("exp(x*y) * sin(a*x + y)", ["y - x**2 + a", "a + 0.5 - x - y"]),
    ("(x + 1.5)**1.5 * cos(y)", ["a + 0.55 - x**2 - y**2"]),
    ("sqrt(y - x)", ["y - x"]),  # not finite-friendly at the edge: quad's path
])
def test_integrals_same_with_and_without_fast_path(weight, conds, monkeypatch):
    x, y, a = sp.symbols("x y a")
    piece = Piece(tuple(Condition(sp.sympify(c, locals={"a": a})) for c in conds), sp.sympify(weight, locals={"a": a}))
    box = [(-1, 1), (0, 2)]
    at = {a: sp.Rational(37, 100)}
    fast = q.quad_pieces([piece], [x, y], box, at)
    monkeypatch.setattr(nested, "_first_panel", lambda *args: None)
    monkeypatch.setattr(pieceproblems, "_DONE", {})  # integrated again, not remembered
    slow = q.quad_pieces([piece], [x, y], box, at)
    assert abs(fast[0] - slow[0]) <= fast[1] + slow[1]
    assert math.isfinite(fast[0]) and fast[1] < 1e-6


def test_pieces_remembered_only_for_the_same_parameter_values():
    # ∫∫ [y ≥ x² − a]·e^{xy} and ∫∫ cos(b·y): at points shifted along a, the second is the same
    # integral (remembered, the same numbers), the first is integrated again (and changes)
    x, y, a, b = sp.symbols("x y a b")
    p1 = Piece((Condition(y - x ** 2 + a),), sp.exp(x * y))
    p2 = Piece((), sp.cos(b * y))
    box = [(-1, 1), (0, 2)]
    _DONE.clear()
    first = [q.quad_pieces([p], [x, y], box, {a: 0.3, b: 0.7}) for p in (p1, p2)]
    assert len(_DONE) == 2
    second = [q.quad_pieces([p], [x, y], box, {a: 0.301, b: 0.7}) for p in (p1, p2)]
    assert len(_DONE) == 3  # p2's key holds b only
    assert second[1] == first[1] and second[0][0] != first[0][0]
    reference = si.quad(lambda t: math.cos(0.7 * t), 0, 2)[0] * 2  # ∫₋₁¹ dx · ∫₀² cos(0.7 y) dy
    assert abs(first[1][0] - reference) <= 1e-9


def _reference_lens():
    # ∫∫ [y ≥ x²]·[(1 + x)/2 − y ≥ 0]·eˣ·cos y over [−1, 1]×[0, 2]: the parabola and the line cross at
    # x = −1/2 and x = 1, so it is ∫_{−1/2}^{1} eˣ (sin((1 + x)/2) − sin(x²)) dx (mpmath, 30 digits)
    mpmath.mp.dps = 30
    return float(mpmath.quad(lambda t: mpmath.e ** t * (mpmath.sin((1 + t) / 2) - mpmath.sin(t ** 2)),
                             [-0.5, 1]))


def test_crossings_of_two_conditions_are_breakpoints(monkeypatch):
    x, y = sp.symbols("x y")
    piece = Piece((Condition(y - x ** 2), Condition((1 + x) / 2 - y)), sp.exp(x) * sp.cos(y))
    box = [(-1, 1), (0, 2)]
    _DONE.clear()
    prob = piece_problem(piece, [x, y], box, {})
    val, err = integrate_problem(prob)
    kinks = [r for _, roots in prob.kinks[0] if roots is not None for r in roots()]
    assert any(abs(r + 0.5) < 1e-12 for r in kinks)  # the crossing x = −1/2, from the resultant
    ref = _reference_lens()
    assert abs(val - ref) <= err + 1e-12
    monkeypatch.setattr(kink_module, "_crossings", lambda p, level, parametric=False: [])  # quad subdivides towards it instead
    _KINKS.clear()
    val2, err2 = integrate_problem(piece_problem(piece, [x, y], box, {}))
    assert abs(val2 - ref) <= err2 + 1e-12


def test_conditions_meeting_a_level_are_breakpoints():
    # [sqrt(y + 2) ≤ 1.71]·[x² + (y − 0.7)² ≤ 0.3]: the circle meets y = 1.71² − 2 at two x's
    x, y = sp.symbols("x y")
    level = 1.71 ** 2 - 2
    piece = Piece((Condition(1.71 - sp.sqrt(y + 2)), Condition(0.3 - x ** 2 - (y - 0.7) ** 2)), sp.Integer(1))
    prob = piece_problem(piece, [x, y], [(0, 1), (0, 1)], {})
    val, err = integrate_problem(prob)
    kinks = [r for _, roots in prob.kinks[0] if roots is not None for r in roots()]
    meet = math.sqrt(0.3 - (level - 0.7) ** 2)
    assert any(abs(r - meet) < 1e-9 for r in kinks)
    # the area of the disc's part with 0 ≤ x, 0 ≤ y ≤ level, by the exact segment formula
    def below(h):  # area of {x ≥ 0, (x, y) in the disc, y − 0.7 ≤ h}: half-disc slice
        r2 = 0.3
        return 0.5 * (r2 * math.asin(h / math.sqrt(r2)) + h * math.sqrt(r2 - h * h)) + math.pi * r2 / 4
    ref = below(level - 0.7) - below(0.0 - 0.7) if 0.7 ** 2 < 0.3 else below(level - 0.7)
    assert abs(val - ref) <= err + 1e-12


def test_a_resultant_sympy_cannot_compute_leaves_the_pair_to_quad():
    # sympy's resultant of (x − 0.83)² + y² − 0.3 and (y − 1.66)² − 0.25 with float coefficients
    # raised PolynomialDivisionFailed (the mutation campaign's eighth program of seed 8): the pair
    # is then only quad's to subdivide, and the value still matches mpmath's.
    x, y = sp.symbols("x y")
    circle, band = (x - 0.83) ** 2 + y ** 2 - 0.3, (y - 1.66) ** 2 - 0.25
    piece = Piece((Condition(circle), Condition(band)), sp.cos(1.66 * x - 2))
    _DONE.clear()
    _KINKS.clear()
    val, err = q.quad_pieces([piece], [x, y], [(-0.17, 1), (-1, 1)], {})
    # outside the disc (the band's condition holds for every y ≤ 1 since (y − 1.66)² ≥ 0.4356):
    # ∫ cos(1.66x − 2)·(2 − chord(x)) dx, chord = 2√(0.3 − (x − 0.83)²) where it is real
    mpmath.mp.dps = 30
    r = mpmath.sqrt(mpmath.mpf("0.3"))
    full = mpmath.quad(lambda t: 2 * mpmath.cos(mpmath.mpf("1.66") * t - 2), [-0.17, 1])
    disc = mpmath.quad(lambda t: mpmath.cos(mpmath.mpf("1.66") * t - 2) * 2 * mpmath.sqrt(r ** 2 - (t - mpmath.mpf("0.83")) ** 2),
                       [mpmath.mpf("0.83") - r, 1])
    assert abs(val - float(full - disc)) <= err + 1e-10
