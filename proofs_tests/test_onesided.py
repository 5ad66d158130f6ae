"""One-sided derivatives of ⟦p⟧ where ⦇p⦈ is not defined (X305; paper §8: Theorem 8.1 holds for
almost every parameter value).  ``langur.onesided`` says exactly whether ⟦p⟧ is differentiable
there, in the direction asked.

Every expected number is derived by hand in the comments from the program's value.  Before, ``deriv``
said "the derivative does not exist" at every X305 point, also where it exists
(``∫₀¹ [a·x ≥ 1/2]`` at a = 0 is 0 for every a ≤ 1/2).
"""

import json
from fractions import Fraction as F

import pytest
import sympy as sp
from paths import DEGENERATE, EXAMPLES

from langur.cli import main
from langur.frontend import load_text
from langur.onesided import one_sided


def sides(src: str, at: dict, direction: dict):
    return one_sided(load_text(src, "<test>").program, at, direction)


@pytest.mark.parametrize("src, at, direction, below, above", [
    # ∫₀¹[x ≤ θ] = Max(0, Min(1, θ)): slope 1 inside [0, 1], 0 outside
    ("param theta = 1\nint ([0, 1]) [x <= theta] d(x)\n", {"theta": F(1)}, {"theta": 1}, 1, 0),
    ("param theta = 0\nint ([0, 1]) [x <= theta] d(x)\n", {"theta": F(0)}, {"theta": 1}, 0, 1),
    # against the direction: D₊ in direction −1 is minus the left slope
    ("param theta = 1\nint ([0, 1]) [x <= theta] d(x)\n", {"theta": F(1)}, {"theta": -1}, 0, -1),
    # ∫₀¹[x ≤ θ](1 − x) = θ − θ²/2 on [0, 1]: at θ = 0, 0 from below and 1 − 0 = 1 from above
    ("param theta = 0\nint ([0, 1]) [x <= theta] * (1 - x) d(x)\n", {"theta": F(0)}, {"theta": 1}, 0, 1),
    # ∫₀¹[x ≥ a][x ≥ b] = 1 − max(a, b) (a, b in [0, 1]): at a = b along a, 0 below and −1 above;
    ("param a = 0.3, b = 0.3\nint ([0, 1]) [x >= a] * [x >= b] d(x)\n",
     {"a": F(3, 10), "b": F(3, 10)}, {"a": 1, "b": 0}, 0, -1),
    # along a = b it is 1 − a: −1 on both sides
    ("param a = 0.3, b = 0.3\nint ([0, 1]) [x >= a] * [x >= b] d(x)\n",
     {"a": F(3, 10), "b": F(3, 10)}, {"a": 1, "b": 1}, -1, -1),
    # ∫₀¹[a·x ≥ 1/2] = 0 for a ≤ 1/2 (a·x ≤ max(a, 0) < 1/2): differentiable at a = 0, slope 0
    ("param a = 0\nint ([0, 1]) [a*x >= 0.5] d(x)\n", {"a": F(0)}, {"a": 1}, 0, 0),
    # ∫₋₁¹[x² ≥ a] = 2 for a ≤ 0 and 2 − 2√a for 0 ≤ a ≤ 1: slope 0 below, −1/√a → −∞ above
    ("param a = 0\nint ([-1, 1]) [x*x >= a] d(x)\n", {"a": F(0)}, {"a": 1}, 0, -sp.oo),
])
def test_one_sided_derivatives_by_hand(src, at, direction, below, above):
    s = sides(src, at, direction)
    assert s.why is None
    assert s.below == below and s.above == above
    assert s.exists is (below == above and sp.sympify(below).is_finite)


def test_collinear_triangle_has_a_corner():
    # triangle.lgr: a = (ax, 0.1), b = (0.9, 0.3), c = (0.4, 0.8) are collinear at ax = 1.1 (on
    # x + y = 1.2); beyond, abc is clockwise and covers nothing: slope 0 from above.  Below, abc has
    # area (0.55 − 0.5·ax)/2, minus the part beyond the pixel's edge x = 1 (a lies outside for
    # ax > 1): with u = ax − 1 the edges ab and ac meet x = 1 at y = 0.1 + 0.2u/(ax − 0.9) and
    # 0.1 + 0.7u/(ax − 0.4), so that part is −(u²/2)·g(ax), g = 0.7/(ax − 0.4) − 0.2/(ax − 0.9),
    # g(1.1) = 0, g'(1.1) = −0.7/0.49 + 0.2/0.04 = 25/7; its slope at 1.1 is −(0.01/2)(25/7) = −1/56,
    # so the covered area's slope from below is −1/4 + 1/56 = −13/56.
    text = (EXAMPLES / "triangle.lgr").read_text()
    s = sides(text, {"px": F(0), "py": F(0), "ax": F(11, 10)}, {"px": 0, "py": 0, "ax": 1})
    assert (s.below, s.above, s.exists) == (sp.Rational(-13, 56), 0, False)


