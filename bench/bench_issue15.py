"""Issue 15's numbers in one command, beside the peers when their checkouts are given (not a test).

Run:  python bench/bench_issue15.py [--potto DIR] [--teg DIR] [--quick] [--plot OUT.png] [--skip-exact]
                                    [--json OUT.json]

DIR is a checkout of the peer's public repository (github.com/divicomp/potto, github.com/ChezJrk/Teg),
imported from there by the programs in ``bench/peer_programs/`` (written against the peers' public
APIs; none of the peers' code is in this project); without it that peer's columns say "not given".
Every table reuses the measurements of the scripts that own them:

* **Microbenchmark 1** (§10.3.2, Fig. 16) at n = 1, 10, 25, 49, 100, CPU medians: Langur's
  ``load`` (the front end, cold), ``link`` and ``eval`` (``bench_text_to_number.mb1``), text to number
  with the front end (their sum) and without it (link + eval); each peer's text to number — compiling
  the program a user writes (``peer_programs/NAME_mb1.py``, the peer's counterpart of a front end),
  building the expression and its derivative (the peer's compile), and evaluating it with 10 samples —
  and its compile + evaluate alone (as ``bench_peers.py`` reports it).  Sizes interleaved: each n runs
  every system before the next n.  Ratios: the peer's time over Langur's, text to number against text
  to number, and compile + evaluate against link + eval.  ``--plot`` draws the growth in n.
* **Microbenchmark 2** (Fig. 17): 90 jumps, 50 shader swaps (``--swaps``), CPU of all swaps: Langur's
  with the incremental front end (and the loads' share) and with every load from scratch
  (``bench_text_to_number.mb2``), the peers' rebuilds (``bench_peers.potto_mb2``, ``teg_mb2``) at
  ``--peer-swaps`` (default 5) scaled to 50: every swap costs them the same (measured 50 swaps:
  Teg alone takes over 5 CPU minutes).
* **One-shot processes** of fig1's program: ``python -m langur eval examples/fig1.lgr --engine mc``
  (the target's command) and ``... deriv ...`` (the derivative, as the peers compute it), and a fresh
  Python process per peer running ``peer_programs/NAME_fig1.py`` (imports the peer, computes the value
  and the derivative in θ at θ = 0.5, as the peer's README does), all with compiled modules kept
  (as installed), interleaved round by round; medians of wall (the target's measure) and CPU; and
  ``python -c "import numpy"``, the floor under all three.  ``--instructions K``: each one-shot
  process's instructions executed as well (valgrind's cachegrind, median of K runs), which the
  machine's load does not change.
* **The Monte Carlo path's import**, CPU beyond numpy's (``bench_text_to_number.import_time``).
* **The exact engine's ``deriv`` per example** (``bench_symbolic.bench_examples``: each example in a
  fresh process, its partial derivatives in turn): median, max, how many over 1 s; minutes of CPU,
  ``--skip-exact`` leaves it out.

Then every target of the issue with the measured number and ✓ / ✗.  The machine may be shared: the
load average is printed beside every table; CPU time is the measure except for the one-shot target,
which is wall time by the issue's words.  ``--quick``: n = 1, 10, 49, 5 swaps, 3 rounds.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_text_to_number as ttn  # noqa: E402  (first: it sets numpy's BLAS threads before numpy loads)
from bench_peers import PROGRAMS, expected_mb1, peer_program, potto_mb2, teg_mb2  # noqa: E402
from issue15_targets import EXACT_S, MB1_49_MS, MB1_100_MS, PEERS, targets  # noqa: E402

ROOT = ttn.ROOT
CLOCK = time.process_time

def load() -> str:
    return f"load average {os.getloadavg()[0]:.1f}"


# -- microbenchmark 1 ---------------------------------------------------------------------------------

def peer_mb1(name: str, n: int, reps: int) -> dict:
    """A peer's microbenchmark 1 from its program's text (module doc), CPU medians of ``reps`` runs:
    ``text`` (the file compiled and its body run: its imports are already loaded), ``build`` (the
    expression and its derivative), ``eval`` (10 samples)."""
    path = os.path.join(PROGRAMS, f"{name}_mb1.py")
    with open(path) as fh:
        source = fh.read()
    peer_program(f"{name}_mb1")  # the peer imported once, before the clock (a process's start-up)
    runs = []
    for _ in range(reps):
        t0 = CLOCK()
        space = {"__name__": f"_{name}_mb1_from_text"}
        exec(compile(source, path, "exec"), space)
        t1 = CLOCK()
        expr, values = space["program"](n)
        t2 = CLOCK()
        value = space["number"](expr, values, 10)
        t3 = CLOCK()
        runs.append((t1 - t0, t2 - t1, t3 - t2, value))
    text, build, eval_ = (statistics.median(r[k] for r in runs) for k in range(3))
    return {"n": n, "text": text, "build": build, "eval": eval_, "total": text + build + eval_,
            "compile_eval": build + eval_, "value": runs[-1][3]}


def run_mb1(sizes, peers: dict, reps: int, peer_reps: int) -> dict:
    out: dict = {"langur": [], **{p: [] for p in peers}}
    print(f"\n## Microbenchmark 1 (Fig. 16): n jumps, 2n deltas, 10 samples — ms CPU ({load()})\n")
    for n in sizes:  # Langur first at every n, before a peer is imported: the peers run in this process, and
        # Langur's numbers should not depend on what they leave in its heap (Teg's expression trees at
        # n = 49 and 100, …).  (Interleaved by n, two runs gave n = 49 14.7 and 24.4 ms; Langur first, 20.4
        # ms: this machine's CPU seconds vary by ±20 % run to run even for a plain loop; minima over
        # alternated processes (bench_text_to_number.py --against) and instruction counts are steadier.)
        r = ttn.mb1(n, reps)
        r["without"], r["loadavg"] = r["link"] + r["eval"], os.getloadavg()[0]
        out["langur"].append(r)
        print(f"(langur at n = {n} measured, {load()})", flush=True)
    for n in sizes:
        for p in peers:
            q = peer_mb1(p, n, peer_reps)
            q["loadavg"] = os.getloadavg()[0]
            out[p].append(q)
        print(f"(the peers at n = {n} measured, {load()})", flush=True)
    print(f"\nLangur: medians of {reps} (the front end's caches emptied before each load); text to number = "
          f"load + link + eval, without the front end = link + eval.\n")
    print("| n | load (front end) | link (compile) | eval | **text to number** | without front end "
          "| load / (link + eval) | D (expected) | load avg |")
    print("|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for r in out["langur"]:
        print(f"| {r['n']} | {1e3 * r['load']:.1f} | {1e3 * r['link']:.1f} | {1e3 * r['eval']:.1f} | "
              f"**{1e3 * r['total']:.1f}** | {1e3 * r['without']:.1f} | {r['load'] / r['without']:.2f} | "
              f"{r['value']:.6g} ({expected_mb1(r['n']):.6g}) | {r['loadavg']:.1f} |")
    if not peers:
        return out
    print(f"\nThe peers: medians of {peer_reps}, each run from its program's text (peer_programs/NAME_mb1.py): "
          "text = the file compiled and run (its imports already loaded), compile = the expression and its "
          "derivative built, eval = 10 samples. Ratios: the peer's time over Langur's at the same n.\n")
    print("| n | system | text | compile | eval | **text to number** | D | **÷ langur's text to number** "
          "| compile + eval ÷ langur's link + eval | load avg |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for i, r in enumerate(out["langur"]):
        for p in peers:
            q = out[p][i]
            print(f"| {q['n']} | {p} | {1e3 * q['text']:.2f} | {1e3 * q['build']:.1f} | {1e3 * q['eval']:.1f} | "
                  f"**{1e3 * q['total']:.1f}** | {q['value']:.6g} | **{q['total'] / r['total']:.0f}×** | "
                  f"{q['compile_eval'] / r['without']:.0f}× | {q['loadavg']:.1f} |")
    return out


# -- microbenchmark 2 ---------------------------------------------------------------------------------

def langur_mb2(swaps: int) -> dict:
    """Langur's microbenchmark 2 at ``swaps``, incremental and from scratch (measured before any peer
    is imported into this process: see :func:`run_mb1`)."""
    inc, stats = ttn.mb2(swaps, True)
    scratch, stats2 = ttn.mb2(swaps, False)
    return {"langur": {"total": inc, "load": stats["load"], "without": inc - stats["load"],
                       "elaborated": stats["elaborated"], "reused": stats["reused"], "loadavg": os.getloadavg()[0]},
            "langur_scratch": {"total": scratch, "load": stats2["load"], "loadavg": os.getloadavg()[0]}}


def run_mb2(swaps: int, peers: dict, peer_swaps: int, langur: dict) -> dict:
    """Langur at ``swaps`` (:func:`langur_mb2`'s numbers); each peer at ``peer_swaps`` (each of its swaps
    costs the same: Potto evaluates the swapped shader's derivative applied to the integral compiled
    once, Teg rebuilds and re-derives the whole integral), scaled to ``swaps`` by (swaps + 1) /
    (peer_swaps + 1) — the number of shaders evaluated — when the two differ."""
    print(f"\n## Microbenchmark 2 (Fig. 17): 90 jumps, {swaps} shader swaps, 10 samples each — s CPU, one run\n")
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


# -- one-shot processes and the import ------------------------------------------------------------------

def run_one_shot(peers: dict, rounds: int, instructions: int = 0) -> dict:
    """Every system's one-shot process, round by round (each round runs each once, in turn), with
    compiled modules kept in a temporary ``PYTHONPYCACHEPREFIX`` (one warm-up run each first)."""
    print(f"\n## One-shot processes: fig1's program, wall and CPU seconds, medians of {rounds} rounds\n")
    with tempfile.TemporaryDirectory() as cache:
        base = ttn._env(cache)
        commands = {"langur eval --engine mc": (ttn.ONE_SHOT, base),
                    "langur deriv --engine mc": (("-m", "langur", "deriv", "examples/fig1.lgr", "--engine", "mc"),
                                                 base)}
        for p, path in peers.items():
            commands[p] = ((os.path.join(PROGRAMS, f"{p}_fig1.py"),), {**base, "PYTHONPATH": os.path.abspath(path)})
        commands["python -c 'import numpy' (the floor: every system imports numpy)"] = (("-c", "import numpy"), base)
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
    langur = out["langur eval --engine mc"]["wall"]
    print("| process | wall (median) | wall (min) | CPU (median) | wall / langur eval's | prints |")
    print("|---|---:|---:|---:|---:|---|")
    for name, t in out.items():
        printed = "; ".join(line.strip() for line in outputs[name].splitlines()[-2:])
        print(f"| {name} | **{t['wall']:.3f}** | {t['wall_min']:.3f} | {t['cpu']:.3f} | {t['wall'] / langur:.2f} "
              f"| {printed} |")
    print(f"\nload average during the rounds: {min(loads):.1f}–{max(loads):.1f}")
    out["loads"] = [min(loads), max(loads)]
    if instructions:
        out["instructions"] = run_instructions(commands, base, instructions)
    return out


def run_instructions(commands: dict, base: dict, reps: int) -> dict:
    """Each one-shot process's instructions executed (valgrind's cachegrind, ``PYTHONHASHSEED=0``,
    compiled modules kept), median of ``reps`` runs: the machine's load does not change them, so two
    systems compare within a few per cent where wall medians on a shared machine do not (what varies
    between runs is Python's start-up: site's ``.pth`` files, hashing of the paths)."""
    if shutil.which("valgrind") is None:
        print("\n(instructions: valgrind not found, not measured)")
        return {}
    print(f"\n### The same processes' instructions executed (cachegrind, median of {reps})\n")
    print("| process | instructions (M) | / langur eval's |")
    print("|---|---:|---:|")
    counts: dict = {}
    with tempfile.TemporaryDirectory() as cache:
        for name, (argv, env) in commands.items():
            env = {**env, "PYTHONHASHSEED": "0", "PYTHONPYCACHEPREFIX": cache}
            env.pop("PYTHONDONTWRITEBYTECODE", None)
            subprocess.run([sys.executable, *argv], cwd=ROOT, env=env, check=True, capture_output=True)
            runs = []
            for _ in range(reps):
                r = subprocess.run(["valgrind", "--tool=cachegrind", "--cache-sim=no", "--cachegrind-out-file=/dev/null",
                                    sys.executable, *argv], cwd=ROOT, env=env, check=True, capture_output=True,
                                   text=True)
                refs = [line for line in r.stderr.splitlines() if "I   refs" in line or "I refs" in line]
                runs.append(int(refs[-1].split(":")[1].replace(",", "").strip()))
            counts[name] = statistics.median(runs)
    ours = counts.get("langur eval --engine mc")
    for name, n in counts.items():
        print(f"| {name} | {n / 1e6:,.0f} | {n / ours:.2f} |")
    return counts


def run_import(reps: int) -> dict:
    with tempfile.TemporaryDirectory() as cache:
        numpy_s, ours = ttn.import_time(reps, cache)
    print(f"\n## Import of the Monte Carlo path ({load()})\n\n`import langur.frontend, langur.operational`: "
          f"**{ours:.3f} s CPU** beyond numpy's {numpy_s:.3f} s (medians of {reps} processes, compiled modules kept)")
    return {"numpy": numpy_s, "beyond": ours}


# -- the exact engine ---------------------------------------------------------------------------------------

def run_exact(limit: float) -> dict:
    # (imported here, not at the top: bench_symbolic imports the exact engine and sympy, which the
    # measurements above must not find already loaded in this process)
    import bench_symbolic

    print(f"\n## The exact engine's `deriv` per example ({load()} at the start)\n")
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
          f"{time.perf_counter() - t0:.0f} s of wall time, {load()} at the end")
    print("slowest: " + ", ".join(f"{name} {c:.2f} s" for c, name in cpu[:5]))
    return out


# -- the targets ----------------------------------------------------------------------------------------------

def print_targets(m: dict) -> None:
    print(f"\n## Issue 15's targets ({load()})\n")
    print("| target | measured | ratio | |\n|---|---|---|---|")
    for row in targets(m):
        print("| " + " | ".join(row) + " |")


# -- the plot ---------------------------------------------------------------------------------------------------

def plot(mb1: dict, out: str) -> None:
    """Microbenchmark 1's growth in n: every system's text to number (log scale), and Langur's parts."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.2))
    ns = [r["n"] for r in mb1["langur"]]
    left.plot(ns, [r["total"] for r in mb1["langur"]], marker="o", label="langur, text to number")
    left.plot(ns, [r["without"] for r in mb1["langur"]], marker=".", linestyle="--", label="langur, link + eval")
    for p in PEERS:
        if mb1.get(p):
            left.plot([r["n"] for r in mb1[p]], [r["total"] for r in mb1[p]], marker="s", label=f"{p}, text to number")
    left.set_yscale("log")
    left.set_xlabel("n (jumps; 2n deltas)")
    left.set_ylabel("CPU seconds (median)")
    left.set_title("Microbenchmark 1 (Fig. 16): text to number", fontsize=10)
    left.legend(fontsize=8)
    left.grid(alpha=0.3, which="both")
    for key, label in (("load", "load (front end)"), ("link", "link (compile)"), ("eval", "evaluate, 10 samples"),
                       ("total", "text to number")):
        right.plot(ns, [1e3 * r[key] for r in mb1["langur"]], marker="o", label=label)
    right.plot([49, 100], [MB1_49_MS, MB1_100_MS], linestyle="none", marker="*", markersize=12, color="black",
               label="issue 15's targets")
    right.set_xlabel("n (jumps; 2n deltas)")
    right.set_ylabel("CPU ms (median)")
    right.set_title("Langur's parts (linear scale)", fontsize=10)
    right.legend(fontsize=8)
    right.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def _describe(peers: dict) -> None:
    import numpy

    try:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                                text=True).stdout.strip() or "?"
    except OSError:
        commit = "?"
    print(f"# Issue 15, end to end — {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {load()} on "
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
    ap.add_argument("--reps", type=int, default=5, help="Langur's repetitions per n (CPU median)")
    ap.add_argument("--peer-reps", type=int, default=3, help="the peers' repetitions per n (CPU median)")
    ap.add_argument("--rounds", type=int, help="one-shot rounds (default 9, 3 with --quick)")
    ap.add_argument("--swaps", type=int, help="microbenchmark 2's swaps (default 50, 5 with --quick)")
    ap.add_argument("--peer-swaps", type=int, default=5,
                    help="the peers' swaps, scaled to --swaps (default 5: at 50 Teg takes over 5 CPU minutes)")
    ap.add_argument("--json", metavar="OUT.json", help="also write every number measured")
    ap.add_argument("--instructions", type=int, default=0, metavar="K",
                    help="also count each one-shot process's instructions (valgrind), median of K runs")
    args = ap.parse_args(argv)
    peers = {p: getattr(args, p) for p in PEERS if getattr(args, p)}
    sys.setrecursionlimit(10**6)  # (the peers' expression trees are deep)
    for path in peers.values():
        sys.path.insert(0, os.path.abspath(path))
    _describe(peers)
    sizes = (1, 10, 49) if args.quick else ttn.SIZES
    m: dict = {"swaps": args.swaps or (5 if args.quick else 50)}
    ours_mb2 = langur_mb2(m["swaps"])  # (before any peer is imported into this process: see run_mb1)
    m["mb1"] = run_mb1(sizes, peers, args.reps, args.peer_reps)
    if args.plot:
        plot(m["mb1"], args.plot)
        print(f"\nplot: {args.plot}")
    m["mb2"] = run_mb2(m["swaps"], peers, min(args.peer_swaps, m["swaps"]), ours_mb2)
    m["one_shot"] = run_one_shot(peers, args.rounds or (3 if args.quick else 9), args.instructions)
    m["import"] = run_import(args.reps)
    if not args.skip_exact:
        m["exact"] = run_exact(args.exact_limit)
    print_targets(m)
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(m, fh, indent=1, default=str)


if __name__ == "__main__":
    main()
