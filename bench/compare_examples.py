"""Behaviour unchanged? ``langur show`` and seeded ``langur eval --engine mc`` on every example
program, run by two source trees (not a test; issue 15's rule for front-end work).

Run:  python bench/compare_examples.py BEFORE_ROOT AFTER_ROOT [--samples N] [--extra FILE.lgr …] [--fast]

``--fast``: instead of the commands, one process per tree prints, for every program, the hash of
its printed core program (``print_program``) and its seeded Monte Carlo value and derivative along
each parameter (or the diagnostics): no exact engine, so minutes become seconds.

Each tree's ``langur`` runs in its own process (``PYTHONPATH=ROOT``, and ``python -P``: without it
the current folder, the AFTER tree, came first on ``sys.path`` and both runs imported the AFTER
tree's ``langur`` — comparisons before 2026-11-26 evening compared a tree with itself) from the
AFTER tree's folder (so examples' relative imports resolve the same), both with
``PYTHONHASHSEED=0`` (sympy's choice among equal antiderivatives follows set order, which follows
string hashing: the same tree printed two closed forms differing by a constant from run to run); prints one line per program and command, and the
differences in full.  Exit status 1 when any output differs.
"""

from __future__ import annotations

import argparse
import glob
import os
import subprocess
import sys


def run(root: str, cwd: str, args: list[str]) -> str:
    env = {**os.environ, "PYTHONPATH": root, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1",
           "PYTHONHASHSEED": "0"}
    p = subprocess.run([sys.executable, "-P", "-m", "langur", *args], cwd=cwd, env=env, capture_output=True, text=True)
    return f"exit {p.returncode}\n{p.stdout}{p.stderr}"


FAST = r"""
import glob, hashlib, sys
from langur import operational
from langur.diagnostics import LangurError
from langur.frontend import load
from langur.syntax.printer import print_program
for f in sys.argv[2:]:
    try:
        p = load(f)
    except LangurError as e:
        print(f, "error", [d.format() for d in e.diagnostics]); continue
    if p.program is None:
        print(f, "no program"); continue
    print(f, hashlib.sha256(print_program(p.program).encode()).hexdigest()[:16])
    try:
        at = p.param_values({})
        print(f, "value", repr(operational.estimate_value(p, at, samples=int(sys.argv[1]), seed=0).value))
        for name in sorted(at):
            d = operational.estimate_derivative(p, at, {name: 1.0}, samples=int(sys.argv[1]), seed=0)
            print(f, "d/d" + name, repr(d.value), repr(d.regular), repr(d.boundary))
    except Exception as e:  # (an engine's refusal is an output too)
        print(f, "raised", type(e).__name__, e)
"""


def fast(a, cwd: str, files: list[str]) -> int:
    outs = []
    for root in (a.before, a.after):
        env = {**os.environ, "PYTHONPATH": os.path.abspath(root), "OPENBLAS_NUM_THREADS": "1",
               "OMP_NUM_THREADS": "1", "PYTHONHASHSEED": "0"}
        outs.append(subprocess.run([sys.executable, "-P", "-c", FAST, str(a.samples), *files], cwd=cwd, env=env,
                                   capture_output=True, text=True))
    x, y = (o.stdout.splitlines() for o in outs)
    differ = sum(u != v for u, v in zip(x, y)) + abs(len(x) - len(y))
    for u, v in zip(x, y):
        print(("same       " if u == v else "DIFFERENT  ") + v + ("" if u == v else "\n   before: " + u))
    print(f"{len(files)} programs, {len(y)} lines, {differ} different", outs[0].stderr[-500:], outs[1].stderr[-500:])
    return 1 if differ else 0


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--extra", nargs="*", default=[])
    ap.add_argument("--fast", action="store_true")
    a = ap.parse_args()
    cwd = os.path.abspath(a.after)
    files = sorted(glob.glob("examples/**/*.lgr", root_dir=cwd, recursive=True)) + a.extra
    if a.fast:
        return fast(a, cwd, files)
    differ = 0
    for f in files:
        for cmd in (["show", f], ["eval", f, "--engine", "mc", "--seed", "0", "--samples", str(a.samples)]):
            x, y = run(os.path.abspath(a.before), cwd, cmd), run(os.path.abspath(a.after), cwd, cmd)
            same = x == y
            differ += not same
            print(f"{'same' if same else 'DIFFERENT'}  {' '.join(cmd)}", flush=True)
            if not same:
                print("--- before\n" + x + "--- after\n" + y)
    print(f"{differ} different")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
