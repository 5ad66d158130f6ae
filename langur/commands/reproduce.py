"""``langur reproduce [NAME…]``: the paper's examples and figures, each with its numbers checked."""

from __future__ import annotations

import importlib

from .. import progress, reproduce
from ..cli import MAX_SAMPLES, UsageError, samples, seed
from ..reproduce import EXPERIMENTS
from . import _common as c
from ._outputs import output_folder


def add_arguments(p):
    p.add_argument("names", nargs="*", metavar="NAME",
                   help=f"experiments to run (default all): {', '.join(EXPERIMENTS)}")
    p.add_argument("--samples", type=samples(100), default=100000, metavar="N",
                   help=f"Monte Carlo samples, 100 to {MAX_SAMPLES:,} (default 100000)")
    p.add_argument("--seed", type=seed, default=0, metavar="S", help="random seed, a non-negative integer (default 0)")
    p.add_argument("--json", action="store_true", help="one JSON object on standard output")
    p.add_argument("--out", metavar="DIR", help="also write each experiment's pictures (Fig. 1, 2, 3, 9, 13, 14) to DIR "
                   "(needs the plot extra: pip install -e '.[plot]')")


def _painter():
    """``viz.paper.draw``, from the optional plot extra (a usage error when it is missing)."""
    try:
        return importlib.import_module("viz.paper").draw
    except ImportError as e:
        raise UsageError(f"--out needs the plot extra ({e.name or e}): pip install -e '.[plot]'") from None


def run(args) -> int:
    names = args.names or list(reproduce.EXPERIMENTS)
    unknown = [n for n in names if n not in reproduce.EXPERIMENTS]
    if unknown:
        raise UsageError(f"no experiment named {unknown[0]} (have: {', '.join(reproduce.EXPERIMENTS)})")
    try:
        reproduce.examples_dir()
    except FileNotFoundError as e:
        raise UsageError(str(e)) from None
    draw = _painter() if args.out else None
    if args.out:
        output_folder(args.out, "--out")
    results = []
    for name in names:
        (ex,) = reproduce.run([name], args.samples, args.seed)
        results.append(ex)
        if draw is not None and ex.figures:
            with progress.phase(f"drawing {name}'s pictures"):
                ex.notes += [f"picture: {p}" for p in draw(name, ex.figures, args.out)]
        if not args.json:
            print(f"{'PASS' if ex.ok else 'FAIL'}  {ex.name}: {ex.title}   ({ex.seconds:.1f} s)")
            for ch in ex.checks:
                mark = "✓" if ch.ok else "✗"
                print(f"   {mark} {ch.what:<58} {c.fmt(ch.got, 8):>14}  expected {c.fmt(ch.expected, 8):<12} [{ch.how}]")
            for note in ex.notes:
                print(f"     {note}")
    ok = all(ex.ok for ex in results)
    if args.json:
        c.dump_json({"ok": ok, "experiments": [
            {"name": ex.name, "title": ex.title, "ok": ex.ok, "seconds": ex.seconds, "notes": ex.notes,
             "checks": [vars(ch) for ch in ex.checks]} for ex in results]})
    else:
        print(f"{sum(ex.ok for ex in results)}/{len(results)} experiments reproduced")
    return 0 if ok else 1
