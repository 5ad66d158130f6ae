"""Undefined is undefined: ⦇p⦈'s delta terms, and exact_batch per parameter cell (branch integ30).

⦇p⦈ = ∫ ⦇t⦈ (Theorem 7.1) needs every delta term's weight integrable on its zero set.  On [0, 1]²,
``[y ≥ x + a] · (1/|(x, y)| − 1/|(1 − x, 1 − y)|)`` is integrable (α = 1 < 2 at two corners), and
⟦p⟧ = 0 at a = 0 by hand: (x, y) ↦ (1 − y, 1 − x) maps {y ≥ x} onto itself and swaps the two terms.
Its delta term sits on the diagonal y = x with the weight 1/(√2·x) − 1/(√2·(1 − x)): α = 1 at both
ends of a set of dimension 1, a principal value (0), no integral; the exact engine returned −4.8e−14
(quadrature along the diagonal converged to the principal value), the linter said X313.  With
``(x² + y²)^(-1/4)`` instead the weight on the diagonal is 2^(−1/4)·x^(−1/2) (α = ½ < 1) and by hand
D⟦p⟧ = −∫₀¹ w(x, x) dx = −2^(−1/4)·2 = −2^(3/4) (the region y ≥ x + a shrinks as a grows).

exact_batch: a cell's closed form is not used where the integral stops existing.  By hand
∫₀¹ (x − a)^(−2) dx = [−1/(x − a)]₀¹ = −1/(1 − a) − 1/a for a ∉ [0, 1]; for a ∈ [0, 1] the pole x = a is
on the box, α = 2 ≥ 1: undefined.  The form derived at a = −1 gave −5.33 at a = 0.25.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from langur.ddenote import ddenote, ddenote_program
from langur.denote import denote_program, divergent_delta
from langur.exact_batch import exact_batch
from langur.frontend import load_text
from langur.lint import singular
from langur.symbolic import integrability
from langur.symbolic.decompose import Ctx
from langur.symbolic.integrability import verdicts
from langur.symbolic.quadrature import UndefinedIntegral
from langur.sympy_bridge import at_symbols

CORNERS = "1 / sqrt(x^2 + y^2) - 1 / sqrt((1 - x)^2 + (1 - y)^2)"


def _load(text: str):
    return load_text(text).program


def _diagonal(weight: str):
    return _load(f"param a = 0\nint ([0, 1], [0, 1]) if y - x - a >= 0 then {weight} else 0 d(x, y)\n")


def test_a_delta_term_with_a_principal_value_is_undefined():
    p = _diagonal(CORNERS)
    with pytest.raises(UndefinedIntegral) as e:
        ddenote_program(p, {"a": 0}, {"a": 1})
    assert "delta term" in e.value.reason and "not integrable" in e.value.reason and "not ⦇p⦈" in e.value.reason


def test_the_linter_and_the_engine_agree_on_it():
    p = _diagonal(CORNERS)
    res = singular.derivative_integrability(p, {"a": 0}, {"a": 1})
    assert res.verdict is integrability.Verdict.DIVERGENT
    assert [part for _, part in res.divergent] == ["a delta term"] * len(res.divergent)


def test_an_integrable_delta_term_keeps_its_hand_value():
    d = ddenote_program(_diagonal("(x^2 + y^2)^(-1/4)"), {"a": 0}, {"a": 1})
    assert d.regular.value == 0
    assert d.value == pytest.approx(-2 ** 0.75, abs=max(10 * d.error, 1e-8))


def test_a_delta_weight_infinite_at_its_root_in_one_variable():
    # δ(x − a) on 1/sqrt(|x − 1/2|) at a = 1/2: the weight at the root is 1/0
    p = _load("param a = 0.5\nint ([0, 1]) if x >= a then 1 / sqrt(abs(x - 0.5)) else 0 d(x)\n")
    at = at_symbols({"a": 0.5})
    nf = ddenote(p.body, {"a": 1}, at={"a": 0.5}, variables=("x",))
    bad = divergent_delta(p, Ctx(at=at, variables=("x",)), nf.deltas)
    assert bad is not None and bad.blowup.shape == "zero set" and bad.blowup.verdict is integrability.Verdict.DIVERGENT
    assert "sifting property" in bad.reason
    # away from the singular point (a = 1/4: the weight at the root is 1/sqrt(1/4) = 2) nothing is claimed
    nf = ddenote(p.body, {"a": 1}, at={"a": 0.25}, variables=("x",))
    assert divergent_delta(p, Ctx(at=at_symbols({"a": 0.25}), variables=("x",)), nf.deltas) is None
def test_exact_batch_undefined_where_the_pole_enters_the_box():
    p = _load("param a = -1\nint ([0, 1]) 1/(x - a)^2 d(x)\n")
    a = np.array([-1.0, -0.5, 0.25, 0.5, 1.5, 2.0])
    e = exact_batch(p, {"a": a})
    outside = [0, 1, 4, 5]
    hand = -1 / (1 - a[outside]) - 1 / a[outside]
    assert np.allclose(e.value[outside], hand, rtol=0, atol=1e-12)
    assert np.all(np.isnan(e.value[[2, 3]])) and sorted(e.undefined) == [2, 3]
    assert all("not integrable" in why or "undefined" in why for why in e.undefined.values())
    assert e.missing == 0


def test_exact_batch_derivative_undefined_where_the_pole_enters_the_box():
    # D_a ∫₀¹ (x − a)^(−2) dx = ∫₀¹ 2 (x − a)^(−3) dx = 1/a² − 1/(1 − a)² outside [0, 1] (by hand)
    p = _load("param a = -1\nint ([0, 1]) 1/(x - a)^2 d(x)\n")
    a = np.array([-1.0, 0.5, -2.0])
    e = exact_batch(p, {"a": a}, {"a": 1})
    assert np.allclose(e.derivative[[0, 2]], 1 / a[[0, 2]] ** 2 - 1 / (1 - a[[0, 2]]) ** 2, rtol=0, atol=1e-12)
    assert math.isnan(e.derivative[1]) and list(e.undefined) == [1]


def test_exact_batch_keeps_an_integrable_singularity_in_the_cell():
    # ∫₀¹ |x − a|^(−1/2) dx = 2√a + 2√(1 − a) on [0, 1] (by hand): integrable, never undefined
    p = _load("param a = 0.25\nint ([0, 1]) 1 / sqrt(abs(x - a)) d(x)\n")
    a = np.array([0.25, 0.5, 0.75])
    e = exact_batch(p, {"a": a})
    assert not e.undefined and e.missing == 0
    assert np.allclose(e.value, 2 * np.sqrt(a) + 2 * np.sqrt(1 - a), rtol=0, atol=1e-7)


def test_exact_batch_derivative_undefined_where_only_the_derivative_stops_existing():
    # ⟦p⟧ = ∫₀¹ log|x − a| dx exists for every a; ⦇p⦈ = ∫₀¹ −1/(x − a) dx = log|a| − log|1 − a| (by hand)
    # only for a ∉ [0, 1]: at a = 1/2 it is a principal value (0), not an integral (X313's case)
    p = _load("param a = -1\nint ([0, 1]) log(abs(x - a)) d(x)\n")
    a = np.array([-1.0, 0.5, 2.0])
    e = exact_batch(p, {"a": a}, {"a": 1})
    assert np.allclose(e.value[0], 2 * math.log(2) - 1, rtol=0, atol=1e-12)  # ∫₀¹ log(x + 1) dx
    assert np.allclose(e.derivative[[0, 2]], np.log(np.abs(a[[0, 2]])) - np.log(np.abs(1 - a[[0, 2]])),
                       rtol=0, atol=1e-12)
    assert math.isnan(e.derivative[1]) and list(e.undefined) == [1] and "regular part" in e.undefined[1]


def test_the_linter_and_the_engine_share_one_analysis(monkeypatch):
    # a command lints ⟦p⟧ (X311) and then the engine asks require_defined at the same point: one analysis
    runs = []
    real = verdicts.blowups
    monkeypatch.setattr(verdicts, "blowups", lambda w, region: runs.append(w) or real(w, region))
    monkeypatch.setattr(verdicts, "_FOUND", {})
    p = _load("param a = 0.5\nint ([0, 1], [0, 1]) a * x / (x^2 + y^2) d(x, y)\n")
    assert singular.value_integrability(p, {"a": 0.5}).verdict is integrability.Verdict.INTEGRABLE
    assert len(runs) == 1
    # ∫∫ x/(x² + y²) = ∫₀¹ atan(1/x) dx = π/4 + log(2)/2 (by hand), times a
    assert denote_program(p, {"a": 0.5}).value == pytest.approx(0.5 * (math.pi / 4 + math.log(2) / 2), abs=1e-9)
    assert len(runs) == 1
