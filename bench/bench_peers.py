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
  authors' microbenchmarks do.  Times: compile (the derivative built: Langur's text to compiled
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


# -- Potto (its public API, as its authors' microbenchmarks use it) ---------------------------------

def potto_mb1(n: int, samples: int = 10):
    from potto import (App, BoundedLebesgue, Const, Function, Heaviside, Int, Shift, Sym, TegVar, Var, VarVal, deriv,
                       evaluate)

    x, f = TegVar("x"), Var("f")
    measure = BoundedLebesgue(-1, 1, x)

    def build():
        big, ctx, vals = Const(0), {}, {}
        for i in range(10, 10 + n):
            a = Var(f"a{i}")
            vals[a.name] = 1 / i
            big += Heaviside(Shift((a,), (x,), Const(1))) * App(f, (a, x))
            da = Sym(f"da{i}")
            ctx[a.name] = da
            vals[da] = 1
        x0, a0 = TegVar("x0"), Var("a0")
        ctx[x0.name], ctx[a0.name] = Sym("x0"), Sym("a0")
        s1, s2 = Function((a0, x0), a0 + x0), Function((a0, x0), a0 - x0)
        integral = Function((f,), Int(big, measure))
        di = deriv(integral, ctx)
        return App(di, (s1, deriv(s1, ctx))) + App(di, (s2, deriv(s2, ctx))), VarVal(vals)

    c, (expr, vals) = median(build, 3)
    e, value = median(lambda: evaluate(expr, vals, samples), 3)
    return c, e, float(value)


# -- Teg --------------------------------------------------------------------------------------------

def teg_mb1(n: int, samples: int = 10):
    from teg import Const, IfElse, Teg, TegVar, Var
    from teg.derivs.fwd_deriv import fwd_deriv
    from teg.eval import evaluate
    from teg.passes.reduce import reduce_to_base

    x = TegVar("x")

    def build():
        ctx, total = [], Const(0)
        for shade in (lambda a, x_: a + x_, lambda a, x_: a - x_):
            big = Const(0)
            for i in range(10, 10 + n):
                a = Var(f"a{i}", float(1 / i))
                big += IfElse(x + a > 0, 1, 0) * shade(a, x)
                ctx.append((a, 1))
            total += Teg(Const(-1), Const(1), big, x)
        return reduce_to_base(fwd_deriv(total, ctx), True)

    c, expr = median(build, 3)
    e, value = median(lambda: evaluate(expr, backend="numpy", num_samples=samples), 3)
    return c, e, float(value)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--potto", metavar="DIR", help="a checkout of github.com/divicomp/potto")
    ap.add_argument("--teg", metavar="DIR", help="a checkout of github.com/ChezJrk/Teg")
    ap.add_argument("--quick", action="store_true", help="n = 1, 10 only")
    args = ap.parse_args()
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
            row += [f"{c * 1e3:.1f} ms", f"{e * 1e3:.1f} ms", f"{d:.6g}"]
        ratios = [f"{totals[s] / totals['langur']:.0f}×" for s in systems if s != "langur"]
        print("| " + " | ".join(row + ratios) + " |")
    # At 10 samples the regular part (∫ of the aᵢ's own derivative) is a rough estimate in every
    # system; the derivative is checked with many samples instead.
    many = 100_000
    print(f"\nThe same derivative with {many:,} samples (each system's own sampling) against the hand formula:\n")
    print("| n | expected D | " + " | ".join(f"{s} D" for s in systems) + " |")
    print("|" + "---|" * (2 + len(systems)))
    for n in (1, 10):
        print(f"| {n} | {expected_mb1(n):.6g} | " + " | ".join(f"{fn(n, many)[2]:.6g}" for fn in systems.values()) + " |")


if __name__ == "__main__":
    with tempfile.TemporaryDirectory():
        main()
