"""The exact engine's sympy budgets count CPU seconds (langur/timebox.py): a sleeping (or starved)
process does not use them up, a busy one does, and a wall-clock backstop still ends a call that
uses no CPU."""

from __future__ import annotations

import time

import pytest

from langur import timebox
from langur.timebox import Deadline, budget, run_with_timeout


def _spin(seconds: float) -> None:
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


def test_a_cpu_limit_ends_a_busy_call_near_its_cpu_seconds():
    start = time.process_time()
    with pytest.raises(TimeoutError, match="CPU"):
        run_with_timeout(lambda: _spin(5.0), 0.2, cpu=True)
    assert time.process_time() - start < 1.5


def test_sleeping_does_not_use_a_cpu_limit():
    assert run_with_timeout(lambda: (time.sleep(0.4), "slept")[1], 0.2, cpu=True) == "slept"


def test_the_wall_clock_backstop_ends_a_call_that_uses_no_cpu(monkeypatch):
    monkeypatch.setattr(timebox, "BACKSTOP_SLACK", 0.0)
    monkeypatch.setattr(timebox, "BACKSTOP_FACTOR", 3.0)  # 0.1 CPU s: at most 0.3 s of wall clock
    start = time.monotonic()
    with pytest.raises(TimeoutError, match="wall clock"):
        run_with_timeout(lambda: time.sleep(5), 0.1, cpu=True)
    assert time.monotonic() - start < 2


def test_a_cpu_limit_inside_a_wall_limit_never_extends_it():
    start = time.monotonic()
    with pytest.raises(TimeoutError):
        run_with_timeout(lambda: run_with_timeout(lambda: time.sleep(5), 10.0, cpu=True), 0.3)
    assert time.monotonic() - start < 2
    # and a wall limit inside a CPU limit: the inner one is reported, the outer goes on
    def outer():
        with pytest.raises(TimeoutError):
            run_with_timeout(lambda: _spin(5.0), 0.1)
        return "outer done"
    assert run_with_timeout(outer, 5.0, cpu=True) == "outer done"


def test_nested_cpu_limits_never_extend_the_outer_one():
    start = time.process_time()
    with pytest.raises(TimeoutError):
        run_with_timeout(lambda: run_with_timeout(lambda: _spin(5.0), 10.0, cpu=True), 0.2, cpu=True)
    assert time.process_time() - start < 1.5


def test_deadlines_and_budgets_count_cpu_seconds():
    d = Deadline(1.0)
    time.sleep(0.3)
    assert d.remaining() > 0.9  # sleeping costs no budget
    _spin(0.3)
    assert d.remaining() < 0.75  # computing does
    with budget(0.2):
        assert d.remaining() <= 0.2
        with pytest.raises(TimeoutError):
            d.run(lambda: _spin(5.0))
    # over once the wall-clock backstop has passed, CPU seconds left or not
    d2 = Deadline(0.0)
    assert d2.remaining() <= 0


def test_a_deadline_is_over_once_its_wall_clock_backstop_passed(monkeypatch):
    monkeypatch.setattr(timebox, "BACKSTOP_FACTOR", 0.0)
    monkeypatch.setattr(timebox, "BACKSTOP_SLACK", 0.2)
    d = Deadline(10.0)
    assert d.remaining() > 9
    time.sleep(0.3)
    assert d.remaining() == 0.0
    with pytest.raises(TimeoutError):
        d.run(lambda: 1)


def test_a_limit_expiring_inside_a_gc_callback_is_delivered_after_it_not_swallowed(monkeypatch):
    """hypothesis times garbage collections with a gc callback; a limit expiring inside it used to
    raise there, where Python only prints "Exception ignored in …".  Now the handler waits for the
    callback to return (the timer repeats every 50 ms) and the call still ends with TimeoutError."""
    import gc
    import sys

    unraisable = []
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)

    def slow_callback(phase, info):  # noqa: ARG001
        if phase == "start":
            _spin(0.3)

    def work():
        gc.collect()  # the limit (0.1 CPU s) expires inside the callback's 0.3 CPU s
        _spin(5.0)

    gc.callbacks.append(slow_callback)
    try:
        start = time.process_time()
        with pytest.raises(TimeoutError):
            run_with_timeout(work, 0.1, cpu=True)
        used = time.process_time() - start
    finally:
        gc.callbacks.remove(slow_callback)
    assert [u for u in unraisable if isinstance(u.exc_value, timebox._Expired)] == []
    assert 0.3 <= used < 2.0


