"""Issue 15's numbers in one command, beside the peers when their checkouts are given (not a test).

Run:  python bench/bench_issue15.py [--potto DIR] [--teg DIR] [--quick] [--plot OUT.png] [--skip-exact]
                                    [--json OUT.json]

DIR is a checkout of the peer's public repository (github.com/divicomp/potto, github.com/ChezJrk/Teg),
imported from there by the programs in ``bench/peer_programs/`` (written against the peers' public
APIs; none of the peers' code is in this project); without it that peer's columns say "not given".
Every table reuses the measurements of the scripts that own them:

* **Microbenchmark 1** (§10.3.2, Fig. 16) at n = 1, 10, 25, 49, 100, in ``--peer-reps`` rounds (default
  3): in each round, at every n, Langur's ``load`` (the front end, cold), ``link`` and ``eval``
  (``bench_text_to_number.mb1``, each the least of ``--reps`` calls), then each peer's text to number
  once in a worker process of its own (``issue15_mb1.py NAME DIR``) — compiling the program a user writes
  (``peer_programs/NAME_mb1.py``, the peer's counterpart of a front end), building the expression and
  its derivative (the peer's compile), and evaluating it with 10 samples.  Tables: medians over rounds
  (and the least); ratios: the peer's time over Langur's, and each round's paired ratio (the peer's
  run over Langur's least just before it).  Where a round's load / (link + eval) came near ½, the two
  phases are also counted in instructions (cachegrind: a process doing K calls minus one doing none).
  ``--plot`` draws the growth in n.
* **Microbenchmark 2** (Fig. 17): 90 jumps, 50 shader swaps (``--swaps``), CPU of all swaps: Langur's
  with the incremental front end (``--mb2-rounds`` runs, default 3, and the loads' share) and with every
  load from scratch (``bench_text_to_number.mb2``), the peers' rebuilds (``bench_peers.potto_mb2``,
  ``teg_mb2``) at ``--peer-swaps`` (default 5) scaled to 50: every swap costs them the same (measured 50
  swaps: Teg alone takes over 5 CPU minutes).
* **One-shot processes** of fig1's program: ``python -m langur eval examples/fig1.lgr --engine mc``
  (the target's command) and ``... deriv ...`` (the derivative, as the peers compute it), and a fresh
  Python process per peer running ``peer_programs/NAME_fig1.py`` (imports the peer, computes the value
  and the derivative in θ at θ = 0.5, as the peer's README does), all with compiled modules kept
  (as installed), interleaved round by round; medians of wall (the target's measure) and CPU, each
  round's paired ratios; and ``python -c "import numpy"``, the floor under all three.
  ``--instructions K`` (default 1; 0: not): each one-shot process's instructions executed as well
  (valgrind's cachegrind, median of K runs), which the machine's load does not change.
* **The Monte Carlo path's import**, CPU beyond numpy's (``bench_text_to_number.import_time``), ``--reps``
  processes.
* **The exact engine's ``deriv`` per example** (``bench_symbolic.bench_examples``: each example in a
  fresh process, its partial derivatives in turn): median, max, how many over 1 s; the examples with a
  partial at or above 0.6 s measured ``--exact-again`` more times (default 2); minutes of CPU,
  ``--skip-exact`` leaves it out.

Then the host's speed over the run (``steady.calibrate``, a fixed loop timed beside every round) and
every target of the issue with the measured band and ✓, ✗ or *borderline* (``issue15_targets``,
``steady``): a CPU target's band runs from its least over rounds (divided by the host's slowdown when
the calibration loop ran slower than on the reference host) to its typical value (the median over
rounds); a ratio's from its paired rounds, and the instructions where counted; ✓ or ✗ only when the
limit lies outside the band.  The machine may be shared: the load average is printed beside every
table; CPU time is the measure except for the one-shot target, which is wall time by the issue's
words.  Without valgrind the counts are left out and said so; the bands alone decide.
``--quick``: n = 1, 10, 49, 5 swaps, 3 rounds.

Here: microbenchmark 2, the import, the exact engine, the order of the whole run and its report;
microbenchmark 1's rounds, its instruction counts and the plot are in ``issue15_mb1.py``, the one-shot
processes in ``issue15_oneshot.py``, the targets' verdicts in ``issue15_targets.py`` and ``steady.py``.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_text_to_number as ttn  # noqa: E402  (first: it sets numpy's BLAS threads before numpy loads)
from bench_peers import potto_mb2, teg_mb2  # noqa: E402
from issue15_mb1 import COUNT_FROM, plot, run_mb1, start_phase_instructions  # noqa: E402
from issue15_oneshot import run_one_shot, start_instructions  # noqa: E402
from issue15_targets import EXACT_S, LOAD_SHARE, PEERS, targets  # noqa: E402
from steady import CALIBRATIONS, REFERENCE_CALIBRATION_S, host, load_average, slowdown  # noqa: E402

ROOT = ttn.ROOT


# -- microbenchmark 2 ---------------------------------------------------------------------------------

def langur_mb2(swaps: int, rounds: int = 1) -> dict:
    """Langur's microbenchmark 2 at ``swaps``: incremental in ``rounds`` rounds (the calibration loop
    beside each; ``rounds``: every round's total, ``total``: their median), and once from scratch
    (measured before any peer's process starts: see :func:`run_mb1`)."""
    runs = []
    for _ in range(max(rounds, 1)):
        host()
        runs.append(ttn.mb2(swaps, True))
    host()
    scratch, stats2 = ttn.mb2(swaps, False)
    inc = statistics.median(t for t, _ in runs)
    stats = min(runs, key=lambda r: abs(r[0] - inc))[1]
    return {"langur": {"total": inc, "rounds": [t for t, _ in runs], "load": statistics.median(s["load"] for _, s in runs),
                       "without": inc - statistics.median(s["load"] for _, s in runs),
                       "elaborated": stats["elaborated"], "reused": stats["reused"], "loadavg": os.getloadavg()[0]},
            "langur_scratch": {"total": scratch, "load": stats2["load"], "loadavg": os.getloadavg()[0]}}


def run_mb2(swaps: int, peers: dict, peer_swaps: int, langur: dict) -> dict:
    """Langur at ``swaps`` (:func:`langur_mb2`'s numbers); each peer at ``peer_swaps`` (each of its swaps
    costs the same: Potto evaluates the swapped shader's derivative applied to the integral compiled
    once, Teg rebuilds and re-derives the whole integral), scaled to ``swaps`` by (swaps + 1) /
    (peer_swaps + 1) — the number of shaders evaluated — when the two differ."""
    rounds = langur["langur"]["rounds"]
    print(f"\n## Microbenchmark 2 (Fig. 17): 90 jumps, {swaps} shader swaps, 10 samples each — s CPU; Langur's "
          f"incremental front end: median of {len(rounds)} rounds ({', '.join(f'{t:.3f}' for t in rounds)}), the "
          "rest one run\n")
    out = dict(langur)
    ours, scratch = out["langur"], out["langur_scratch"]
    inc = ours["total"]
    print("| system | text to number | of which loading (front end) | without front end | ratio to langur "
          "| load avg |\n|---|---:|---:|---:|---:|---:|")
    print(f"| langur, incremental front end | **{inc:.3f}** | {ours['load']:.3f} ({ours['elaborated']} modules "
          f"elaborated, {ours['reused']} reused) | {ours['without']:.3f} | 1 | {ours['loadavg']:.1f} |")
    print(f"| langur, every load from scratch | {scratch['total']:.3f} | {scratch['load']:.3f} | "
          f"{scratch['total'] - scratch['load']:.3f} | {scratch['total'] / inc:.2f} | {scratch['loadavg']:.1f} |",
          flush=True)
    for p in peers:
        measured = {"potto": potto_mb2, "teg": teg_mb2}[p](peer_swaps)
        t = measured * (swaps + 1) / (peer_swaps + 1)
        out[p] = {"total": t, "measured": measured, "swaps": peer_swaps}
        how = ("the integral compiled once, each swap's shader derivative applied" if p == "potto"
               else "each swap rebuilds and re-derives the integral")
        shown = (f"**{t:.3f}**" if peer_swaps == swaps else
                 f"**≈ {t:.1f}** (scaled from {measured:.3f} s at {peer_swaps} swaps)")
        print(f"| {p} ({how}) | {shown} | — | — | **{t / inc:.0f}×** | {os.getloadavg()[0]:.1f} |", flush=True)
    return out


# -- the import of the Monte Carlo path ----------------------------------------------------------------

def run_import(reps: int) -> dict:
    """CPU of ``import langur.frontend, langur.operational`` beyond numpy's, ``reps`` processes
    (``bench_text_to_number.import_time``, one process each; ``rounds``: every process's)."""
    runs = []
    with tempfile.TemporaryDirectory() as cache:
        for _ in range(reps):
            host()
            runs.append(ttn.import_time(1, cache))
    numpy_s, ours = statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)
    print(f"\n## Import of the Monte Carlo path ({load_average()})\n\n`import langur.frontend, langur.operational`: "
          f"**{ours:.3f} s CPU** beyond numpy's {numpy_s:.3f} s (medians of {reps} processes, compiled modules kept; "
          f"least {min(r[1] for r in runs):.3f} s)")
    return {"numpy": numpy_s, "beyond": ours, "rounds": [r[1] for r in runs]}


