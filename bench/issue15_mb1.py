"""Issue 15's microbenchmark 1 (paper §10.3.2, Fig. 16) beside the peers, in rounds (not a test; run by
``bench/bench_issue15.py``, whose module doc says what is measured and how it is judged).

At every n of a round: Langur's ``load``, ``link`` and ``eval`` in this process
(``bench_text_to_number.mb1``, each phase the least of some calls), then each peer's text to number
once in a worker process of its own (:class:`PeerWorker`: the peers' expression trees stay out of this
process's heap); the calibration loop beside each (``steady.host``).  Where a round's
load / (link + eval) came near the limit, the two phases are also counted in instructions
(:func:`start_phase_instructions`); :func:`plot` draws the growth in n.

``python -P bench/issue15_mb1.py NAME DIR`` is a peer's worker process (NAME ``potto`` or ``teg``, DIR
its checkout): one n per line in, one JSON line out.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_text_to_number as ttn  # noqa: E402  (first: it sets numpy's BLAS threads before numpy loads)
from bench_peers import PROGRAMS, expected_mb1, peer_program  # noqa: E402
from issue15_targets import MB1_49_MS, MB1_100_MS, PEERS  # noqa: E402
from steady import CALIBRATIONS, have_valgrind, host, instructions, load_average, per_operation  # noqa: E402

ROOT = ttn.ROOT
CLOCK = ttn.CLOCK


def _least(f, reps: int, setup=None):
    """``bench_text_to_number._median`` giving the least CPU seconds of ``reps`` calls instead."""
    ts, out = ttn._times(f, reps, setup)
    return min(ts), out


def langur_mb1(n: int, reps: int) -> dict:
    """``bench_text_to_number.mb1`` (load, link, eval at ``n``), each phase the least of ``reps`` calls."""
    saved, ttn._median = ttn._median, _least
    try:
        return ttn.mb1(n, reps)
    finally:
        ttn._median = saved


class PeerWorker:
    """A process of its own running one peer's microbenchmark 1 on request (this module run as a
    script): the peers' expression trees stay out of this process's heap, so Langur's rounds can
    alternate with theirs (measured inside the worker, CPU seconds of that process)."""

    def __init__(self, name: str, path: str):
        self.proc = subprocess.Popen([sys.executable, "-P", os.path.abspath(__file__), name, path],
                                     stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True, cwd=ROOT)

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
    """The worker process's loop (module doc): one n per line in, one JSON line out (:func:`peer_mb1`, one run)."""
    for line in sys.stdin:
        print(json.dumps(peer_mb1(name, int(line), 1)), flush=True)


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
    print(f"\n## Microbenchmark 1 (Fig. 16): n jumps, 2n deltas, 10 samples — ms CPU ({load_average()})\n")
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
            print(f"(round {k + 1} of {rounds} measured, {load_average()})", flush=True)
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


if __name__ == "__main__":  # a peer's worker process (module doc)
    peer, checkout = sys.argv[1:3]
    sys.setrecursionlimit(10**6)  # (the peers' expression trees are deep)
    sys.path.insert(0, os.path.abspath(checkout))
    peer_worker(peer)
