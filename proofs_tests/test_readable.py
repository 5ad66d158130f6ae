"""Readable closed forms (langur.symbolic.readable, issue 14): on every example, each case of ⟦p⟧
(and of ⦇p⦈ for fig1/fig9/risk) agrees with the engine's closed form at ≥ 5 parameter points inside
the case, and the case of the evaluation point gives the engine's (quadrature-checked) value."""

from __future__ import annotations

import math
import random

import mpmath
import pytest
import sympy as sp
from paths import EXAMPLES

from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.exact import readable_of
from langur.frontend import load
from langur.sympy_bridge import at_symbols, symbol

FILES = sorted(p for p in [*EXAMPLES.glob("*.lgr"), *EXAMPLES.glob("degenerate/*.lgr")]
               if p.name != "densities.lgr")


def _points(case, rd, at):
    """Five exact parameter points inside ``case``."""
    if rd.parameter is not None and case.interval is not None:
        iv = case.interval
        if isinstance(iv, sp.FiniteSet):
            return [{rd.parameter: v} for v in iv]
        lo, hi = iv.inf, iv.sup
        lo = hi - 10 if lo is sp.S.NegativeInfinity else lo
        hi = lo + 10 if hi is sp.S.Infinity else hi
        return [{rd.parameter: lo + (hi - lo) * sp.Rational(k, 6)} for k in range(1, 6)]
    base = at_symbols(at)
    pts = []
    if case.point is not None:  # several parameters: around the case's inner point, near and far
        rng = random.Random(len(str(case.condition)))
        for _ in range(400):
            scale = rng.choice((sp.Rational(1, 100), sp.Rational(1, 2), 3, 40))
            pt = {**base, **{s: v + scale * sp.Rational(rng.randint(-1000, 1000), 1000)
                             for s, v in case.point.items()}}
            if case.condition.subs(pt) == sp.true:
                pts.append(pt)
            if len(pts) == 5:
                return pts
        return pts
    for k in range(1, 40):
        pt = {s: v + sp.Rational((-1) ** (k + i) * ((k * (i + 3)) % 7), 1000) for i, (s, v) in enumerate(base.items())}
        if case.condition.subs(pt) == sp.true:
            pts.append(pt)
        if len(pts) == 5:
            break
    return pts


def _agree(expr, rd, at, value):
    assert rd.cases
    inside = 0
    syms = sorted(expr.free_symbols, key=str)
    mpmath.mp.dps = 30
    engine_form = sp.lambdify(syms, expr, modules="mpmath")  # Min/Max/Piecewise evaluated as written
    for case in rd.cases:
        pts = _points(case, rd, at)
        assert len(pts) >= (1 if isinstance(case.interval, sp.FiniteSet) else 5), case
        for pt in pts:
            engine = complex(engine_form(*[mpmath.mpf(sp.Rational(pt[s]).p) / sp.Rational(pt[s]).q for s in syms]))
            shown = complex(sp.N(case.expr.subs(pt), 30))
            assert abs(engine - shown) <= 1e-9 * (1 + abs(engine)), (case, pt, engine, shown)
        point = at_symbols(at)
        if case.condition.subs(point) == sp.true:
            inside += 1
            assert math.isclose(float(sp.N(case.expr.subs(point))), value, rel_tol=1e-9, abs_tol=1e-12)
    assert inside == 1 or rd.parameter is None and not at  # the cases are disjoint and cover the point


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.name)
def test_readable_denotation_agrees_on_every_piece(path):
    loaded = load(str(path))
    if loaded.program is None:
        pytest.skip(f"{path.name}: a library module, no program")
    at = loaded.param_values()
    r = denote_program(loaded.program, at)
    if r.expr is None:
        pytest.skip(f"{path.name}: no closed form ({r.method})")
    rd = readable_of(r.expr, at, (r,))
    assert rd is not None, f"{path.name}: no readable form of {r.expr}"
    _agree(r.expr, rd, at, r.value)


@pytest.mark.parametrize("name, wrt", [("fig1.lgr", "theta"), ("fig9.lgr", "theta"), ("risk.lgr", "a")])
def test_readable_derivative_agrees_on_every_piece(name, wrt):
    loaded = load(str(EXAMPLES / name))
    at = loaded.param_values()
    res = ddenote_program(loaded.program, at, {k: int(k == wrt) for k in at})
    rd = readable_of(res.expr, at, (res.regular, res.boundary))
    _agree(res.expr, rd, at, res.value)