def test_a_limit_expiring_inside_a_weakref_callback_is_delivered_after_it_not_swallowed(monkeypatch):
    """CI printed "Exception ignored in: <function WeakValueDictionary.__init__.<locals>.remove>
    … _Expired": a limit expiring inside the weakref module's callbacks is swallowed like one in a
    gc callback.  A ``weakref.finalize`` whose callback runs 0.3 CPU s when its object dies."""
    import sys
    import weakref

    unraisable = []
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)

    class Dying:
        pass

    def work():
        obj = Dying()
        weakref.finalize(obj, _spin, 0.3)
        del obj  # the limit (0.1 CPU s) expires inside the finalizer's 0.3 CPU s
        _spin(5.0)

    start = time.process_time()
    with pytest.raises(TimeoutError):
        run_with_timeout(work, 0.1, cpu=True)
    used = time.process_time() - start
    assert [u for u in unraisable if isinstance(u.exc_value, timebox._Expired)] == []
    assert 0.3 <= used < 2.0


def test_a_limit_firing_while_an_extension_initialises_is_a_time_limit(tmp_path, monkeypatch):
    """CI: `langur deriv --timeout 0.5` once printed "internal error: ImportError: initialization
    failed": the limit fired while scipy lazily imported a pybind11 module, whose init re-raises any
    exception as ``ImportError("initialization failed")`` chained to it.  A module whose top level
    does the same stands in for it; the call must end as a time limit, on either clock."""
    (tmp_path / "slow_extension_tb.py").write_text(
        "import time\n"
        "try:\n"
        "    end = time.process_time() + 5.0\n"
        "    while time.process_time() < end:\n"
        "        pass\n"
        "except BaseException as e:\n"
        "    raise ImportError('initialization failed') from e\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import importlib
    import sys

    for cpu in (False, True):
        sys.modules.pop("slow_extension_tb", None)
        start = time.process_time()
        with pytest.raises(TimeoutError):
            run_with_timeout(lambda: importlib.import_module("slow_extension_tb"), 0.2, cpu=cpu)
        assert time.process_time() - start < 1.5
    # an ImportError of its own (no limit behind it) is still an ImportError
    (tmp_path / "broken_extension_tb.py").write_text("raise ImportError('initialization failed')\n")
    with pytest.raises(ImportError):
        run_with_timeout(lambda: importlib.import_module("broken_extension_tb"), 5.0)


def test_a_limit_expiring_inside_a_tracer_waits_for_it_and_leaves_it_on(monkeypatch):
    """CI printed "Exception ignored in: <generator object all_children> … _Expired" from
    hypothesis's coverage tracer: raised inside a trace function, the limit switches tracing off
    and lands in whatever frame is traced (there a generator being finalized).  The handler now
    waits for the tracer to return.  Here the tracer takes most of the time; on the old handler the
    tracer was switched off in about 2 runs of 3."""
    import sys

    unraisable = []
    monkeypatch.setattr(sys, "unraisablehook", unraisable.append)

    def work():
        while True:
            sum(range(2000))

    def tracer(frame, event, arg):  # noqa: ARG001
        if frame.f_code is work.__code__:
            for _ in range(3000):
                pass
        return tracer

    for _ in range(5):
        start = time.monotonic()
        sys.settrace(tracer)
        try:
            with pytest.raises(TimeoutError):
                run_with_timeout(work, 0.1)
            still_on = sys.gettrace() is tracer
        finally:
            sys.settrace(None)
        assert still_on
        # late by at most MAX_DECLINED repeats of 50 ms
        assert time.monotonic() - start < 0.1 + timebox.MAX_DECLINED * 0.05 + 1.0
    assert [u for u in unraisable if isinstance(u.exc_value, timebox._Expired)] == []
