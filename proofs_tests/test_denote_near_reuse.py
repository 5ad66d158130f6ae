"""``denote_program(near=True)`` (what Theorem 8.1's check asks for every partial derivative) reuses
a closed form already found for the same program and point without ``near``: one valid on a wider
set of parameters is valid near the point too.  A fallback to quadrature is not reused that way."""

from __future__ import annotations

from fractions import Fraction

import sympy as sp

from langur import denote
from langur.exact import exact_deriv
from langur.frontend import load_text
from langur.symbolic.pieces import Method

# ∫₀¹ [x ≤ θ] · x dx = θ²/2 on [0, 1]
TEXT = "param theta = 0.5\nint ([0, 1]) [x <= theta] * x d(x)"


def test_near_reuses_the_closed_form_found_everywhere(monkeypatch):
    program = load_text(TEXT).program
    at = {"theta": Fraction(2, 5)}
    wide = denote.denote_program(program, at)
    assert wide.method == Method.CLOSED_FORM
    theta = next(iter(wide.expr.free_symbols))
    for t in (sp.Rational(2, 5), sp.Rational(3, 5)):
        assert wide.expr.subs(theta, t) == t**2 / 2
    calls = []
    monkeypatch.setattr(denote, "decompose", lambda *a, **k: calls.append(a) or [])
    near = denote.denote_program(program, at, near=True)
    assert calls == [] and near.expr == wide.expr and near.method == Method.CLOSED_FORM
    # a point not yet seen is decomposed again
    denote.denote_program(program, {"theta": Fraction(3, 5)}, near=True)
    assert len(calls) == 1


def test_the_check_of_theorem_8_1_is_the_same_with_the_reuse():
    program = load_text(TEXT).program
    at = {"theta": Fraction(2, 5)}
    denote._remembered.clear()
    fresh = exact_deriv(program, at, {"theta": 1})  # ⟦p⟧ near the point, computed for the check
    denote._remembered.clear()
    denote.denote_program(program, at)  # ⟦p⟧ everywhere first, as `langur fuzz` and `eval` do
    reused = exact_deriv(program, at, {"theta": 1})
    assert abs(fresh.value - 0.4) < 1e-12 and abs(reused.value - 0.4) < 1e-12  # d/dθ θ²/2 = θ
    assert fresh.theorem_8_1 is not None and reused.theorem_8_1 is not None
    assert fresh.theorem_8_1 == reused.theorem_8_1
