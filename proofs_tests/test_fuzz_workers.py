"""Long-lived campaign workers (langur/fuzz/pool.py): one worker runs many units and keeps what
it learned; a unit past its limit is killed with its worker, which a fresh one replaces; what
the campaign's process tells the workers reaches each of them before its next unit."""

from __future__ import annotations

import os
import time

from langur import fuzz
from langur.fuzz import pool

_TOLD: list = []


def _pid_or_spin(text):
    if text.startswith("slow"):  # burns CPU until killed
        end = time.monotonic() + 60
        while time.monotonic() < end:
            pass
    return fuzz.ProgramResult(text, "agree", reason=f"{os.getpid()} {' '.join(map(str, _TOLD))}")


def _run(texts, **kw):
    return pool.run_units(texts, _pid_or_spin, workers=1, limit=0.5,
                          on_time_limit=lambda t, why: fuzz.ProgramResult(t, "timeout", reason=why),
                          on_error=lambda t, why: fuzz.ProgramResult(t, "exact_error", reason=why), **kw)


def test_one_worker_runs_many_units_and_is_replaced_after_a_kill(monkeypatch):
    monkeypatch.setattr(pool, "GRACE", 0.0)
    out = _run(["a", "b", "slow", "c", "d"])
    assert [r.status for r in out] == ["agree", "agree", "timeout", "agree", "agree"]
    pids = [r.reason.split()[0] for r in out]
    assert pids[0] == pids[1] and pids[3] == pids[4]  # the same process ran both units
    assert pids[1] != pids[3]  # the killed worker was replaced
    assert str(os.getpid()) not in pids


def test_what_the_campaign_tells_reaches_the_worker_before_its_next_unit():
    p = pool.Pool(_pid_or_spin, workers=1, limit=5.0, told=_TOLD.append,
                  on_time_limit=lambda t, why: None, on_error=lambda t, why: None)
    p.submit("a")
    while p._busy():
        p._collect()
    p.tell("x")
    p.tell("y")
    p.submit("b")
    first, second = p.finish()
    assert first.reason.split()[1:] == [] and second.reason.split()[1:] == ["x", "y"]
    assert _TOLD == []  # told in the worker, not in this process


def test_examples_counts_distinct_programs_continuing_the_same_draws(tmp_path):
    """`--examples N` checks N distinct programs: those N draws give (hypothesis repeats some),
    in the same order, followed by more of the same sequence (seed 5: 19 distinct in 20 draws)."""
    from hypothesis import HealthCheck, given, seed, settings

    from langur.fuzz.generate import hypothesis_home

    drawn = []

    with hypothesis_home(str(tmp_path)):
        @settings(max_examples=20, deadline=None, database=None, suppress_health_check=list(HealthCheck))
        @seed(5)
        @given(fuzz.programs())
        def draw(prog):
            drawn.append(prog.text)

        draw()
        texts = fuzz.generated(20, 5)
    once = list(dict.fromkeys(drawn))
    assert len(drawn) == 20 and len(once) < 20  # the plain run repeats a program
    assert len(texts) == len(set(texts)) == 20
    assert texts[: len(once)] == once
