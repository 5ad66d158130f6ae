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
                          on_time_limit=lambda t, why, last=None: fuzz.ProgramResult(t, "timeout", reason=why),
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
                  on_time_limit=lambda t, why, last=None: None, on_error=lambda t, why: None)
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


def test_a_killed_unit_reports_the_cpu_seconds_it_used(monkeypatch):
    """A unit killed at its limit is a timeout that says what it used (camp9: `-v` printed "0.0s"):
    at least its limit of CPU seconds (the spinning unit burns CPU only), read from /proc by the
    pool, and shown by `langur fuzz -v` in place of the exact engine's unknown share."""
    from langur.commands.fuzz import verbose_times
    from langur.fuzz import campaign

    monkeypatch.setattr(pool, "GRACE", 0.0)
    before = time.process_time()
    out = pool.run_units(["a", "slow"], _pid_or_spin, workers=1, limit=0.5,
                         on_time_limit=campaign._time_limited, on_error=campaign._unit_error)
    assert [r.status for r in out] == ["agree", "timeout"]
    killed = out[1]
    if pool.cpu_seconds(os.getpid()) is not None:  # Linux: the limit counts CPU seconds
        assert 0.5 <= killed.cpu_seconds < 5.0
        assert killed.seconds >= killed.cpu_seconds - 0.05  # one thread: no more CPU than wall time
        line = verbose_times(killed)
        assert line.split()[:2] == ["timeout", "-"] and f"{killed.cpu_seconds:.1f} CPU s" in line
    assert time.process_time() - before < 0.5  # the spinning was the worker's, not this process's
