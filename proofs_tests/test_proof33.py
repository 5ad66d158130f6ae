"""The exact engine proves tight bounds (paper §8.2's ⟦p⟧ at a point; branch proof33, bench/history/2026-11-29.md#proof33.

exact32 enclosed a piece's integral by the midpoint rule with an enclosed second derivative: a smooth
one-variable integral got "error estimate 1.3e-10, proved ≤ 3e-08", a two-variable one "proved ≤ 0.77"
on a value of 2.15.  :mod:`langur.symbolic.quadrature.enclosed` now uses the product Gauss–Legendre
rule with its remainder enclosed (``c_n·h^(2n+1)·f^(2n)``) and, on a cell crossed by one condition's
boundary, the measure of ``{c ≥ 0}`` enclosed through the condition's mean-value form.

Values computed independently: by hand (26/81, e − 2, 1/4, 1/8, e^(1/3) − 1), mpmath's quadrature at
30 digits, 2·K₀(1) (∫_ℝ e^(−cosh x) dx, mpmath's Bessel K), and for the curved boundary a one-variable
mpmath quadrature of the inner integral written by hand (the root of y³ + y = ½ − x³ − x by findroot).
"""

from __future__ import annotations

import math
import time

import mpmath
import pytest
import sympy as sp

from langur.enclosures import enclose
from langur.exact import exact_eval
from langur.frontend import load_text
from langur.symbolic import offbox
from langur.symbolic.pieces import Method, Piece
from langur.symbolic.quadrature import enclosed
from langur.symbolic.quadrature.enclosed import CELLS, enclose_integral
from langur.timebox import run_with_timeout

x, y, a = sp.symbols("x y a")
COSH = sp.exp(-(sp.exp(x) + sp.exp(-x)) / 2)


def _mp(f, points):
    with mpmath.workdps(30):
        return float(mpmath.quad(f, points))


SMOOTH = [
    (COSH, (0, 1), lambda: _mp(lambda t: mpmath.exp(-mpmath.cosh(t)), [0, 1])),
    (sp.cos(2 * sp.sin(x)) * sp.exp(-x), (0, 3), lambda: _mp(lambda t: mpmath.cos(2 * mpmath.sin(t)) * mpmath.exp(-t), [0, 3])),
    (sp.exp(-sp.sin(x) ** 2 * x), (0, 2), lambda: _mp(lambda t: mpmath.exp(-mpmath.sin(t) ** 2 * t), [0, 2])),
    (sp.exp(-x ** 2), (0, 2), lambda: math.sqrt(math.pi) / 2 * math.erf(2)),
    (x ** 2, (sp.Rational(1, 3), 1), lambda: 26 / 81),
]


@pytest.mark.parametrize("weight, box, ref", SMOOTH)
def test_smooth_one_variable_integrals_are_proved_to_quadpack_accuracy(weight, box, ref):
    e = enclose_integral([], weight, [x], [box], {}, target=1e-10)
    value = ref()
    assert e.lo <= value <= e.hi
    # exact32 (midpoint rule): 1.7e-08, 3.7e-06, 1.7e-06, …, after all 300 cells
    assert e.hi - e.lo <= 1.1e-10 and e.cells < CELLS


def test_a_moving_end_and_a_condition_in_one_variable():
    e = enclose_integral([a - x], sp.exp(x), [x], [(0, 1)], {a: sp.Rational(1, 3)}, target=1e-10)
    assert e.lo <= math.exp(1 / 3) - 1 <= e.hi and e.hi - e.lo <= 1.1e-10
    e = enclose_integral([], sp.exp(x), [x], [(0, a)], {a: sp.Rational(1, 3)}, target=1e-10)  # [0, a] at a = 1/3
    assert e.lo <= math.exp(1 / 3) - 1 <= e.hi and e.hi - e.lo <= 1.1e-10


