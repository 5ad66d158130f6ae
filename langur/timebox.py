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
"""

from __future__ import annotations

import signal
import threading
import time
from contextlib import contextmanager
from typing import Callable, Iterator, TypeVar

T = TypeVar("T")

_HAS_ALARM = hasattr(signal, "SIGALRM") and hasattr(signal, "setitimer")


class _Expired(BaseException):
    """Raised from the alarm handler; a BaseException so that library code catching
    ``Exception`` cannot swallow it.  Converted to :class:`TimeoutError` at the boundary."""

    def __init__(self, token: object):
        super().__init__("time limit")
        self.token = token


def _can_use_alarm() -> bool:
    if not _HAS_ALARM or threading.current_thread() is not threading.main_thread():
        return False
    try:  # sub-interpreters cannot install signal handlers
        signal.getsignal(signal.SIGALRM)
    except (ValueError, RuntimeError):  # pragma: no cover - defensive
        return False
    return True


def run_with_timeout(fn: Callable[[], T], seconds: float) -> T:
    """``fn()``, or :class:`TimeoutError` when it runs longer than ``seconds``."""
    if seconds is None:
        return fn()
    if seconds <= 0:
        raise TimeoutError("no time left")
    if not _can_use_alarm():
        start = time.monotonic()
        result = fn()
        if time.monotonic() - start > seconds:
            raise TimeoutError(f"call took longer than {seconds:.3g} s")
        return result

    token = object()
    state = {"done": False}
    start = time.monotonic()
    old_remaining, old_interval = signal.getitimer(signal.ITIMER_REAL)
    limit = seconds if old_remaining <= 0 else min(seconds, old_remaining)

    def handler(signum, frame):  # noqa: ARG001
        if not state["done"]:
            raise _Expired(token)

    old_handler = signal.signal(signal.SIGALRM, handler)
    # The alarm repeats every 50 ms until disarmed: an exception raised where Python swallows it
    # (a garbage-collector callback, a __del__, a bare ``except:``) does not lose the limit.
    signal.setitimer(signal.ITIMER_REAL, limit, 0.05)
    try:
        return fn()
    except _Expired as exc:
        state["done"] = True
        if exc.token is token:
            raise TimeoutError(f"call took longer than {limit:.3g} s") from None
        raise
    finally:
        state["done"] = True
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old_handler)
        if old_remaining > 0:
            left = old_remaining - (time.monotonic() - start)
            if left <= 0:
                # The outer limit expired while we ran: deliver it now to the outer handler.
                signal.setitimer(signal.ITIMER_REAL, 1e-4, old_interval)
            else:
                signal.setitimer(signal.ITIMER_REAL, left, old_interval)


#: The ends (``time.monotonic()``) of the enclosing :func:`budget` blocks, innermost last.
_BUDGETS: list[float] = []


@contextmanager
def budget(seconds: float | None) -> Iterator[None]:
    """Within the block, no :class:`Deadline` has more than ``seconds`` left from now (None: no
    bound; nested blocks only shorten)."""
    if seconds is None:
        yield
        return
    _BUDGETS.append(time.monotonic() + max(0.0, seconds))
    try:
        yield
    finally:
        _BUDGETS.pop()


class Deadline:
    """An overall time budget: ``run(fn, cap)`` runs ``fn`` under the remaining time (at most
    ``cap`` seconds when given, and never past the end of an enclosing :func:`budget`)."""

    def __init__(self, seconds: float):
        self.seconds = seconds
        self.end = time.monotonic() + seconds

    def remaining(self) -> float:
        return min([self.end, *_BUDGETS]) - time.monotonic()

    def run(self, fn: Callable[[], T], cap: float | None = None) -> T:
        left = self.remaining()
        if cap is not None:
            left = min(left, cap)
        return run_with_timeout(fn, left)
