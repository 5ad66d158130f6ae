"""Benchmarks of the operational (Monte Carlo) engine, langur/operational (not a test).

Run:  python3 bench/bench_operational.py [--quick]

Prints markdown tables:
 1. samples per second, vectorized engine against the naive per-sample pure-Python evaluator
    (langur.operational.naive) in the same run, for the value and the derivative of Fig. 1,
    the risk program (§2) and Fig. 9;
 2. the paper's first microbenchmark (§10.3.2): ∫_{-1}^{1} Σ_i [x + a_i ≥ 0]·f(a_i, x) dx with
    a_i = 1/i and f bound to a + x and to a − x (two defs), so n jumps give 2n deltas; compile
    (front end excluded) and evaluation time separated, derivative in direction (1, …, 1) with
    10 samples;
 3. the second microbenchmark: 90 jumps each shaded by a def of a swappable module `shader`,
    swapped n times (n distinct shader modules, so every swap really compiles a new module);
    cumulative compile and evaluation time, and the front end's load time separately.

Every program is written as .lgr text and loaded by the front end (langur.frontend); timings are
CPU time of this process by default (``--wall`` for wall-clock time; the machine is shared), the
median of several repetitions (compile: with the cache cleared before each repetition).
Zero-set samplers are compiled lazily, on a site's first use, so "compile" is linking the
separately compiled modules and "first evaluation" includes compiling the samplers; the cold total
(their sum) is the number to compare with the paper's compile + evaluate.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from functools import partial

from langur.frontend import load
from langur.operational import clear_cache, estimate_derivative, estimate_value, link
from langur.operational.naive import naive_derivative, naive_value

EX = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")  # the project's own


CLOCK = time.process_time  # CPU time of this process: the machine is shared (bench/history/2026-11-22.md#operational-engine-languroperational-benchmark-results)


def median_time(f, reps: int, clock=None) -> float:
    clock = clock or CLOCK
    ts = []
    for _ in range(reps):
        t0 = clock()
        f()
        ts.append(clock() - t0)
    return statistics.median(ts)


def params_of(L):
    return {k: float(v) for k, v in L.param_values().items()}


# -- 1. throughput -------------------------------------------------------------------------------

def throughput(quick: bool) -> None:
    print("## Samples per second: vectorized engine vs naive per-sample evaluator\n")
    print("| program | quantity | vectorized (samples/s) | naive (samples/s) | speed-up |")
    print("|---|---|---:|---:|---:|")
    nv, nn = (20000, 500) if quick else (200000, 2000)
    for name, wrt in (("fig1.lgr", "theta"), ("risk.lgr", "mu"), ("fig9.lgr", "theta")):
        L = load(os.path.join(EX, name))
        p = params_of(L)
        d = {wrt: 1.0}
        estimate_derivative(L, p, d, samples=100)  # compile once (cached)
        rows = [
            ("value", partial(estimate_value, L, p, samples=nv), partial(naive_value, L.program, p, samples=nn)),
            (f"derivative d/d{wrt}", partial(estimate_derivative, L, p, d, samples=nv),
             partial(naive_derivative, L.program, p, d, samples=nn)),
        ]
        for label, fast, slow in rows:
            tf = median_time(fast, 3)
            ts = median_time(slow, 1)
            # a derivative "sample" is one domain point plus, for each delta, one zero-set point
            print(f"| {name} | {label} | {nv / tf:,.0f} | {nn / ts:,.0f} | {(nv / tf) / (nn / ts):,.0f}× |")
    print()


# -- 2. number of jumps --------------------------------------------------------------------------

def balanced_sum(terms: list[str]) -> str:
    """t1 + … + tn parenthesized as a balanced tree (the parser limits nesting to 200 levels)."""
    if len(terms) == 1:
        return terms[0]
    mid = len(terms) // 2
    return f"({balanced_sum(terms[:mid])}) + ({balanced_sum(terms[mid:])})"


def jumps_text(n: int) -> str:
    ps = ", ".join(f"a{i} = {1 / i!r}" for i in range(1, n + 1))
    terms = balanced_sum([f"[x + a{i} >= 0] * fp(x, a{i}) + [x + a{i} >= 0] * fm(x, a{i})" for i in range(1, n + 1)])
    return f"from fs import fp, fm\nparam {ps}\nint ([-1, 1]) {terms} d(x)\n"


def jumps(quick: bool, tmp: str) -> None:
    with open(os.path.join(tmp, "fs.lgr"), "w") as f:
        f.write("def fp(x: var, a: param) = a + x\ndef fm(x: var, a: param) = a - x\n")
    print("## Microbenchmark 1 (§10.3.2): n jumps, 2n deltas, derivative with 10 samples\n")
    print("| jumps n | deltas | front end load (ms) | compile (ms) | first evaluation (ms) | "
          "**compile + evaluate, cold (ms)** | evaluate again (ms) | naive evaluate (ms) | value |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for n in ((1, 10, 49) if quick else (1, 5, 10, 25, 49, 75, 100)):
        path = os.path.join(tmp, f"jumps{n}.lgr")
        with open(path, "w") as f:
            f.write(jumps_text(n))
        t0 = CLOCK()
        L = load(path)
        t_load = CLOCK() - t0
        p = params_of(L)
        d = {k: 1.0 for k in p}
        comp, first = [], []
        for _ in range(9):  # cold: empty cache, link (compile), then the first evaluation
            clear_cache()
            t0 = CLOCK()
            link(L)
            t1 = CLOCK()
            r = estimate_derivative(L, p, d, samples=10)
            t2 = CLOCK()
            comp.append(t1 - t0)
            first.append(t2 - t1)
        cold = statistics.median(a + b for a, b in zip(comp, first))
        t_eval = median_time(partial(estimate_derivative, L, p, d, samples=10), 9)
        t_naive = median_time(partial(naive_derivative, L.program, p, d, samples=10), 1)
        print(f"| {n} | {2 * n} | {t_load * 1e3:.0f} | {statistics.median(comp) * 1e3:.2f} | "
              f"{statistics.median(first) * 1e3:.2f} | **{cold * 1e3:.2f}** | {t_eval * 1e3:.2f} | "
              f"{t_naive * 1e3:.1f} | {r.value:.3f} ± {r.stderr:.3f} |")
    print()


# -- 3. shader swaps -----------------------------------------------------------------------------

def swaps(quick: bool, tmp: str) -> None:
    n_jumps = 90
    ps = ", ".join(f"a{i} = {1 / i!r}" for i in range(1, n_jumps + 1))
    terms = balanced_sum([f"[x + a{i} >= 0] * shade(x, a{i})" for i in range(1, n_jumps + 1)])
    main = os.path.join(tmp, "scene.lgr")
    with open(main, "w") as f:
        f.write(f"from shader import shade\nparam {ps}\nint ([-1, 1]) {terms} d(x)\n")
    max_swaps = 10 if quick else 50
    shaders = []
    for k in range(max_swaps + 1):
        path = os.path.join(tmp, f"shader_{k}.lgr")
        with open(path, "w") as f:
            f.write(f"def shade(x: var, c: param) = 1 / (sqrt(2) * (x + c) + {k + 3})\n")
        shaders.append(path)
    print(f"## Microbenchmark 2 (§10.3.2): {n_jumps} jumps, n shader swaps (each a new module)\n")
    print("| swaps n | front end load, total (s) | compile, total (ms) | evaluate, total (ms) "
          "| compile + evaluate (ms) | per swap (ms) | defs compiled |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    checkpoints = {1, 5, 10, 20, 30, 40, 50} if not quick else {1, 5, 10}
    clear_cache()
    L = load(main, {"shader": shaders[0]})
    p = params_of(L)
    d = {k: 1.0 for k in p}
    link(L)
    estimate_derivative(L, p, d, samples=10)  # the scene and the first shader, compiled once
    from langur.operational import cache_stats, reset_cache_stats
    reset_cache_stats()
    t_load = t_comp = t_eval = 0.0
    for i in range(1, max_swaps + 1):
        t0 = CLOCK()
        L = load(main, {"shader": shaders[i]})
        t1 = CLOCK()
        link(L)
        t2 = CLOCK()
        estimate_derivative(L, p, d, samples=10)
        t3 = CLOCK()
        t_load += t1 - t0
        t_comp += t2 - t1
        t_eval += t3 - t2
        if i in checkpoints:
            total = t_comp + t_eval
            print(f"| {i} | {t_load:.2f} | {t_comp * 1e3:.1f} | {t_eval * 1e3:.1f} | {total * 1e3:.1f} | "
                  f"{total / i * 1e3:.1f} | {len(cache_stats()['compiled'])} |")
    print()


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="smaller sizes (a smoke run)")
    ap.add_argument("--wall", action="store_true", help="wall-clock time instead of this process's CPU time")
    args = ap.parse_args()
    global CLOCK
    if args.wall:
        CLOCK = time.perf_counter
    print(f"clock: {'wall (perf_counter)' if args.wall else 'CPU time of this process (process_time)'}; "
          f"load average at start: {', '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores\n")
    with tempfile.TemporaryDirectory() as tmp:
        throughput(args.quick)
        jumps(args.quick, tmp)
        swaps(args.quick, tmp)
    return 0


if __name__ == "__main__":
    sys.exit(main())
