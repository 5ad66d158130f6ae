"""The exact engine within one budget per call; notes printed at a readable length (session 33,
bench/history/2026-11-29.md#budget33.

(1) ``delta._jacobian``: sympy's determinant of DΨ̂⁻¹ is time-boxed within the call's budget
(``DET_SECONDS``), else the determinant is written by cofactor expansion — the same function (hand
values below).  (2) ``exact_deriv``/``exact_eval``: one CPU budget (``seconds``) for the derivative and
its Theorem 8.1 check together; past it, quadrature and :data:`~langur.exact.CHECK_STOPPED`.
(3) ``langur deriv``/``eval`` print a note of thousands of characters shortened, its whole text in
``--json``.
"""

import json
import math
import time

import pytest
import sympy as sp

from langur import exact
from langur.cli import main
from langur.commands import _common
from langur.frontend import load_text
from langur.symbolic import delta
from langur.symbolic.context import Context
from langur.timebox import Deadline

U0, U1 = sp.symbols("budget33_u0 budget33_u1", real=True)
# Ψ̂⁻¹ = (√(u₀ + u₁² + 1), u₁(u₀ + 2)); by hand det DΨ̂⁻¹ = (u₀ + 2)/(2√(u₀ + u₁² + 1)) − u₁²/√(u₀ + u₁² + 1),
# at u₀ = 0: (1 − u₁²)/√(1 + u₁²)
COMPS = (sp.sqrt(U0 + U1 ** 2 + 1), U1 * (U0 + 2))


def by_hand(u1: float) -> float:
    return (1 - u1 ** 2) / math.sqrt(1 + u1 ** 2)


def _value(J, u1: float) -> float:
    return float(J.xreplace({U1: sp.Rational(u1)}).evalf(30))


@pytest.mark.parametrize("u1", [0.5, -1.75, 3.0])
def test_jacobian_within_time_is_sympys_determinant(u1):
    ctx = Context({}, Deadline(30.0))
    J = delta._jacobian(COMPS, (U0, U1), ctx)
    assert _value(J, u1) == pytest.approx(by_hand(u1), rel=1e-14)
    assert not any("cofactor" in n for n in ctx.notes)


def test_a_slow_determinant_is_cut_at_its_cap_and_written_by_cofactors(monkeypatch):
    comps = (COMPS[0] + 0, U1 * (U0 + 2) + U0 * 0 + 1)  # (u₁(u₀ + 2) + 1: the same derivatives, a new key)
    calls = []

    def slow_det(self, *args, **kwargs):  # sympy's determinant on a large inverse branch: seconds
        calls.append(1)
        start = time.process_time()
        while time.process_time() - start < 30:
            pass
        raise AssertionError("not cut")

    monkeypatch.setattr(sp.Matrix, "det", slow_det)
    ctx = Context({}, Deadline(60.0))
    start = time.process_time()
    J = delta._jacobian(comps, (U0, U1), ctx)
    spent = time.process_time() - start
    assert calls == [1]
    assert spent < delta.DET_SECONDS + 3  # cut at its cap (a generous backstop, not a timing)
    for u1 in (0.5, -1.75, 3.0):
        assert _value(J, u1) == pytest.approx(by_hand(u1), rel=1e-14)
    assert any("cofactor expansion" in n for n in ctx.notes)
    assert (comps, (U0, U1)) not in delta._JACOBIANS  # a call with more time gets sympy's form


def test_a_spent_budget_gives_the_cofactor_determinant_at_once():
    comps = (COMPS[0], U1 * (U0 + 2) - 7)
    ctx = Context({}, Deadline(0.0))
    J = delta._jacobian(comps, (U0, U1), ctx)
    assert _value(J, 0.5) == pytest.approx(by_hand(0.5), rel=1e-14)


# ⟦p⟧ = a²/2, ⦇p⦈ = a = 0.37 by hand (the delta at x = a weighs x = a): all of it boundary
PROGRAM = "param a = 0.37\nint ([0, 1]) x * [x <= a] d(x)\n"


def test_deriv_within_its_budget_is_a_closed_form_with_its_check():
    d = exact.exact_deriv(load_text(PROGRAM).program, {"a": 0.37}, {"a": 1})
    assert d.method.value == "closed_form" and d.value == pytest.approx(0.37, abs=1e-15)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds


