"""The fundamental theorem of calculus with its ends taken from inside (``langur.symbolic.definite``).

``∫₀¹ log|x − a| dx`` has the antiderivative ``(x − a)·log(x − a) − x`` on ``x > a``, which at its
lower end ``x = a`` is ``0·log 0``: sympy says NaN, the limit is ``−a``.  The exact engine used to
call such a closed form "singular at the evaluation point" and fall back to quadrature; it now takes
the one-sided limit there and gives the closed form.  Every expected value is worked out by hand
in the test.
"""

from __future__ import annotations

import json
import math

import pytest
import sympy as sp

from langur import exact as api
from langur import frontend
from langur.cli import main
from langur.symbolic import elementary
from langur.symbolic.context import Context
from langur.symbolic.definite import at_end
from langur.symbolic.pieces import Method
from langur.timebox import Deadline


def _exact(text: str, at: dict):
    return api.exact_eval(frontend.load_text(text).program, at)


@pytest.mark.parametrize("a", [0.3, 0.5, 0.9])
def test_log_of_a_distance_has_its_closed_form(a):
    # ∫₀¹ log|x − a| dx = [t log t − t]₀^{1−a} + [t log t − t]₀^{a} = (1 − a) log(1 − a) + a log a − 1
    r = _exact(f"param a = {a}\nint ([0, 1]) log(abs(x - a)) d(x)\n", {"a": a})
    assert r.method is Method.CLOSED_FORM, r.notes
    assert abs(float(r.value) - ((1 - a) * math.log(1 - a) + a * math.log(a) - 1)) <= 1e-12
    assert not r.inconsistent


def test_a_product_with_the_distance():
    # ∫₀¹ (x − a) log|x − a| dx = [t²/2 log|t| − t²/4] from t = −a to 1 − a
    a = 0.3

    def g(t):
        return t * t / 2 * math.log(abs(t)) - t * t / 4

    r = _exact(f"param a = {a}\nint ([0, 1]) (x - a) * log(abs(x - a)) d(x)\n", {"a": a})
    assert r.method is Method.CLOSED_FORM
    assert abs(float(r.value) - (g(1 - a) - g(-a))) <= 1e-12


def test_an_inner_end_at_an_outer_variable():
    # ∫₀¹∫₀¹ log|x − y| dy dx = −3/2 (by hand: 2∫₀¹∫₀^x log(x − y) dy dx = 2∫₀¹ (x log x − x) dx = 2(−1/4 − 1/2));
    # the inner antiderivative at y = x is (x − y) log(x − y) at x − y = 0 (0·∞, limit 0)
    r = _exact("param a = 0.5\nint ([0, 1], [0, 1]) log(abs(x - y)) + a d(x, y)\n", {"a": 0.5})
    assert r.method is Method.CLOSED_FORM
    assert sp.simplify(sp.sympify(r.expr) - (sp.Symbol("a") - sp.Rational(3, 2))) == 0


def test_at_an_end_where_the_choice_of_the_end_is_a_tie_nothing_is_claimed():
    # a = 0: the end Max(0, a) is a tie at the point; no single formula holds on both sides, and the
    # value comes from quadrature (∫₀¹ log x dx = −1), with its bound
    r = _exact("param a = 0\nint ([0, 1]) log(abs(x - a)) d(x)\n", {"a": 0})
    assert abs(float(r.value) + 1) <= r.error + 1e-12


def test_at_end_substitutes_where_nothing_is_indeterminate():
    x, a = sp.symbols("x a")
    ctx = Context({a: sp.Float(0.3, 30)}, Deadline(10), frozenset({a}))
    F = x ** 3 / 3 + a * x
    assert at_end(F, x, sp.Max(0, a), 1, ctx) == F.xreplace({x: sp.Max(0, a)}) and ctx.cell == []
    G = (x - a) * sp.log(x - a) - x  # at x = Max(0, a) = a: the limit −a, claimed where a > 0
    assert at_end(G, x, sp.Max(0, a), 1, ctx) == -a and sp.StrictGreaterThan(a, 0) in ctx.cell


def test_deriv_decides_the_one_sided_derivatives(capsys, tmp_path):
    # ⦇p⦈'s regular part 1/(x − a) is not integrable (X313), but ⟦p⟧ = (1 − a) log(1 − a) + a log a − 1
    # now has its closed form, whose derivative is log a − log(1 − a) on both sides
    f = tmp_path / "logdist.lgr"
    f.write_text("param a = 0.3\nint ([0, 1]) log(abs(x - a)) d(x)\n")
    status = main(["deriv", str(f), "--wrt", "a", "--json"])
    j = json.loads(capsys.readouterr().out)
    d = math.log(0.3) - math.log(0.7)
    assert status == 1 and j["exact"] is None and "X313" in j["undefined"]
    assert j["one_sided"]["exists"] is True
    assert j["one_sided"]["below"] == pytest.approx(d, abs=1e-12) == j["one_sided"]["above"]


def test_a_power_times_a_log_of_the_same_affine_function_has_its_closed_form():
    # ∫₀¹ √x·log x dx = [x^{3/2}(2/3·log x − 4/9)]₀¹ = −4/9 (by hand; hopeless() called it a product
    # of two non-polynomial factors and the piece went to quadrature)
    r = _exact("param a = 0.3\nint ([0, 1]) sqrt(x) * log(x) + a d(x)\n", {"a": 0.3})
    assert r.method is Method.CLOSED_FORM
    assert sp.simplify(sp.sympify(r.expr) - (sp.Symbol("a") - sp.Rational(4, 9))) == 0
    # ∫_a^1 (x − a)² log(x − a) dx = ∫₀^{1−a} t² log t dt = (1 − a)³ log(1 − a)/3 − (1 − a)³/9, written
    # with the guard (the bracket factor [x >= a] * … evaluates log(x − a) at x < a: undefined,
    # LANGUAGE.md §1, §3; test_exact28)
    a = 0.3
    r = _exact(f"param a = {a}\nint ([0, 1]) if x >= a then (x - a)^2 * log(x - a) else 0 d(x)\n", {"a": a})
    assert r.method is Method.CLOSED_FORM
    assert abs(float(r.value) - ((1 - a) ** 3 * math.log(1 - a) / 3 - (1 - a) ** 3 / 9)) <= 1e-12


@pytest.mark.parametrize("w", ["sqrt(x)*log(x)", "(x - a)**(3/2)*log(x - a)**2", "x*sqrt(2*x + 1)*log(2*x + 1)",
                               "log(x)/x", "log(x)**3/x", "x**2*log(3 - x)", "(x + 1)**(-2)*log(x + 1)"])
def test_power_log_antiderivatives_differentiate_back(w):
    x = sp.Symbol("x")
    w = sp.sympify(w)
    F = elementary.power_log_antiderivative(w, x)
    assert F is not None and sp.simplify(sp.diff(F, x) - w) == 0
