"""CPU time of `langur deriv` on conditions split at moving turning points (issue 18, certified).

Runs each program with this checkout and with a baseline checkout (``--baseline DIR``, e.g. a
worktree of main) in the same run, each as a fresh process (``python -m langur deriv FILE --wrt a
--no-theorem``, ``PYTHONPATH`` set to the checkout), and reports the CPU time (user + sys of the
child), the median of ``--repeat`` runs, and the derivative each engine printed (each run in the checkout's directory:
``python -m`` puts the working directory before ``PYTHONPATH``).

    python bench/bench_turning_certified.py --baseline /work/main
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent

PROGRAMS = {
    "turning.lgr (fixed turning points)": (HERE / "examples" / "turning.lgr").read_text(),
    "sin(a*x) on [-2, 2], a = 2 (7 moving slots)":
        "param a = 2\nint ([-2, 2]) [sin(a * x) - 0.5 >= 0] * (1 + x) d(x)\n",
    "two turning points 0.002 apart (atan)":
        "param a = 0.002\nint ([-1, 1]) [x - a * atan((x - 0.0019) / 0.001) - 0.0019 >= 0] * (1 + x) d(x)\n",
    "x^3 - a*x - 0.2 on [-2, 2], a = 1":
        "param a = 1\nint ([-2, 2]) [x^3 - a * x - 0.2 >= 0] * exp(x / 2) d(x)\n",
    "x^3 - x - a on [0, a + 1], a = 0.5 (moving bound, roots4)":
        "param a = 0.5\nint ([0, a + 1]) [x^3 - x - a >= 0] * (1 + x) d(x)\n",
    "x^3 - a*x + y^3 - a*y - 0.1, split along y, a = 1 (roots4)":
        "param a = 1\nint ([-2, 2], [-1.5, 1.5]) [x^3 - a * x + y^3 - a * y - 0.1 >= 0] * (1 + x * y) d(x, y)\n",
    "x^3 - x*y + y^3 - a, split along y at turning points moving with x, a = 0.1 (roots5)":
        (HERE / "examples" / "turning2d.lgr").read_text() if (HERE / "examples" / "turning2d.lgr").exists()
        else "param a = 0.1\nint ([-1, 1], [-1, 1]) [x^3 - x * y + y^3 - a >= 0] * (1 + x + y) d(x, y)\n",
    "T9(x) + a*x^2 - 0.1 on [-1, 1]: 8 moving turning points, a = 0.05 (roots5)":
        "param a = 0.05\nint ([-1, 1]) [256*x^9 - 576*x^7 + 432*x^5 - 120*x^3 + 9*x + a*x^2 - 0.1 >= 0] * (1 + x) d(x)\n",
}


def run(checkout: Path, text: str) -> tuple[float, str]:
    with tempfile.NamedTemporaryFile("w", suffix=".lgr", delete=False) as f:
        f.write(text)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    r = subprocess.run([sys.executable, "-m", "langur", "deriv", f.name, "--wrt", "a", "--no-theorem"],
                       capture_output=True, text=True, env={**os.environ, "PYTHONPATH": str(checkout)}, timeout=600,
                       cwd=checkout)  # -m puts the working directory first on sys.path
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    os.unlink(f.name)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    values = re.findall(r"^\s+(exact|MC)\s+: (\S+)", r.stdout, re.MULTILINE)
    return cpu, " / ".join(f"{k} {v}" for k, v in values) or "no value"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--baseline", required=True, type=Path)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"load average at start: {os.getloadavg()[0]:.2f}")
    print("| program | baseline CPU (s) | this checkout CPU (s) | baseline d/da | this checkout d/da |")
    print("|---|---:|---:|---|---|")
    for name, text in PROGRAMS.items():
        rows = {}
        for label, checkout in (("base", args.baseline), ("here", HERE)):
            runs = [run(checkout, text) for _ in range(args.repeat)]
            rows[label] = (statistics.median(c for c, _ in runs), runs[0][1])
        print(f"| {name} | {rows['base'][0]:.2f} | {rows['here'][0]:.2f} | {rows['base'][1]} | {rows['here'][1]} |")
    print(f"load average at end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
