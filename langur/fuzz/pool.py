"""The campaign's unit of work run in worker processes (``langur fuzz --workers N``).

A *unit* is one generated program: load it, run both engines on it, give a verdict
(:class:`~langur.fuzz.compare.ProgramResult`).  :class:`Pool` runs units in forked worker
processes, at most ``workers`` at a time, one process per unit, and kills a unit that runs past
its time limit: a killed unit is reported as ``timeout`` (time-limited, never a verdict).  Units
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


def default_workers() -> int:
    """The core count this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


def _child(conn, work, text):
    """In a forked worker: ``work(text)`` sent back through ``conn`` (pickled), or the error."""
    import gc

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
    """Units ``work(text)`` in forked processes, ``workers`` at a time (module doc): a unit still
    running ``limit + GRACE`` seconds after it started is killed and replaced by
    ``on_time_limit(text, reason)``, one whose process died or raised by ``on_error(text, why)``;
    ``progress(result)`` is called as results arrive (in completion order)."""

    def __init__(self, work: Callable[[str], object], *, workers: int, limit: float,
                 on_time_limit: Callable[[str, str], object], on_error: Callable[[str, str], object],
                 progress: Callable[[object], None] | None = None):
        self.work, self.workers, self.cap = work, max(1, workers), limit + GRACE
        self.on_time_limit, self.on_error, self.progress = on_time_limit, on_error, progress
        self.ctx = mp.get_context("fork")
        self.texts: list[str] = []
        self.results: list = []
        self.running: dict = {}  # reader -> (index, process, deadline)

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
        self.running[reader] = (i, proc, time.monotonic() + self.cap)

    def finish(self) -> list:
        """Every submitted unit's result, in the order they were submitted."""
        while self.running:
            self._collect()
        return self.results

    def _done(self, i: int, res) -> None:
        self.results[i] = res
        if self.progress is not None:
            self.progress(res)

    def _collect(self) -> None:
        """Wait for a unit to end or to reach its deadline; record what ended, kill what is late."""
        running = self.running
        now = time.monotonic()
        ready = wait(list(running), timeout=max(0.0, min(d for _, _, d in running.values()) - now))
        for reader in ready:
            i, proc, _ = running.pop(reader)
            try:
                status, payload = pickle.loads(reader.recv_bytes())
            except (EOFError, OSError):
                proc.join()
                status, payload = "error", f"worker process died (exit code {proc.exitcode})"
            reader.close()
            proc.join()
            self._done(i, payload if status == "ok" else self.on_error(self.texts[i], payload))
        now = time.monotonic()
        for reader, (i, proc, deadline) in list(running.items()):
            if now >= deadline and reader not in ready:
                proc.kill()
                proc.join()
                reader.close()
                del running[reader]
                self._done(i, self.on_time_limit(self.texts[i], f"the program took longer than {self.cap:g} s (killed)"))


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
