"""A piece as it is on the box at the point: what the quadrature cross-check integrates (§6.3, §7.3).

pole31 splits ``[(x − a)/(y + b) ≥ 0]`` into ``[y + b ≥ 0] ⊕ [x − a ≥ 0]`` (langur.syntax.poles) for
every parameter value, also where the pole y = −b is off the box: raytrace/scene.lgr's depth shader
``[zth − k/(n·d) ≥ 0]`` has its pole n·d = 0 far from the pixel, and its exact ``deriv --wrt t`` went
from 0.67 to 1.3–1.4 CPU s, most of it the quadrature of the split's extra pieces.  The exact engine
now gives the quadrature each piece as it is on the box at the point (langur.symbolic.offbox): 0 where
a condition is proved negative on the whole box (or a delta's zero set misses it), without the
conditions proved positive there; the closed forms are sought for the pieces as they were
(bench/history/2026-11-29.md#split32.

Hand values, box [0, 1]², ``[(x − a)/(y + b) ≥ 0]``, a ∈ (0, 1):
* b > 0 (y + b > 0 on the box): x ≥ a, ⟦p⟧ = 1 − a, d/da = −1, d/db = 0;
* b < −1 (y + b < 0 on the box): x ≤ a, ⟦p⟧ = a, d/da = 1, d/db = 0;
* −1 < b < 0 (the pole y = −b inside): ⟦p⟧ = (1 + b)(1 − a) − b·a, d/da = −1 − 2b, d/db = 1 − 2a.
"""

from __future__ import annotations

import pytest
import sympy as sp

from langur import operational
from langur.ddenote import ddenote_program
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load, load_text
from langur.symbolic import offbox
from langur.symbolic.pieces import Condition, DeltaPiece, Piece, Psi

x, y, a, b = sp.symbols("x y a b")
UNIT = {x: (sp.Integer(0), sp.Integer(1)), y: (sp.Integer(0), sp.Integer(1))}
QUOTIENT = "int ([0, 1], [0, 1]) [(x - a)/(y + b) >= 0] d(x, y)"


@pytest.mark.parametrize("expr, at, sign", [
    (x + y + a, {a: sp.Rational(1, 2)}, 1),  # [1/2, 5/2]
    (x + y + a, {a: -3}, -1),  # [−3, −1]
    (x + y + a, {a: -1}, 0),  # [−1, 1]: its zero set crosses the box
    (x + y, {}, 0),  # 0 at a corner: not strictly positive
    (1 / (x - a), {a: sp.Rational(1, 2)}, 0),  # a pole in the box: not enclosed finitely
    (1 / (x - a), {a: 2}, -1),  # [−2, −1]
    (sp.Max(x, a), {a: 2}, 0),  # Max has no interval rule: kept
    (x + a, {}, 0),  # a not given: nothing decided
])
def test_the_sign_on_the_box_is_proved_or_left_open(expr, at, sign):
    assert offbox.sign_on_box(expr, UNIT, at) == sign


def test_pieces_as_they_are_on_the_box():
    at = {a: sp.Rational(1, 4), b: 2}
    straddles, positive, negative = Condition(x - a), Condition(y + b), Condition(-(y + b))
    kept = Piece((straddles,), x)
    psi = Psi((x, y), (y + b, x), sp.symbols("u0 u1"), ())
    out = offbox.reduced([Piece((straddles, positive), x), Piece((negative, straddles), x), kept,
                          DeltaPiece(psi, (straddles,), x)], UNIT, at)
    assert out[0] == Piece((straddles,), x)  # y + b ≥ 2 on the box: the condition is 1
    assert out[1] is None  # −(y + b) ≤ −2: the piece is 0
    assert out[2] is kept
    assert out[3] is None  # the delta's zero set y = −2 misses the box
    # a box reversed at the point (h < 0) or not numeric: nothing decided
    assert offbox.reduced([Piece((negative,), x)], {x: (sp.Integer(1), sp.Integer(0))}, at)[0].conditions == (negative,)


