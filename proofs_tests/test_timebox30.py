"""Nested time limits (langur/timebox.py): an enclosing limit is never lost to an inner one.

An inner limit's time is at most the enclosing limit's remaining time.  When that inner limit
expired, the enclosing one had expired too; it used to be re-armed for a few microseconds later,
where the next inner limit took it as its own — so a loop of limited calls, each catching its
TimeoutError and going on (the linter's analyses do: X312 "took longer than 15 CPU s"), ran to its
end past the enclosing budget.  CI showed it: ``langur check --timeout 0.2`` (CPU seconds since
determ30) ran its whole analysis and exited 0 instead of X399.  Behaviour, not timings, is asserted:
the enclosing call ends with TimeoutError, and before that fix it returned normally.
"""

from __future__ import annotations

import time

import pytest

from langur.timebox import run_with_timeout


def _spin(seconds: float) -> None:
    start = time.process_time()
    while time.process_time() - start < seconds:
        pass


def _loop_of_limited_calls(call, inner_budget: float, times: int = 100) -> int:
    """``times`` limited calls, each catching its own TimeoutError (as the linter's analyses do)."""
    caught = 0
    for _ in range(times):
        try:
            run_with_timeout(call, inner_budget, cpu=True)
        except TimeoutError:
            caught += 1
    return caught


def test_an_enclosing_cpu_limit_stops_a_loop_of_inner_limits_that_catch_their_timeouts():
    # 100 calls of 0.05 CPU s each under a 0.3 CPU s limit: the limit must end the loop
    with pytest.raises(TimeoutError, match="0.3 CPU s"):
        run_with_timeout(lambda: _loop_of_limited_calls(lambda: _spin(0.05), 5.0), 0.3, cpu=True)


def test_an_enclosing_wall_clock_limit_stops_a_loop_of_inner_limits_that_catch_their_timeouts():
    def loop():
        for _ in range(100):
            try:
                run_with_timeout(lambda: time.sleep(0.05), 5.0)
            except TimeoutError:
                pass
    with pytest.raises(TimeoutError, match="0.3 s"):
        run_with_timeout(loop, 0.3)


def test_three_levels_the_outermost_limit_still_ends_the_call():
    def middle():
        return _loop_of_limited_calls(lambda: _spin(0.05), 5.0)

    def outer_body():
        caught = 0
        for _ in range(20):
            try:
                run_with_timeout(middle, 10.0, cpu=True)
            except TimeoutError:
                caught += 1
        return caught

    with pytest.raises(TimeoutError, match="0.4 CPU s"):
        run_with_timeout(outer_body, 0.4, cpu=True)


def test_an_inner_limit_shorter_than_the_enclosing_one_is_still_its_own():
    # the inner 0.1 s expires first: the caller catches it and the enclosing 5 s limit goes on
    def body():
        return _loop_of_limited_calls(lambda: _spin(1.0), 0.1, times=3)

    assert run_with_timeout(body, 5.0, cpu=True) == 3
