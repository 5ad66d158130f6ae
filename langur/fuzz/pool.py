"""The campaign's unit of work run in worker processes (``langur fuzz --workers N``).

A *unit* is one generated program: load it, run both engines on it, give a verdict
(:class:`~langur.fuzz.compare.ProgramResult`).  :class:`Pool` runs units in forked worker
processes, at most ``workers`` at a time, one process per unit, and kills a unit that runs past
its time limit, counted in CPU seconds of its process (:data:`BACKSTOP`): a killed unit is
reported as ``timeout`` (time-limited, never a verdict).  Units
are submitted one at a time as the programs are generated (:meth:`Pool.submit` waits only for a
free worker), so checking starts with the first program; :func:`run_units` runs a list.
Every unit is a pure function of its program text and the campaign's options (the Monte Carlo
seed is the campaign's, not the unit's position), so the verdicts do not depend on the number of
workers nor on the order in which units finish; results are returned in the programs' order.

``workers=0`` runs the units in this process, one after the other (what the hypothesis shrinker
and the tests of a single comparison use); the exact engine then runs in a forked child killed
at the time limit (:func:`langur.fuzz.compare._exact_fork`).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import pickle
import time
from collections.abc import Callable, Iterable
from multiprocessing.connection import wait

#: Seconds a unit may run past its time limit before it is killed (the process's own start-up,
#: the Monte Carlo estimates after an exact engine that used its whole budget).
GRACE = 5.0

#: A unit's limit is CPU seconds of its process (on Linux, read from ``/proc``), so that a busy
#: machine, which gives each process a fraction of a core, does not turn programs into timeouts;
#: a unit is also killed after ``BACKSTOP · (limit + GRACE) + 10`` wall seconds (one that waits
#: without computing).  Without ``/proc`` the limit is wall seconds.
BACKSTOP = 4.0
#: Seconds between two looks at the running units' CPU times.
POLL = 0.2
_TICKS = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") and "SC_CLK_TCK" in os.sysconf_names else 100


def cpu_seconds(pid: int) -> float | None:
    """User + system CPU seconds of process ``pid`` so far (None when ``/proc`` cannot tell)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii", errors="replace") as fh:
            fields = fh.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / _TICKS  # utime, stime (fields 14, 15)
    except (OSError, IndexError, ValueError):
        return None


def default_workers() -> int:
    """The core count this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


#: In a worker: how :func:`note` reaches the campaign's process (None elsewhere).
_NOTE = None


def note(payload) -> None:
    """In a worker, tell the campaign's process where the unit is (``payload``, small and
    picklable: e.g. the phase it starts); kept for the unit's ``on_time_limit`` should it be
    killed.  Does nothing outside a worker."""
    if _NOTE is not None:
        _NOTE(payload)


def _child(conn, work, text):
    """In a forked worker: ``work(text)`` sent back through ``conn`` (pickled), or the error."""
    import gc

    global _NOTE
    _NOTE = lambda payload: conn.send_bytes(pickle.dumps(("note", payload)))  # noqa: E731
    gc.callbacks.clear()  # a time limit firing inside a gc callback would be swallowed there
    try:
        out = ("ok", work(text))
    except BaseException as e:  # noqa: BLE001 - reported as the unit's failure
        out = ("error", f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
    try:
        conn.send_bytes(pickle.dumps(out))
    finally:
        conn.close()


class Pool:
    """Units ``work(text)`` in forked processes, ``workers`` at a time (module doc): a unit that
    has used ``limit + GRACE`` CPU seconds (:data:`BACKSTOP`) is killed and replaced by
    ``on_time_limit(text, reason)``, or ``on_time_limit(text, reason, last)`` after the unit's
    :func:`note` ``last``,
    one whose process died or raised by ``on_error(text, why)``; ``progress(result)`` is called as
    results arrive (in completion order)."""

    def __init__(self, work: Callable[[str], object], *, workers: int, limit: float,
                 on_time_limit: Callable[[str, str], object], on_error: Callable[[str, str], object],
                 progress: Callable[[object], None] | None = None):
        self.work, self.workers, self.cap = work, max(1, workers), limit + GRACE
        self.on_time_limit, self.on_error, self.progress = on_time_limit, on_error, progress
        self.ctx = mp.get_context("fork")
        self.texts: list[str] = []
        self.results: list = []
        self.running: dict = {}  # reader -> (index, process, start)
        self.notes: dict = {}  # reader -> the unit's last note

    def submit(self, text: str) -> None:
        """Start ``work(text)`` as soon as a worker is free (waiting for one if need be)."""
        while len(self.running) >= self.workers:
            self._collect()
        i = len(self.texts)
        self.texts.append(text)
        self.results.append(None)
        reader, writer = self.ctx.Pipe(duplex=False)
        proc = self.ctx.Process(target=_child, args=(writer, self.work, text), daemon=True)
        proc.start()
        writer.close()
        start = time.monotonic()
        self.running[reader] = (i, proc, start)

    def finish(self) -> list:
        """Every submitted unit's result, in the order they were submitted."""
        while self.running:
            self._collect()
        return self.results

    def _done(self, i: int, res) -> None:
        self.results[i] = res
        if self.progress is not None:
            self.progress(res)

    def _late(self, proc, start: float, now: float) -> str | None:
        """Why the unit in ``proc`` (started at ``start``) is past its limit, or None."""
        cpu = cpu_seconds(proc.pid)
        if cpu is None:
            if now - start >= self.cap:
                return f"the program took longer than {self.cap:g} s (killed)"
            return None
        if cpu >= self.cap:
            return f"the program took longer than {self.cap:g} CPU seconds (killed)"
        if now - start >= BACKSTOP * self.cap + 10:
            return (f"the program ran {BACKSTOP * self.cap + 10:g} s (wall clock) with {cpu:.1f} CPU seconds "
                    "(killed)")
        return None

    def _collect(self) -> None:
        """Wait for a unit to end or to reach its limit; record what ended, kill what is late."""
        running = self.running
        ready = wait(list(running), timeout=POLL)
        for reader in ready:
            try:
                status, payload = pickle.loads(reader.recv_bytes())
            except (EOFError, OSError):
                status, payload = "error", None
            if status == "note":
                self.notes[reader] = payload
                continue
            i, proc, _ = running.pop(reader)
            self.notes.pop(reader, None)
            if payload is None and status == "error":
                proc.join()
                payload = f"worker process died (exit code {proc.exitcode})"
            reader.close()
            proc.join()
            self._done(i, payload if status == "ok" else self.on_error(self.texts[i], payload))
        now = time.monotonic()
        for reader, (i, proc, start) in list(running.items()):
            why = self._late(proc, start, now) if reader not in ready else None
            if why is not None:
                proc.kill()
                proc.join()
                reader.close()
                del running[reader]
                last = self.notes.pop(reader, None)
                self._done(i, self.on_time_limit(self.texts[i], why) if last is None
                           else self.on_time_limit(self.texts[i], why, last))


def run_units(texts: Iterable[str], work: Callable[[str], object], *, workers: int, limit: float,
              on_time_limit: Callable[[str, str], object], on_error: Callable[[str, str], object],
              progress: Callable[[object], None] | None = None) -> list:
    """``[work(t) for t in texts]``, each in its own forked process, ``workers`` at a time
    (:class:`Pool`)."""
    pool = Pool(work, workers=workers, limit=limit, on_time_limit=on_time_limit, on_error=on_error,
                progress=progress)
    for t in texts:
        pool.submit(t)
    return pool.finish()
