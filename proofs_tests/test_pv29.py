"""An integral that does not exist is reported as undefined by the exact engine as a library.

⟦int t d(x⃗)⟧ = ∫ ⟦t⟧ (Fig. 12) needs ⟦t⟧ integrable on the box; a principal value is not an
integral.  ``1/t − 1/(1 − t)`` on [0, 1] diverges at both ends (like 1/t at 0: ∫_ε 1/t = −log ε),
yet its two halves cancel, scipy's ``quad`` converges to 0 without a warning, and the engine
returned ≈ 0 (``langur eval`` said X311 only because the linter ran first).  Closed forms do the
same when the antiderivative is evaluated at the ends: ``x/(x²+y²)²`` on [−1, 1]² (odd in x) gave
0, ``y/(x²+y²)²`` + a gave 4a.  The decision is now ``langur.symbolic.integrability`` (|w| ~ dist^−α
near a set of codimension c is integrable iff α < c), asked by ``langur.denote.require_defined``
after integrating, and by the linter's X311–X313.

Hand values of the integrable ones: ∫₀¹ x^(−1/2) = 2; ∫₀¹ log x = [x log x − x]₀¹ = −1;
∫∫_{[0,1]²} 1/r = 2 ∫₀^{π/4} ∫₀^{sec θ} dr dθ = 2 log(1 + √2); ∫₀¹ 1/x − 1/sin x
= [log x − log tan(x/2)]₀¹ = −log tan(1/2) − log 2 (bounded: 1/x − 1/sin x → 0 at 0).
"""

from __future__ import annotations

import importlib
import math
import warnings

import numpy as np
import pytest
from scipy import integrate

from langur.ddenote import ddenote_program
from langur.denote import denote_program, divergent_where
from langur.exact import ExactUndefined, exact_deriv, exact_eval
from langur.exact_batch import exact_batch
from langur.frontend import load_text
from langur.lint import singular
from langur.symbolic import integrability
from langur.symbolic.decompose import Ctx
from langur.symbolic.quadrature import UndefinedIntegral
from langur.sympy_bridge import at_symbols


def _program(body: str, box: str, variables: str = "x"):
    return load_text(f"param a = 0.5\nint ({box}) {body} d({variables})\n").program


def test_premise_quad_converges_to_the_principal_value_without_a_warning():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an IntegrationWarning would raise
        value, err = integrate.quad(lambda t: 1 / t - 1 / (1 - t), 0, 1)
    assert abs(value) < 1e-10 and err < 1e-8
    # and the integral diverges: ∫_ε^(1/2) 1/t − 1/(1 − t) = log(1/2) − log ε − log(1 − ε) + log(1/2) → ∞
    part, _ = integrate.quad(lambda t: 1 / t - 1 / (1 - t), 1e-12, 0.5)
    assert part == pytest.approx(2 * math.log(0.5) - math.log(1e-12), rel=1e-6) and part > 25


# (body, box, variables, where it blows up): each diverges (α ≥ c at the point)
DIVERGENT = [
    ("1/x - 1/(1 - x)", "[0, 1]", "x", "x = 0"),  # α = 1 at both ends, c = 1 (main: ≈ 0 by quadrature)
    ("a * (1/x - 1/(1 - x))", "[0, 1]", "x", "x = 0"),
    ("tan(pi * (x - a))", "[0, 1]", "x", "x = 0"),  # poles at both ends (main: closed form 0)
    ("1/(x - a)", "[0, 1]", "x", None),  # the pole inside (main: undefined by quadrature)
    ("x/(x^2 + y^2)^2", "[-1, 1], [-1, 1]", "x, y", "(x, y) = (0, 0)"),  # α = 3, c = 2 (main: 0)
    ("y/(x^2 + y^2)^2 + a", "[-1, 1], [-1, 1]", "x, y", "(x, y) = (0, 0)"),  # (main: 4a = 2)
    ("x*y/(x^2 + y^2)^2", "[-1, 1], [-1, 1]", "x, y", "(x, y) = (0, 0)"),  # α = 2 = c (main: 0)
    ("1/(x^2 + y^2)", "[0, 1], [0, 1]", "x, y", None),  # α = 2 at the corner (main: quadrature's)
]


@pytest.mark.parametrize("body, box, variables, where", DIVERGENT)
def test_library_calls_say_undefined(body, box, variables, where):
    p = _program(body, box, variables)
    with pytest.raises(ExactUndefined) as e:
        exact_eval(p, {"a": 0.5})
    with pytest.raises(UndefinedIntegral):
        denote_program(p, {"a": 0.5})
    with pytest.raises(ExactUndefined):
        exact_deriv(p, {"a": 0.5}, {"a": 1}, check=False)
    with pytest.raises(UndefinedIntegral):
        ddenote_program(p, {"a": 0.5}, {"a": 1})
    if where is not None:  # the engine's new reason: the blow-up and its order
        assert "is not integrable: it blows up at " + where in e.value.reason


def test_the_reason_names_the_order_and_the_codimension():
    with pytest.raises(ExactUndefined) as e:
        exact_eval(_program("x/(x^2 + y^2)^2", "[-1, 1], [-1, 1]", "x, y"), {"a": 0.5})
    assert "like dist^-3 near a set of codimension 2" in e.value.reason


