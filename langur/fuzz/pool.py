"""The campaign's unit of work run in worker processes (``langur fuzz --workers N``).

A *unit* is one generated program: load it, run both engines on it, give a verdict
(:class:`~langur.fuzz.compare.ProgramResult`).  :class:`Pool` runs units in ``workers``
long-lived worker processes forked from the campaign's process, one unit at a time each: a
worker keeps what it has learned (sympy's caches, the antiderivatives it found, the modules it
imported) from one unit to the next, instead of starting every unit from a fresh fork of the
campaign's process (which cost each unit a copy-on-write copy of the whole heap and a cold
start; bench/history/2026-11-26.md#campaign3, "Campaign throughput, third pass").  A unit that runs past its time
limit, counted in CPU seconds its worker spent on it (:data:`BACKSTOP`), is killed with its
worker, which a fresh fork replaces: a killed unit is reported as ``timeout`` (time-limited,
never a verdict); a worker that dies is replaced the same way and its unit reported by
``on_error``.  Units are submitted one at a time as the programs are generated
(:meth:`Pool.submit` waits only for a free worker), so checking starts with the first program;
:func:`run_units` runs a list.  Every unit is a function of its program text and the campaign's
options (the Monte Carlo seed is the campaign's, not the unit's position); what a worker
remembers from earlier units (caches of exact results) makes a unit faster, never different,
except where a CPU-second budget decides (a closed form found within it, or quadrature), as on
a faster machine; results are returned in the programs' order.  :meth:`Pool.tell` hands every
worker something to take in before its next unit (the campaign: the antiderivatives the other
workers found).

``workers=0`` runs the units in this process, one after the other (what the hypothesis shrinker
and the tests of a single comparison use); the exact engine then runs in a forked child killed
at the time limit (:func:`langur.fuzz.compare._exact_fork`).
"""

from __future__ import annotations

import gc
import multiprocessing as mp
import os
import pickle
import time
from collections.abc import Callable, Iterable
from multiprocessing.connection import wait

from .. import framestack

#: Seconds a unit may run past its time limit before it is killed (the Monte Carlo estimates
#: after an exact engine that used its whole budget).
GRACE = 5.0

#: A unit's limit is CPU seconds its worker spends on it (on Linux, read from ``/proc``), so that a
#: busy machine, which gives each process a fraction of a core, does not turn programs into
#: timeouts; a unit is also killed after ``BACKSTOP · (limit + GRACE) + 10`` wall seconds (one that
#: waits without computing).  Without ``/proc`` the limit is wall seconds.
BACKSTOP = 4.0
#: A worker's cyclic garbage collector thresholds (CPython's default: 700, 10, 10).  Units build
#: sympy expressions by the million, few of them in cycles: at the default the collector ran
#: 2,726 times over 98 programs of seed 1 and took 4.8 % of their CPU (6.2 of 128.9 s); at these
#: 67 times, 2.2 % (2.7 of 121.8 s), no full collection, the same verdicts
#: (bench/history/2026-11-27.md#camp10, campaign throughput, tenth pass).  Cycles are still collected (the youngest generation once
#: 20,000 more container objects are allocated than freed), only less often.
GC_THRESHOLDS = (20000, 20, 20)
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
    """In a worker, tell the campaign's process where the unit is (``payload``, a small picklable
    dict: e.g. the phase it starts); kept for the unit's ``on_time_limit`` should it be killed.
    Does nothing outside a worker."""
    if _NOTE is not None:
        _NOTE(payload)


