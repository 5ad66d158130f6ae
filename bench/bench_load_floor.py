"""Microbenchmark 1's loading at small n: where a small program's load goes, and what "link + eval" it is
compared with (issue 15's "loading ≤ ½ (link + eval)"; bench/history/2026-11-29.md#load32; not a test).

Run:  python bench/bench_load_floor.py [--sizes 1,10,25,49,100] [--reps K] [--no-instructions]

* **Instructions per call** (valgrind's cachegrind, ``steady.instructions``: a process doing ``k`` calls
  minus one doing none, ``steady.per_operation``), for MB1 at n = 1 and 10 and for the smallest program
  with a domain, ``int ([-1, 1]) x d(x)``: the driver's lexer alone (its ``findall`` over the text); the
  driver's LALR loop with callbacks that build nothing; the whole parse (the builder's nodes too); the
  cold load (``bench_text_to_number.cold`` first, as in every measurement of issue 15); the load with
  its parsed module kept (the part after the parse); and link + eval as ``issue15_mb1``'s phases count
  it (``clear_cache(); link(); estimate_derivative(…, samples=10)`` on one loaded program).  The parse's
  share of link + eval is the floor of the loading ratio for any front end that keeps this parser.
* **CPU of a user's sequence** at each n (the least over ``--reps`` sequences, ``time.process_time``):
  a cold load, the link of that freshly loaded program, its first evaluation; then ``clear_cache()``,
  the link of the same program again, its evaluation, and one more evaluation.  Three "link + eval"s
  follow: the user's (fresh link + first evaluation); the instruction phases' (a relink of a program
  linked before + the evaluation after it); the CPU rounds' of ``bench_issue15`` (a relink + an
  evaluation repeated without linking again: ``bench_text_to_number.mb1`` times ``link`` and ``eval``
  each on its own, the least or median of repeated calls).  A fresh program's first link computes what
  the nodes keep once asked (their hashes, the memos of the link's walks): a relink finds it done.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ThreadPoolExecutor

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import bench_text_to_number as ttn  # noqa: E402  (first: it sets numpy's BLAS threads before numpy loads)
from bench_peers import langur_text  # noqa: E402
from steady import have_valgrind, instructions, per_operation  # noqa: E402

ROOT = ttn.ROOT
TINY = "int ([-1, 1]) x d(x)\n"
MODES = ("lexer", "loop", "parse", "load", "post", "le")

#: One process of the instruction counts: ``ROOT TEXT MODE K`` — K calls of MODE after a warm-up.
_COUNT = r"""
import os, sys
sys.path.insert(0, os.path.join(sys.argv[1], "bench"))
import bench_text_to_number as b
from langur import frontend
from langur.syntax import lalr
from langur.syntax.parser import parse_bytes
from langur.operational import clear_cache, estimate_derivative, link
text, mode, k = sys.argv[2], sys.argv[3], int(sys.argv[4])
data = text.encode()
tables = lalr.load()
findall = lalr.glued(tables["scanner"]).findall
nothing = lalr.driver(tables, [lambda children: None] * len(tables["rules"]))
def le(loaded):
    clear_cache()
    link(loaded)
    estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=10, seed=0)
for _ in range(2):  # the warm-up, the same in every process
    b.cold()
    loaded = frontend.load_text(text)
    if loaded.program is not None and "a" in loaded.params:
        le(loaded)
parsed = frontend.CACHE.parsed[("<string>", data)]
out = None
for _ in range(k):
    if mode == "lexer":
        out = findall(text, 0, len(text))
    elif mode == "loop":
        out = nothing(text, "start")
    elif mode == "parse":
        out = parse_bytes(data, "<string>")
    elif mode == "load":
        out = None
        b.cold()
        out = frontend.load_text(text)
    elif mode == "post":
        out = None
        b.cold()
        frontend.CACHE.parsed[("<string>", data)] = parsed
        out = frontend.load_text(text)
    elif mode == "le":
        le(loaded)
