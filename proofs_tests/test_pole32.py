"""pole31's split, leftovers found by fuzz32 (bench/history/2026-11-29.md#fuzz32 D1 and D5; hostile32's X306): bench/history/2026-11-29.md#pole32.

D1 — a factor of multiplicity > 1.  ``[(y − a)³ ≥ 0]`` has ∂/∂y = 3(y − a)² = 0 on its zero set: Ψ̂ is no
diffeomorphism there (Def. 3.4), a degenerate turning point (X316 in both engines, or X315/X305 and
MC NaN for a square).  A.e. ``[c·Π fᵢ^kᵢ ≥ 0]`` is the parity of the signs of the odd-power factors
(:mod:`langur.syntax.poles`): the front end now splits whenever a factor is repeated.  Hand values:
* ``int ([0, 2]) [(2y − a)³(2y − a − 0.3) ≥ 0]``: y ≤ a/2 or y ≥ (a + 0.3)/2: 2 − 0.15 = 1.85, ∂a = 0;
* ``int ([0, 2]) [(y − a)³(y − 1) ≥ 0]``: y ≤ a or y ≥ 1: a + 1, ∂a = 1;
* ``int ([0, 2]) [(y − a)³ ≥ 0]``: y ≥ a: 2 − a, ∂a = −1;
* ``int ([−1, 1]) [(x − a)³(eˣ − 1.5) ≥ 0]``: x ≤ a or x ≥ log 1.5 (a = 0.2 < log 1.5 ≈ 0.405):
  (a + 1) + (1 − log 1.5), ∂a = 1;
* ``int ([0, 2]) [(y − a)²(y − 1) ≥ 0]``: y ≥ 1 a.e.: 1, ∂a = 0;
* ``int ([−1, 1]) [(x − a)²(eˣ − 1.5) ≥ 0]``: x ≥ log 1.5 a.e.: 1 − log 1.5, ∂a = 0;
* ``int ([−1, 1]) [(x − 0.2)²(eˣ − (a + 1)) ≥ 0]`` (a fixed square): 1 − log(1 + a), ∂a = −1/(1 + a);
* ``int ([0, 1]) [−(x − a)² ≥ 0]``: true at x = a only: 0, ∂a = 0 (no factor left: ``ifge0 −1``).

D5 — ``int ([0, 1]) [x + 0·(1/(x − a)) ≥ a]``: the condition as written is x − a off x = a and
undefined at x = a, its own zero set.  ⟦p⟧ = 1 − a (a null set changes no integral), D⟦p⟧ = −1.
The completion is that of its continuous extension x − a (a C¹ diffeomorphism, the one sympy read:
the exact engine said −1), and Monte Carlo, which evaluated the written term at the delta's sample
x = a (0·∞: NaN), now evaluates the same Ψ̂: −1 in both, Theorem 8.1 holds.  Only poles are so
extended: ``0·log(x − a)`` is undefined on a set of positive measure and is left as written.

X306 — six roots 0.01 apart, ``(x − a)(x − a − 0.01)…(x − a − 0.05)``: the product depends on x − a
only, so its values at its five turning points (±1.7e-11, ±5e-12, −3.5e-12 by hand) are the same for
every a and never 0; a root sits on no turning point.  An absolute tolerance of 1e-9 said it did
(5 × X306); the tolerance is now how far the value moves when the parameters move by 1e-9
(∂f/∂a = 0 there), so ``x³ − x − a`` at a = 2/(3√3) to 16 digits is still reported.
"""

from __future__ import annotations

import math

import pytest

from langur import operational
from langur.cli import main
from langur.core import IfDiffeo, Pow, free_vars, subterms
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.syntax import poles

LOG15 = math.log(1.5)

CASES = [  # (program, a, ⟦p⟧ by hand, ∂a by hand)
    ("int ([0, 2]) [(2 * y - a) ^ 3 * (2 * y - (a + 0.3)) >= 0] d(y)", 0.23, 1.85, 0.0),
    ("int ([0, 2]) [(y - a) ^ 3 * (y - 1) >= 0] d(y)", 0.25, 1.25, 1.0),
    ("int ([0, 2]) [(y - a) ^ 3 >= 0] d(y)", 0.25, 1.75, -1.0),
    ("int ([-1, 1]) [(x - a) ^ 3 * (exp(x) - 1.5) >= 0] d(x)", 0.2, 1.2 + 1 - LOG15, 1.0),
    ("int ([0, 2]) [(y - a) ^ 2 * (y - 1) >= 0] d(y)", 0.25, 1.0, 0.0),
    ("int ([-1, 1]) [(x - a) ^ 2 * (exp(x) - 1.5) >= 0] d(x)", 0.2, 1 - LOG15, 0.0),
    ("int ([-1, 1]) [(x - 0.2) ^ 2 * (exp(x) - (a + 1)) >= 0] d(x)", 0.5, 1 - math.log(1.5), -1 / 1.5),
    ("int ([0, 1]) [-(x - a) ^ 2 >= 0] d(x)", 0.3, 0.0, 0.0),  # only a square, a negative coefficient: false a.e.
    ("int ([0, 1]) [x + 0 * (1 / (x - a)) >= a] d(x)", 0.3, 0.7, -1.0),  # D5
]


