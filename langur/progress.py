"""A status line for long commands: on a terminal, ``show``, ``eval`` and ``deriv`` say on standard
error which phase they are in and for how long (``exact engine… 12 s``), so that a computation of
minutes is not mistaken for a hang.  Nothing is written when standard error is not a terminal (a
pipe, a file, CI), so output stays byte-for-byte the same there.

    with progress.phase("exact engine"):
        ...
"""

from __future__ import annotations

import contextlib
import sys
import threading
import time

_STATE = threading.local()
_INTERVAL = 0.5  # seconds between updates
_DELAY = 1.0  # a phase shorter than this is never shown


def enabled() -> bool:
    return bool(getattr(_STATE, "on", False))


def enable(command: str, on: bool | None = None) -> None:
    """Show phases of ``command`` from now on (when standard error is a terminal, or ``on``)."""
    _STATE.on = sys.stderr.isatty() if on is None else on
    _STATE.command = command


@contextlib.contextmanager
def phase(what: str):
    """Show ``what`` and the time spent in it on the status line while the block runs."""
    if not enabled():
        yield
        return
    done = threading.Event()
    start = time.monotonic()
    command = getattr(_STATE, "command", "langur")
    shown = [False]

    def tick():
        while not done.wait(_INTERVAL):
            elapsed = time.monotonic() - start
            if elapsed >= _DELAY:
                sys.stderr.write(f"\r\x1b[2Klangur {command}: {what}… {elapsed:.0f} s")
                sys.stderr.flush()
                shown[0] = True

    worker = threading.Thread(target=tick, daemon=True)
    worker.start()
    try:
        yield
    finally:
        done.set()
        worker.join()
        if shown[0]:
            sys.stderr.write("\r\x1b[2K")  # clear the line: the answer follows
            sys.stderr.flush()
