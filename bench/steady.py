"""Verdicts that an unsteady host does not flip (issue 15's ``bench/bench_issue15.py``; not a test).

On a shared machine the CPU seconds of the same code move by up to 2× within half an hour (bench18's,
``bench/history/2026-11-28.md#bench18``, and the coordinator's runs after it, indexed by ``bench/RESULTS.md``): a single median against a limit gives ✓ in one run and ✗
in the next.  Three tools, each measured in the same run as what it judges:

* **Rounds and a band**: a quantity is measured in several rounds spread over the run (each round the
  least of a few repetitions); its *least* (the minimum over rounds, what the code costs when the host
  lets it run) and its *typical* value (the median over rounds) bound it.  A limit between them is
  ``borderline``: the margin is inside the spread that was measured, so a ✓ or ✗ would be a coin flip.
* **A calibration loop** (:func:`calibrate`), a fixed piece of pure-Python work timed beside every
  round (:func:`host`, each time kept in :data:`CALIBRATIONS`): its least over the run says how fast the host was, and its value beside a round how fast the
  host was *then*.  :data:`REFERENCE_CALIBRATION_S` is the loop's least on the host where issue 15's
  targets were measured, idle; a run whose fastest loop is ``f`` times slower widens the band's low
  end by ``f`` (:func:`slowdown`), never its high end: a slow host makes a verdict borderline, never ✓.
* **Instructions executed** (valgrind's cachegrind, ``PYTHONHASHSEED=0``), which the load does not
  change, for the targets that compare two parts of one program or two programs: the per-operation
  count is the difference of a process doing ``k`` operations and one doing none (:func:`per_operation`),
  as load20's ``count.sh``.  When valgrind is absent, :func:`instructions` returns ``None`` and the
  verdicts use the CPU bands alone.
"""

from __future__ import annotations

import os
import shutil
import statistics
import subprocess
import time

CLOCK = time.process_time

#: The calibration loop's least CPU seconds (:func:`calibrate`, least of 5 calls) on the host issue 15's
#: numbers were taken on (2 KVM cores of an Intel Xeon, Python 3.11.7): the least of 218 measurements
#: every 5 s over 12:22–12:43 UTC on 2026-11-28, at load average 3–11 (5.66 ms; the median 6.0 ms,
#: the most 11.9 ms; the least hardly moves with the load: 5.66 ms at load 3.4, 5.72 ms at 9.5);
#: :func:`slowdown` reads a run's calibration against it.
REFERENCE_CALIBRATION_S = 0.0056

BORDERLINE = "borderline"


def calibration_work() -> int:
    """The calibration loop: a fixed piece of interpreter work (tuples, a small dict, ``str`` of ints, a
    call per item), ≈ 5.7 ms on the reference host; its result is returned so that nothing is skipped."""
    counts: dict = {}
    total = 0
    for i in range(20000):
        key = (i & 7, i & 3)
        counts[key] = counts.get(key, 0) + i
        total += len(str(i))
    return total + len(counts)


def calibrate(reps: int = 5, clock=CLOCK) -> float:
    """The least CPU seconds of :func:`calibration_work` over ``reps`` calls."""
    best = float("inf")
    for _ in range(reps):
        t0 = clock()
        calibration_work()
        best = min(best, clock() - t0)
    return best


#: Every calibration of the run (:func:`host`), in order: :func:`slowdown` reads them.
CALIBRATIONS: list = []


def host() -> float:
    """The calibration loop timed now (appended to :data:`CALIBRATIONS`): how fast the host runs."""
    c = calibrate()
    CALIBRATIONS.append(c)
    return c


def load_average() -> str:
    """The host's load average over the last minute, as printed beside every table."""
    return f"load average {os.getloadavg()[0]:.1f}"


def slowdown(calibrations, reference: float = REFERENCE_CALIBRATION_S) -> float:
    """How much slower the host ran this run than the reference host idle: the least of the run's
    ``calibrations`` over ``reference``, at least 1 (a faster host gives 1, no correction)."""
    return max(1.0, min(calibrations) / reference)


def band(values) -> tuple[float, float]:
    """(least, typical) of one quantity's values over rounds: the minimum and the median."""
    values = list(values)
    return min(values), statistics.median(values)


def verdict(low: float, high: float, limit: float, at_most: bool = True) -> str:
    """✓, ✗ or :data:`BORDERLINE` for a quantity known to lie in [``low``, ``high``] against ``limit``:
    for an upper limit (``at_most``) ✓ when even ``high`` is within it, ✗ when even ``low`` is over it;
    for a lower limit (a ratio to reach) the other way round; borderline when the limit lies inside."""
    if low > high:
        low, high = high, low
    if at_most:
        return "✓" if high <= limit else ("✗" if low > limit else BORDERLINE)
    return "✓" if low >= limit else ("✗" if high < limit else BORDERLINE)


def combine(*verdicts: str) -> str:
    """One verdict from several measures of the same target (CPU band, instructions): ✓ or ✗ when they
    agree, borderline when they do not; ``None``s (a measure not taken) are left out."""
    given = {v for v in verdicts if v is not None}
    if not given:
        return "—"
    return given.pop() if len(given) == 1 else BORDERLINE


def all_of(verdicts) -> str:
    """The verdict of "at every n": ✗ if one is ✗, else borderline if one is, else ✓."""
    verdicts = list(verdicts)
    if "✗" in verdicts:
        return "✗"
    return BORDERLINE if BORDERLINE in verdicts else "✓"


# -- instructions --------------------------------------------------------------------------------------------

def have_valgrind() -> bool:
    return shutil.which("valgrind") is not None


def parse_refs(stderr: str) -> int:
    """The ``I refs`` (instructions executed) of cachegrind's summary in ``stderr``."""
    refs = [line for line in stderr.splitlines() if "I   refs" in line or "I refs" in line]
    if not refs:
        raise ValueError("no 'I refs' line in valgrind's output")
    return int(refs[-1].split(":")[1].replace(",", "").strip())


def instructions(argv, env: dict, cwd: str) -> int | None:
    """Instructions executed by the process ``argv`` (cachegrind, no cache simulation, with
    ``PYTHONHASHSEED=0`` so that hashing, and with it every dict's and set's layout, is the same in each
    run); ``None`` when valgrind is not installed."""
    if not have_valgrind():
        return None
    env = {**env, "PYTHONHASHSEED": "0"}
    r = subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null", *argv],
                       cwd=cwd, env=env, check=True, capture_output=True, text=True)
    return parse_refs(r.stderr)


def per_operation(with_k: int, with_none: int, k: int) -> float:
    """Instructions of one operation: (a process doing ``k`` of them − the same process doing none) / ``k``
    (what both processes share — the interpreter's start, the imports, the warm-up — cancels out)."""
    if k <= 0:
        raise ValueError("k must be positive")
    if with_k < with_none:
        raise ValueError(f"the process with {k} operations executed fewer instructions than the one with none")
    return (with_k - with_none) / k