@pytest.mark.parametrize("av, bv, value, slopes, decided", [
    (0.25, 2, 0.75, {"a": -1, "b": 0}, True),
    (0.25, -2, 0.25, {"a": 1, "b": 0}, True),
    (0.25, -0.5, 0.5, {"a": 0, "b": 0.5}, False),
])
def test_the_split_quotient_against_the_hand_values(monkeypatch, av, bv, value, slopes, decided):
    seen = []
    real = offbox.reduced

    def spy(pieces, boxd, at):
        out = real(pieces, boxd, at)
        seen.append(any(p is None or p is not q for p, q in zip(out, pieces)))
        return out

    monkeypatch.setattr(offbox, "reduced", spy)
    loaded = load_text(f"param a = {av}, b = {bv}\n{QUOTIENT}\n")
    params = loaded.param_values()
    v = exact_eval(loaded.program, params)
    assert not v.inconsistent and v.value == pytest.approx(value, rel=1e-12)
    for name, slope in slopes.items():
        d = ddenote_program(loaded.program, params, {name: 1})
        assert not d.inconsistent, d.inconsistent
        assert d.value == pytest.approx(slope, abs=1e-12), (name, d.value)
        # the quadrature cross-check, of the pieces as they are on the box, agrees with the hand value too
        assert d.regular.check + (d.boundary.check or 0.0) == pytest.approx(slope, abs=1e-7)
        full = exact_deriv(loaded.program, params, {name: 1}, check=True)
        assert full.theorem_8_1 is not None and full.theorem_8_1.holds, full.theorem_8_1
        mc = operational.estimate_derivative(loaded, params, {name: 1}, samples=20_000, seed=7)
        assert abs(mc.value - slope) <= 5 * mc.stderr + 1e-12, (name, mc.value, mc.stderr)
    assert any(seen) == decided  # the pole off the box: some piece reduced; inside it: none


def test_a_closed_form_wrong_on_a_piece_that_is_0_on_the_box_is_still_caught(monkeypatch):
    """The quadrature's 0 for a piece proved 0 on the box is a cross-check: a closed form that is not 0
    there disagrees and the quadrature is reported (an engine bug, said so)."""
    from langur.symbolic import regions

    real = regions.integrate_region

    def wrong(conds, weight, uvars, ubox, ctx):
        out = real(conds, weight, uvars, ubox, ctx)
        return out + 1 if any(str(c.expr) == "-b - y" for c in conds) else out  # the piece y + b < 0

    monkeypatch.setattr(regions, "integrate_region", wrong)
    loaded = load_text("param a = 0.25, b = 3\n" + QUOTIENT + "\n")  # (a point no other test asks)
    v = exact_eval(loaded.program, loaded.param_values())
    assert v.value == pytest.approx(0.75, rel=1e-9)
    assert v.inconsistent, "the wrong closed form was not caught"


def test_the_ray_tracer_pixel_prints_what_it_printed_before_the_split(monkeypatch):
    """raytrace/scene.lgr at its parameters (an empty pixel): the value 0 with the cell pole31's
    predecessor printed (``h > 0`` and the real roots); the pole's pieces are 0 on the pixel."""
    monkeypatch.chdir("examples/raytrace")
    loaded = load("scene.lgr")
    params = loaded.param_values()
    d = exact_deriv(loaded.program, params, {"t": 1}, check=True)
    assert d.value == 0 and d.method == "closed_form" and d.theorem_8_1.holds
    assert d.notes[0] == ("closed form valid in the parameter cell containing the evaluation point: "
                          "1 - 2*ch >= 0; h > 0 (and with the same real roots)")


def test_a_ray_tracer_pixel_across_an_edge_against_monte_carlo(monkeypatch):
    """A pixel the triangle's edge AB crosses, ∂/∂px: the pole's pieces are 0 there, the edge's are
    not; both engines and Theorem 8.1 (the value, −23.129…, is the same on the tree before this change)."""
    monkeypatch.chdir("examples/raytrace")
    loaded = load("scene.lgr")
    params = {**loaded.param_values(), "px": -0.02, "py": -0.16}
    d = exact_deriv(loaded.program, params, {"px": 1}, check=True)
    assert not d.inconsistent and d.method == "closed_form" and d.theorem_8_1.holds
    mc = operational.estimate_derivative(loaded, params, {"px": 1}, samples=20_000, seed=7)
    assert abs(mc.value - d.value) <= 5 * mc.stderr, (d.value, mc.value, mc.stderr)
    assert d.value < -1  # the edge's delta: not the empty pixel's 0
