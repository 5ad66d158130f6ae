"""Behaviour unchanged? ``langur show`` and seeded ``langur eval --engine mc`` on every example
program, run by two source trees (not a test; issue 15's rule for front-end work).

Run:  python bench/compare_examples.py BEFORE_ROOT AFTER_ROOT [--samples N] [--extra FILE.lgr …]

Each tree's ``langur`` runs in its own process (``PYTHONPATH=ROOT``) from the AFTER tree's folder
(so examples' relative imports resolve the same); prints one line per program and command, and the
differences in full.  Exit status 1 when any output differs.
"""

from __future__ import annotations

import argparse
import glob
import os
import subprocess
import sys


def run(root: str, cwd: str, args: list[str]) -> str:
    env = {**os.environ, "PYTHONPATH": root, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    p = subprocess.run([sys.executable, "-m", "langur", *args], cwd=cwd, env=env, capture_output=True, text=True)
    return f"exit {p.returncode}\n{p.stdout}{p.stderr}"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("before")
    ap.add_argument("after")
    ap.add_argument("--samples", type=int, default=2000)
    ap.add_argument("--extra", nargs="*", default=[])
    a = ap.parse_args()
    cwd = os.path.abspath(a.after)
    files = sorted(glob.glob("examples/**/*.lgr", root_dir=cwd, recursive=True)) + a.extra
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