def _serve(tasks, results, work, told) -> None:
    """A worker's life: ``(text, news)`` from ``tasks``, ``told(n)`` for each of ``news``, then
    ``work(text)`` (or the error it raised) sent back through ``results``, until ``tasks`` closes."""
    global _NOTE
    _NOTE = lambda payload: results.send_bytes(pickle.dumps(("note", payload)))  # noqa: E731
    gc.callbacks.clear()  # a time limit firing inside a gc callback would be swallowed there
    gc.freeze()  # the inherited heap is never collected here: no copy-on-write of it by the collector
    gc.set_threshold(*GC_THRESHOLDS)
    while True:
        try:
            task = pickle.loads(tasks.recv_bytes())
        except (EOFError, OSError):
            break
        if task is None:  # the campaign is over (an explicit end: later workers hold copies of this pipe)
            break
        text, news = task
        try:
            for n in news:
                if told is not None:
                    told(n)
            out = ("ok", work(text))
        except BaseException as e:  # noqa: BLE001 - reported as the unit's failure
            out = ("error", f"{type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        results.send_bytes(pickle.dumps(out))
    results.close()


class _Worker:
    """A worker process, its two pipes, and the unit it runs (``index`` None when idle)."""

    def __init__(self, ctx, work, told):
        task_reader, self.tasks = ctx.Pipe(duplex=False)
        self.results, result_writer = ctx.Pipe(duplex=False)
        # a worker's frame stack kept grown: no mmap/munmap per call-depth swing (langur.framestack)
        self.proc = ctx.Process(target=framestack.run, args=(_serve, task_reader, result_writer, work, told),
                                daemon=True)
        self.proc.start()
        task_reader.close()
        result_writer.close()
        self.index: int | None = None
        self.cpu0, self.start = 0.0, 0.0
        self.news: list = []  # what to tell it before its next unit
        self.last = None  # its unit's last note

    def run(self, index: int, text: str) -> None:
        self.index, self.last = index, None
        self.cpu0, self.start = cpu_seconds(self.proc.pid) or 0.0, time.monotonic()
        self.tasks.send_bytes(pickle.dumps((text, self.news)))
        self.news = []

    def stop(self, kill: bool = False) -> None:
        if kill:
            self.proc.kill()
        elif self.proc.is_alive():
            try:
                self.tasks.send_bytes(pickle.dumps(None))
            except OSError:  # it ended meanwhile
                pass
        self.tasks.close()
        self.proc.join()
        self.results.close()


class Pool:
    """Units ``work(text)`` in ``workers`` long-lived forked processes (module doc): a unit that
    has used ``limit + GRACE`` CPU seconds (:data:`BACKSTOP`) is killed with its worker and
    replaced by ``on_time_limit(text, reason, last)``: ``last`` is the unit's last :func:`note`
    (a dict; empty when it sent none) with ``"cpu"`` and ``"wall"`` added, the CPU seconds (None
    without ``/proc``) and wall seconds the unit had used when it was killed; one that raised, or
    whose worker died, by ``on_error(text, why)``;
    ``progress(result)`` is called as results arrive (in completion order); ``told(n)`` is what a
    worker does with each ``n`` of :meth:`tell`."""

    def __init__(self, work: Callable[[str], object], *, workers: int, limit: float,
                 on_time_limit: Callable[[str, str], object], on_error: Callable[[str, str], object],
                 progress: Callable[[object], None] | None = None, told: Callable[[object], None] | None = None):
        self.work, self.workers, self.cap = work, max(1, workers), limit + GRACE
        self.on_time_limit, self.on_error, self.progress, self.told = on_time_limit, on_error, progress, told
        self.ctx = mp.get_context("fork")
        self.texts: list[str] = []
        self.results: list = []
        self.pool: list[_Worker] = []

    def tell(self, news) -> None:
        """Every worker takes in ``news`` (``told(news)``) before its next unit."""
        for w in self.pool:
            w.news.append(news)

    def _busy(self) -> list[_Worker]:
        return [w for w in self.pool if w.index is not None]

    def submit(self, text: str) -> None:
        """Start ``work(text)`` as soon as a worker is free (waiting for one if need be)."""
        while len(self._busy()) >= self.workers:
            self._collect()
        i = len(self.texts)
        self.texts.append(text)
        self.results.append(None)
        idle = next((w for w in self.pool if w.index is None), None)
        if idle is None:
            idle = _Worker(self.ctx, self.work, self.told)
            self.pool.append(idle)
        idle.run(i, text)

    def finish(self) -> list:
        """Every submitted unit's result, in the order they were submitted; the workers stop."""
        while self._busy():
            self._collect()
        for w in self.pool:
            w.stop()
        self.pool = []
        return self.results

    def _done(self, i: int, res) -> None:
        self.results[i] = res
        if self.progress is not None:
            self.progress(res)

    def _late(self, w: _Worker, now: float) -> tuple[str, dict] | None:
        """Why the unit in worker ``w`` is past its limit and what it used (``{"cpu": CPU seconds or
        None without /proc, "wall": seconds}``), or None."""
        cpu, wall = cpu_seconds(w.proc.pid), now - w.start
        if cpu is None:
            if wall >= self.cap:
                return f"the program took longer than {self.cap:g} s (killed)", {"cpu": None, "wall": wall}
            return None
        cpu -= w.cpu0
        used = {"cpu": cpu, "wall": wall}
        if cpu >= self.cap:
            return f"the program took longer than {self.cap:g} CPU seconds (killed)", used
        if wall >= BACKSTOP * self.cap + 10:
            return (f"the program ran {BACKSTOP * self.cap + 10:g} s (wall clock) with {cpu:.1f} CPU seconds "
                    "(killed)"), used
        return None

    def _retire(self, w: _Worker, kill: bool) -> None:
        w.stop(kill)
        self.pool.remove(w)

    def _collect(self) -> None:
        """Wait for a unit to end or to reach its limit; record what ended, kill what is late."""
        busy = {w.results: w for w in self._busy()}
        ready = wait(list(busy), timeout=POLL)
        for reader in ready:
            w = busy[reader]
            try:
                status, payload = pickle.loads(reader.recv_bytes())
            except (EOFError, OSError):
                status, payload = "died", None
            if status == "note":
                w.last = payload
                continue
            i, w.index = w.index, None
            if status == "died":  # the worker ended during its unit: replaced by a fresh one
                self._retire(w, kill=False)
                payload = f"worker process died (exit code {w.proc.exitcode})"
                self._done(i, self.on_error(self.texts[i], payload))
            else:
                self._done(i, payload if status == "ok" else self.on_error(self.texts[i], payload))
        now = time.monotonic()
        for reader, w in busy.items():
            late = self._late(w, now) if reader not in ready and w.index is not None else None
            if late is not None:
                (why, used), i = late, w.index
                self._retire(w, kill=True)
                self._done(i, self.on_time_limit(self.texts[i], why, {**(w.last or {}), **used}))


def run_units(texts: Iterable[str], work: Callable[[str], object], *, workers: int, limit: float,
              on_time_limit: Callable[[str, str], object], on_error: Callable[[str, str], object],
              progress: Callable[[object], None] | None = None) -> list:
    """``[work(t) for t in texts]`` in ``workers`` worker processes (:class:`Pool`)."""
    pool = Pool(work, workers=workers, limit=limit, on_time_limit=on_time_limit, on_error=on_error,
                progress=progress)
    for t in texts:
        pool.submit(t)
    return pool.finish()
