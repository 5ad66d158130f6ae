"""A campaign unit asks the linter only what decides it, and the exact engine prints no notes it
does not read (issue 13, camp10).

``langur fuzz`` discards a program on X301 or X305 (``langur.fuzz.generate.LINT_DISCARD``): a unit
runs only the analyses that can report them (``check_loaded(..., only=...)``); the others (tangency
X302, families X303, domains X307, empty domains X314, double roots X315, integrability X311–X313)
run again in full for a unit that fails, whose findings are shown.  The programs and their findings
are those of ``test_transversality`` / ``examples/degenerate`` (worked out by hand there).
"""

import gc
import math
from pathlib import Path

import mpmath
import pytest
import sympy as sp

from langur import engines
from langur import transversality as tv
from langur.frontend import load_text
from langur.fuzz import compare
from langur.fuzz.generate import LINT_DISCARD
from langur.symbolic import integrate
from langur.symbolic.integrate import integrate_pieces
from langur.symbolic.pieces import Condition, Piece

DEGENERATE = Path(__file__).resolve().parent.parent / "examples" / "degenerate"
ONLY = frozenset(LINT_DISCARD)

TANGENT_CIRCLES = "param a = 0.5\nint ([-2, 2], [-2, 2]) [x^2 + y^2 <= 1] * [(x - a)^2 + y^2 <= (1 - a)^2] d(x, y)\n"


def _found(text, at=None, only=None):
    loaded = load_text(text, "t.lgr")
    return [(f.code, f.message) for f in tv.check_loaded(loaded, at=at, sources={"t.lgr": text}, only=only)]


@pytest.mark.parametrize("text,code", [
    # two circles tangent at (1, 0) (centres 0 and a = 1/2, radii 1 and 1/2): a null-set failure
    (TANGENT_CIRCLES, "X302"),
    # x = a, y = a and x + y = 2a through (a, a): three normals of ℝ² are dependent
    ((DEGENERATE / "three_lines.lgr").read_text(), "X303"),
    # t²x² − 2tx + 1 = (tx − 1)²: the condition touches 0 at x = 1/t without changing sign
    ("param t = 0.7\nint ([-1, 1]) [t^2 * x^2 - 2*t*x + 1 > 0] d(x)\n", "X315"),
    # log(x − 2) on [0, 1]: its argument is negative everywhere, the integral does not exist
    ("int ([0, 1]) log(x - 2) d(x)\n", "X311"),
])
def test_analyses_that_cannot_discard_are_not_run_when_only_the_discard_codes_are_asked(text, code):
    full, only = _found(text), _found(text, only=ONLY)
    assert code in {c for c, _ in full} and code not in {c for c, _ in only}
    assert [f for f in only if f[0] in ONLY] == [f for f in full if f[0] in ONLY] == []


@pytest.mark.parametrize("text,at", [
    # coincident zero sets x + y = c and 2x + 2y − 2c = 0 for every c: X301
    ("param c = 0.1\nint ([0, 1], [0, 1]) [x + y >= c] * [2*x + 2*y - 2*c >= 0] d(x, y)\n", None),
    # [x + k > 0]·[x + l > 0] on [−1, 1] at k = 1, l = 2: the jump x = −1 on the bound, the other
    # factor 1 there: ∫ = 1 + min(k, 1), a kink at k = 1 — X305 at these values
    ("param k = 1, l = 2\nint ([-1, 1]) [x + k > 0] * [x + l > 0] d(x)\n", {"k": 1.0, "l": 2.0}),
    # the window [θ, v] closing at θ = v = 0 with weight x − θ + 1 (1 there): X305
    ("param theta = 0, v = 0\nint ([theta, v], [0, 1]) x - theta + 1 d(x, y)\n", {"theta": 0.0, "v": 0.0}),
    # [x ≤ θ] on [0, 1] at θ = 1: the jump on the domain's end, min(max(θ, 0), 1) has a corner: X305
    ((DEGENERATE / "boundary.lgr").read_text(), {"theta": 1.0}),
])
def test_the_discarding_findings_are_the_full_analysis_ones(text, at):
    full = [f for f in _found(text, at) if f[0] in ONLY]
    assert full  # each of these programs is discarded by a campaign
    assert [f for f in _found(text, at, only=ONLY) if f[0] in ONLY] == full