@pytest.mark.parametrize("power, exact", [(3, sp.Rational(1, 4)), (7, sp.Rational(1, 8))])
def test_rules_exact_on_polynomials_hold_the_exact_value_after_rounding(power, exact):
    # Gauss–Legendre of n points is exact to degree 2n − 1 (the remainder's derivative is 0): the nodes
    # 1/√3, √(3/7 ± …) are irrational, so only outward rounding keeps the exact rational inside
    e = enclose_integral([], x ** power, [x], [(0, 1)], {}, target=0.0, cells=1)
    assert e.cells == 1 and e.lo <= exact <= e.hi and e.hi - e.lo < 1e-15


def _implicit2d(at_a: float) -> float:
    """∫_{[-1,1]²} [x³ + x + y³ + y ≥ a]·(1 + xy + x): y ≥ r(x), r the root of y³ + y = a − x³ − x,
    the inner integral by hand: (1 + x)(1 − r) + x(1 − r²)/2."""
    def inner(t):
        r = mpmath.findroot(lambda s: s ** 3 + s - (at_a - t ** 3 - t), 0)
        r = min(max(r, -1), 1)
        return (1 + t) * (1 - r) + t * (1 - r * r) / 2
    c = mpmath.findroot(lambda t: t ** 3 + t - (at_a + 2), 1)  # r(x) = −1 from x = c on
    lo = mpmath.findroot(lambda t: t ** 3 + t - (at_a - 2), -1)  # r(x) = 1 until x = lo
    points = [-1] + [p for p in (lo, c) if -1 < p < 1] + [1]
    with mpmath.workdps(20):
        return float(mpmath.quad(inner, points))


def test_two_variable_proofs_are_stronger():
    e = enclose_integral([1 - x - y], sp.exp(x), [x, y], [(0, 1), (0, 1)], {})  # ∫∫_{x+y≤1} eˣ = e − 2
    assert e.lo <= math.e - 2 <= e.hi and e.hi - e.lo < 0.01  # exact32: 0.105
    ref = _implicit2d(0.5)
    assert ref == pytest.approx(2.15293234983, rel=1e-9)  # the exact engine's quadrature (examples/implicit2d.lgr)
    e = enclose_integral([x ** 3 + x + y ** 3 + y - a], 1 + x * y + x, [x, y], [(-1, 1), (-1, 1)], {a: sp.Rational(1, 2)})
    assert e.lo <= ref <= e.hi and e.hi - e.lo < 0.05  # exact32: 0.223
    more = enclose_integral([x ** 3 + x + y ** 3 + y - a], 1 + x * y + x, [x, y], [(-1, 1), (-1, 1)],
                            {a: sp.Rational(1, 2)}, cells=3000)
    assert more.lo <= ref <= more.hi and more.hi - more.lo < 1e-3  # the boundary band is O(h²): exact32 0.022


def test_a_deliberately_wrong_bound_is_caught(monkeypatch):
    """Each ingredient of the proof is needed: drop the rule's remainder, or the mean-value form's
    rest, and some enclosure excludes the true value (so the tests above can fail)."""
    cases = [(w, box, ref()) for w, box, ref in SMOOTH[:3]]
    assert all(enclose_integral([], w, [x], [box], {}, target=1e-10).holds(v) for w, box, v in cases)
    rule = enclosed._gauss_legendre

    def no_remainder(n):
        nodes, _ = rule(n)
        return nodes, mpmath.iv.mpf(0)
    monkeypatch.setattr(enclosed, "_gauss_legendre", no_remainder)
    enclosed._compiled.cache_clear()
    wrong = [enclose_integral([], w, [x], [box], {}, target=1e-14, cells=4) for w, box, _ in cases]
    assert not all(e.holds(v) for e, (_, _, v) in zip(wrong, cases))
    monkeypatch.undo()
    real = enclosed._measure

    def no_rest(c, grad, cell, X, values):  # the affine part alone, as if c were affine
        m = [lo + (hi - lo) / 2 for lo, hi in cell]
        C = c(*(mpmath.iv.mpf(v) for v in m), *values)
        g = [enclosed._mid(z) for z in (gr(*X, *values) for gr in grad)]
        u = [(mpmath.iv.mpf(lo) - v, mpmath.iv.mpf(hi) - v) for (lo, hi), v in zip(cell, m)]
        z = enclosed._half_space(enclosed._mid(C), g, u, mpmath.iv.mpf(0))
        return z if z is not None else real(c, grad, cell, X, values)
    monkeypatch.setattr(enclosed, "_measure", no_rest)
    e = enclose_integral([1 - x * x - y * y], sp.Integer(1), [x, y], [(0, 1), (0, 1)], {}, cells=40)  # π/4
    assert not e.holds(math.pi / 4)
    monkeypatch.undo()
    e = enclose_integral([1 - x * x - y * y], sp.Integer(1), [x, y], [(0, 1), (0, 1)], {}, cells=40)
    assert e.holds(math.pi / 4)


