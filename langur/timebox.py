"""Time limits: a command's whole budget (`--timeout`) and the sympy calls that can blow up.

``run_with_timeout(fn, seconds)`` calls ``fn()`` and raises :class:`TimeoutError` when it takes
longer than ``seconds``.  On the main thread of the main interpreter this is enforced with
``signal.SIGALRM`` (``setitimer``), nesting correctly: an inner limit never extends an outer one,
and the outer timer is re-armed afterwards.  Elsewhere (worker threads, sub-interpreters, platforms
without ``SIGALRM``) the call cannot be interrupted: ``fn`` runs to completion and a
``TimeoutError`` is raised afterwards when it overran, so callers still fall back consistently.

:class:`Deadline` is a small helper for an overall time budget split over many calls.
``with budget(seconds):`` bounds every :class:`Deadline` created or used inside it by one shared
end: the exact engine's symbolic work for a whole request (a value, its partial derivatives and
their Theorem 8.1 checks) then draws on one budget, and what is not done by its end falls back to
quadrature instead of each integral starting a fresh limit of its own.

Clocks.  ``run_with_timeout`` counts wall-clock seconds (a command's ``--timeout``).
``run_with_timeout(fn, s, cpu=True)`` counts the CPU seconds of this process instead
(``time.process_time``, enforced by ``ITIMER_PROF``/``SIGPROF``), with a wall-clock backstop of
:data:`BACKSTOP_FACTOR` × s + :data:`BACKSTOP_SLACK` seconds, so a call still ends when the
process is starved or blocked.  :class:`Deadline` and :func:`budget` count CPU seconds and
:meth:`Deadline.run` uses ``cpu=True``: the exact engine's sympy budgets then give the same closed
forms on a loaded machine as on an idle one (a wall-clock budget ran out sooner under load, and
the answer changed from a closed form to quadrature), while every sympy call stays bounded in both
CPU and wall time (a deadline is also over once its wall-clock backstop has passed).

Signals go through ``_signal``, the C module that the standard ``signal`` wraps: the same functions,
with plain integers where ``signal`` returns its enums (handlers, signal numbers) — building those
enums at import was ~3 M instructions of every ``langur`` process (issue 15, one-shot start-up).
"""

from __future__ import annotations

import _signal as signal  # (the C module the standard ``signal`` wraps: see the end of the docstring)
import _weakrefset
import gc
import inspect
import sys
import threading
import time
import weakref
from contextlib import contextmanager
from enum import StrEnum
from typing import Callable, Iterator, TypeVar

T = TypeVar("T")

_HAS_ALARM = hasattr(signal, "SIGALRM") and hasattr(signal, "setitimer")
_HAS_PROF = _HAS_ALARM and hasattr(signal, "SIGPROF") and hasattr(signal, "ITIMER_PROF")

#: A CPU-second limit of s seconds is also a wall-clock limit of BACKSTOP_FACTOR·s + BACKSTOP_SLACK.
BACKSTOP_FACTOR = 10.0
BACKSTOP_SLACK = 5.0


def backstop(seconds: float) -> float:
    """The wall-clock seconds allowed to a limit of ``seconds`` CPU seconds."""
    return BACKSTOP_FACTOR * seconds + BACKSTOP_SLACK


class Clock(StrEnum):
    """Which limit ended a call (its value: the unit its message gives the seconds in)."""

    CPU = "CPU s"  # a limit of CPU seconds (``run_with_timeout(…, cpu=True)``)
    BACKSTOP = "s (wall clock)"  # the wall-clock backstop of such a limit (:func:`backstop`)
    WALL = "s"  # a limit of wall-clock seconds


class TimeLimit(TimeoutError):
    """The :class:`TimeoutError` of a limit that ended a call, saying which (``clock``) and after
    how many seconds (``seconds``): a command's message can then say whether its CPU budget ran out
    or the wall-clock backstop stopped it on a loaded machine, and how to raise either."""

    def __init__(self, seconds: float, clock: Clock):
        super().__init__(f"call took longer than {seconds:.3g} {clock}")
        self.seconds, self.clock = seconds, clock


def stopped_by(exc: BaseException) -> Clock | None:
    """The clock of the limit that raised ``exc`` (None: a TimeoutError of something else)."""
    return exc.clock if isinstance(exc, TimeLimit) else None


def by_backstop(seconds: float, used: float | None = None) -> str:
    """How a report says that the wall-clock backstop, not the CPU budget of ``seconds``, ended a
    computation (``used``: the CPU seconds it had used, when known)."""
    return (f"by its wall-clock backstop after {backstop(seconds):g} s ({BACKSTOP_FACTOR:g} × {seconds:g} + "
            f"{BACKSTOP_SLACK:g})" + (f", having used {used:.2g} of its {seconds:g} CPU s" if used is not None else
                                      f", before its {seconds:g} CPU s were used")
            + ": the machine is busy or it waited")