# -- the exact engine ---------------------------------------------------------------------------------------

#: A partial derivative whose first run takes at least this share of the limit is measured again.
AGAIN_FROM = 0.6


def run_exact(limit: float, again: int = 2) -> dict:
    """Every example's exact ``deriv`` (module doc); then each example with a partial derivative at or
    above :data:`AGAIN_FROM` × the limit run ``again`` more times (fresh processes, the calibration loop
    beside each): ``again`` holds those partials' CPU seconds of every run, the first included."""
    # (imported here, not at the top: bench_symbolic imports the exact engine and sympy, which the
    # measurements above must not find already loaded in this process)
    import bench_symbolic

    print(f"\n## The exact engine's `deriv` per example ({load_average()} at the start)\n")
    t0 = time.perf_counter()
    rows = list(bench_symbolic.bench_examples(limit))
    cpu = sorted(((r["cpu"], f"{r['example']} ∂{r['wrt']}") for r in rows if r.get("wrt") is not None), reverse=True)
    failed = [r["example"] for r in rows if r.get("wrt") is None and "error" in r]
    values = [c for c, _ in cpu]
    out = {"count": len(values), "median": statistics.median(values) if values else None,
           "max": values[0] if values else None, "over": sum(c > EXACT_S for c in values), "failed": failed,
           "slowest": cpu[:5]}
    print(f"{len(values)} partial derivatives of {len({r['example'] for r in rows})} examples (each example in a "
          f"fresh process, CPU limit {limit:g} s): **median {out['median']:.2f} s, max {out['max']:.2f} s, "
          f"{out['over']} over {EXACT_S:g} s**; not finished: {failed or 'none'}; "
          f"{time.perf_counter() - t0:.0f} s of wall time, {load_average()} at the end")
    print("slowest: " + ", ".join(f"{name} {c:.2f} s" for c, name in cpu[:5]))
    slow = [r for r in rows if r.get("wrt") is not None and r["cpu"] >= AGAIN_FROM * EXACT_S]
    if not again or not slow:
        return out
    runs = {f"{r['example']} ∂{r['wrt']}": [r["cpu"]] for r in slow}
    examples = sorted({r["example"] for r in slow})
    for _ in range(again):  # (round by round: each example once per round)
        for example in examples:
            host()
            for r in bench_symbolic.bench_examples(limit, only=example):
                key = f"{r['example']} ∂{r.get('wrt')}"
                if r["example"] == example and key in runs:
                    runs[key].append(r["cpu"])
    out["again"] = runs
    print(f"\nmeasured {again} more times (the partials at or above {AGAIN_FROM:g} s in the first run; {load_average()}): "
          + ", ".join(f"{k} {', '.join(f'{c:.2f}' for c in v)}" for k, v in sorted(runs.items(), key=lambda kv: -max(kv[1]))))
    return out


