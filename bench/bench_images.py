"""Benchmark of images (issue 12, §10.1 Fig. 13): both engines over a grid of parameters (not a test).

Run:  python3 bench/bench_images.py [--pixels 100] [--samples 50] [--wall]
      python3 bench/bench_images.py --fig14 [--repeat 5] [--no-reuse] [--wall]   (the ray tracer of §10.2)

Prints a markdown table: for each of the three shaders of ``examples/scene.lgr``, the time of the
Fig. 13 image (pixels × pixels, value and derivative in c, ``--samples`` per pixel)

* by the per-point Monte Carlo API in a Python loop (``estimate_value`` + ``estimate_derivative``
  per pixel: the baseline, measured in the same run on ``--baseline`` pixels and scaled);
* by the batch API (``langur.operational.batch.estimate_batch``: one pass over all pixels);
* by the exact engine over the grid (``langur.exact_batch``: the derivation and the lambdified
  closed form over every pixel).

and checks the numbers while it is at it: the batch equals the per-point API on the baseline's
pixels, the exact boundary summed over the pixels is the line integral 0.997·s on the line (1, 1/2,
1/4), and the Monte Carlo images lie within 5 standard errors of the exact ones.
CPU time of this process by default (the machine is shared); ``--wall`` for wall-clock time.

``--fig14``: Fig. 14 instead — ``examples/raytrace/scene.lgr`` with each shader module (depth,
thresholded Lambert), 40 × 40 pixels over [−0.3, 0.3]², 3 colour channels, value and D_t, 64
samples per pixel (what ``langur reproduce raytrace`` computes, without its numpy reference), by
the batch (the median of ``--repeat`` runs; the first channel alone too, since the zero sets' work
is reused by the other channels and by the second shader unless ``--no-reuse``) and, as the
baseline, by the per-point loop on ``--baseline`` pixels scaled; the batch is checked equal to
the per-point API on those pixels.
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

from langur.exact_batch import exact_batch
from langur.frontend import load
from langur.operational import estimate_derivative, estimate_value
from langur.operational.batch import estimate_batch

EX = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")
ON_LINE = {"shader": 1.0, "lin_shader": 0.5, "quad_shader": 0.25}


def fig14(clock, baseline: int, repeat: int = 1, reuse: bool = True) -> None:
    """The ray tracer's two shaders × 3 channels × 40² pixels, value and D_t (64 samples): the
    median of ``repeat`` runs, the zero-set work kept between runs forgotten before each run
    (``reuse``: kept between the channels and shaders of one run, as ``reproduce raytrace`` does)."""
    from langur.operational import batch as batch_module

    pixels, samples, h = 40, 64, 0.6 / 40
    xs = -0.3 + np.arange(pixels) * h
    px, py = (a.ravel() for a in np.meshgrid(xs, xs))
    memo = getattr(batch_module, "_GEOMETRY", None)  # absent in the engine before it was kept
    if not reuse and memo is not None:
        batch_module.GEOMETRY_BYTES = -1
    shaders = (("depth", "shader.lgr"), ("lambert", "lambert.lgr"))
    loaded = {name: load(os.path.join(EX, "raytrace", "scene.lgr"),
                         modules={"shader": os.path.join(EX, "raytrace", module)}) for name, module in shaders}
    for name, _ in shaders:  # compile outside the timings
        estimate_batch(loaded[name], {"px": px[:4], "py": py[:4], "h": h, "ch": 0.0, "t": 0.0}, direction={"t": 1.0},
                       samples=samples)
    times: dict[str, list[float]] = {name: [] for name, _ in shaders}
    firsts: dict[str, list[float]] = {name: [] for name, _ in shaders}
    out: dict[str, list] = {}
    for _ in range(repeat):
        if memo is not None:
            memo.clear()
        for name, _ in shaders:
            t, out[name] = clock(), []
            for ch in range(3):
                out[name].append(estimate_batch(loaded[name], {"px": px, "py": py, "h": h, "ch": float(ch), "t": 0.0},
                                                direction={"t": 1.0}, samples=samples, seed=0))
                if ch == 0:
                    firsts[name].append(clock() - t)
            times[name].append(clock() - t)
    rows = []
    for name, _ in shaders:
        idx = np.linspace(0, len(px) - 1, min(baseline, len(px))).astype(int)
        t, same = clock(), True
        for ch in range(3):
            for i in idx:
                at = {"px": float(px[i]), "py": float(py[i]), "h": h, "ch": float(ch), "t": 0.0}
                v = estimate_value(loaded[name], at, samples=samples, seed=0)
                d = estimate_derivative(loaded[name], at, {"t": 1.0}, samples=samples, seed=0)
                same &= v.value == out[name][ch].value[i] and d.value == out[name][ch].regular[i] + out[name][ch].boundary[i]
        loop = (clock() - t) * len(px) / len(idx)
        rows.append((name, loop, float(np.median(firsts[name])), float(np.median(times[name])), same))
    unit = "wall-clock" if clock is time.perf_counter else "CPU"
    how = ("this engine keeps no zero-set work" if memo is None else
           f"zero-set work {'reused' if reuse else 'not reused'} across channels and shaders")
    print(f"Fig. 14: {pixels}×{pixels} pixels × 3 channels, value and D_t, {samples} samples per pixel ({unit} "
          f"seconds; batch: median of {repeat}; {how})\n")
    print("| shader | per-point loop (baseline) | batch, first channel | batch, 3 channels | speed-up | batch = per-point |")
    print("|---|---|---|---|---|---|")
    for name, loop, first, batch, same in rows:
        print(f"| {name} | {loop:.2f} | {first:.3f} | {batch:.3f} | {loop / batch:.0f}× | {'yes' if same else 'NO'} |")
    loop, batch = sum(r[1] for r in rows), sum(r[3] for r in rows)
    total = float(np.median([sum(times[name][i] for name, _ in shaders) for i in range(repeat)]))
    print(f"| both | {loop:.2f} | | {total:.3f} | {loop / batch:.0f}× | |")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--pixels", type=int, default=100)
    ap.add_argument("--samples", type=int, default=50)
    ap.add_argument("--baseline", type=int, default=500, help="pixels timed by the per-point loop")
    ap.add_argument("--wall", action="store_true")
    ap.add_argument("--fig14", action="store_true", help="the ray tracer (Fig. 14) instead of Fig. 13")
    ap.add_argument("--repeat", type=int, default=1, help="--fig14: runs of the batch (the median is printed)")
    ap.add_argument("--no-reuse", action="store_true",
                    help="--fig14: do not keep a site's zero-set work between channels and shaders")
    args = ap.parse_args()
    clock = time.perf_counter if args.wall else time.process_time
    if args.fig14:
        fig14(clock, min(args.baseline, 40), args.repeat, not args.no_reuse)
        return
    n, h = args.pixels, 1.0 / args.pixels
    xs = np.arange(n) * h
    px, py = np.meshgrid(xs, xs)
    grid = {"px": px.ravel(), "py": py.ravel(), "c": -1.003, "h": h}
    rows, totals = [], {"loop": 0.0, "batch": 0.0, "exact": 0.0}
    for name, s_line in ON_LINE.items():
        loaded = load(os.path.join(EX, "scene.lgr"), modules={"shader": os.path.join(EX, f"{name}.lgr")})
        estimate_batch(loaded, {k: (v[:4] if np.ndim(v) else v) for k, v in grid.items()},
                       direction={"c": 1.0}, samples=args.samples)  # compile outside the timings
        t = clock()
        b = estimate_batch(loaded, grid, direction={"c": 1.0}, samples=args.samples, seed=0)
        batch = clock() - t
        idx = np.linspace(0, n * n - 1, min(args.baseline, n * n)).astype(int)
        t = clock()
        same = True
        for i in idx:
            at = {"px": float(px.ravel()[i]), "py": float(py.ravel()[i]), "c": -1.003, "h": h}
            v = estimate_value(loaded, at, samples=args.samples, seed=0)
            d = estimate_derivative(loaded, at, {"c": 1.0}, samples=args.samples, seed=0)
            same &= v.value == b.value[i] and d.value == b.regular[i] + b.boundary[i]
        loop = (clock() - t) * (n * n) / len(idx)
        t = clock()
        e = exact_batch(loaded.program, grid, {"c": 1.0})
        exact = clock() - t
        line = 0.997 * s_line
        sums = abs(float(np.sum(e.boundary)) * h * h - line) < 1e-9
        slack = np.where(b.stderr > 0, 5 * b.stderr, 14.0 / args.samples) + 1e-9
        agree = bool(np.all(np.abs(b.value - e.value) <= slack)
                     and np.all(np.abs(b.derivative - e.derivative) <= 5 * b.derivative_stderr + 1e-9))
        rows.append((name, loop, batch, exact, e.derivations, same, sums, agree))
        totals["loop"] += loop
        totals["batch"] += batch
        totals["exact"] += exact
    unit = "wall-clock" if args.wall else "CPU"
    print(f"Fig. 13: {n}×{n} pixels, value and D_c, {args.samples} samples per pixel ({unit} seconds)\n")
    print("| shader | per-point loop (baseline) | batch | speed-up | exact over the grid | derivations | "
          "batch = per-point | Σ boundary = line integral | MC within 5 SE of exact |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, loop, batch, exact, der, same, sums, agree in rows:
        print(f"| {name} | {loop:.2f} | {batch:.3f} | {loop / batch:.0f}× | {exact:.2f} | {der} | "
              f"{'yes' if same else 'NO'} | {'yes' if sums else 'NO'} | {'yes' if agree else 'NO'} |")
    print(f"| all three | {totals['loop']:.2f} | {totals['batch']:.3f} | {totals['loop'] / totals['batch']:.0f}× | "
          f"{totals['exact']:.2f} | | | | |")


if __name__ == "__main__":
    main()