def test_exp_of_a_hugely_negative_interval_is_enclosed_at_once():
    # exp(−e^(10⁶)): mpmath took minutes (on main this stops at the CPU backstop: TimeoutError)
    t = time.process_time()
    z = run_with_timeout(lambda: enclose(sp.exp(-sp.exp(x)), {x: (1e6, 2e6)}), 20, cpu=True)
    assert time.process_time() - t < 5  # (a generous backstop: it takes milliseconds)
    assert z.a == 0 and 0 < z.b < 1e-300
    z = enclose(sp.exp(x), {x: (-2.0, 1.0)})
    assert z.a <= math.exp(-2) <= z.b and z.a > 0 and z.b >= math.e  # ordinary arguments as before


def test_the_cosh_weight_on_a_huge_range_is_proved():
    # (a generous CPU backstop, not a timing: on main this runs for minutes, mpmath's exp(−e^(10⁶)) per cell)
    e = run_with_timeout(lambda: enclose_integral([], COSH, [x], [(-10 ** 6, 10 ** 6)], {}, target=1e-10), 30, cpu=True)
    ref = float(2 * mpmath.besselk(0, 1))
    assert e is not None and e.lo <= ref <= e.hi and e.hi - e.lo <= 1.1e-10  # exact32: no proof (its CPU cap)


def test_one_box_at_helper():
    """offbox's box at a point and the enclosure's are the same helper: numbers, the empty box kept."""
    box = offbox.box_at({x: (0, a), y: (a, 0)}, {a: sp.Rational(1, 2)})
    assert box == {x: (0, sp.Rational(1, 2)), y: (sp.Rational(1, 2), 0)}
    assert offbox.box_at({x: (0, y)}, {}) is None  # an end that moves: no box
    piece = Piece((), x)
    assert offbox.reduced([piece], {x: (1, 0)}, {}) == [piece]  # empty: nothing decided
    assert enclose_integral([], x, [x], [(1, 0)], {}) == enclosed.Enclosed(0.0, 0.0, 0, 0.0, 1)
    assert enclose_integral([], x, [x], [(0, y)], {}) is None


def test_the_piece_is_derived_once_for_every_point():
    enclosed._compiled.cache_clear()
    for value in ("0.2", "0.3", "0.4"):
        e = enclose_integral([a - x], COSH, [x], [(0, 1)], {a: sp.Rational(value)}, target=1e-10)
        ref = _mp(lambda t: mpmath.exp(-mpmath.cosh(t)), [0, mpmath.mpf(value)])
        assert e.lo <= ref <= e.hi and e.hi - e.lo <= 1.1e-10
    info = enclosed._compiled.cache_info()
    assert info.misses == 1 and info.hits == 2


@pytest.mark.parametrize("text", [
    "int ([0, 1]) exp(-(exp(x) + exp(-x))/2) d(x)\n",
    "int ([0, 3]) cos(2*sin(x)) * exp(-x) d(x)\n",
])
def test_the_exact_engine_prints_a_proved_bound(text):
    loaded = load_text(text)
    r = exact_eval(loaded.program, loaded.param_values())
    assert r.method == Method.QUADRATURE and r.proved is not None and r.proved <= r.error
    assert r.how() == f"quadrature, error ≤ {r.error:.3g}"  # main: "error estimate …, proved ≤ 3e-08 / 4e-06"
