"""The transversality linter inside a fuzz unit (issues 13 and 18; Def. 7.2, §7.3): a CPU budget
for the whole analysis, handed down by the campaign, whose end is said in an X310 warning; its
limits count CPU seconds, so a checker sharing its core with busy processes finds the same; and
the exact shortcuts that replace sympy calls give what sympy gives.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time

import pytest
import sympy as sp

from langur.frontend import load_text
from langur.lint import algebra
from langur.transversality import check_loaded

# Two conditions whose zero sets coincide when a = b (X304, hand-derived: x = a and x = b), a
# third that multiplies both: pairs, a tangency and a family to check.
COINCIDE = """param a = 0.3, b = 0.6
int ([0, 1], [0, 1])
  [x - a >= 0] * [x - b >= 0] * [y - x * x >= 0]
d(x, y)
"""


def _check(text: str, **kw):
    loaded = load_text(text, path="<t>.lgr")
    return check_loaded(loaded, sources={"<t>.lgr": text}, **kw)


def _key(findings):
    return [(f.code, f.span.line if f.span else 0, f.span.col if f.span else 0, f.message) for f in findings]


def test_a_budget_large_enough_changes_nothing():
    alone = _check(COINCIDE)
    assert [f.code for f in alone].count("X304") == 1 and "when a = b" in str([f.message for f in alone])
    assert _key(_check(COINCIDE, budget=60.0)) == _key(alone)


def test_a_spent_budget_is_said_and_not_remembered():
    stopped = _check(COINCIDE, budget=0.0)
    assert any(f.code == "X310" and "its budget" in f.message for f in stopped)
    assert not any(f.code == "X304" for f in stopped)  # unchecked, not decided "transverse"
    # a later analysis with a budget of its own decides again (nothing undecided was remembered)
    assert _key(_check(COINCIDE)) == _key(_check(COINCIDE, budget=60.0))


def test_budget_spent_is_not_memoized():
    calls = []

    @algebra._memo
    def question(e):
        calls.append(e)
        raise algebra.BudgetSpent("spent")

    for _ in range(2):
        with pytest.raises(algebra.BudgetSpent):
            question(sp.Integer(1))
    assert len(calls) == 2  # asked again: a budget's end is no answer


def _busy(seconds: float) -> None:
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        pass


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="needs CPU affinity (Linux)")
def test_busy_siblings_on_the_same_core_change_no_finding():
    # The checker and three busy processes share one core: the checker gets about a quarter of
    # it, so its wall-clock time is ~4x its CPU time.  A budget of twice its CPU time alone is
    # then passed by the wall clock but not by the CPU clock: the findings are the same (with a
    # wall-clock budget they would end in X310 "stopped").
    saved = os.sched_getaffinity(0)
    core = {min(saved)}
    _check(COINCIDE)  # the checker's caches warm: the runs below cost the same
    c0 = time.process_time()
    alone = _check(COINCIDE)
    need = time.process_time() - c0
    budget = 2 * need + 0.05
    os.sched_setaffinity(0, core)
    ctx = mp.get_context("fork")
    busy = [ctx.Process(target=_busy, args=(60.0,)) for _ in range(3)]
    try:
        for p in busy:
            p.start()
        w0, c0 = time.monotonic(), time.process_time()
        loaded = _check(COINCIDE, budget=budget)
        wall, cpu = time.monotonic() - w0, time.process_time() - c0
    finally:
        for p in busy:
            p.kill()
            p.join()
        os.sched_setaffinity(0, saved)
    assert _key(loaded) == _key(alone)
    assert cpu <= budget + 1.0
    if wall <= budget:  # pragma: no cover - the siblings did not slow it down: nothing shown
        pytest.skip(f"the busy siblings did not slow the checker down (wall {wall:.2f} s)")


a, b, c = sp.symbols("a b c", real=True)


def test_linear_parameter_shortcut_is_what_sympy_solves():
    # equations the linter met in campaign programs (seed 1 and `--turning --kinks --seed 11`): a
    # restriction of one condition to another's zero set, transcendental in one parameter, linear
    # with a number as coefficient in another
    eqs = [-20 * b + 20 * sp.sin(6 * a) + 9, a + b * sp.log(b + 1) - sp.log(b + 1) ** 2]
    for eq in eqs:
        params = sorted(eq.free_symbols, key=str)
        short = algebra._solved_linearly([eq], params)
        assert short == sp.solve([eq], params, dict=True)
        (s, v), = short[0].items()
        assert sp.simplify(eq.subs(s, v)) == 0
    # not for a coefficient that is not a number, a single parameter, a polynomial: sympy decides
    assert algebra._solved_linearly([a * b + sp.sin(a)], [a, b]) is None
    assert algebra._solved_linearly([b + sp.sin(a)], [b]) is None
    assert algebra._solved_linearly([b + a ** 3], [a, b]) is None


def test_never_together_agrees_with_sympy():
    x, y = sp.symbols("x y", real=True)
    no = [
        [y - x ** 3 - sp.Rational(29, 100), y - x ** 3 - sp.Rational(31, 100)],
        [sp.Rational(161, 100) - sp.sqrt(y + 2), -1 / (2 * sp.sqrt(y + 2))],
    ]
    for eqs in no:
        assert algebra._never_together(eqs)
        assert [s for s in sp.solve(eqs, [x, y], dict=True) if not any(v.has(sp.I) for v in s.values())] == []
    maybe = [[x - sp.sin(y) - sp.Rational(53, 100), sp.cos(y)], [x ** 2 - 1, x - 1]]
    for eqs in maybe:
        assert not algebra._never_together(eqs)
        assert sp.solve(eqs, [x, y], dict=True)  # they do meet


def test_plainly_zero_is_a_proof():
    x = sp.Symbol("x", real=True)
    assert algebra._plainly_zero((x + 1) ** 2 - x ** 2 - 2 * x - 1)
    assert algebra._plainly_zero(1 / (x + 1) - 1 / (x + 1))
    assert algebra._plainly_zero((x ** 2 - 1) / (x - 1) - x - 1)
    assert not algebra._plainly_zero(sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1)  # simplify's, not ours
    assert algebra.vanishes(sp.sin(x) ** 2 + sp.cos(x) ** 2 - 1, [x])