def test_no_closed_form_is_not_decided():
    # exp(sin(x)) has no elementary antiderivative: ⟦p⟧ is known by quadrature only, and the
    # one-sided derivatives are not guessed from numbers
    s = sides("param theta = 1\nint ([0, 1]) [x <= theta] * exp(sin(x)) d(x)\n", {"theta": F(1)}, {"theta": 1})
    assert s.exists is None and s.below is None and "closed form" in s.why


def run_json(capsys, *argv):
    status = main([*argv, "--json"])
    return status, json.loads(capsys.readouterr().out)


def test_deriv_says_which(capsys, tmp_path):
    # at θ = 1 (boundary.lgr) the derivative does not exist: one-sided 1 and 0
    status, j = run_json(capsys, "deriv", str(DEGENERATE / "boundary.lgr"), "--wrt", "theta")
    assert status == 1 and j["exact"] is None
    assert j["one_sided"] == {"exists": False, "below": 1.0, "above": 0.0, "why": None}
    assert "does not exist" in j["undefined"] and "X305" in j["undefined"]
    # the Monte Carlo number is ⦇p⦈'s, marked as not the derivative (its variance is finite)
    assert any("not the derivative" in n for n in j["mc"]["notes"])
    # at a = 0 of [a·x ≥ 1/2] ⦇p⦈ is not defined, but ⟦p⟧ is differentiable, slope 0
    f = tmp_path / "scaled.lgr"
    f.write_text("param a = 0\nint ([0, 1]) [a*x >= 0.5] d(x)\n")
    status, j = run_json(capsys, "deriv", str(f), "--wrt", "a")
    assert status == 1 and j["one_sided"] == {"exists": True, "below": 0.0, "above": 0.0, "why": None}
    assert "does not exist" not in j["undefined"] and "differentiable" in j["undefined"]
    # with the Monte Carlo engine alone nothing is decided, and nothing is claimed
    status, j = run_json(capsys, "deriv", str(f), "--wrt", "a", "--engine", "mc")
    assert j["one_sided"] is None and "not defined" in j["undefined"] and "exist" not in j["undefined"]


def test_deriv_of_a_program_whose_derivative_denotation_is_not_an_integral(capsys, tmp_path):
    # ⟦p⟧ = ∫₀¹ |x − a|^(-1/2) dx = 2√a + 2√(1 − a) (a in (0, 1)), so D⟦p⟧ = 1/√a − 1/√(1 − a) (by hand),
    # while ⦇p⦈'s regular part −(1/2)|x − a|^(-3/2)·sign(a − x) is not integrable (X313): ⦇p⦈ gives no
    # number, the derivative of ⟦p⟧'s closed form does
    f = tmp_path / "root.lgr"
    f.write_text("param a = 0.3\nint ([0, 1]) 1 / sqrt(abs(x - a)) d(x)\n")
    status, j = run_json(capsys, "deriv", str(f), "--wrt", "a")
    d = 1 / 0.3 ** 0.5 - 1 / 0.7 ** 0.5
    assert status == 1 and j["exact"] is None and "X313" in j["undefined"]
    assert j["one_sided"]["exists"] is True
    assert j["one_sided"]["below"] == pytest.approx(d, abs=1e-12) and j["one_sided"]["above"] == pytest.approx(d, abs=1e-12)
    assert "differentiable" in j["undefined"] and "not an integral" in j["undefined"]
    # where ⟦p⟧ itself is not an integral (X311) there is nothing to differentiate: no one-sided derivatives
    g = tmp_path / "pole.lgr"
    g.write_text("param a = 0.3\nint ([0, 1]) 1 / (x - a) d(x)\n")
    status, j = run_json(capsys, "deriv", str(g), "--wrt", "a")
    assert status == 1 and j["one_sided"] is None and "X311" in j["undefined"]
