"""CPU per program of a `langur fuzz` campaign (issue 13): the machine is shared, so wall times
say more about the other sessions than about the campaign; CPU seconds do not.

    python bench/bench_campaign.py --examples 60 --seed 1 [--workers 2] [--json OUT.json]
    python bench/bench_campaign.py --examples 1000 --seed 1 --first 150 [--in-process]

Runs ``langur.fuzz.run_fuzz`` (the same units as ``langur fuzz``: generation, front end, linter,
both engines, in worker processes) and prints the programs, their statuses, the wall time, the CPU
seconds of this process (generation, the pool) and of its worker processes (``os.times`` of the
reaped children: killed units included), CPU seconds per program, minor page faults, and the
load average before and after.  ``--first N`` checks only the first N distinct programs of the
campaign (generated first, timed apart: the same fixed list for two versions of the code);
``--in-process`` runs them one after the other in this process instead (``compare_text`` with the
exact engine in this process: what one warm process costs, no time limit).  To measure another
version of the code, run it with ``PYTHONPATH`` pointing at that tree (the fixed list is handed to
``run_fuzz`` by replacing ``generated`` in the module that defines ``run_fuzz``: ``langur.fuzz.campaign``,
or ``langur.fuzz.compare`` in trees before 2026-11-27).
``--programs FILE`` checks a JSON list of program texts instead (a fixed list saved once);
``--profile OUT`` (with ``--in-process``) writes a cProfile of the units; ``--against JSON`` prints
the programs whose status or methods (closed form / quadrature per answer) differ from an earlier
``--json`` of the same list; ``--json`` keeps each program's phases (front end, lint, exact
symbolic / quadrature / other, mc).
"""

from __future__ import annotations

import argparse
import cProfile
import json
import os
import resource
import sys
import tempfile
import time

from langur import fuzz
from langur.fuzz import compare, coverage


def _cpu(k0, k1, children: bool) -> float:
    if children:
        return (k1.children_user - k0.children_user) + (k1.children_system - k0.children_system)
    return (k1.user - k0.user) + (k1.system - k0.system)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--examples", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--first", type=int, metavar="N", help="only the first N distinct programs (generated first)")
    ap.add_argument("--programs", metavar="FILE", help="a JSON list of program texts to check instead")
    ap.add_argument("--in-process", action="store_true", help="one program after the other in this process")
    ap.add_argument("--json", metavar="OUT")
    ap.add_argument("--profile", metavar="OUT", help="with --in-process: a cProfile of the units to OUT (pstats)")
    ap.add_argument("--against", metavar="JSON", help="an earlier --json of the same list: print the programs "
                    "whose status or methods differ")
    a = ap.parse_args()
    load0 = os.getloadavg()
    generation = None
    with tempfile.TemporaryDirectory() as hyp:
        texts = None
        if a.programs:
            with open(a.programs, encoding="utf-8") as fh:
                texts = json.load(fh)
        elif a.first is not None or a.in_process:
            g0 = time.process_time()
            with fuzz.generate.hypothesis_home(hyp):
                texts = fuzz.generated(a.examples, a.seed)
            generation = {"programs": len(texts), "cpu": round(time.process_time() - g0, 2)}
        if texts is not None and a.first is not None:
            texts = texts[: a.first]
        if texts is not None:
            def fixed(examples, seed, light=False, each=None, **shape):
                for t in texts:
                    if each is not None:
                        each(t)
                return list(texts)

            sys.modules[fuzz.run_fuzz.__module__].generated = fixed  # the driver's module (module doc)
        t0, k0 = time.monotonic(), os.times()
        f0 = resource.getrusage(resource.RUSAGE_SELF).ru_minflt + resource.getrusage(resource.RUSAGE_CHILDREN).ru_minflt
        if a.in_process:
            results = []
            prof = cProfile.Profile() if a.profile else None
            for t in texts:
                c = time.process_time()
                if prof is not None:
                    prof.enable()
                with coverage.recording():
                    r = compare.compare_text(t, seed=a.seed, timeout=a.timeout, isolate=False)
                if prof is not None:
                    prof.disable()
                r.cpu_seconds = time.process_time() - c
                results.append(r)
            if prof is not None:
                prof.dump_stats(a.profile)
        else:
            results = fuzz.run_fuzz(a.examples, a.seed, timeout=a.timeout, workers=a.workers, storage=hyp,
                                    shrink=False).results
    wall, k1 = time.monotonic() - t0, os.times()
    faults = resource.getrusage(resource.RUSAGE_SELF).ru_minflt + resource.getrusage(resource.RUSAGE_CHILDREN).ru_minflt - f0
    own, children = _cpu(k0, k1, False), _cpu(k0, k1, True)
    n = len(results)
    counts: dict[str, int] = {}
    for r in results:
        counts[r.status] = counts.get(r.status, 0) + 1
    out = {"code": fuzz.__file__, "examples": a.examples, "seed": a.seed, "first": a.first,
           "workers": 0 if a.in_process else a.workers, "programs": n, "generation": generation,
           "counts": counts, "wall": round(wall, 1),
           "cpu_campaign_process": round(own, 1), "cpu_workers": round(children, 1),
           "cpu_per_program": round((own + children) / max(n, 1), 3),
           "cpu_units": round(sum(r.cpu_seconds for r in results), 1), "minor_page_faults": faults,
           "load_before": load0, "load_after": os.getloadavg(),
           "timing": {k: round(sum(r.timing.get(k, 0.0) for r in results), 1) for k in compare.PHASES},
           "results": [{"program": r.text, "status": r.status, "methods": r.methods,
                        "cpu_seconds": round(r.cpu_seconds, 3), "timing": r.timing_json(),
                        "rows": [[row.quantity, row.wrt, row.ok] for row in r.rows]} for r in results]}
    print(json.dumps({k: v for k, v in out.items() if k != "results"}))
    if a.json:
        with open(a.json, "w", encoding="utf-8") as fh:
            json.dump(out, fh, indent=1)
    if a.against:
        with open(a.against, encoding="utf-8") as fh:
            before = {r["program"]: r for r in json.load(fh)["results"]}
        differ = [(before[r["program"]], r) for r in out["results"] if r["program"] in before
                  and (before[r["program"]]["status"], before[r["program"]]["methods"]) != (r["status"], r["methods"])]
        common = sum(r["program"] in before for r in out["results"])
        print(f"{len(differ)} of {common} programs differ in status or methods from {a.against}")
        for b, r in differ:
            print(f"  {b['status']} {b['methods']} -> {r['status']} {r['methods']}: {r['program']!r}")


if __name__ == "__main__":
    main()
