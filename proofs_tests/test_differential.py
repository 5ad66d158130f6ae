"""Differential testing: the exact (sympy) and Monte Carlo (numpy) engines agree on random
well-typed, transverse programs (langur/fuzz.py), generated as .lgr text and loaded by the front end.

The engines are independent implementations of ⟦p⟧ and ⦇p⦈ (LANGUAGE.md §3–§4), so agreement on
value, derivative, regular part and boundary part is evidence for both; the harness itself is
checked on programs whose numbers are known by hand, and on a degenerate program where it must
report a failure (so the property test can fail).
"""

import math

import pytest
from hypothesis import HealthCheck, given, settings

from langur import fuzz
from langur.frontend import load_text


def _row(res, quantity, wrt=None):
    (row,) = [r for r in res.rows if r.quantity == quantity and r.wrt == wrt]
    return row


STATUSES: list[str] = []


@settings(derandomize=True, max_examples=25, deadline=None, database=None,
          suppress_health_check=list(HealthCheck))
@given(fuzz.programs(max_summands=2, max_factors=2, max_conds=2, max_params=2, light=True))
def test_engines_agree_on_random_transverse_programs(prog):
    res = fuzz.compare_text(prog.text, samples=20000, seed=0, timeout=8.0)
    STATUSES.append(res.status)
    bad = [r for r in res.rows if not r.ok]
    assert not res.failed, f"{res.status} {res.reason}\n{prog.text}\n{bad}"


def test_most_random_programs_were_really_compared():
    """The property above is not vacuous: most programs reached both engines (not timeouts,
    not discarded by the linter)."""
    if not STATUSES:
        pytest.skip("run together with the property test")
    assert STATUSES.count("agree") >= len(STATUSES) // 2, STATUSES


def test_generated_programs_are_generic_and_load():
    """Whatever the draw, the generator's texts load, declare their defaults, and the numeric
    genericity check rejects a zero set through a corner of the box."""
    from hypothesis import find

    prog = find(fuzz.programs(), lambda p: "[" in p.text and "d(x, y)" in p.text,
                settings=settings(database=None, derandomize=True, max_examples=200))
    loaded = load_text(prog.text)
    assert [(k, str(v)) for k, v in loaded.params.items()] == \
        [(k, str(__import__("fractions").Fraction(d))) for k, d in prog.params]
    assert len(loaded.program.variables) == 2


def test_harness_on_fig1_by_hand():
    # ∫₀¹ [x ≤ θ] dx = θ = 0.5; D_θ = 1, all of it boundary (a 1-D delta: exact in MC, stderr 0)
    res = fuzz.compare_text("param theta = 0.5\nint ([0, 1]) [x <= theta] d(x)\n", samples=4000)
    assert res.status == "agree", res
    assert _row(res, "value").exact == 0.5
    assert abs(_row(res, "value").mc - 0.5) < 5 * _row(res, "value").stderr
    b = _row(res, "boundary", "theta")
    assert b.exact == 1.0 and b.mc == pytest.approx(1.0, abs=1e-12) and b.stderr == 0.0
    assert _row(res, "regular", "theta").exact == 0.0
    assert _row(res, "theorem_8_1", "theta").ok


def test_harness_reports_coincident_jumps():
    # [x ≥ a]·[x ≥ a] on [0, 1]: ⟦p⟧ = 1 − a, D_a = −1, but ⦇p⦈ counts the jump twice: −2 in
    # both engines (they agree with each other) — the Theorem 8.1 row must catch it.
    text = "param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n"
    res = fuzz.compare_text(text, samples=4000, lint=False)
    assert res.status == "discrepancy"
    th = _row(res, "theorem_8_1", "a")
    assert not th.ok and th.exact == pytest.approx(-1.0) and th.mc == pytest.approx(-2.0)
    assert _row(res, "derivative", "a").ok  # engines agree with each other on −2
    # with the linter, the program is discarded (X301), not run
    linted = fuzz.compare_text(text, samples=4000)
    assert linted.status == "discarded" and any(f.startswith("X301") for f in linted.findings)


def test_agree_tolerance():
    assert fuzz.agree(1.0, 0.0, 1.0 + 4.9e-3, 1e-3)
    assert not fuzz.agree(1.0, 0.0, 1.0 + 5.1e-3, 1e-3)
    assert fuzz.agree(1.0, 1e-2, 1.0 + 1.4e-2, 1e-3)     # exact engine's quadrature error bound
    assert fuzz.agree(3.0, 0.0, 3.0 * (1 + 5e-10), 0.0)  # 1-D delta: relative 1e-9
    assert not fuzz.agree(3.0, 0.0, 3.0 * (1 + 1e-8), 0.0)
    assert not fuzz.agree(math.nan, 0.0, 1.0, 1.0)
    assert not fuzz.agree(1.0, 0.0, math.nan, 1.0)


def test_load_error_is_a_failure():
    res = fuzz.compare_text("param a = 0.5\nint ([0, 1]) [x <= q] d(x)\n")
    assert res.status == "load_error" and res.failed and "q" in res.reason