class _Expired(BaseException):
    """Raised from the alarm handler; a BaseException so that library code catching
    ``Exception`` cannot swallow it.  Converted to :class:`TimeoutError` at the boundary."""

    def __init__(self, token: object):
        super().__init__("time limit")
        self.token = token


def _where_swallowed(frame) -> bool:
    """Whether ``frame`` runs where Python would swallow an exception: inside a garbage-collector
    callback (hypothesis times collections with one), a ``__del__``, the weakref module's
    callbacks (a ``WeakValueDictionary`` dropping a dead entry, a ``finalize``), or a trace or
    profile function (hypothesis's coverage tracer: an exception raised there switches tracing off
    and lands in the traced frame, which may be a generator being finalized — CI printed
    "Exception ignored in: <generator object all_children>").  Raised there, the limit would be
    lost; the handler declines and the timer's 50 ms repeat delivers it once that code has
    returned."""
    callbacks = {getattr(cb, "__code__", None) for cb in gc.callbacks}
    callbacks |= {getattr(hook, "__code__", None) for hook in (sys.gettrace(), sys.getprofile())}
    callbacks.discard(None)
    depth = 0
    while frame is not None and depth < 64:
        code = frame.f_code
        if code in callbacks or code.co_name == "__del__" or code.co_filename in _WEAKREF_FILES:
            return True
        frame, depth = frame.f_back, depth + 1
    return False


def _ours(exc: BaseException, token: object) -> bool:
    """Whether ``exc`` is, or was raised because of, this limit's :class:`_Expired`: a limit
    firing while a C extension initialises is re-raised by the extension as an ``ImportError``
    ("initialization failed", pybind11's module init) chained to it, and must still end the call
    as a time limit, not as an internal error."""
    seen = 0
    while exc is not None and seen < 16:
        if isinstance(exc, _Expired) and exc.token is token:
            return True
        exc, seen = exc.__cause__ or exc.__context__, seen + 1
    return False


#: How many times in a row a limit waits (50 ms each) for code where an exception would be lost
#: (:func:`_where_swallowed`) to return before it is raised there anyway: a limit is late by at
#: most 3 s, even inside a tracer that takes most of the time.
MAX_DECLINED = 60

#: The files of the weakref module's callbacks (``WeakValueDictionary``'s ``remove``, ``finalize``).
_WEAKREF_FILES = frozenset({weakref.__file__, _weakrefset.__file__})


def _can_use_alarm() -> bool:
    if not _HAS_ALARM or threading.current_thread() is not threading.main_thread():
        return False
    try:  # sub-interpreters cannot install signal handlers
        signal.getsignal(signal.SIGALRM)
    except (ValueError, RuntimeError):  # pragma: no cover - defensive
        return False
    return True


def run_with_timeout(fn: Callable[[], T], seconds: float, *, cpu: bool = False) -> T:
    """``fn()``, or :class:`TimeoutError` when it runs longer than ``seconds`` (wall clock; with
    ``cpu``, CPU seconds of this process, and at most :func:`backstop` seconds of wall clock)."""
    if seconds is None:
        return fn()
    if seconds <= 0:
        raise TimeoutError("no time left")
    if not _can_use_alarm():
        clock = time.process_time if cpu else time.monotonic
        start, wall = clock(), time.monotonic()
        result = fn()
        if clock() - start > seconds:
            raise TimeLimit(seconds, Clock.CPU if cpu else Clock.WALL)
        if cpu and time.monotonic() - wall > backstop(seconds):
            raise TimeLimit(backstop(seconds), Clock.BACKSTOP)
        return result
    if not cpu:
        return _limited(fn, seconds, signal.ITIMER_REAL, signal.SIGALRM, time.monotonic, Clock.WALL)
    wall = backstop(seconds)
    bounded = (lambda: _limited(fn, wall, signal.ITIMER_REAL, signal.SIGALRM, time.monotonic, Clock.BACKSTOP))
    if not _HAS_PROF:  # pragma: no cover - every POSIX platform has ITIMER_PROF
        return bounded()
    return _limited(bounded, seconds, signal.ITIMER_PROF, signal.SIGPROF, time.process_time, Clock.CPU)


