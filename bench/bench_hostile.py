"""Front-end cost on hostile files (issue "Safe on hostile input", SECURITY.md): prints a table.

The doubling file (``f_i = f_{i-1}(x, a) + f_{i-1}(x, a)``, n definitions: 2ⁿ terms written out)
against its baseline in the same run, the same doubling through ``let`` (``b_i = b_{i-1} + b_{i-1}``,
which the language shares by construction), for ``langur check`` and the exact ``eval``; and a
10,000-term sum.  Each row is the wall time of a fresh ``python -m langur`` process (start-up
included, as a user or a CI job meets it), the median of ``--repeat`` runs; the value printed by
``eval`` is checked against the hand formula 2^(n-1)·a (∫₀¹ 2ⁿ·x·a dx) at a = 1/2.

    python3 bench/bench_hostile.py [--repeat 3] [--sizes 10,20,30,40]

With ``--distinct 1000,3000,10000`` it prints instead, for sums of that many *distinct* conditions
(``[x - k/n >= 0] * x``, fixed; ``[x - a * k/n >= 0] * x``, moving with a parameter;
``[x >= k/n] / (x + 1)``, a weight with a pole off the domain), the CPU seconds and the maximum
resident set of one ``langur check`` process each (``os.wait4``'s resource usage: CPU time, so that
the numbers do not depend much on the machine's load) and the codes it reports.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def doubling(n: int) -> str:
    lines = ["def f0(x: var, a: param) = x * a"]
    lines += [f"def f{i}(x: var, a: param) = f{i - 1}(x, a) + f{i - 1}(x, a)" for i in range(1, n + 1)]
    return "\n".join(lines + ["param a = 0.5", f"int ([0, 1]) f{n}(x, a) d(x)"]) + "\n"


def let_doubling(n: int) -> str:
    lets = "let b0 = a in " + "".join(f"let b{i} = b{i - 1} + b{i - 1} in " for i in range(1, n + 1))
    return f"param a = 0.5\nint ([0, 1]) {lets}x * b{n} d(x)\n"


def long_sum(n: int) -> str:
    return "param a = 0.5\nint ([0, 1]) " + " + ".join(f"{i % 9 + 1} * x^{i % 4}" for i in range(n)) + \
        " * [x <= a] d(x)\n"


DISTINCT = {
    "fixed": lambda n: "int ([0, 1]) " + " + ".join(f"[x - {k}/{n} >= 0] * x" for k in range(n)) + " d(x)\n",
    "moving": lambda n: "param a = 0.25\nint ([0, 1]) " + " + ".join(f"[x - a * {k}/{n} >= 0] * x"
                                                                   for k in range(n)) + " d(x)\n",
    "pole": lambda n: "int ([0, 1]) " + " + ".join(f"[x >= {k}/{n}] / (x + 1)" for k in range(n)) + " d(x)\n",
}


def cpu_and_memory(path: Path, *args: str) -> tuple[float, float, str]:
    """CPU seconds (user + system) and maximum resident set (MB) of one ``langur`` process, and its
    output."""
    with tempfile.TemporaryFile() as out:
        p = subprocess.Popen([sys.executable, "-m", "langur", *args, str(path)], stdout=out, stderr=out)
        _, status, usage = os.wait4(p.pid, 0)
        p.returncode = os.waitstatus_to_exitcode(status)
        out.seek(0)
        text = out.read().decode("utf-8", errors="replace")
    return usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024, text


def distinct(sizes: list[int]) -> None:
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; "
          "one `langur check --timeout 3000` process per row")
    print()
    print("| program | terms | CPU s | max RSS MB | reported |")
    print("|---|---:|---:|---:|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for kind, make in DISTINCT.items():
            for n in sizes:
                path = Path(tmp) / f"{kind}{n}.lgr"
                path.write_text(make(n), encoding="utf-8")
                cpu, rss, text = cpu_and_memory(path, "check", "--timeout", "3000")
                codes = sorted(w.split()[1] for w in text.split(": ")[1:] if w.split()[:1] in (["warning"], ["error"]))
                said = ", ".join(f"{c} ×{codes.count(c)}" for c in dict.fromkeys(codes)) or "nothing"
                print(f"| {kind} | {n:,} | {cpu:.1f} | {rss:.0f} | {said} |", flush=True)


def run(path: Path, *args: str) -> tuple[float, str]:
    start = time.perf_counter()
    r = subprocess.run([sys.executable, "-m", "langur", *args, str(path)], capture_output=True, text=True,
                       timeout=600)
    elapsed = time.perf_counter() - start
    if r.returncode != 0:
        raise SystemExit(f"langur {' '.join(args)} {path}: exit {r.returncode}\n{r.stdout}{r.stderr}")
    return elapsed, r.stdout


def median_time(path: Path, repeat: int, *args: str) -> tuple[float, str]:
    times, out = [], ""
    for _ in range(repeat):
        t, out = run(path, *args)
        times.append(t)
    return statistics.median(times), out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--sizes", default="10,20,30,40")
    ap.add_argument("--distinct", default=None, help="sizes of the sums of distinct conditions (see above)")
    args = ap.parse_args()
    if args.distinct:
        distinct([int(s) for s in args.distinct.split(",")])
        return
    sizes = [int(s) for s in args.sizes.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        empty = tmp / "empty.lgr"
        empty.write_text("param a = 0.5\nint ([0, 1]) x * a d(x)\n", encoding="utf-8")
        startup, _ = median_time(empty, args.repeat, "check")
        print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores; median of {args.repeat} runs; "
              f"a one-line program's `check` (start-up) takes {startup:.2f} s")
        print()
        print("| n | written-out terms | check, doubling defs | check, doubling lets (baseline) | "
              "eval --engine exact, defs | value (expected 2^(n-1)·a at a = 1/2) |")
        print("|---|---|---|---|---|---|")
        for n in sizes:
            f, g = tmp / f"defs{n}.lgr", tmp / f"lets{n}.lgr"
            f.write_text(doubling(n), encoding="utf-8")
            g.write_text(let_doubling(n), encoding="utf-8")
            t_defs, _ = median_time(f, args.repeat, "check")
            t_lets, _ = median_time(g, args.repeat, "check")
            t_eval, out = median_time(f, args.repeat, "eval", "--engine", "exact")
            value = out.split("exact :")[1].split()[0]
            expected = 2.0 ** (n - 1) * 0.5
            ok = "✓" if abs(float(value) - expected) <= 1e-9 * expected else "✗"
            print(f"| {n} | 2^{n} ≈ {2.0 ** n:.2g} | {t_defs:.2f} s | {t_lets:.2f} s | {t_eval:.2f} s | "
                  f"{value} {ok} |")
        print()
        s = tmp / "sum.lgr"
        s.write_text(long_sum(10_000), encoding="utf-8")
        for command in (["check"], ["eval", "--samples", "1000"], ["deriv", "--wrt", "a", "--samples", "1000"]):
            t, _ = median_time(s, 1, *command)
            print(f"10,000-term sum, `langur {' '.join(command)}`: {t:.2f} s")


if __name__ == "__main__":
    main()