# -- the targets ----------------------------------------------------------------------------------------------

def print_host(m: dict) -> None:
    """How fast the host ran during the run: the calibration loop's least, median and most."""
    cal = m["calibrations"]
    print(f"\n## The host's speed: the calibration loop (steady.calibrate, least of 5 calls), {len(cal)} times "
          f"through the run\n\nleast {1e3 * min(cal):.2f} ms, median {1e3 * statistics.median(cal):.2f} ms, most "
          f"{1e3 * max(cal):.2f} ms; the reference host idle: {1e3 * REFERENCE_CALIBRATION_S:.2f} ms; this run's "
          f"slowdown (least ÷ reference, at least 1): **{m['slowdown']:.2f}×** — a CPU target's band runs from its "
          "least ÷ the slowdown to its typical value (the median over rounds); ✓ / ✗ only when the limit is outside "
          "the band, else borderline")


def print_targets(m: dict) -> None:
    print(f"\n## Issue 15's targets ({load_average()})\n")
    print("| target | measured | ratio | |\n|---|---|---|---|")
    for row in targets(m):
        print("| " + " | ".join(row) + " |")


def _describe(peers: dict) -> None:
    import numpy

    try:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True).stdout.strip() or "?"
    except OSError:
        commit = "?"
    print(f"# Issue 15, end to end — {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {load_average()} on "
          f"{os.cpu_count()} cores; Python {platform.python_version()}, numpy {numpy.__version__}; langur at {commit}")
    for p in PEERS:
        print(f"- {p}: " + (os.path.abspath(peers[p]) if p in peers else
                           f"not given (pass --{p} DIR, a checkout of its public repository, to compare)"))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--potto", metavar="DIR", help="a checkout of github.com/divicomp/potto")
    ap.add_argument("--teg", metavar="DIR", help="a checkout of github.com/ChezJrk/Teg")
    ap.add_argument("--quick", action="store_true", help="n = 1, 10, 49; 5 swaps; 3 rounds (a smoke run)")
    ap.add_argument("--plot", metavar="OUT.png", help="draw microbenchmark 1's growth in n (matplotlib)")
    ap.add_argument("--skip-exact", action="store_true", help="leave out the exact engine's examples (minutes)")
    ap.add_argument("--exact-limit", type=float, default=60.0, metavar="S", help="CPU seconds per example's process")
    ap.add_argument("--reps", type=int, default=5, help="Langur's calls per phase and n in each round (their least)")
    ap.add_argument("--peer-reps", type=int, default=3,
                    help="microbenchmark 1's rounds: Langur's and each peer's runs per n, alternated (medians)")
    ap.add_argument("--rounds", type=int, help="one-shot rounds (default 9, 3 with --quick)")
    ap.add_argument("--swaps", type=int, help="microbenchmark 2's swaps (default 50, 5 with --quick)")
    ap.add_argument("--mb2-rounds", type=int, default=3, help="Langur's microbenchmark 2 runs (incremental; median)")
    ap.add_argument("--peer-swaps", type=int, default=5,
                    help="the peers' swaps, scaled to --swaps (default 5: at 50 Teg takes over 5 CPU minutes)")
    ap.add_argument("--json", metavar="OUT.json", help="also write every number measured")
    ap.add_argument("--instructions", type=int, default=1, metavar="K",
                    help="count each one-shot process's instructions (valgrind), median of K runs; 0: not")
    ap.add_argument("--phase-calls", type=int, default=3, metavar="K",
                    help="count microbenchmark 1's load and link + eval in instructions, K calls − none; 0: not")
    ap.add_argument("--exact-again", type=int, default=2, metavar="K",
                    help=f"run the examples with a partial ≥ {AGAIN_FROM:g} s K more times")
    args = ap.parse_args(argv)
    peers = {p: getattr(args, p) for p in PEERS if getattr(args, p)}
    sys.setrecursionlimit(10**6)  # (the peers' expression trees are deep)
    for path in peers.values():
        sys.path.insert(0, os.path.abspath(path))
    _describe(peers)
    sizes = (1, 10, 49) if args.quick else ttn.SIZES
    m: dict = {"swaps": args.swaps or (5 if args.quick else 50), "wall": {}}
    clock = [time.perf_counter()]

    def took(section: str) -> None:  # (the sections' wall time, printed at the end)
        now = time.perf_counter()
        m["wall"][section] = now - clock[0]
        clock[0] = now

    ours_mb2 = langur_mb2(m["swaps"], args.mb2_rounds)  # (before any peer is imported into this process: see run_mb1)
    took("Langur's microbenchmark 2")
    m["mb1"] = run_mb1(sizes, peers, args.reps, args.peer_reps)
    took("microbenchmark 1's rounds")
    if args.plot:
        plot(m["mb1"], args.plot)
        print(f"\nplot: {args.plot}")
    # The instruction counts (valgrind, two processes at a time) run beside the peers' microbenchmark 2, whose
    # seconds no target reads, and are waited for before the one-shot rounds time anything.
    near = [r["n"] for r in m["mb1"]["langur"] if max(r["share_rounds"]) >= COUNT_FROM * LOAD_SHARE]
    with tempfile.TemporaryDirectory() as cache, ThreadPoolExecutor(2) as pool:
        phases = start_phase_instructions(pool, near, args.phase_calls, cache) if args.phase_calls and near else None
        shots = start_instructions(pool, peers, args.instructions, cache) if args.instructions else None
        m["mb2"] = run_mb2(m["swaps"], peers, min(args.peer_swaps, m["swaps"]), ours_mb2)
        counted = phases() if phases else {}
        for r in m["mb1"]["langur"]:
            if r["n"] in counted:
                r["share_instructions"], r["instructions"] = counted[r["n"]]["share"], counted[r["n"]]
        counts = shots() if shots else None
    took("the peers' microbenchmark 2 and the instruction counts beside it")
    m["one_shot"] = run_one_shot(peers, args.rounds or (3 if args.quick else 9), counts)
    m["import"] = run_import(args.reps)
    took("the one-shot processes and the import")
    if not args.skip_exact:
        m["exact"] = run_exact(args.exact_limit, args.exact_again)
        took("the exact engine")
    host()
    m["calibrations"], m["slowdown"] = CALIBRATIONS, slowdown(CALIBRATIONS)
    print_host(m)
    print_targets(m)
    print(f"\nwall time: {sum(m['wall'].values()) / 60:.1f} min (" + ", ".join(f"{k} {v / 60:.1f}" for k, v in
                                                                     m["wall"].items()) + f"; {load_average()} at the end)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(m, fh, indent=1, default=str)

if __name__ == "__main__":
    main()
