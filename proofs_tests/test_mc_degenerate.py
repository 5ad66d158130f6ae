"""The Monte Carlo engine where a condition's completion divides by a parameter coefficient that is
0 at the values asked (``Diffeo.nonzero``): Ψ̂ is no diffeomorphism there and ⦇p⦈ is not defined,
so the engine says so (NaN and a note) instead of a number.

Before, ``operational.estimate_derivative`` on examples/stylize/linear.lgr at bx = cx = 0.35 (the
edge bc vertical, completed by y, dividing by cx − bx) returned −0.081 ± 0.003 without a word;
the derivative there is 0.12 (docs/commands.md: `langur deriv` completes that edge by x).  Expected
values are derived by hand in the comments.
"""

import math

import numpy as np
import pytest
from paths import EXAMPLES

from langur import operational
from langur.frontend import load, load_text
from langur.operational.batch import estimate_batch

SCALED = "param a = 1\nint ([0, 1]) [a*x >= 0.5] d(x)\n"


def test_a_vanishing_coefficient_gives_nan_and_says_why():
    # ∫₀¹[a·x ≥ 1/2] = 1 − 1/(2a) for a ≥ 1/2: derivative 1/(2a²) = 1/2 at a = 1; at a = 0 the
    # completion x = (u + 1/2)/a divides by 0
    loaded = load_text(SCALED, "<t>")
    r = operational.estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0})
    assert r.value == pytest.approx(0.5, abs=1e-12) and r.notes == ()
    r = operational.estimate_derivative(loaded, {"a": 0.0}, {"a": 1.0})
    assert math.isnan(r.value) and math.isnan(r.boundary.value)
    assert any("not defined" in n and "divides by a parameter coefficient that is 0" in n for n in r.notes)
    # the value itself needs no completion: 0 at a = 0 (a·x ≤ 0 < 1/2)
    assert operational.estimate_value(loaded, {"a": 0.0}).value == 0.0


def test_the_batch_marks_only_the_degenerate_points():
    # 1/(2a²) at a = 1 and 2: 1/2 and 1/8; NaN at a = 0
    loaded = load_text(SCALED, "<t>")
    b = estimate_batch(loaded, {"a": np.array([0.0, 1.0, 2.0])}, direction={"a": 1.0})
    assert math.isnan(b.derivative[0])
    assert b.derivative[1:] == pytest.approx([0.5, 0.125], abs=1e-12)
    assert any("not defined at 1 of 3 points" in n for n in b.notes)


def test_the_stylize_triangle_at_a_vertical_edge():
    # the edge bc is completed by y, dividing by cx − bx: NaN at bx = cx (test_recomplete.py checks
    # that `langur deriv` completes it by x there instead), a number beside it
    loaded = load(str(EXAMPLES / "stylize" / "linear.lgr"))
    p = {k: float(v) for k, v in loaded.param_values().items()}
    d = {k: (1.0 if k == "bx" else 0.0) for k in p}
    r = operational.estimate_derivative(loaded, dict(p, bx=0.35, cx=0.35), d, samples=2000)
    assert math.isnan(r.value) and any("not defined" in n for n in r.notes)
    r = operational.estimate_derivative(loaded, dict(p, bx=0.36, cx=0.35), d, samples=2000)
    assert math.isfinite(r.value) and r.notes == ()
