"""The paper's microbenchmarks (§10.3, Fig. 16 and 17) side by side with Potto and Teg (not a test).

Run:  python3 bench/bench_peers.py [--potto DIR] [--teg DIR] [--quick] [--plot OUT.png]

DIR is a checkout of the peer's public repository (divicomp/potto, ChezJrk/Teg) — its source is
imported from there, never shipped with this project; without it, only Langur's numbers are
printed, and the script says so.  Every system runs in this one process, interleaved size by
size, CPU time (the machine is shared), the median of a few repetitions.

* **Microbenchmark 1** (Fig. 16): ∫₋₁¹ Σᵢ [x + aᵢ ≥ 0]·(aᵢ + x) + Σᵢ [x + aᵢ ≥ 0]·(aᵢ − x) dx with
  aᵢ = 1/i for i = 10 … 9 + n: n jumps, 2n deltas, the derivative in the direction where every aᵢ
  moves by 1, 10 samples.  In Langur the loop is the paper's finite loop (§9), unrolled by the
  front end, ``sum i in 10..9+n: …``, with the aᵢ = 1/i + (a − 1) moved by one parameter a at a = 1
  (daᵢ/da = 1, the same deltas).  The peers build the same sum through their APIs, as their
  authors' microbenchmarks do: the programs ``bench/peer_programs/potto_mb1.py`` and ``teg_mb1.py``
  (they import the peer; none of its code is here).  Times: compile (the derivative built: Langur's text to compiled
  program, the peers' symbolic derivative) and evaluate (10 samples).
* **Microbenchmark 2** (Fig. 17): 90 jumps (i = 10 … 99) shaded by one shader, swapped n times:
  Langur loads the scene and links each swapped shader module (separate compilation, §9); the
  peers rebuild as their microbenchmarks do.

Each system's derivative is checked against the hand formula: for a jump at x = −aᵢ the delta
contributes the shader at x = −aᵢ (once per sum) and the regular part ∫ ∂ₐ(a ± x) = the length
of [−aᵢ, 1]; summed: Σᵢ [(aᵢ − aᵢ) + (aᵢ + aᵢ)] + Σᵢ 2·(1 + aᵢ) over the two sums.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import statistics
import sys
import tempfile
import time

CLOCK = time.process_time


def median(f, reps: int) -> tuple[float, object]:
    out, ts = None, []
    for _ in range(reps):
        t0 = CLOCK()
        out = f()
        ts.append(CLOCK() - t0)
    return statistics.median(ts), out


def expected_mb1(n: int) -> float:
    # d/da ∫₋₁¹ [x + a ≥ 0] (a + x) dx = (a + x)|_{x=−a} + ∫_{−a}^1 1 dx = 0 + 1 + a;
    # d/da ∫₋₁¹ [x + a ≥ 0] (a − x) dx = (a − x)|_{x=−a} + ∫_{−a}^1 1 dx = 2a + 1 + a
    return sum((1 + 1 / i) + (2 / i + 1 + 1 / i) for i in range(10, 10 + n))


# -- Langur -----------------------------------------------------------------------------------------

def langur_text(n: int) -> str:
    return (f"param a = 1\n"
            f"int ([-1, 1]) (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x))"
            f" + (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")


def langur_mb1(n: int, samples: int = 10):
    from langur.frontend import load_text
    from langur.operational import clear_cache, estimate_derivative, link

    def compile_():
        clear_cache()
        loaded = load_text(langur_text(n))
        link(loaded)
        return loaded

    c, loaded = median(compile_, 3)
    e, est = median(lambda: estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=samples, seed=0), 3)
    return c, e, est.value


# -- the peers: the programs a user of each writes (bench/peer_programs/), timed here ------------------

PROGRAMS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "peer_programs")


def peer_program(name: str):
    """``bench/peer_programs/NAME.py``, a program written against a peer's public API, as a module
    (imported once; it imports its peer, so the peer's checkout must be on ``sys.path`` first)."""
    key = f"_peer_program_{name}"
    if key not in sys.modules:
        spec = importlib.util.spec_from_file_location(key, os.path.join(PROGRAMS, f"{name}.py"))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[key] = module
    return sys.modules[key]


def peer_mb1(name: str, n: int, samples: int = 10):
    """Compile (the expression and its symbolic derivative built) and evaluate of a peer's
    microbenchmark 1 (``peer_programs/NAME_mb1.py``), CPU medians of 3, and the derivative."""
    prog = peer_program(f"{name}_mb1")
    c, (expr, vals) = median(lambda: prog.program(n), 3)
    e, value = median(lambda: prog.number(expr, vals, samples), 3)
    return c, e, value


def potto_mb1(n: int, samples: int = 10):
    return peer_mb1("potto", n, samples)


def teg_mb1(n: int, samples: int = 10):
    return peer_mb1("teg", n, samples)


# -- microbenchmark 2: 90 jumps, n shader swaps ----------------------------------------------------

SCENE = ("from shader import shade\nparam a = 1\n"
         "int ([-1, 1]) sum i in 10..99: [x + 1/i + a - 1 >= 0] * shade(x, 1/i + a - 1) d(x)\n")


def langur_mb2(n: int, folder: str):
    """The scene loaded and linked with n + 1 shader modules in turn (n swaps to a + x, then
    a − x, each module a new file: every swap compiles one module), each swap's derivative
    evaluated with 10 samples; the front end (reading the scene again) is counted."""
    from langur.frontend import load
    from langur.operational import clear_cache, estimate_derivative

    scene = os.path.join(folder, "scene.lgr")
    with open(scene, "w") as fh:
        fh.write(SCENE)
    paths = []
    for k in range(n + 1):
        path = os.path.join(folder, f"shader_{n}_{k}.lgr")
        with open(path, "w") as fh:  # a constant term k·0 makes each module's text (and cache key) new
            op = "+" if k < n else "-"
            fh.write(f"def shade(x: var, a: param) = a {op} x + {k} * 0\n")
        paths.append(path)

    def run():
        clear_cache()
        total = 0.0
        for path in paths:
            loaded = load(scene, modules={"shader": path})
            total += estimate_derivative(loaded, {"a": 1.0}, {"a": 1.0}, samples=10, seed=0).value
        return total

    t, _ = median(run, 1)
    return t


def potto_mb2(n: int):
    from potto import Function, VarVal

    prog = peer_program("potto_mb1")

    def run():
        di, (a0, x0), ctx, vals = prog.integral(10, 99)  # compiled once
        total = 0.0
        for k in range(n + 1):  # each swap: the shader's derivative, applied to the compiled integral
            s = Function((a0, x0), a0 + x0) if k < n else Function((a0, x0), a0 - x0)
            total += prog.number(prog.applied(di, s, ctx), VarVal(vals), 10)
        return total

    t, _ = median(run, 1)
    return t


def teg_mb2(n: int):
    prog = peer_program("teg_mb1")

    def run():
        total = 0.0
        for k in range(n + 1):  # no separate compilation: each swap rebuilds and re-derives the integral
            expr, ctx = prog.integral(10, 99, prog.plus if k < n else prog.minus)
            total += prog.number(prog.derivative(expr, ctx))
        return total

    t, _ = median(run, 1)
    return t


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--potto", metavar="DIR", help="a checkout of github.com/divicomp/potto")
    ap.add_argument("--teg", metavar="DIR", help="a checkout of github.com/ChezJrk/Teg")
    ap.add_argument("--quick", action="store_true", help="n = 1, 10 only")
    ap.add_argument("--plot", metavar="OUT.png", help="also draw both microbenchmarks' times against n (matplotlib)")
    args = ap.parse_args()
    curves: dict[str, dict[str, list]] = {"mb1": {}, "mb2": {}}
    sys.setrecursionlimit(10**6)
    systems = {"langur": langur_mb1}
    for name, path, fn in (("potto", args.potto, potto_mb1), ("teg", args.teg, teg_mb1)):
        if path:
            sys.path.insert(0, os.path.abspath(path))
            systems[name] = fn
        else:
            print(f"({name}: not given — pass --{name} DIR, a checkout of its public repository, to compare)")
    sizes = (1, 10) if args.quick else (1, 10, 25, 49, 100)
    print("\nMicrobenchmark 1 (Fig. 16): n jumps, 2n deltas, 10 samples; CPU seconds, median of 3\n")
    head = "| n | expected D | " + " | ".join(f"{s} compile | {s} evaluate | {s} D" for s in systems)
    print(head + " |" + "".join(f" {s}/langur |" for s in systems if s != "langur"))
    print("|" + "---|" * (2 + 3 * len(systems) + len(systems) - 1))
    for n in sizes:
        row = [str(n), f"{expected_mb1(n):.6g}"]
        totals = {}
        for s, fn in systems.items():  # interleaved: each size runs every system before the next size
            c, e, d = fn(n)
            totals[s] = c + e
            curves["mb1"].setdefault(s, []).append((n, c + e))
            row += [f"{c * 1e3:.1f} ms", f"{e * 1e3:.1f} ms", f"{d:.6g}"]
        ratios = [f"{totals[s] / totals['langur']:.0f}×" for s in systems if s != "langur"]
        print("| " + " | ".join(row + ratios) + " |")
    print("\nMicrobenchmark 2 (Fig. 17): 90 jumps, n shader swaps (compile and evaluate each), 10 samples; CPU "
          "seconds in all, one run\n")
    mb2 = {"langur": lambda n: langur_mb2(n, folder), "potto": potto_mb2, "teg": teg_mb2}
    print("| swaps | " + " | ".join(systems) + " |" + "".join(f" {s}/langur |" for s in systems if s != "langur"))
    print("|" + "---|" * (1 + 2 * len(systems) - 1))
    with tempfile.TemporaryDirectory() as folder:
        for n in ((1, 5) if args.quick else (1, 5, 10, 25)):
            times = {s: mb2[s](n) for s in systems}
            for s_, t_ in times.items():
                curves["mb2"].setdefault(s_, []).append((n, t_))
            print(f"| {n} | " + " | ".join(f"{times[s]:.3f} s" for s in systems) + " |"
                  + "".join(f" {times[s] / times['langur']:.0f}× |" for s in systems if s != "langur"))
    if args.plot:
        plot(curves, args.plot)
        print(f"\n{args.plot}")
    # At 10 samples the regular part (∫ of the aᵢ's own derivative) is a rough estimate in every
    # system; the derivative is checked with many samples instead, at n = 1 (Potto evaluates
    # sample by sample in Python: 10⁵ samples at n = 10 would take it over half an hour).
    many = 100_000
    print(f"\nThe same derivative with {many:,} samples (each system's own sampling) against the hand formula:\n")
    print("| n | expected D | " + " | ".join(f"{s} D" for s in systems) + " |")
    print("|" + "---|" * (2 + len(systems)))
    for n in (1,):
        print(f"| {n} | {expected_mb1(n):.6g} | " + " | ".join(f"{fn(n, many)[2]:.6g}" for fn in systems.values()) + " |")


def plot(curves: dict, out: str) -> None:
    """Fig. 16 and 17 as the paper draws them: time against n, one line per system, log scale."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    titles = {"mb1": "Fig. 16: n jumps (2n deltas), compile + evaluate",
              "mb2": "Fig. 17: 90 jumps, n shader swaps, in all"}
    for ax, (key, systems) in zip(axes, curves.items()):
        for name, pts in systems.items():
            ns, ts = zip(*pts)
            ax.plot(ns, ts, marker="o", label=name)
        ax.set_yscale("log")
        ax.set_xlabel("n")
        ax.set_ylabel("CPU seconds")
        ax.set_title(titles[key], fontsize=10)
        ax.legend()
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
