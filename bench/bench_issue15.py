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
  once in a worker process of its own (``--peer-worker``) — compiling the program a user writes
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
from bench_peers import PROGRAMS, expected_mb1, peer_program, potto_mb2, teg_mb2  # noqa: E402
from issue15_targets import EXACT_S, LOAD_SHARE, MB1_49_MS, MB1_100_MS, PEERS, targets  # noqa: E402
from steady import REFERENCE_CALIBRATION_S, calibrate, have_valgrind, instructions, per_operation, slowdown  # noqa: E402

ROOT = ttn.ROOT
CLOCK = time.process_time

def load() -> str:
    return f"load average {os.getloadavg()[0]:.1f}"


#: Every calibration of the run (``steady.calibrate``: CPU seconds of a fixed loop), in order.
CALIBRATIONS: list = []


def host() -> float:
    """The calibration loop timed now (appended to :data:`CALIBRATIONS`): how fast the host runs."""
    c = calibrate()
    CALIBRATIONS.append(c)
    return c


def _least(f, reps: int, setup=None):
    """``bench_text_to_number._median``'s twin giving the least CPU seconds of ``reps`` calls."""
    best, out = float("inf"), None
    for _ in range(reps):
        out = None
        if setup is not None:
            setup()
        t0 = CLOCK()
        out = f()
        best = min(best, CLOCK() - t0)
    return best, out


def langur_mb1(n: int, reps: int) -> dict:
    """``bench_text_to_number.mb1`` (load, link, eval at ``n``), each phase the least of ``reps`` calls."""
    saved, ttn._median = ttn._median, _least
    try:
        return ttn.mb1(n, reps)
    finally:
        ttn._median = saved


class PeerWorker:
    """A process of its own running one peer's microbenchmark 1 on request (``--peer-worker``): the
    peers' expression trees stay out of this process's heap, so Langur's rounds can alternate with
    theirs (measured inside the worker, CPU seconds of that process)."""

    def __init__(self, name: str, path: str):
        self.proc = subprocess.Popen([sys.executable, "-P", os.path.abspath(__file__), "--peer-worker", name,
                                      f"--{name}", path], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
                                     cwd=ROOT)

    def mb1(self, n: int) -> dict:
        self.proc.stdin.write(f"{n}\n")
        self.proc.stdin.flush()
        line = self.proc.stdout.readline()
        if not line:
            raise RuntimeError("the peer's worker process ended")
        return json.loads(line)

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait()


def peer_worker(name: str) -> None:
    """The ``--peer-worker`` loop: one n per line in, one JSON line out (:func:`peer_mb1`, one run)."""
    for line in sys.stdin:
        print(json.dumps(peer_mb1(name, int(line), 1)), flush=True)


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


