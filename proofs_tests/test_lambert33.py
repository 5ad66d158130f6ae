"""The paper's renderer with the point-light shader (§10.2, Fig. 14c: examples/raytrace/lambert.lgr)
usable pixel by pixel: ``langur deriv``'s transversality gate asks only X301 and X305
(``transversality.HERE_CODES``), and the checker then solves for a *set* of degenerate parameter values
only when the values in force lie in it (bench/history/2026-11-29.md#lambert33.

What the gate reports must be what the whole analysis reports for those two codes: checked here on
programs with X305 of every kind (a kink on the domain's bound named with every set its jump lies on,
two moving jumps, two circles, a coefficient that vanishes) and on programs without.
"""

from __future__ import annotations

import time

import pytest
from paths import EXAMPLES

from langur import transversality
from langur.commands import _defined
from langur.frontend import load, load_text
from langur.lint import classify

SCENE = str(EXAMPLES / "raytrace" / "scene.lgr")
LAMBERT = {"shader": str(EXAMPLES / "raytrace" / "lambert.lgr")}

# (program, --at values): each X305/X301 line of the whole analysis at those values is checked by hand
# in the comments
PROGRAMS = [
    # the jump x = a on the domain's bound x = 1 at a = 1; the set names a = 0 (the other bound) and
    # a = b (the pair with [x >= b], which does not meet it at a = 1, b = 0.5)
    ("param a = 0.5, b = 0.5\nint ([0, 1]) [x <= a] * [x >= b] * [x <= 2*a] d(x)\n", {"a": 1.0}),
    ("param a = 1\nint ([0, 1]) [x <= a] d(x)\n", {"a": 1.0}),
    ("param a = 1\nint ([0, 1]) [x <= a] d(x)\n", {"a": 0.5}),  # no finding
    # two moving jumps on one side: they coincide when a = b (X305 at a = b = 0.3)
    ("param a = 0.3, b = 0.3\nint ([0, 1]) [x <= a] * [x <= b] d(x)\n", {"a": 0.3, "b": 0.3}),
    ("param a = 0.3, b = 0.3\nint ([0, 1]) [x <= a] * [x <= b] d(x)\n", {"a": 0.3, "b": 0.4}),
    # X301: the same zero set for every a
    ("param a = 0.3\nint ([0, 1]) [x <= a] * [2*x <= 2*a] d(x)\n", {"a": 0.3}),
    # a coefficient that vanishes at t = 0: [t*x >= 1/2] is no diffeomorphism there
    ("param t = 0\nint ([0, 1]) [t * x - 0.5 >= 0] d(x)\n", {"t": 0.0}),
    ("param t = 1\nint ([0, 1]) [t * x - 0.5 >= 0] d(x)\n", {"t": 1.0}),
    # two circles, two branches each: the same zero set when r = c (X305 at r = c = 1)
    ("param r = 1, c = 1\nint ([-2, 2], [-2, 2]) [x^2 + y^2 - r^2 <= 0] * [x^2 + y^2 - c^2 <= 0] d(x, y)\n",
     {"r": 1.0, "c": 1.0}),
    ("param r = 1, c = 0.5\nint ([-2, 2], [-2, 2]) [x^2 + y^2 - r^2 <= 0] * [x^2 + y^2 - c^2 <= 0] d(x, y)\n",
     {"r": 1.0, "c": 0.5}),
]


ALL = None


def _lines(findings, codes=transversality.HERE_CODES):
    return [(f.code, f.span.line if f.span else 0, f.span.col if f.span else 0, f.message)
            for f in findings if codes is None or f.code in codes]


@pytest.mark.parametrize(("text", "at"), PROGRAMS)
def test_the_gate_reports_what_the_whole_analysis_reports_for_its_codes(text, at):
    loaded = load_text(text, "p.lgr")
    whole = _lines(transversality.check_loaded(loaded, at=at, sources={"p.lgr": text}))
    asked = transversality.check_loaded(loaded, at=at, sources={"p.lgr": text}, only=transversality.HERE_CODES)
    assert _lines(asked) == whole


KINKS = [
    # [x <= a] on the bound x = 1 at the defaults (a = 1), on x = 0 when a = 0, on [x >= b] when a = b
    "param a = 1, b = 0.5\nint ([0, 1]) [x >= b] * [x <= a] d(x)\n",
    "param a = 0.5, b = 0.5\nint ([0, 1]) [x <= a] * [x >= b] * [x <= 2*a] d(x)\n",
    # a moving circle against the box's four sides: on x = 1 (and y = 1) when r = 1 (the defaults)
    "param r = 1\nint ([0, 1], [0, 1]) [x^2 + y^2 - r^2 <= 0] d(x, y)\n",
    "param r = 0.5\nint ([0, 1], [0, 1]) [x^2 + y^2 - r^2 <= 0] d(x, y)\n",
]


@pytest.mark.parametrize("text", KINKS + [t for t, _ in PROGRAMS])
@pytest.mark.parametrize("explicit", [False, True])
def test_passing_over_a_parameter_set_changes_no_finding(monkeypatch, text, explicit):
    # the whole analysis (`langur check`, with and without --at) against the same analysis solving
    # every pair's parameter set, as main did (Checker.pass_over never true): the same findings, in
    # the same words and order
    loaded = load_text(text, "p.lgr")
    at = {k: float(v) for k, v in loaded.param_values({}).items()} if explicit else None
    fast = transversality.check_loaded(loaded, at=at, sources={"p.lgr": text})
    monkeypatch.setattr(classify.Checker, "pass_over", lambda self, c, g: False)
    slow = transversality.check_loaded(loaded, at=at, sources={"p.lgr": text})
    assert _lines(fast, ALL) == _lines(slow, ALL)


def test_the_kink_names_every_set_its_jump_lies_on():
    # by hand: [x <= a] meets the bound x = 1 at a = 1 (in force), the bound x = 0 at a = 0, and
    # [x >= b]'s zero set at a = b; the gate passes over the last two pairs (not at a = 1) and must
    # solve them when it reports the kink
    text, at = PROGRAMS[0]
    loaded = load_text(text, "p.lgr")
    got = transversality.check_loaded(loaded, at=at, sources={"p.lgr": text}, only=transversality.HERE_CODES)
    assert [f.code for f in got if f.code in transversality.HERE_CODES] == ["X305"]
    assert "(degenerate when a ∈ {0, 1} or a = b)" in got[0].message


def test_a_lambert_pixel_passes_the_gate_in_a_few_cpu_seconds():
    # main: ~40 CPU s (the X304/X306 parameter sets of the conic |L(n.d) - k d|^2 - rho^2 (n.d)^2
    # against the pixel's four bounds and the triangle's three edges, in t and the shader's 4
    # parameters).  By hand at the defaults (t = 0, pixel [0, 0.015]^2): the conic restricted to
    # x = px is a quadratic in y whose y^2 coefficient is a nonzero number at those values, and so for
    # every other restriction: nothing coincides there, no X301 and no X305.
    loaded = load(SCENE, modules=LAMBERT)
    params = loaded.param_values({})
    start = time.process_time()
    gate = _defined.transversal(loaded, SCENE, params)
    spent = time.process_time() - start
    assert gate.findings == [] and gate.here == []
    assert spent < 20.0  # a generous backstop (2.0–2.6 CPU s on the branch, 40 on main)