def test_a_derivative_whose_regular_part_is_a_principal_value_is_undefined():
    # ⟦p⟧ = ∫₀¹ log(x + a) + log(1 − x − a) exists at a = 0 (= −2); ⦇p⦈'s regular part in a is
    # 1/(x + a) − 1/(1 − x − a) = 1/x − 1/(1 − x): no integral (X313), though quadrature gave ≈ 0
    p = load_text("param a = 0\nint ([0, 1]) log(x + a) + log(1 - x - a) d(x)\n").program
    assert exact_eval(p, {"a": 0}).value == pytest.approx(-2.0, abs=1e-8)
    with pytest.raises(ExactUndefined) as e:
        exact_deriv(p, {"a": 0}, {"a": 1}, check=False)
    assert e.value.reason.startswith("the regular part of ⦇t⦈")


@pytest.mark.parametrize("body, box, variables, value, derivative", [
    ("a / sqrt(x)", "[0, 1]", "x", 0.5 * 2, 2.0),  # α = 1/2 < 1
    ("a * log(x)", "[0, 1]", "x", -0.5, -1.0),
    ("1/x - 1/sin(x) + a", "[0, 1]", "x", -math.log(math.tan(0.5)) - math.log(2) + 0.5, 1.0),
    ("a / sqrt(x^2 + y^2)", "[0, 1], [0, 1]", "x, y", 0.5 * 2 * math.log(1 + math.sqrt(2)),
     2 * math.log(1 + math.sqrt(2))),  # α = 1 < 2
    ("a * x / (x^2 + y^2)", "[0, 1], [0, 1]", "x, y", 0.5 * math.pi / 4 + 0.5 * 0.5 * math.log(2),
     math.pi / 4 + 0.5 * math.log(2)),  # α = 1 < 2; ∫∫ x/r² = ∫₀¹ atan(1/x) dx = π/4 + log(2)/2
])
def test_integrable_singularities_keep_their_values(body, box, variables, value, derivative):
    p = _program(body, box, variables)
    got = exact_eval(p, {"a": 0.5})
    tol = 1e-8 if got.error is None else max(10 * got.error, 1e-8)
    assert got.value == pytest.approx(value, abs=tol)
    d = exact_deriv(p, {"a": 0.5}, {"a": 1}, check=False)
    assert d.value == pytest.approx(derivative, abs=max(tol, 1e-7))


def test_nothing_is_claimed_past_the_time_limit(monkeypatch):
    monkeypatch.setattr(integrability.driver, "TIME_LIMIT", 0.0)
    p = _program("x/(x^2 + y^2)^2", "[-1, 1], [-1, 1]", "x, y")
    ctx = Ctx(at=at_symbols({"a": 0.5}), variables=("x", "y"))
    assert divergent_where(p, ctx) is None
    monkeypatch.setattr(integrability.driver, "TIME_LIMIT", 5.0)
    assert divergent_where(p, ctx).blowup.verdict is integrability.Verdict.DIVERGENT


def test_the_linter_asks_the_same_analysis():
    # one declaration: langur.lint has no copy of the blow-up analysis, X311 reads the engine's
    assert singular.Blowup is integrability.Blowup and singular.piece_blowups is integrability.piece_blowups
    assert singular.delta_blowups is integrability.delta_blowups  # X313's delta half too (integ30)
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("langur.lint.blowup")
    res = singular.value_integrability(_program("1/x - 1/(1 - x)", "[0, 1]"), {"a": 0.5})
    assert res.verdict is integrability.Verdict.DIVERGENT


def test_exact_batch_says_undefined_past_a_domain_end_instead_of_nan():
    # ∫₀¹ sqrt(x − a) dx = (2/3)((1 − a)^(3/2) − (−a)^(3/2)) for a ≤ 0 (by hand); for a > 0 the root
    # is evaluated at negative numbers on [0, a): undefined.  The cell's closed form read NaN there.
    p = load_text("param a = -1\nint ([0, 1]) sqrt(x - a) d(x)\n").program
    a = np.array([-1.0, -0.5, 0.25, 0.5])
    e = exact_batch(p, {"a": a}, {"a": 1})
    hand = 2 / 3 * ((1 - a[:2]) ** 1.5 - (-a[:2]) ** 1.5)
    assert np.allclose(e.value[:2], hand, rtol=0, atol=1e-12)
    assert np.allclose(e.derivative[:2], -((1 - a[:2]) ** 0.5 - (-a[:2]) ** 0.5), rtol=0, atol=1e-12)
    assert np.all(np.isnan(e.value[2:])) and sorted(e.undefined) == [2, 3]
    assert all("undefined" in why for why in e.undefined.values()) and e.missing == 0
    assert list(e.closed) == [True, True, False, False]


def test_exact_batch_keeps_going_after_an_undefined_point():
    # the first point derived is undefined (1/(x − a) with the pole inside): the batch goes on
    p = load_text("param a = 0.5\nint ([0, 1]) 1/(x - a) d(x)\n").program
    e = exact_batch(p, {"a": np.array([0.5, -1.0])})
    assert list(e.undefined) == [0] and np.isnan(e.value[0])
    assert e.value[1] == pytest.approx(math.log(2), abs=1e-12)  # ∫₀¹ dx/(x + 1) = log 2
