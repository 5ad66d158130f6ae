"""The transversality checker's time limits (Def. 7.2, §7.3: what `langur check` cannot decide in
time is X310) count CPU seconds, not wall-clock seconds: a checker that waits (a loaded machine,
another process on the core) decides the same questions as one that runs alone.  Each test would
fail with the wall-clock limits the checker had before."""

import time

import pytest

from langur.frontend import load_text
from langur.lint import algebra, classify
from langur.transversality import check_loaded

TRIANGLE = """param ax = 0.2
int ([0, 1], [0, 1])
  [y - 0.1 - ax * x >= 0] * [x + y - 1.2 <= 0] * [x - 0.3 >= 0]
d(x, y)
"""


def test_a_sympy_call_that_waits_is_not_cut_off():
    # 0.6 s of waiting, almost no CPU: under a 0.3 s wall-clock limit this was Undecided
    assert algebra.timed(lambda: time.sleep(0.6) or 7, seconds=0.3) == 7


def test_a_sympy_call_that_computes_is_cut_off():
    def busy():
        end = time.process_time() + 5.0
        while time.process_time() < end:
            pass
        return 7

    start = time.process_time()
    with pytest.raises(algebra.Undecided, match="CPU s"):
        algebra.timed(busy, seconds=0.3)
    assert time.process_time() - start < 2.0


def _codes(monkeypatch, pause: float) -> list[str]:
    loaded = load_text(TRIANGLE, path="<triangle>.lgr")
    pair, waits = classify.Checker.pair, [pause]

    def waiting_pair(self, a, b):
        if waits:  # the first check waits: wall-clock time, no CPU, as on a loaded machine
            time.sleep(waits.pop())
        return pair(self, a, b)

    monkeypatch.setattr(classify.Checker, "pair", waiting_pair)
    monkeypatch.setattr(classify, "BUDGET", 1.0)
    return [f.code for f in check_loaded(loaded, at={"ax": 0.2})]


def test_the_whole_analysis_budget_counts_cpu_time(monkeypatch):
    # the first of the checks waits 1.3 s of wall clock against a 1 s budget, and more checks
    # follow; in CPU time they are far inside it, so nothing is left unchecked (no X310)
    alone = _codes(monkeypatch, 0.0)
    waiting = _codes(monkeypatch, 1.3)
    assert "X310" not in waiting
    assert waiting == alone
