"""Issue 15's one-shot processes of fig1's program (not a test; run by ``bench/bench_issue15.py``, whose
module doc says what is measured and how it is judged): ``langur eval`` and ``langur deriv`` with the
Monte Carlo engine, each peer's ``peer_programs/NAME_fig1.py`` and ``python -c "import numpy"``, timed
round by round (:func:`run_one_shot`) and counted in instructions (:func:`start_instructions`).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_text_to_number as ttn  # noqa: E402  (first: it sets numpy's BLAS threads before numpy loads)
from bench_peers import PROGRAMS  # noqa: E402
from steady import have_valgrind, instructions  # noqa: E402

ROOT = ttn.ROOT


def one_shot_commands(peers: dict, cache: str) -> dict:
    """The one-shot processes by name: (argv after ``python``, environment), compiled modules in ``cache``."""
    base = ttn._env(cache)
    commands = {"langur eval --engine mc": (ttn.ONE_SHOT, base),
                "langur deriv --engine mc": (("-m", "langur", "deriv", "examples/fig1.lgr", "--engine", "mc"), base)}
    for p, path in peers.items():
        commands[p] = ((os.path.join(PROGRAMS, f"{p}_fig1.py"),), {**base, "PYTHONPATH": os.path.abspath(path)})
    commands["python -c 'import numpy' (the floor: every system imports numpy)"] = (("-c", "import numpy"), base)
    return commands


def run_one_shot(peers: dict, rounds: int, counted=None) -> dict:
    """Every system's one-shot process, round by round (each round runs each once, in turn), with
    compiled modules kept in a temporary ``PYTHONPYCACHEPREFIX`` (one warm-up run each first).
    ``walls`` of Langur's ``eval``: every round's wall time; ``paired`` of a peer: each round's wall and
    CPU over Langur's ``eval``'s in the same round; ``counted``: the processes' instructions
    (:func:`start_instructions`), printed after the rounds and kept under ``instructions``."""
    print(f"\n## One-shot processes: fig1's program, wall and CPU seconds, medians of {rounds} rounds\n")
    with tempfile.TemporaryDirectory() as cache:
        commands = one_shot_commands(peers, cache)
        outputs = {}
        for name, (argv, env) in commands.items():  # the warm-up writes the compiled modules
            outputs[name] = subprocess.run([sys.executable, *argv], cwd=ROOT, env=env, check=True,
                                           capture_output=True, text=True).stdout.strip()
        loads = [os.getloadavg()[0]]
        times: dict = {name: [] for name in commands}
        for _ in range(rounds):
            for name, (argv, env) in commands.items():
                times[name].append(ttn.process(argv, env))
            loads.append(os.getloadavg()[0])
    out = {name: {"wall": statistics.median(w for w, _ in ts), "cpu": statistics.median(c for _, c in ts),
                  "wall_min": min(w for w, _ in ts)} for name, ts in times.items()}
    mine = times["langur eval --engine mc"]
    out["langur eval --engine mc"]["walls"] = [w for w, _ in mine]
    out["langur eval --engine mc"]["cpus"] = [c for _, c in mine]
    for p in peers:
        out[p]["paired"] = [{"wall": w / mw, "cpu": c / mc} for (w, c), (mw, mc) in zip(times[p], mine)]
    langur = out["langur eval --engine mc"]["wall"]
    print("| process | wall (median) | wall (min) | CPU (median) | wall / langur eval's | prints |")
    print("|---|---:|---:|---:|---:|---|")
    for name, t in out.items():
        printed = "; ".join(line.strip() for line in outputs[name].splitlines()[-2:])
        print(f"| {name} | **{t['wall']:.3f}** | {t['wall_min']:.3f} | {t['cpu']:.3f} | {t['wall'] / langur:.2f} "
              f"| {printed} |")
    print(f"\nload average during the rounds: {min(loads):.1f}–{max(loads):.1f}")
    out["loads"] = [min(loads), max(loads)]
    if counted is not None:
        print_instructions(counted)
        out["instructions"] = counted
    return out


def start_instructions(pool, peers: dict, reps: int, cache: str):
    """Each one-shot process's instructions executed (``steady.instructions``: cachegrind,
    ``PYTHONHASHSEED=0``, compiled modules kept in ``cache``), median of ``reps`` runs, submitted to
    ``pool`` (``deriv`` left out: no target names it); returns the function that waits, prints and returns
    them.  The load does not change them, so two systems compare within a few per cent where wall medians
    on a shared machine do not (what varies between runs is Python's start-up: site's ``.pth`` files)."""
    if not have_valgrind():
        return dict
    commands = {k: v for k, v in one_shot_commands(peers, cache).items() if k != "langur deriv --engine mc"}
    futures = {}
    for name, (argv, env) in commands.items():
        subprocess.run([sys.executable, *argv], cwd=ROOT, env=env, check=True, capture_output=True)  # (compiles)
        env = {**env, "PYTHONHASHSEED": "0"}
        futures[name] = [pool.submit(instructions, [sys.executable, *argv], env, ROOT) for _ in range(reps)]

    def finish() -> dict:
        return {name: statistics.median(f.result() for f in fs) for name, fs in futures.items()}
    return finish


def print_instructions(counts: dict) -> None:
    if not counts:
        print("\n(instructions: valgrind not found, not counted; the one-shot verdicts use the paired rounds alone)")
        return
    print("\n### The same processes' instructions executed (cachegrind, PYTHONHASHSEED=0)\n")
    print("| process | instructions (M) | / langur eval's |")
    print("|---|---:|---:|")
    ours = counts.get("langur eval --engine mc")
    for name, n in counts.items():
        print(f"| {name} | {n / 1e6:,.0f} | {n / ours:.2f} |")