def test_a_spent_budget_is_quadrature_and_stops_the_check():
    # (a program of its own: a closed form found with more time is remembered for every point of its cell)
    # ⦇p⦈ = (a + 3)·a² by hand
    p = load_text("param a = 0.38\nint ([0, 1]) (x + 3) * x * x * [x <= a] d(x)\n").program
    d = exact.exact_deriv(p, {"a": 0.38}, {"a": 1}, seconds=1e-9)
    assert d.method.value == "quadrature"
    assert d.value == pytest.approx(3.38 * 0.38 ** 2, abs=max(d.error, 1e-12))
    assert d.boundary == pytest.approx(3.38 * 0.38 ** 2, abs=1e-12) and d.regular == 0
    assert exact.CHECK_STOPPED in d.notes and d.theorem_8_1 is None


def test_the_check_gets_only_what_the_derivative_left(monkeypatch):
    seen = []
    real = exact.run_with_timeout

    def spy(fn, seconds, cpu=False):
        seen.append(seconds)
        return real(fn, seconds, cpu=cpu)

    monkeypatch.setattr(exact, "run_with_timeout", spy)
    exact.exact_deriv(load_text(PROGRAM).program, {"a": 0.37}, {"a": 1}, seconds=7.0)
    assert len(seen) == 1 and 0 < seen[0] <= 7.0
    exact.exact_deriv(load_text(PROGRAM).program, {"a": 0.37}, {"a": 1}, seconds=7.0, check_seconds=2.0)
    assert seen[1] == 2.0


def test_eval_within_its_budget_and_past_it():
    # a shape of its own, ⟦p⟧ = a⁵/5 + 5a⁴/4 by hand (a closed form of a common shape found by another test in the
    # same process is remembered for every point of its cell)
    p = load_text("param a = 0.41\nint ([0, 1]) (x + 5) * x * x * x * [x <= a] d(x)\n").program
    q = exact.exact_eval(p, {"a": 0.41}, seconds=1e-9)  # (first: a closed form found is remembered)
    assert q.method.value == "quadrature" and q.value == pytest.approx((0.41 ** 5 / 5 + 5 * 0.41 ** 4 / 4), abs=max(q.error, 1e-12))
    v = exact.exact_eval(p, {"a": 0.41})
    assert v.method.value == "closed_form" and v.value == pytest.approx((0.41 ** 5 / 5 + 5 * 0.41 ** 4 / 4), abs=1e-15)


# -- notes at a readable length ------------------------------------------------------------------

def test_a_short_note_is_printed_whole():
    note = "x" * _common.NOTE_CHARS
    assert _common.readable_note(note) == note


def test_a_long_note_keeps_its_beginning_and_end_and_says_what_was_left_out():
    note = "sign of det DΨ̂⁻¹ = " + "+".join(f"t**{k}" for k in range(900)) + " taken as + (sampled)"
    out = _common.readable_note(note)
    head = _common.NOTE_CHARS - _common.NOTE_TAIL
    assert out.startswith(note[:head]) and out.endswith(note[-_common.NOTE_TAIL:])
    assert f"[{len(note) - _common.NOTE_CHARS} characters left out; the whole note: --json]" in out
    assert len(out) < _common.NOTE_CHARS + 80


@pytest.fixture
def long_note(monkeypatch):
    note = "delta piece 0: solving " + " + ".join(f"{k}*t**{k}" for k in range(800)) + ": time limit"
    real = exact.ExactValue.of

    def of(r):
        v = real(r)
        v.notes.append(note)
        return v

    monkeypatch.setattr(exact.ExactValue, "of", of)
    return note


@pytest.mark.parametrize("command", ["eval", "deriv"])
def test_deriv_and_eval_print_a_long_note_shortened_and_json_keeps_it(tmp_path, capsys, long_note, command):
    path = tmp_path / "p.lgr"
    path.write_text("param a = 0.43\nint ([0, 1]) x * [x <= a] d(x)\n")
    wrt = ["--wrt", "a"] if command == "deriv" else []
    main([command, str(path), *wrt, "--engine", "exact"])
    out = capsys.readouterr().out
    assert long_note not in out
    lines = [line for line in out.splitlines() if "delta piece 0: solving" in line]
    assert len(lines) == 1 and len(lines[0]) < _common.NOTE_CHARS + 120 and "the whole note: --json" in lines[0]
    assert lines[0].endswith(long_note[-_common.NOTE_TAIL:])
    main([command, str(path), *wrt, "--engine", "exact", "--json"])
    assert long_note in json.loads(capsys.readouterr().out)["exact"]["notes"]