def run_mb1(sizes, peers: dict, reps: int, rounds: int) -> dict:
    """Microbenchmark 1 in ``rounds`` rounds; in each, at every n, Langur (each phase the least of
    ``reps`` calls) and then each peer once (its worker process), the calibration loop beside each.
    A row's load / link / eval / total are the medians over rounds of Langur's leasts (its *typical*
    values), ``total_rounds`` and ``share_rounds`` (load ÷ (link + eval) of each round) every round's;
    a peer's row the medians over rounds, ``paired`` each round's run beside Langur's least just before."""
    out: dict = {"langur": [], **{p: [] for p in peers}}
    print(f"\n## Microbenchmark 1 (Fig. 16): n jumps, 2n deltas, 10 samples — ms CPU ({load()})\n")
    workers = {p: PeerWorker(p, path) for p, path in peers.items()}
    ours: dict = {n: [] for n in sizes}
    theirs: dict = {(p, n): [] for p in peers for n in sizes}
    try:
        for k in range(rounds):
            for n in sizes:  # Langur in this process, the peers in theirs, one after the other
                host()
                r = langur_mb1(n, reps)
                ours[n].append(r)
                for p, worker in workers.items():
                    q = worker.mb1(n)
                    q["langur"], q["cal"], q["loadavg"] = r["total"], host(), os.getloadavg()[0]
                    theirs[p, n].append(q)
            print(f"(round {k + 1} of {rounds} measured, {load()})", flush=True)
    finally:
        for worker in workers.values():
            worker.close()
    fastest = min(CALIBRATIONS)
    for n in sizes:
        rs = ours[n]
        row = {key: statistics.median(r[key] for r in rs) for key in ("load", "link", "eval")}
        row.update(n=n, total=row["load"] + row["link"] + row["eval"], value=rs[-1]["value"],
                   total_rounds=[r["total"] for r in rs], share_rounds=[r["load"] / (r["link"] + r["eval"]) for r in rs],
                   least=min(r["total"] for r in rs), loadavg=os.getloadavg()[0])
        row["without"] = row["link"] + row["eval"]
        out["langur"].append(row)
        for p in peers:
            qs = theirs[p, n]
            q = {key: statistics.median(x[key] for x in qs) for key in ("text", "build", "eval", "total", "compile_eval")}
            q.update(n=n, value=qs[-1]["value"], loadavg=qs[-1]["loadavg"], least=min(x["total"] for x in qs),
                     paired=[{"peer": x["total"], "langur": x["langur"], "host": x["cal"] / fastest} for x in qs])
            out[p].append(q)
    print(f"\nLangur: {rounds} rounds, each phase the least of {reps} calls in a round (the front end's caches "
          f"emptied before each load); shown: the median over rounds (typical) and the least; text to number = "
          f"load + link + eval, without the front end = link + eval.\n")
    print("| n | load (front end) | link (compile) | eval | **text to number** (least) | without front end "
          "| load / (link + eval), rounds | D (expected) | load avg |")
    print("|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    for r in out["langur"]:
        shares = ", ".join(f"{x:.2f}" for x in r["share_rounds"])
        print(f"| {r['n']} | {1e3 * r['load']:.1f} | {1e3 * r['link']:.1f} | {1e3 * r['eval']:.1f} | "
              f"**{1e3 * r['total']:.1f}** ({1e3 * r['least']:.1f}) | {1e3 * r['without']:.1f} | {shares} | "
              f"{r['value']:.6g} ({expected_mb1(r['n']):.6g}) | {r['loadavg']:.1f} |")
    if not peers:
        return out
    print(f"\nThe peers: medians of {rounds} rounds, each run from its program's text (peer_programs/NAME_mb1.py) "
          "in a process of its own: text = the file compiled and run (its imports already loaded), compile = the "
          "expression and its derivative built, eval = 10 samples. Ratios: the peer's time over Langur's at the same "
          "n; paired: each round's over Langur's least just before it.\n")
    print("| n | system | text | compile | eval | **text to number** (least) | D | **÷ langur's text to number** "
          "| paired, rounds | compile + eval ÷ langur's link + eval | load avg |")
    print("|---:|---|---:|---:|---:|---:|---:|---:|---|---:|---:|")
    for i, r in enumerate(out["langur"]):
        for p in peers:
            q = out[p][i]
            paired = ", ".join(f"{x['peer'] / x['langur']:.0f}" for x in q["paired"])
            print(f"| {q['n']} | {p} | {1e3 * q['text']:.2f} | {1e3 * q['build']:.1f} | {1e3 * q['eval']:.1f} | "
                  f"**{1e3 * q['total']:.1f}** ({1e3 * q['least']:.1f}) | {q['value']:.6g} | "
                  f"**{q['total'] / r['total']:.0f}×** | {paired} | {q['compile_eval'] / r['without']:.0f}× | "
                  f"{q['loadavg']:.1f} |")
    return out


_PHASES = r"""
import os, sys
sys.path.insert(0, os.path.join(sys.argv[1], "bench"))
import bench_text_to_number as b
from bench_peers import langur_text
from langur import frontend
from langur.operational import clear_cache, estimate_derivative, link
n, what, k = int(sys.argv[2]), sys.argv[3], int(sys.argv[4])
text = langur_text(n)
def load():
    b.cold()
    return frontend.load_text(text)
def le(loaded):
    clear_cache()
    link(loaded)
    estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=10, seed=0)
for _ in range(2):  # the warm-up, the same in the three processes of this n
    loaded = None
    loaded = load()
    le(loaded)
for _ in range(k):  # each call frees the previous one's result (the last warm-up's for the first), as in the rounds
    if what == "load":
        loaded = None
        loaded = load()
    elif what == "le":
        le(loaded)
sys.stdout.flush()
os._exit(0)  # (no teardown: what is left alive differs between the processes, and freeing it is no call's work)
"""


#: Microbenchmark 1's phases are counted in instructions at the n whose rounds reached this share of
#: the loading limit (the others are far below it; each n costs three valgrind processes, ≈ 1 min).
COUNT_FROM = 0.7


def start_phase_instructions(pool, sizes, k: int, cache: str):
    """Microbenchmark 1's load and link + eval in instructions per call at each n, which the host's
    load does not change: a process doing ``k`` of them (after a warm-up at that n, the collector on
    as in the CPU rounds) minus one doing none after the same warm-up (``steady.per_operation``;
    ``bench_text_to_number.cold`` before each load, as in the rounds), submitted to ``pool``; returns
    the function that waits for them, prints them and returns them (``{}`` without valgrind)."""
    if not have_valgrind():
        def nothing():
            print("\n(instructions per phase: valgrind not found, not counted; the loading verdict uses the CPU rounds "
                  "alone)")
            return {}
        return nothing
    env = ttn._env(cache)
    subprocess.run([sys.executable, "-P", "-c", _PHASES, ROOT, "1", "none", "0"], cwd=ROOT, env=env,
                   check=True, capture_output=True)  # (writes the compiled modules)
    futures = {(what, n): pool.submit(instructions, [sys.executable, "-P", "-c", _PHASES, ROOT, str(n), what,
                                                     str(0 if what == "none" else k)], env, ROOT)
               for n in sizes for what in ("none", "load", "le")}

    def finish() -> dict:
        counts = {key: f.result() for key, f in futures.items()}
        out = {n: {what: per_operation(counts[what, n], counts["none", n], k) for what in ("load", "le")} for n in sizes}
        print(f"\n### Microbenchmark 1 in instructions per call (cachegrind, PYTHONHASHSEED=0; {k} calls − none; at "
              f"the n whose rounds reached {COUNT_FROM:g} × the loading limit)\n")
        print("| n | load (M) | link + eval (M) | load / (link + eval) |\n|---:|---:|---:|---:|")
        for n, r in out.items():
            r["share"] = r["load"] / r["le"]
            print(f"| {n} | {r['load'] / 1e6:.3f} | {r['le'] / 1e6:.3f} | {r['share']:.3f} |")
        return out
    return finish


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


# -- one-shot processes and the import ------------------------------------------------------------------

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


def run_import(reps: int) -> dict:
    """CPU of ``import langur.frontend, langur.operational`` beyond numpy's, ``reps`` processes
    (``bench_text_to_number.import_time``, one process each; ``rounds``: every process's)."""
    runs = []
    with tempfile.TemporaryDirectory() as cache:
        for _ in range(reps):
            host()
            runs.append(ttn.import_time(1, cache))
    numpy_s, ours = statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)
    print(f"\n## Import of the Monte Carlo path ({load()})\n\n`import langur.frontend, langur.operational`: "
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
    print(f"\nmeasured {again} more times (the partials at or above {AGAIN_FROM:g} s in the first run; {load()}): "
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
    ap.add_argument("--peer-worker", metavar="NAME", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    peers = {p: getattr(args, p) for p in PEERS if getattr(args, p)}
    sys.setrecursionlimit(10**6)  # (the peers' expression trees are deep)
    for path in peers.values():
        sys.path.insert(0, os.path.abspath(path))
    if args.peer_worker:
        peer_worker(args.peer_worker)
        return
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
                                                                     m["wall"].items()) + f"; {load()} at the end)")
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(m, fh, indent=1, default=str)

if __name__ == "__main__":
    main()
