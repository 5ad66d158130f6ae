"""CPU of ``langur deriv``'s transversality gate (X301: is ⦇p⦈ the derivative; X305: at these
values?), this tree against a baseline tree, program by program (bench/history/2026-11-29.md#lambert33.

    python bench/bench_gate.py [--baseline /tmp/base] [--json OUT] [--pixels 3]
    (baseline: ``git archive REV | tar -x -C /tmp/base``)

Each case — every example with a program at its default values, and lambert pixels of the paper's
renderer (§10.2, Fig. 14c: examples/raytrace/scene.lgr with the lambert shader) on a diagonal of the
image — is run in a fresh process per tree (``-P``, the tree first on the path), the two trees
alternating case by case so that both see the same load.  CPU is ``time.process_time`` around
``langur.commands._defined.transversal`` only (the load excluded); the gate's findings (code, line,
column, message) must be equal in both trees.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLES = os.path.join(HERE, "examples")

_ONE = """
import json, sys, time
from langur.frontend import load
from langur.commands import _defined
path, modules, at = json.loads(sys.argv[1])
loaded = load(path, modules=modules)
params = loaded.param_values(at)
c0 = time.process_time()
gate = _defined.transversal(loaded, path, params)
cpu = time.process_time() - c0
found = [[f.code, f.span.line if f.span else 0, f.span.col if f.span else 0, f.message]
         for f in gate.findings + gate.here]
print(json.dumps({"cpu": cpu, "findings": found}))
"""


def cases(pixels: int) -> list[tuple[str, dict, dict]]:
    out = []
    for root, _, files in sorted(os.walk(EXAMPLES)):
        for name in sorted(files):
            if name.endswith(".lgr") and "adapters" not in root:
                out.append((os.path.join(root, name), {}, {}))
    lam = {"shader": os.path.join(EXAMPLES, "raytrace", "lambert.lgr")}
    scene = os.path.join(EXAMPLES, "raytrace", "scene.lgr")
    for k in range(pixels):  # the pixels of the image's diagonal from (-0.3, -0.3) to (0.285, 0.285)
        v = -0.3 + k * 0.585 / max(1, pixels - 1)
        out.append((scene, lam, {"px": round(v, 4), "py": round(v, 4)}))
    return out


def run(tree: str, case) -> dict | None:
    env = {**os.environ, "PYTHONPATH": tree}
    r = subprocess.run([sys.executable, "-P", "-c", _ONE, json.dumps(case)], cwd=tree, env=env,
                       capture_output=True, text=True, timeout=1200)
    if r.returncode != 0:  # a program without parameters or without a program: not a gate case
        return None
    return json.loads(r.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--baseline", help="the other tree (without it: this tree only, base = new)")
    ap.add_argument("--pixels", type=int, default=3)
    ap.add_argument("--json")
    args = ap.parse_args()
    rows = []
    for case in cases(args.pixels):
        new = run(HERE, case)
        old = run(args.baseline, case) if args.baseline else new
        if new is None or old is None:
            continue
        name = os.path.relpath(case[0], HERE) + (" lambert " + json.dumps(case[2]) if case[1] else "")
        same = new["findings"] == old["findings"]
        rows.append({"case": name, "base": old["cpu"], "new": new["cpu"], "same": same,
                     "codes": sorted({f[0] for f in new["findings"]}), "diff": None if same else [old, new]})
        print(f"{name:70s} {old['cpu']:8.2f} {new['cpu']:8.2f} {'same' if same else 'DIFFERENT'} "
              f"{','.join(rows[-1]['codes'])}", flush=True)
    print(f"total CPU s: base {sum(r['base'] for r in rows):.2f}, new {sum(r['new'] for r in rows):.2f}; "
          f"{sum(not r['same'] for r in rows)} case(s) with different findings")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