def _cases(name):
    loaded = load(str(EXAMPLES / name))
    at = loaded.param_values()
    r = denote_program(loaded.program, at)
    return readable_of(r.expr, at, (r,))


def test_fig1_and_fig9_read_as_the_hand_computed_cases():
    t = symbol("theta")
    rd = _cases("fig1.lgr")  # ∫₀¹ [x ≤ θ] dx = clamp(θ, 0, 1)
    assert [c.interval for c in rd.cases] == [sp.Interval(-sp.oo, 0), sp.Interval.Lopen(0, 1), sp.Interval.open(1, sp.oo)]
    assert [sp.expand(c.expr) for c in rd.cases] == [0, t, 1]
    rd = _cases("fig9.lgr")
    # θ > 2: the whole square, ∫∫ (1 + θ + x + y) = 4(1 + θ); θ ≤ −2: the line misses the square
    assert sp.expand(rd.cases[0].expr) == 0 and sp.expand(rd.cases[-1].expr - 4 * (1 + t)) == 0
    assert [c.interval.sup for c in rd.cases] == [-2, 0, 2, sp.oo]
    for c in rd.cases[1:-1]:  # inside, against the engine's own value at a point of the case
        mid = (c.interval.inf + c.interval.sup) / 2
        loaded = load(str(EXAMPLES / "fig9.lgr"))
        assert math.isclose(float(c.expr.subs(t, mid)), denote_program(loaded.program, {"theta": mid}).value,
                            rel_tol=1e-9)


def _risk_by_quadrature(a, b, mu):
    """R(a, b, mu) of §2, Eq. (2), by mpmath quadrature split at the window's ends (independent of
    the engine): ∫_{-10}^{10} N(x; mu)·[a ≤ x ≤ b]·(N(x; mu) − 2 N(x; 2)) + N(x; 2)² dx."""
    def n(x, m):
        return mpmath.exp(-0.5 * ((x - m) / 5) ** 2)
    lo, hi = max(a, -10), min(b, 10)
    window = mpmath.quad(lambda x: n(x, mu) * (n(x, mu) - 2 * n(x, 2)), [lo, hi]) if lo < hi else 0
    return window + mpmath.quad(lambda x: n(x, 2) ** 2, [-10, 10])


def test_risk_reads_as_the_clipped_window_cases():
    """Three parameters (issue 14): one case per way the window [a, b] meets [-10, 10], the empty
    window "otherwise"; each case's formula against quadrature of the program at two points."""
    a, b, mu = symbol("a"), symbol("b"), symbol("mu")
    rd = _cases("risk.lgr")
    assert rd.complete and len(rd.cases) == 5 and rd.cases[-1].otherwise
    assert not rd.cases[-1].expr.free_symbols  # an empty window: ∫ g² alone
    text = rd.text()
    assert "a <= -10 and -10 <= b <= 10" in text and "-10 <= a <= 10 and b >= 10" in text
    mpmath.mp.dps = 20
    for case in rd.cases:
        for pt in _points(case, rd, {"a": -1, "b": 4, "mu": 1})[:2]:
            want = _risk_by_quadrature(*(mpmath.mpf(sp.Rational(pt[s]).p) / sp.Rational(pt[s]).q
                                         for s in (a, b, mu)))
            assert math.isclose(float(sp.N(case.expr.subs(pt), 20)), float(want), rel_tol=1e-12), (case, pt)


def test_risk_derivative_reads_as_one_case_and_zero():
    """∂R/∂a = −N(a; mu)(N(a; mu) − 2N(a; 2)) where a is an end of a nonempty window inside the box,
    0 elsewhere (by hand: the fundamental theorem of calculus on Eq. (2))."""
    a, mu = symbol("a"), symbol("mu")
    loaded = load(str(EXAMPLES / "risk.lgr"))
    at = loaded.param_values()
    res = ddenote_program(loaded.program, at, {k: int(k == "a") for k in at})
    rd = readable_of(res.expr, at, (res.regular, res.boundary))
    assert len(rd.cases) == 2 and rd.cases[1].otherwise and rd.cases[1].expr == 0
    assert rd.text().splitlines()[0].startswith("-10 < a < 10 and b > a")
    n = lambda m: sp.exp(-sp.Rational(1, 2) * ((a - m) / 5) ** 2)  # noqa: E731
    assert sp.simplify(rd.cases[0].expr + n(mu) * (n(mu) - 2 * n(2))) == 0
