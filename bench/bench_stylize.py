"""The image stylization kernel of §10.3.1 (Fig. 15) beside Teg (and Potto) — not a test.

Run:  python3 bench/bench_stylize.py [--teg DIR] [--potto DIR] [--pixels 16] [--samples 50]
                                     [--plot OUT.png]

The kernel (``examples/stylize/linear.lgr``, ``quadratic.lgr``; Teg's triangulation benchmark,
Bangaru et al. 2021, Figs. 5–6) is one triangle against one pixel: the squared error between
the triangle's shaded colour (linear: barycentric blend of 3 vertex colours; quadratic: the
6-colour quadratic finite element) and the pixel's target colour, integrated over the part of the
pixel the triangle covers.  Stylization needs its gradient in the vertices (whose edges are the
parametric discontinuities: the deltas) and in the shader's colours; the paper's Fig. 15 compares
the derivative's compile time, evaluation time, total and AST size, for both shaders.

Here the image is ``--pixels``² pixels over [0, 1]² (target colour (x, y, 0.5) at the pixel's
centre), one triangle, and the gradient is the 6 vertex coordinates plus every shader colour
(15 directions for the linear shader, 24 for the quadratic), ``--samples`` per pixel.

* **Langur**: compile = the ``.lgr`` text to a linked program (front end included); evaluate =
  ``estimate_batch`` over all pixels, once per direction (forward mode).  Baseline in the same
  run: the per-point API in a Python loop (``estimate_derivative`` per pixel and direction) on a
  few pixels, scaled.  AST size: the core term's distinct nodes (it is a DAG: lets and vectors
  share subterms) and its size written out as a tree.
* **Teg** (its public repository's source, given by ``--teg``; nothing of it ships here): the
  same integrand built through its API (as its own triangulation benchmark builds it), its
  reverse-mode derivative in the same parameters, ``reduce_to_base(simplify(…))`` = compile;
  evaluate = its numpy backend (the paper's choice), pixel by pixel, with the pixel bound by
  ``bind_variable``, on ``--teg-pixels`` pixels of the middle row, scaled to the image.  That
  backend integrates each dimension by the trapezoid rule on ``num_samples`` points, so it is
  given round(√samples) per axis (7 × 7 = 49 points per pixel for 50).  AST size: nodes of the
  compiled derivative written out.
* **Potto**: not run (yet).  Its conditions are Heavisides of diffeomorphisms from its library
  (``potto.libs.diffeos``); an edge function whose coefficients are expressions of two moving
  vertices would need its ``Affine`` with non-variable coefficients, or a new diffeomorphism class
  written for it — not attempted, and not known to work.  Potto also evaluates sample by sample
  in Python (see bench_peers.py), so a 256-pixel, 15-direction gradient would take hours.

CPU time of this one process (the machine is shared), every system interleaved per shader.
The numbers are checked while at it: the batch equals the per-point API on the baseline's pixels
bit for bit, and Langur's and Teg's gradients summed over the image agree within their errors.
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

CLOCK = time.process_time
EX = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples", "stylize")
VERTS = ("ax", "ay", "bx", "by", "cx", "cy")
COLOURS = {"linear": tuple(k + ch for k in "abc" for ch in "rgb"),
           "quadratic": tuple(k + ch for k in "abcmnq" for ch in "rgb")}


def image(pixels: int) -> dict:
    h = 1.0 / pixels
    xs = np.arange(pixels) * h
    px, py = np.meshgrid(xs, xs)
    px, py = px.ravel(), py.ravel()
    return {"px": px, "py": py, "h": h, "pr": px + h / 2, "pg": py + h / 2, "pb": np.full(px.shape, 0.5)}


# -- Langur -----------------------------------------------------------------------------------------

def core_size(term) -> tuple[int, int]:
    """(distinct nodes, nodes written out as a tree) of a core term."""
    import dataclasses

    from langur.core import Term

    tree: dict[int, int] = {}

    def kids(t):
        for f in dataclasses.fields(t):
            v = getattr(t, f.name)
            for w in (v if isinstance(v, tuple) else (v,)):
                if isinstance(w, Term):
                    yield w

    def go(t):
        if id(t) not in tree:
            tree[id(t)] = 1 + sum(go(c) for c in kids(t))
        return tree[id(t)]

    return len(tree) if go(term) else 0, tree[id(term)]


def langur(shader: str, grid: dict, samples: int, baseline: int):
    from langur.frontend import load
    from langur.operational import clear_cache, estimate_derivative, link
    from langur.operational.batch import estimate_batch
    from langur.syntax.diffeo import _complete_cached

    path = os.path.join(EX, f"{shader}.lgr")
    _complete_cached.cache_clear()  # cold: no condition completed before (the front end's one memo)
    t0 = CLOCK()
    clear_cache()
    loaded = load(path)
    link(loaded)
    compile_ = CLOCK() - t0
    dirs = VERTS + COLOURS[shader]
    t0 = CLOCK()
    grads = {d: estimate_batch(loaded, grid, direction={d: 1.0}, samples=samples, seed=0) for d in dirs}
    evaluate = CLOCK() - t0
    npts = len(grid["px"])
    idx = np.linspace(0, npts - 1, min(baseline, npts)).astype(int)
    t0 = CLOCK()
    same = True
    for i in idx:
        at = {k: (float(v[i]) if np.ndim(v) else v) for k, v in grid.items()}
        for d in dirs:
            e = estimate_derivative(loaded, at, {d: 1.0}, samples=samples, seed=0)
            same &= e.value == grads[d].regular[i] + grads[d].boundary[i]
    loop = (CLOCK() - t0) * npts / len(idx)
    distinct, tree = core_size(loaded.program.body)
    defaults = {k: float(v) for k, v in loaded.params.items()}
    grad = {d: (g.derivative, g.derivative_stderr) for d, g in grads.items()}
    return dict(compile=compile_, evaluate=evaluate, loop=loop, same=same, size=(distinct, tree), grad=grad,
                defaults=defaults)


# -- Teg --------------------------------------------------------------------------------------------

def teg_size(expr) -> int:
    seen, stack = set(), [expr]
    n = 0
    while stack:  # written out: every reference counts (Teg duplicates rather than shares)
        e = stack.pop()
        n += 1
        stack.extend(getattr(e, "children", ()))
        seen.add(id(e))
    return n


def teg(shader: str, grid: dict, samples: int, defaults: dict, pixels_timed: int):
    from teg import Const, IfElse, Teg, TegVar, Tup, Var
    from teg.derivs.reverse_deriv import reverse_deriv
    from teg.eval import evaluate
    from teg.math import Sqr
    from teg.passes.reduce import reduce_to_base
    from teg.passes.simplify import simplify

    def build():
        v = {k: Var(k, defaults[k]) for k in VERTS + COLOURS[shader]}
        pix = {k: Var(k, 0.0) for k in ("px0", "px1", "py0", "py1", "pr", "pg", "pb")}
        x, y = TegVar("x"), TegVar("y")
        a, b, c = (v["ax"], v["ay"]), (v["bx"], v["by"]), (v["cx"], v["cy"])

        def edge(u, w):  # twice the signed area of (u, w, p): >= 0 inside (counter-clockwise)
            return (w[0] - u[0]) * (y - u[1]) - (w[1] - u[1]) * (x - u[0])

        area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
        la, lb, lc = edge(b, c) / area, edge(c, a) / area, edge(a, b) / area
        mask = IfElse(edge(b, c) >= 0, 1, 0) * IfElse(edge(c, a) >= 0, 1, 0) * IfElse(edge(a, b) >= 0, 1, 0)
        loss = Const(0)
        for ch, target in zip("rgb", ("pr", "pg", "pb")):
            col = lambda k, ch=ch: v[k + ch]  # noqa: E731
            if shader == "linear":
                shade = la * col("a") + lb * col("b") + lc * col("c")
            else:
                shade = (la * (2 * la - 1) * col("a") + lb * (2 * lb - 1) * col("b") + lc * (2 * lc - 1) * col("c")
                         + 4 * lb * lc * col("m") + 4 * lc * la * col("n") + 4 * la * lb * col("q"))
            loss = loss + Sqr(shade - pix[target])
        integral = Teg(pix["py0"], pix["py1"], Teg(pix["px0"], pix["px1"], loss * mask, x), y)
        outputs = [v[k] for k in VERTS + COLOURS[shader]]
        _, d = reverse_deriv(integral, Tup(Const(1)), output_list=outputs)
        return reduce_to_base(simplify(d)), pix

    # Teg's numpy backend integrates each dimension by the trapezoid rule on num_samples points
    # (one Python evaluation of the integrand per point): √samples per axis gives a pixel about
    # Langur's number of points
    per_axis = max(2, int(round(np.sqrt(samples))))
    t0 = CLOCK()
    expr, pix = build()
    compile_ = CLOCK() - t0
    npts = len(grid["px"])
    side = int(round(np.sqrt(npts)))  # pixels along the middle row, which the triangle's edges cross
    idx = side * (side // 2) + np.linspace(0, side - 1, min(pixels_timed, side)).astype(int)
    t0 = CLOCK()
    out = {}
    for i in idx:
        h = grid["h"]
        vals = {"px0": grid["px"][i], "px1": grid["px"][i] + h, "py0": grid["py"][i], "py1": grid["py"][i] + h,
                "pr": grid["pr"][i], "pg": grid["pg"][i], "pb": grid["pb"][i]}
        out[int(i)] = np.asarray(evaluate(expr, {pix[k]: float(val) for k, val in vals.items()},
                                          backend="numpy", num_samples=per_axis), dtype=float).ravel()
    evaluate_ = (CLOCK() - t0) * npts / len(idx)
    return dict(compile=compile_, evaluate=evaluate_, size=teg_size(expr), grads=out)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--teg", metavar="DIR", help="a checkout of github.com/ChezJrk/Teg")
    ap.add_argument("--potto", metavar="DIR", help="a checkout of github.com/divicomp/potto (see the docstring)")
    ap.add_argument("--pixels", type=int, default=16)
    ap.add_argument("--samples", type=int, default=50)
    ap.add_argument("--baseline", type=int, default=16, help="pixels timed by the per-point loop")
    ap.add_argument("--teg-pixels", type=int, default=8, help="pixels Teg evaluates (0.3-2 s each at 7 x 7 points)")
    ap.add_argument("--plot", metavar="OUT.png")
    args = ap.parse_args()
    sys.setrecursionlimit(10**6)
    if args.teg:
        sys.path.insert(0, os.path.abspath(args.teg))
    else:
        print("(teg: not given — pass --teg DIR, a checkout of its public repository, to compare)")
    if args.potto:
        print("(potto: given, but not run: a triangle edge moved by two vertices is not among its library's "
              "diffeomorphisms, and writing one for it was not attempted; see the docstring)")
    grid = image(args.pixels)
    npts = len(grid["px"])
    rows = {}
    for shader in ("linear", "quadratic"):
        rows[shader] = {"langur": langur(shader, grid, args.samples, args.baseline)}
        if args.teg:
            rows[shader]["teg"] = teg(shader, grid, args.samples, rows[shader]["langur"]["defaults"], args.teg_pixels)
    dirs = {s: VERTS + COLOURS[s] for s in rows}
    print(f"\nFig. 15: one triangle against {args.pixels}×{args.pixels} pixels, the gradient in the vertices and the "
          f"shader's colours, {args.samples} samples per pixel; CPU seconds\n")
    print("| shader | directions | system | compile | evaluate (all pixels) | total | AST size | note |")
    print("|---|---|---|---|---|---|---|---|")
    for s, r in rows.items():
        lg = r["langur"]
        print(f"| {s} | {len(dirs[s])} | langur (batch) | {lg['compile']:.3f} | {lg['evaluate']:.3f} | "
              f"{lg['compile'] + lg['evaluate']:.3f} | {lg['size'][0]} distinct ({lg['size'][1]} written out) | "
              f"batch = per-point: {'yes' if lg['same'] else 'NO'} |")
        print(f"| {s} | {len(dirs[s])} | langur per-point loop (baseline) | {lg['compile']:.3f} | {lg['loop']:.2f} | "
              f"{lg['compile'] + lg['loop']:.2f} | | timed on {min(args.baseline, npts)} pixels, scaled |")
        if "teg" in r:
            tg = r["teg"]
            print(f"| {s} | {len(dirs[s])} | teg (numpy backend) | {tg['compile']:.3f} | {tg['evaluate']:.2f} | "
                  f"{tg['compile'] + tg['evaluate']:.2f} | {tg['size']} | evaluated on {len(tg['grads'])} pixels, "
                  f"scaled; {(tg['compile'] + tg['evaluate']) / (lg['compile'] + lg['evaluate']):.0f}× langur |")
    if any("teg" in r for r in rows.values()):
        print("\nThe gradient at the pixels Teg evaluated, summed over them: Langur (± its summed standard errors) "
              "against Teg (each with its own samples)\n")
        print("| shader | parameter | langur | teg |")
        print("|---|---|---|---|")
    for s, r in rows.items():
        if "teg" not in r:
            continue
        idx = sorted(r["teg"]["grads"])
        teg_sum = np.sum([r["teg"]["grads"][i] for i in idx], axis=0)
        for j, d in enumerate(dirs[s]):
            g, se = r["langur"]["grad"][d]
            print(f"| {s} | {d} | {float(np.sum(g[idx])):.5g} ± {float(np.sum(se[idx])):.2g} | {teg_sum[j]:.5g} |")
    if args.plot:
        plot(rows, args.plot)
        print(f"\n{args.plot}")


def plot(rows: dict, out: str) -> None:
    """Fig. 15 as the paper draws it: bars of compile, evaluate and total time (log scale) and AST
    size, per shader and system."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    systems = [("langur", "langur (batch)"), ("teg", "teg (numpy)")]
    fig, axes = plt.subplots(1, 4, figsize=(13, 3.6))
    for ax, (key, title) in zip(axes, (("compile", "compile time (s)"), ("evaluate", "evaluation time (s)"),
                                       ("total", "total time (s)"), ("size", "AST size (nodes written out)"))):
        for k, (name, label) in enumerate(systems):
            vals = []
            for s in rows:
                r = rows[s].get(name)
                if r is None:
                    vals.append(np.nan)
                elif key == "total":
                    vals.append(r["compile"] + r["evaluate"])
                elif key == "size":  # written out (Teg's derivative duplicates; Langur's term is a DAG)
                    vals.append(r["size"][1] if isinstance(r["size"], tuple) else r["size"])
                else:
                    vals.append(r[key])
            ax.bar(np.arange(len(rows)) + 0.38 * k, vals, width=0.38, label=label)
        ax.set_xticks(np.arange(len(rows)) + 0.19, [f"{s} shader" for s in rows])
        ax.set_yscale("log")
        ax.set_title(title, fontsize=10)
    axes[0].legend(fontsize=8)
    fig.suptitle("Fig. 15 remade: image stylization kernel, gradient over the image (smaller is better)", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    main()
