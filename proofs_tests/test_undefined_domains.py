"""A primitive applied outside its domain is undefined even where complex arithmetic would give a
real number (LANGUAGE.md §1; X311, ``langur.symbolic.definedness``).

``sqrt(x)·sqrt(x − 1)`` at x < 0 is (i√|x|)·(i√(1 − x)) = −√(x² − x) to sympy and numpy's complex
arithmetic, a real number, so the integrability analysis used to find nothing undefined and the
exact engine reported ∫₋₂⁰ of it as a number, while the Monte Carlo engine (real arithmetic) said
NaN.  Each primitive's argument is now checked on its own.  A bracket factor is not a guard
(LANGUAGE.md §3, ⟦t · s⟧ = ⟦t⟧ · ⟦s⟧; CODES.md, X311): ``[x >= a] · log(x − a)`` is
0 · undefined at x < a; only the conditional ``if x >= a then log(x - a) else 0`` evaluates
``log`` only where the condition holds (test_guard27).
"""

from __future__ import annotations

import json
import math

import pytest

from langur.cli import main


def _eval(capsys, tmp_path, text: str) -> tuple[int, dict]:
    f = tmp_path / "p.lgr"
    f.write_text(text)
    status = main(["eval", str(f), "--json", "--engine", "exact"])
    return status, json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("body, box", [
    ("sqrt(x) * sqrt(x - 1) + a", "[-2, 0]"),  # both roots of negatives on all of [−2, 0]
    ("[x >= a] * sqrt(x - 2) * sqrt(x - 3)", "[-2, 1]"),  # where the condition holds, x − 2 < 0
    ("(x - 2)^(1/3) * (x - 3)^(2/3) + a", "[0, 1]"),  # fractional powers of negatives (not real roots)
])
def test_products_of_roots_of_negatives_are_undefined(capsys, tmp_path, body, box):
    status, j = _eval(capsys, tmp_path, f"param a = 0.5\nint ({box}) {body} d(x)\n")
    assert status == 1 and j["exact"] is None
    assert "X311" in j["undefined"] and "undefined on a set of positive measure" in j["undefined"]


def test_roots_of_non_negatives_keep_their_value(capsys, tmp_path):
    # ∫₁² √x·√(x − 1) dx = [((2x − 1)√(x² − x))/4 − log(√x + √(x − 1))/4]₁² = 3√2/4 − log(√2 + 1)/4 (by hand)
    status, j = _eval(capsys, tmp_path, "param a = 0\nint ([1, 2]) sqrt(x) * sqrt(x - 1) + a d(x)\n")
    assert status == 0 and j["undefined"] is None
    assert abs(j["exact"]["value"] - (3 * math.sqrt(2) / 4 - math.log(math.sqrt(2) + 1) / 4)) <= 1e-12


def test_a_conditional_guards_its_branch(capsys, tmp_path):
    # ∫₀¹ (if x ≥ a then log(x − a) else 0) dx = [(x − a) log(x − a) − x]_a^1 = (1 − a) log(1 − a) − (1 − a)
    # (by hand); the product [x >= a] * log(x - a) evaluates log at x < a too: undefined (X311)
    a = 0.3
    status, j = _eval(capsys, tmp_path, f"param a = {a}\nint ([0, 1]) if x >= a then log(x - a) else 0 d(x)\n")
    assert status == 0 and j["undefined"] is None
    assert abs(j["exact"]["value"] - ((1 - a) * math.log(1 - a) - (1 - a))) <= 1e-12
    status, j = _eval(capsys, tmp_path, f"param a = {a}\nint ([0, 1]) [x >= a] * log(x - a) d(x)\n")
    assert status == 1 and j["exact"] is None and "X311" in j["undefined"]