sys.stdout.flush()
os._exit(0)
"""


def count_instructions(programs: dict[str, str], k: int) -> dict:
    """Instructions per call of each mode (:data:`MODES`) for each program (name → text); link + eval
    only for MB1's (the programs with the parameter ``a``)."""
    env = ttn._env(None)  # (every module compiled at start, in both processes: it cancels out)

    def run(text, mode, calls):
        return instructions([sys.executable, "-P", "-c", _COUNT, ROOT, text, mode, str(calls)], env, ROOT)

    jobs = {}
    with ThreadPoolExecutor(max_workers=2) as pool:
        for name, text in programs.items():
            jobs[name, "none"] = pool.submit(run, text, "none", 0)
            for mode in MODES:
                if mode == "le" and name == "tiny":
                    continue
                jobs[name, mode] = pool.submit(run, text, mode, k)
        counts = {key: f.result() for key, f in jobs.items()}
    return {name: {mode: per_operation(counts[name, mode], counts[name, "none"], k)
                   for mode in MODES if (name, mode) in counts} for name in programs}


def print_instructions(out: dict) -> None:
    print("\n## Instructions per call (cachegrind, PYTHONHASHSEED=0; k calls − none)\n")
    print("| program | lexer | LALR loop, no nodes | parse | load (cold) | after the parse | link + eval "
          "| parse ÷ (link + eval) | load ÷ (link + eval) |\n|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for name, r in out.items():
        le = r.get("le")
        ratios = (f"{r['parse'] / le:.3f} | {r['load'] / le:.3f}" if le else "— | —")
        print(f"| {name} | {r['lexer'] / 1e3:.0f} k | {r['loop'] / 1e3:.0f} k | {r['parse'] / 1e6:.3f} M | "
              f"{r['load'] / 1e6:.3f} M | {r['post'] / 1e6:.3f} M | "
              f"{(f'{le / 1e6:.3f} M' if le else '—')} | {ratios} |")


def user_sequence(n: int, reps: int) -> dict:
    """The least CPU seconds of each step of :func:`_sequence` over ``reps`` sequences (after 3 more)."""
    from langur import frontend
    from langur.operational import clear_cache, estimate_derivative, link

    text = langur_text(n)
    clock = time.process_time
    steps = ("load", "link", "eval", "relink", "eval_relinked", "eval_again")
    best = dict.fromkeys(steps, float("inf"))

    def evaluate(loaded):
        return estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=10, seed=0)

    for i in range(reps + 3):
        loaded = None
        ttn.cold()
        clear_cache()
        t = [clock()]
        loaded = frontend.load_text(text)
        t.append(clock())
        link(loaded)
        t.append(clock())
        evaluate(loaded)
        t.append(clock())
        clear_cache()
        link(loaded)
        t.append(clock())
        evaluate(loaded)
        t.append(clock())
        evaluate(loaded)
        t.append(clock())
        if i >= 3:
            for s, a, b in zip(steps, t, t[1:]):
                best[s] = min(best[s], b - a)
    return best


def print_sequences(rows: dict) -> None:
    print("\n## A user's sequence, CPU ms (the least of each step over the sequences)\n")
    print("| n | load | link (fresh) | first eval | relink | eval after it | eval again | load ÷ (fresh link + "
          "first eval) | load ÷ (relink + eval after it) | load ÷ (relink + eval again) |")
    print("|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|")
    for n, b in rows.items():
        user = b["load"] / (b["link"] + b["eval"])
        phases = b["load"] / (b["relink"] + b["eval_relinked"])
        rounds = b["load"] / (b["relink"] + b["eval_again"])
        print(f"| {n} | {1e3 * b['load']:.3f} | {1e3 * b['link']:.3f} | {1e3 * b['eval']:.3f} | "
              f"{1e3 * b['relink']:.3f} | {1e3 * b['eval_relinked']:.3f} | {1e3 * b['eval_again']:.3f} | "
              f"{user:.3f} | {phases:.3f} | {rounds:.3f} |")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sizes", default="1,10,25,49,100")
    ap.add_argument("--reps", type=int, default=200)
    ap.add_argument("--calls", type=int, default=10, help="calls per counted process (instructions)")
    ap.add_argument("--no-instructions", action="store_true")
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.1f}")
    rows = {n: user_sequence(n, args.reps) for n in map(int, args.sizes.split(","))}
    print_sequences(rows)
    if args.no_instructions:
        return
    if not have_valgrind():
        print("\n(valgrind not found: no instruction counts)")
        return
    print_instructions(count_instructions({"MB1 n = 1": langur_text(1), "MB1 n = 10": langur_text(10), "tiny": TINY},
                                          args.calls))


if __name__ == "__main__":
    main()
