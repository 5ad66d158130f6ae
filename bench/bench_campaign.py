"""CPU per program of a `langur fuzz` campaign (issue 13): the machine is shared, so wall times
say more about the other sessions than about the campaign; CPU seconds do not.

    python bench/bench_campaign.py --examples 60 --seed 1 [--workers 2] [--json OUT.json]

Runs ``langur.fuzz.run_fuzz`` (the same units as ``langur fuzz``: generation, front end, linter,
both engines, in forked workers) and prints the programs, their statuses, the wall time, the CPU
seconds of this process (generation, the pool) and of its worker processes (``os.times`` of the
reaped children: killed units included), CPU seconds per program, and the load average before and
after.  To measure another version of the code, run it with ``PYTHONPATH`` pointing at that tree.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time

from langur import fuzz


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--examples", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--json", metavar="OUT")
    a = ap.parse_args()
    load0 = os.getloadavg()
    t0, c0, k0 = time.monotonic(), time.process_time(), os.times()
    with tempfile.TemporaryDirectory() as hyp:
        s = fuzz.run_fuzz(a.examples, a.seed, timeout=a.timeout, workers=a.workers, storage=hyp, shrink=False)
    wall, own, k1 = time.monotonic() - t0, time.process_time() - c0, os.times()
    children = (k1.children_user - k0.children_user) + (k1.children_system - k0.children_system)
    n = len(s.results)
    out = {"code": fuzz.__file__, "examples": a.examples, "seed": a.seed, "workers": a.workers, "programs": n,
           "counts": {k: v for k, v in s.counts().items() if v}, "wall": round(wall, 1),
           "cpu_campaign_process": round(own, 1), "cpu_workers": round(children, 1),
           "cpu_per_program": round((own + children) / max(n, 1), 3),
           "load_before": load0, "load_after": os.getloadavg(),
           "statuses": {r.text: r.status for r in s.results}}
    print(json.dumps({k: v for k, v in out.items() if k != "statuses"}))
    if a.json:
        with open(a.json, "w", encoding="utf-8") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
