"""fuzz33's F2 (bench/history/2026-11-29.md#zero33: a smooth factor undefined
exactly on a moving jump.

``int ([0, 1]) (1 + 0·(1/(x − a)))·exp(min(x, a))``: the factor is 1 off x = a and undefined at x = a,
the zero set of ``min``'s kink, where the derivative's delta evaluates the integrand (Fig. 8).  The
exact engine read sympy's ``0·z = 0`` (the continuous extension) and Monte Carlo the term as written
(0·∞: NaN).  One meaning now, pole32's for conditions: a subterm undefined at poles only whose
continuous extension is defined everywhere (:func:`langur.syntax.poles.removable`) is that extension
in the core both engines evaluate (:func:`langur.syntax.poles.extended`); a pole that is no removable
singularity stays, and both engines say the derivative is undefined.  Hand values (a = 0.53, b = 0.4):

* ``(1 + 0·(1/(x − a)))·exp(min(x, a))``: ⟦p⟧ = ∫₀ᵃ eˣ + (1 − a)eᵃ = (2 − a)eᵃ − 1, ∂a = (1 − a)eᵃ
  (also through a def, ``g(x, a)``);
* ``(1 + 0·(1/(x − a)))·[x ≤ a]`` and ``(x − a)/(x − a)·[x ≤ a]``: ⟦p⟧ = a, ∂a = 1;
* 2-D ``(x − a)(y + 1)/(x − a)·[x + y ≤ a + b]`` on [0, 1]²: with s = a + b < 1, ⟦p⟧ =
  ∫₀ˢ (s − y)(y + 1) dy = s³/6 + s²/2, ∂a = s + s²/2 (the delta's line x + y = s meets the pole x = a).

X307's witness of a crossed pole was the first sample where the denominator is negative ("e.g. at
x = 0.27" for a zero at 0.53): it is now the zero, found by bisection between samples of both signs.
"""

from __future__ import annotations

import math
import re

import pytest

from langur import operational
from langur.cli import main
from langur.core import Pow, subterms
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text

A, B = 0.53, 0.4
S = A + B
F2 = "(1 + 0 * (1 / (x - a))) * exp(min(x, a))"
CASES = [  # (program, ⟦p⟧ by hand, ∂a by hand)
    (f"param a = {A}\nint ([0, 1]) {F2} d(x)\n", (2 - A) * math.exp(A) - 1, (1 - A) * math.exp(A)),
    (f"param a = {A}\ndef g(x: var, q: param) = 1 + 0 * (1 / (x - q))\nint ([0, 1]) g(x, a) * exp(min(x, a)) d(x)\n",
     (2 - A) * math.exp(A) - 1, (1 - A) * math.exp(A)),
    (f"param a = {A}\nint ([0, 1]) (1 + 0 * (1 / (x - a))) * [x <= a] d(x)\n", A, 1.0),
    (f"param a = {A}\nint ([0, 1]) (x - a) / (x - a) * [x <= a] d(x)\n", A, 1.0),
    (f"param a = {A}, b = {B}\nint ([0, 1], [0, 1]) (x - a) * (y + 1) / (x - a) * [x + y <= a + b] d(x, y)\n",
     S ** 3 / 6 + S ** 2 / 2, S + S ** 2 / 2),
]


@pytest.mark.parametrize("text, value, slope", CASES)
def test_both_engines_agree_with_the_hand_values(text, value, slope):
    # main: exact right, Monte Carlo's boundary NaN (cases 0-3; "1 of 1 samples on the discontinuities
    # are not finite")
    loaded = load_text(text)
    params = loaded.param_values()
    assert exact_eval(loaded.program, params).value == pytest.approx(value, rel=1e-10)
    d = exact_deriv(loaded.program, params, {"a": 1}, check=True)
    assert d.value == pytest.approx(slope, rel=1e-10)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds, d.theorem_8_1
    mc = operational.estimate_derivative(loaded, params, {"a": 1}, samples=20_000, seed=7)
    assert math.isfinite(mc.value) and abs(mc.value - slope) <= 5 * mc.stderr + 1e-12, (mc.value, mc.stderr)
    mv = operational.estimate_value(loaded, params, samples=20_000, seed=7)
    assert abs(mv.value - value) <= 5 * mv.stderr + 1e-12


def test_only_a_removable_pole_is_extended():
    # the extension is in the core both engines get: no negative power left
    extended = load_text(CASES[0][0]).program.integrand
    assert not any(isinstance(u, Pow) and u.exponent < 0 for u in subterms(extended))
    # a true pole stays as written (x/(x − a) is no removable singularity), and so does one that
    # sympy does not cancel ((x² − a²)/(x − a), below)
    kept = load_text(f"param a = {A}\nint ([0, 1]) x / (x - a) * [x <= a] d(x)\n").program.integrand
    assert any(isinstance(u, Pow) and u.exponent < 0 for u in subterms(kept))


@pytest.mark.parametrize("body", ["(1 / (x - a)) * [x <= a]", "((x^2 - a^2) / (x - a)) * [x <= a]",
                                  "exp(-(1 / (x - a)^2)) * [x <= a]"])
def test_a_pole_on_the_zero_set_that_stays_is_undefined_in_both_engines(tmp_path, capsys, body):
    # 1/(x − a): ⟦p⟧ diverges (X311); the others: ⦇p⦈'s delta weight is undefined at x = a (X313)
    path = tmp_path / "p.lgr"
    path.write_text(f"param a = {A}\nint ([0, 1]) {body} d(x)\n")
    main(["deriv", "--wrt", "a", str(path)])
    out = capsys.readouterr().out
    exact = next(line for line in out.splitlines() if line.strip().startswith("exact"))
    mc = next(line for line in out.splitlines() if line.strip().startswith("MC"))
    assert "undefined" in exact, out
    assert "nan" in mc and "not finite" in out, out


def _witness(tmp_path, capsys, text: str) -> str:
    path = tmp_path / "w.lgr"
    path.write_text(text)
    main(["check", str(path)])
    out = capsys.readouterr().out
    found = re.search(r"the denominator changes sign, so it divides by zero inside the region, e\.g\. at ([^;]*);", out)
    assert found, out
    return found.group(1)


def test_x307_names_the_zero_of_a_crossed_denominator(tmp_path, capsys):
    # main: "e.g. at x = 0.27" (a sample where the denominator is negative) for a zero at 0.3
    assert _witness(tmp_path, capsys, f"param a = {A}\nint ([0, 1]) sin(x) / (x - 0.3) * [x <= a] d(x)\n") == "x = 0.3"
    # 2-D: the point is on the line x − y/2 − 0.1 = 0 (to the printed 3 digits); main: x = 0.27, y = 1.03
    where = _witness(tmp_path, capsys, f"param a = {A}\nint ([0, 1], [0, 2]) (x + y) / (x - y / 2 - 0.1) * [x <= a] d(x, y)\n")
    x, y = (float(v) for v in re.fullmatch(r"x = ([-0-9.e]+), y = ([-0-9.e]+)", where).groups())
    assert abs(x - y / 2 - 0.1) <= 0.006 and 0 <= x <= 1 and 0 <= y <= 2, where


def test_x307_says_where_a_denominator_jumps_across_zero(tmp_path, capsys):
    # min(x, 0.3) − 0.7 + [x ≥ 0.6]: below −0.4 on [0, 0.6), 0.6 on [0.6, 1]: no zero, a jump at 0.6
    where = _witness(tmp_path, capsys, "int ([0, 1]) 1 / (min(x, 0.3) - 0.7 + [x >= 0.6]) d(x)\n")
    assert where == "x = 0.6 (where it jumps across 0)", where