@pytest.mark.parametrize("body, a, value, slope", CASES)
def test_both_engines_and_theorem_8_1_against_the_hand_values(body, a, value, slope):
    # before: X316 in both engines (cubes), X305/X315 and MC NaN (squares), MC NaN (D5)
    loaded = load_text(f"param a = {a}\n{body}\n")
    params = loaded.param_values()
    r = exact_eval(loaded.program, params)
    assert r.value == pytest.approx(value, rel=1e-12)
    d = exact_deriv(loaded.program, params, {"a": 1}, check=True)
    assert not d.inconsistent, d.inconsistent
    assert d.value == pytest.approx(slope, rel=1e-12, abs=1e-12)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds, d.theorem_8_1
    mc = operational.estimate_derivative(loaded, params, {"a": 1}, samples=20_000, seed=7)
    assert math.isfinite(mc.value) and abs(mc.value - slope) <= 5 * mc.stderr + 1e-12, (mc.value, mc.stderr)
    mv = operational.estimate_value(loaded, params, samples=20_000, seed=7)
    assert abs(mv.value - value) <= 5 * mv.stderr + 1e-12


def _conditions(body: str, a: float):
    """The integrand's conditions (the box's bounds, also conditions, left out)."""
    def conditions(text):
        return [t.psi.forward[0] for t in subterms(load_text(text).program.body) if isinstance(t, IfDiffeo)]
    box = conditions(body.split(") ", 1)[0] + ") 1 " + body.rsplit(" ", 1)[1])
    return [c for c in conditions(f"param a = {a}\n{body}\n") if c not in box]


def test_a_repeated_factor_is_split_to_its_parity():
    # the cube keeps y − a once (no power left); the square drops out: only y − 1 is a condition
    (cube,) = _conditions(CASES[2][0], 0.25)
    assert not any(isinstance(u, Pow) for u in subterms(cube))
    square = _conditions(CASES[4][0], 0.25)
    assert len(square) == 1 and "a" not in {u.name for u in subterms(square[0]) if hasattr(u, "name")}


def test_only_a_pole_is_extended_by_continuity():
    (pole,) = _conditions(CASES[8][0], 0.3)
    assert not any(isinstance(u, Pow) and u.exponent < 0 for u in subterms(pole)) and free_vars(pole) == {"x"}
    # a logarithm is undefined for x < a, a set of positive measure: not extended, the condition as written
    written = _conditions("int ([0, 1]) [x + 0 * log(x - a + 2) >= a] d(x)", 0.3)
    assert len(written) == 1 and any(getattr(u, "op", None) == "log" for u in subterms(written[0]))
    assert poles.removable(written[0]) is None


def test_close_simple_roots_are_not_turning_point_roots(tmp_path, capsys):
    six = tmp_path / "six.lgr"
    six.write_text("param a = 0.1\nint ([0, 1]) [(x - a)*(x - a - 0.01)*(x - a - 0.02)*(x - a - 0.03)"
                   "*(x - a - 0.04)*(x - a - 0.05) >= 0] d(x)\n")
    main(["check", str(six)])
    assert "X306" not in capsys.readouterr().out  # main: 5 × X306, "the default values a = 0.1 lie in this set"
    # a true tangent root, its parameter written to 16 digits: still reported, and an error at --at
    tangent = tmp_path / "tangent.lgr"
    tangent.write_text("param a = 0.3849001794597505\nint ([-2, 2]) [x^3 - x - a >= 0] d(x)\n")
    main(["check", str(tangent)])
    assert "the default values a = 0.3849 lie in this set" in capsys.readouterr().out
    assert main(["check", "--at", "a=0.3849001794597505", str(tangent)]) == 1
    assert "X305" in capsys.readouterr().out