def _limited(fn: Callable[[], T], seconds: float, which: int, signum: int, clock: Callable[[], float],
             unit: str) -> T:
    """``fn()`` under the interval timer ``which`` (delivering ``signum``), measured by ``clock``;
    nesting: an inner limit never extends an outer one of the same timer, which is re-armed after.
    ``unit``: the :class:`Clock` the limit counts in (said by its :class:`TimeLimit`)."""
    token = object()
    state = {"done": False, "declined": 0}
    start = clock()
    old_remaining, old_interval = signal.getitimer(which)
    limit = seconds if old_remaining <= 0 else min(seconds, old_remaining)

    def handler(signum, frame):  # noqa: ARG001
        if state["done"]:
            return
        if _where_swallowed(frame) and state["declined"] < MAX_DECLINED:
            state["declined"] += 1
            return
        raise _Expired(token)

    handler.ends_a_limit = True  # (an enclosing limit's handler: see the ``finally`` below)
    old_handler = signal.getsignal(signum)
    try:
        # Installed and armed inside the ``try``: a signal delivered between two of these
        # statements (an outer limit of another timer, or this one when ``limit`` is tiny) still
        # passes through the ``finally``, which disarms the timer and puts the old handler back —
        # outside it, a handler left installed raised its _Expired later, anywhere, uncaught.
        signal.signal(signum, handler)
        # The alarm repeats every 50 ms until disarmed: the handler does not raise inside a
        # garbage-collector callback or a __del__ (:func:`_where_swallowed`), and an exception
        # swallowed elsewhere (a bare ``except:``) does not lose the limit either.
        signal.setitimer(which, limit, 0.05)
        return fn()
    except BaseException as exc:
        state["done"] = True
        if _ours(exc, token):
            state["expired"] = True
            raise TimeLimit(limit, Clock(unit)) from None
        raise
    finally:
        state["done"] = True
        signal.setitimer(which, 0)
        signal.signal(signum, old_handler)
        if old_remaining > 0:
            left = old_remaining - (clock() - start)
            # Our limit was the outer one's remaining time and it expired: the outer limit did too,
            # whatever ``clock`` says (the interval timer and ``clock`` count in different steps).
            if left <= 0 or (old_remaining <= seconds and state.get("expired")):
                # The outer limit expired while we ran: deliver it to the outer handler now.  Left to
                # a timer re-armed for later, it was taken by the next inner limit as its own (that
                # limit's remaining time is then the outer's few microseconds), and a caller catching
                # the inner TimeoutError and going on lost the outer limit for good (CI: ``check
                # --timeout 0.2`` ran its whole analysis).  The re-armed timer stays as the fallback
                # for a handler that declines (:func:`_where_swallowed`) or is not a limit's.
                signal.setitimer(which, 1e-4, old_interval)
                if getattr(old_handler, "ends_a_limit", False):
                    old_handler(signum, inspect.currentframe())
            else:
                signal.setitimer(which, left, old_interval)


#: The enclosing :func:`budget` blocks' ends, innermost last: (CPU end, wall-clock backstop end).
_BUDGETS: list[tuple[float, float]] = []


def _left(end: tuple[float, float]) -> float:
    """CPU seconds left before ``end``; none once its wall-clock backstop has passed."""
    cpu_end, wall_end = end
    return cpu_end - time.process_time() if time.monotonic() < wall_end else 0.0


@contextmanager
def budget(seconds: float | None) -> Iterator[None]:
    """Within the block, no :class:`Deadline` has more than ``seconds`` CPU seconds left from now
    (None: no bound; nested blocks only shorten; over once :func:`backstop` wall seconds passed)."""
    if seconds is None:
        yield
        return
    seconds = max(0.0, seconds)
    _BUDGETS.append((time.process_time() + seconds, time.monotonic() + backstop(seconds)))
    try:
        yield
    finally:
        _BUDGETS.pop()


class Deadline:
    """An overall budget of CPU seconds: ``run(fn, cap)`` runs ``fn`` under the remaining time (at
    most ``cap`` seconds when given, and never past the end of an enclosing :func:`budget`); the
    budget is also over once its wall-clock backstop (:func:`backstop`) has passed."""

    def __init__(self, seconds: float):
        self.seconds = seconds
        self.end = (time.process_time() + seconds, time.monotonic() + backstop(seconds))

    def remaining(self) -> float:
        return min(_left(e) for e in [self.end, *_BUDGETS])

    def stopped_by(self) -> Clock | None:
        """Which limit has ended this budget: :attr:`Clock.CPU` when CPU seconds ran out (its own or
        an enclosing :func:`budget`'s), :attr:`Clock.BACKSTOP` when a wall-clock backstop passed
        first (a loaded machine); None while time is left."""
        ends = [self.end, *_BUDGETS]
        if all(_left(e) > 0 for e in ends):
            return None
        now = time.process_time()
        return Clock.CPU if any(cpu_end <= now for cpu_end, _ in ends) else Clock.BACKSTOP

    def run(self, fn: Callable[[], T], cap: float | None = None) -> T:
        left = self.remaining()
        if cap is not None:
            left = min(left, cap)
        return run_with_timeout(fn, left, cpu=True)