class _ByHand:
    """An engine answering for :data:`TANGENT_CIRCLES` by hand: the disc of centre (a, 0) and radius
    1 − a lies in the unit disc, so ⟦p⟧ = π(1 − a)² and ∂ₐ⟦p⟧ = −2π(1 − a); ``off``: the value
    one too large (every comparison of it fails)."""

    name, kind = "by-hand", engines.Kind.BOUNDED

    def __init__(self, off=0.0):
        self.off = off

    def value(self, program, params):
        return engines.Answer(math.pi * (1 - params["a"]) ** 2 + self.off, 1e-9)

    def derivative(self, program, params, direction):
        return engines.Answer(-2 * math.pi * (1 - params["a"]) * direction["a"], 1e-9)


def test_a_unit_reports_the_other_findings_only_when_it_fails():
    ok = compare.compare_engine(TANGENT_CIRCLES, _ByHand(), timeout=20.0, isolate=False)
    assert ok.status == "agree"
    assert not [f for f in ok.findings if f.startswith("X302")]  # not asked: it cannot discard
    bad = compare.compare_engine(TANGENT_CIRCLES, _ByHand(off=1.0), timeout=20.0, isolate=False)
    assert bad.status == "discrepancy"
    # the failure's findings are the full linter's: the tangency at (1, 0), as `langur check` says
    full = [f"{c} {m}" for c, m in _found(TANGENT_CIRCLES, at={"a": 0.5})]
    assert [f for f in bad.findings if f[:1] == "X"] == full
    assert any(f.startswith("X302") and "(x, y) = (1, 0)" in f for f in bad.findings)


def test_a_quadrature_within_untidied_prints_no_exact_part():
    # ∫₀¹ exp(x³) dx (no elementary antiderivative) + ∫₀¹ [x ≤ θ] dx = θ at θ = 1/2: mpmath for the first
    x, theta = sp.Symbol("x", real=True), sp.Symbol("theta", real=True)
    pieces = [Piece((), sp.exp(x**3)), Piece((Condition(theta - x),), sp.Integer(1))]
    want = float(mpmath.quad(lambda v: mpmath.exp(v**3), [0, 1])) + 0.5
    read = integrate_pieces(pieces, (x,), ((0, 1),), {theta: sp.Rational(1, 2)})
    with integrate.untidied():
        fuzz = integrate_pieces(pieces, (x,), ((0, 1),), {theta: sp.Rational(1, 2)})
    assert any(n.startswith("exact part") for n in read.notes)
    assert not any(n.startswith("exact part") for n in fuzz.notes)
    assert fuzz.value == read.value and fuzz.error == read.error and fuzz.method == read.method == "quadrature"
    assert math.isclose(fuzz.value, want, abs_tol=max(fuzz.error, 1e-12))


def _worker_gc(text):
    """In a pool worker: its collector's thresholds, and whether a dropped reference cycle is
    collected while the unit keeps allocating (no explicit ``gc.collect``)."""
    import weakref

    class Node:
        pass

    a, b = Node(), Node()
    a.other, b.other = b, a
    gone = []
    weakref.finalize(a, gone.append, True)
    del a, b
    keep = [[i] for i in range(200_000)]  # container allocations: what the young generation counts
    return gc.get_threshold(), bool(gone), len(keep)


def test_a_worker_collects_cycles_less_often_but_still_collects_them():
    from langur.fuzz import pool

    out = pool.run_units(["unit"], _worker_gc, workers=1, limit=60.0, on_time_limit=lambda t, r, *a: r,
                         on_error=lambda t, r: r)
    (thresholds, collected, n), = out
    assert thresholds == pool.GC_THRESHOLDS and thresholds[0] > gc.get_threshold()[0]
    assert collected and n == 200_000
