"""The transversality linter's CPU inside fuzz campaigns (issues 13 and 18; Def. 7.2, §7.3).

    python bench/bench_lint.py --save PROGRAMS.json [--seed 1 --examples 1000 --first 150]
    python bench/bench_lint.py --save T.json --seed 11 --examples 40 --kinks --turning --slice 26:30
    python bench/bench_lint.py --programs PROGRAMS.json --baseline /tmp/b_lint8 [--json OUT]
    python bench/bench_lint.py --programs PROGRAMS.json --units [--json OUT]

``--save`` regenerates a campaign's programs (``langur.fuzz.generated``: the same seed gives
the same list) and writes them.  ``--programs`` lints each, as ``langur fuzz`` does
(``check_loaded`` at the default parameter values), in a server process per tree: this tree and,
with ``--baseline DIR``, another one (``git archive REV | tar -x -C DIR``), the two alternating
program by program so that both see the same load; CPU seconds are ``time.process_time`` of the
server around the lint only.  It prints the CPU of each tree and every program whose findings
(code, line, column, message) differ.  ``--units`` runs whole campaign units instead (load, lint,
both engines: ``compare_text`` in a worker of ``langur.fuzz.pool``, killed at 20 + 5 CPU s, as
``langur fuzz`` runs them) and prints the linter's share of each unit's CPU.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _findings_of(text: str, budget: float | None) -> tuple[float, list]:
    from langur.frontend import load_text
    from langur.transversality import check_loaded

    loaded = load_text(text, path="<fuzz>.lgr")
    at = {k: float(v) for k, v in loaded.param_values({}).items()}
    kw = {"budget": budget} if budget is not None else {}
    c0 = time.process_time()
    found = check_loaded(loaded, at=at, sources={"<fuzz>.lgr": text}, **kw)
    cpu = time.process_time() - c0
    return cpu, [[f.code, f.span.line if f.span else 0, f.span.col if f.span else 0, f.message] for f in found]


def _driver(fuzz):
    """The module of ``langur fuzz``'s driver in the tree being measured: ``langur.fuzz.campaign``
    (``langur.fuzz.compare`` in trees before 2026-11-27)."""
    return sys.modules[fuzz.run_fuzz.__module__]


def serve(budget: float | None) -> None:
    """One program text per line (JSON) in, ``{"cpu", "findings"}`` per line out."""
    from langur import fuzz

    _driver(fuzz)._warm_up(True)  # as the campaign's process does before forking its workers
    print(json.dumps({"ready": True}), flush=True)
    for line in sys.stdin:
        try:
            cpu, found = _findings_of(json.loads(line), budget)
            out = {"cpu": cpu, "findings": found}
        except Exception as e:  # noqa: BLE001 - reported, the next program goes on
            out = {"cpu": 0.0, "findings": [["crash", 0, 0, f"{type(e).__name__}: {e}"]]}
        print(json.dumps(out), flush=True)


class _Server:
    def __init__(self, tree: str, budget: float | None):
        env = dict(os.environ, PYTHONPATH=tree, PYTHONDONTWRITEBYTECODE="1")
        cmd = [sys.executable, "-P", os.path.abspath(__file__), "--serve"]
        if budget is not None:
            cmd += ["--budget", str(budget)]
        self.tree = tree
        self.proc = subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=env, text=True, cwd=tree)
        json.loads(self.proc.stdout.readline())

    def lint(self, text: str) -> dict:
        self.proc.stdin.write(json.dumps(text) + "\n")
        self.proc.stdin.flush()
        return json.loads(self.proc.stdout.readline())

    def close(self) -> None:
        self.proc.stdin.close()
        self.proc.wait()


def units(texts: list[str], timeout: float) -> list[dict]:
    """Whole campaign units in one pool worker; the lint's CPU measured inside the unit."""
    from langur import fuzz
    from langur.fuzz import compare, coverage, pool

    lint_cpu = [0.0]
    inner = compare.check_loaded

    def timed_lint(*a, **kw):
        c0 = time.process_time()
        try:
            return inner(*a, **kw)
        finally:
            lint_cpu[0] = time.process_time() - c0

    phase = compare._phase

    def noted_phase(name, result):  # the lint's CPU goes with the phase notes a killed unit leaves
        result.timing["lint_cpu"] = lint_cpu[0]
        phase(name, result)

    compare.check_loaded, compare._phase = timed_lint, noted_phase

    def work(text: str) -> dict:
        lint_cpu[0] = 0.0
        c0 = time.process_time()
        with coverage.recording():
            r = compare.compare_text(text, timeout=timeout, isolate=False)
        return {"status": r.status, "unit_cpu": time.process_time() - c0, "lint_cpu": lint_cpu[0],
                "lint": [f.split(" ", 1)[0] for f in r.findings if f[:1] == "X"]}

    def killed(text: str, reason: str, last=None) -> dict:
        lint = (last or {}).get("timing", {}).get("lint_cpu")
        if (last or {}).get("phase") == "lint":
            lint = None  # killed in the lint: its CPU is the unit's minus the front end's
        return {"status": "timeout", "unit_cpu": timeout + pool.GRACE, "lint_cpu": lint,
                "phase": (last or {}).get("phase"), "reason": reason}

    _driver(fuzz)._warm_up(True)
    return pool.run_units(texts, work, workers=1, limit=timeout, on_time_limit=killed,
                          on_error=lambda t, r: {"status": "error", "reason": r, "unit_cpu": 0, "lint_cpu": 0})


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--serve", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--budget", type=float, help="the lint's CPU budget handed to check_loaded (trees that take it)")
    ap.add_argument("--save", metavar="OUT")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--examples", type=int, default=1000)
    ap.add_argument("--first", type=int)
    ap.add_argument("--slice", metavar="A:B")
    ap.add_argument("--kinks", action="store_true")
    ap.add_argument("--turning", action="store_true")
    ap.add_argument("--programs", metavar="FILE")
    ap.add_argument("--baseline", metavar="DIR")
    ap.add_argument("--units", action="store_true")
    ap.add_argument("--timeout", type=float, default=20.0)
    ap.add_argument("--json", metavar="OUT")
    a = ap.parse_args()
    if a.serve:
        return serve(a.budget)
    if a.save:
        import tempfile

        from langur import fuzz
        from langur.fuzz import generate

        with tempfile.TemporaryDirectory() as hyp, generate.hypothesis_home(hyp):
            texts = fuzz.generated(a.examples, a.seed, kinks=a.kinks, turning=a.turning)
        if a.first is not None:
            texts = texts[: a.first]
        if a.slice:
            lo, hi = (int(v) for v in a.slice.split(":"))
            texts = texts[lo:hi]
        with open(a.save, "w", encoding="utf-8") as fh:
            json.dump(texts, fh, indent=0)
        print(f"{len(texts)} programs written to {a.save}")
        return
    with open(a.programs, encoding="utf-8") as fh:
        texts = json.load(fh)
    load0 = os.getloadavg()
    if a.units:
        rows = units(texts, a.timeout)
        unit = sum(r["unit_cpu"] for r in rows)
        lint = sum(r["lint_cpu"] or 0.0 for r in rows)
        for i, r in enumerate(rows):
            print(i, r["status"], f"unit {r['unit_cpu']:.2f}", f"lint {r['lint_cpu']}", r.get("lint", r.get("phase")))
        counts: dict = {}
        for r in rows:
            counts[r["status"]] = counts.get(r["status"], 0) + 1
        print(json.dumps({"programs": len(rows), "counts": counts, "unit_cpu": round(unit, 1),
                          "lint_cpu": round(lint, 1), "lint_share": round(lint / max(unit, 1e-9), 3),
                          "load": [load0, os.getloadavg()]}))
        out = {"rows": rows}
    else:
        servers = {"new": _Server(HERE, a.budget)}
        if a.baseline:
            servers["base"] = _Server(os.path.abspath(a.baseline), None)
        got: dict[str, list] = {k: [] for k in servers}
        for i, t in enumerate(texts):
            for k, s in (servers.items() if i % 2 == 0 else reversed(servers.items())):
                got[k].append(s.lint(t))
        for s in servers.values():
            s.close()
        summary = {k: {"cpu": round(sum(r["cpu"] for r in v), 2), "max": round(max(r["cpu"] for r in v), 2)}
                   for k, v in got.items()}
        summary["load"] = [load0, os.getloadavg()]
        print(json.dumps(summary))
        if "base" in got:
            for i, (b, n) in enumerate(zip(got["base"], got["new"])):
                mark = "" if b["findings"] == n["findings"] else "  DIFFERENT"
                print(f"{i:4d} base {b['cpu']:7.2f} new {n['cpu']:7.2f}{mark}")
                if mark:
                    print("     base:", [f[:3] for f in b["findings"]], "\n     new: ", [f[:3] for f in n["findings"]])
                    for f in b["findings"]:
                        if f not in n["findings"]:
                            print("     - ", f)
                    for f in n["findings"]:
                        if f not in b["findings"]:
                            print("     + ", f)
        out = got
    if a.json:
        with open(a.json, "w", encoding="utf-8") as fh:
            json.dump(out, fh, indent=1)


if __name__ == "__main__":
    main()
