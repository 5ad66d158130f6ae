"""How the exact (symbolic) engine's time grows with the number of discontinuities.

Programs: int ([-1, 1]) Σ_{i<n} [x + a_i ≥ 0]·(a_i + x) d(x) for n = 1, 2, 4, …, 64 with a_i spread
over (−1, 1), differentiated in the direction γ' = (1, …, 1).  Each row times ⟦p⟧ (denote_program)
and ⦇p⦈ (ddenote, then ddenote_program with the integration) and checks the value against the
hand-derived closed form

    ⟦p⟧ = Σ_i (1 + a_i)²/2,    ⦇p⦈(γ, 1⃗) = Σ_i [(1 + a_i) + 0] = Σ_i (1 + a_i)

(the regular part ∫_{−a_i}^{1} 1 dx = 1 + a_i, the boundary δ(x + a_i)·1·(a_i + x) vanishes at the root).
Also times the risk program's full exact gradient (paper §2).

``--examples``: instead, the exact ``deriv`` of every example (``examples/**/*.lgr``) in each of its
parameters, as ``langur deriv FILE --wrt P --engine exact`` computes it (``langur.exact.exact_deriv``:
⦇p⦈ and its Theorem 8.1 check), each example in a fresh process (no cache from another example),
CPU seconds (``time.process_time``) per partial derivative, the method and the value.  An example's
later partial derivatives reuse what its first one remembered (⟦p⟧ near the point for Theorem 8.1,
kinks, compiled conditions); ``--one-shot`` gives each partial derivative a fresh process, as one
``langur deriv FILE --wrt P`` has; ``--repeat N`` reports the median of N such runs (CPU seconds of
one run scatter by tens of per cent on a shared machine).

``--campaign N --seed S``: instead, the exact engine's answers to each distinct program of a
seeded ``langur fuzz --examples N --seed S`` campaign (the value and every partial derivative with
its Theorem 8.1 check, as a campaign's unit asks them: ``langur.fuzz.compare._exact_answers``),
CPU seconds per program in this one process, and how many answers are closed forms.

Run:  python bench/bench_symbolic.py  [--max 64]
      python bench/bench_symbolic.py --examples [--baseline DIR] [--only TEXT] [--limit SECONDS] [--repeat N]
                                        [--one-shot]
      python bench/bench_symbolic.py --campaign 30 --seed 1
"""

from __future__ import annotations

import argparse
import glob
import json
import os
import statistics
import subprocess
import sys
import time
from fractions import Fraction

from langur.core import Add, Diffeo, IfDiffeo, InverseBranch, Mul, Param, Program, Var, const, sub
from langur.ddenote import ddenote, ddenote_program
from langur.denote import denote_program
from langur.frontend import load

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "examples")  # the project's own


def _indicator(cond, inverse, v="x"):
    psi = Diffeo((v,), (cond,), ("u0",), (InverseBranch((inverse,)),), solved_for=v)
    return IfDiffeo(psi, const(1), const(0))


def jumps_program(n: int) -> tuple[Program, dict[str, Fraction]]:
    x, u0 = Var("x"), Var("u0")
    body = None
    at = {}
    for i in range(n):
        a = Param(f"a{i}")
        at[a.name] = Fraction(2 * i + 1, 2 * n) * Fraction(9, 10) - Fraction(9, 20)  # in (−0.45, 0.45)
        term = Mul(_indicator(Add(x, a), sub(u0, a)), Add(a, x))
        body = term if body is None else Add(body, term)
    lo, hi = const(-1), const(1)
    box = Mul(_indicator(sub(x, lo), Add(u0, lo)), _indicator(sub(hi, x), sub(hi, u0)))
    return Program(Mul(box, body), ("x",), ((lo, hi),)), at


def bench_jumps(max_n: int) -> list[dict]:
    rows = []
    n = 1
    while n <= max_n:
        program, at = jumps_program(n)
        direction = {k: 1 for k in at}
        t0 = time.perf_counter()
        val = denote_program(program, at)
        t1 = time.perf_counter()
        nf = ddenote(program.body, direction, at=at, variables=("x",))
        t2 = time.perf_counter()
        der = ddenote_program(program, at, direction)
        t3 = time.perf_counter()
        want_val = float(sum((1 + a) ** 2 / 2 for a in at.values()))
        want_der = float(sum(1 + a for a in at.values()))
        rows.append({"n": n, "pieces": len(nf.regular), "deltas": len(nf.deltas),
                     "denote_s": t1 - t0, "ddenote_s": t2 - t1, "deriv_s": t3 - t2,
                     "value_ok": abs(val.value - want_val) < 1e-9 * max(1, want_val),
                     "deriv_ok": abs(der.value - want_der) < 1e-9 * max(1, want_der),
                     "method": der.method})
        n *= 2
    return rows


def bench_risk() -> dict | None:
    try:
        from langur.frontend import load
    except ImportError:
        return None
    loaded = load(os.path.join(EXAMPLES, "risk.lgr"))
    at = loaded.param_values()
    t0 = time.perf_counter()
    grads = {z: ddenote_program(loaded.program, at, {z: 1}).value for z in at}
    return {"seconds": time.perf_counter() - t0, "gradient": grads}


_ONE = """
import json, sys, time
from langur.exact import exact_deriv
from langur.frontend import load
loaded = load(sys.argv[1])
if loaded.program is None:  # a module of definitions (a shader), not a program
    print("[]")
    sys.exit(0)
at = loaded.param_values()
out = []
for p in (sys.argv[2:] or at):
    t0 = time.process_time()
    r = exact_deriv(loaded.program, at, {q: int(q == p) for q in at})
    out.append({"wrt": p, "cpu": time.process_time() - t0, "method": str(r.method), "value": r.value,
                "theorem": None if r.theorem_8_1 is None else r.theorem_8_1.holds,
                "how": None if r.theorem_8_1 is None else str(r.theorem_8_1.how), "expr": r.expr,
                "at": {k: str(v) for k, v in at.items()},
                # everything else the command prints (compared with --baseline)
                "detail": [r.regular, r.boundary, r.standard_ad, r.error, r.notes, list(r.inconsistent)]
                + ([] if r.theorem_8_1 is None else [r.theorem_8_1.d_denotation,
                   r.theorem_8_1.derivative_denotation, r.theorem_8_1.notes,
                   [[pt.params, pt.d_denotation, pt.derivative_denotation] for pt in r.theorem_8_1.points]])})
print(json.dumps(out))
"""


#: CPU seconds one example's process may take (all its partial derivatives together).
EXAMPLE_LIMIT = 300.0


def bench_examples(limit: float = EXAMPLE_LIMIT, baseline: str | None = None, only: str | None = None,
                   repeat: int = 1, one_shot: bool = False):
    """Every example's exact deriv per parameter, each example in a fresh process (module doc);
    yields rows as they are measured.  With ``baseline`` (a directory holding another version's
    ``langur`` package, e.g. ``git archive main | tar -x -C DIR``), each example is measured with
    that version too, at the same time in a second process (rows with ``"version": "baseline"``):
    both under the same load; ``only``: a substring of the examples' paths to keep.  ``repeat``:
    that many fresh processes per example and version, one after the other; a row's ``cpu`` is the
    median of its runs (``cpu_runs``: all of them), everything else is the first run's (the runs'
    printed parts are compared: ``stable`` says whether they were the same).  ``one_shot``: each
    partial derivative in a fresh process of its own, as one ``langur deriv FILE --wrt P`` computes
    it (without it, an example's later partial derivatives reuse what its first one remembered)."""
    for path in sorted(glob.glob(os.path.join(EXAMPLES, "**", "*.lgr"), recursive=True)):
        name = os.path.relpath(path, EXAMPLES)
        if only and only not in name:
            continue
        measured: dict[str, list[list[dict]]] = {"baseline": [], "this": []}
        for _ in range(max(repeat, 1)):
            for wrt in _partials(path) if one_shot else [()]:
                # both versions at once, in two processes: each is measured under the same load
                runs = [("baseline", _start(path, limit, baseline, wrt))] if baseline else []
                runs.append(("this", _start(path, limit, None, wrt)))
                for version, proc in runs:
                    measured[version].append(list(_finish(proc, name, limit)))
        for version, runs in measured.items():
            # one group per partial derivative (or per failure), its rows from every run
            groups: dict = {}
            for r in (r for run in runs for r in run):
                groups.setdefault(r["wrt"] if r.get("wrt") is not None else ("error", r.get("error")), []).append(r)
            yield from (_median_row(tuple(group), version) for group in groups.values())


def _median_row(group: tuple[dict, ...], version: str) -> dict:
    """One partial derivative's runs (:func:`bench_examples`) as one row: the median CPU seconds."""
    first = group[0]
    if first.get("wrt") is None:
        return {**first, "version": version}
    cpu = [r["cpu"] for r in group]
    printed = [{k: v for k, v in r.items() if k != "cpu"} for r in group]
    return {**first, "cpu": statistics.median(cpu), "cpu_runs": cpu, "version": version,
            "stable": all(p == printed[0] for p in printed)}


def _partials(path: str) -> list[tuple[str]]:
    """The example's parameters, one tuple each (the arguments of one one-shot process)."""
    loaded = load(path)
    return [(p,) for p in loaded.param_values()] if loaded.program is not None else [()]


def _start(path: str, limit: float, pythonpath: str | None, wrt: tuple = ()) -> subprocess.Popen:
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = os.path.abspath(pythonpath) + os.pathsep + env.get("PYTHONPATH", "")
    code = f"import resource; resource.setrlimit(resource.RLIMIT_CPU, ({int(limit)}, {int(limit) + 5}))\n" + _ONE
    return subprocess.Popen([sys.executable, "-c", code, path, *wrt], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, cwd=os.path.dirname(path), env=env)


def _finish(proc: subprocess.Popen, name: str, limit: float):
    out, err = proc.communicate()
    if proc.returncode != 0:
        why = (err.strip().splitlines() or [f"killed after {limit:g} CPU seconds"])[-1]
        yield {"example": name, "wrt": None, "error": why}
        return
    for r in json.loads(out):
        yield {"example": name, **r}


def bench_campaign(examples: int, seed: int) -> list[dict]:
    """The exact engine's answers per program of a seeded campaign (module doc), CPU seconds."""
    from langur import fuzz
    from langur.frontend import load_text
    from langur.fuzz import compare
    from langur.fuzz.generate import hypothesis_home

    with hypothesis_home(None):
        texts = fuzz.generated(examples, seed)
    rows = []
    for t in texts:
        loaded = load_text(t, path="<fuzz>.lgr")
        c0 = time.process_time()
        res = compare._exact_answers(loaded.program, loaded.param_values({}), 20.0)
        methods = [str(r.method) for r in [res[1], *res[2].values()]] if res[0] == "ok" else []
        rows.append({"cpu": time.process_time() - c0, "status": res[0], "methods": methods})
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max", type=int, default=64)
    ap.add_argument("--examples", action="store_true", help="time every example's exact deriv instead")
    ap.add_argument("--limit", type=float, default=EXAMPLE_LIMIT,
                    help="CPU seconds per example process (default %(default)s)")
    ap.add_argument("--baseline", metavar="DIR",
                    help="with --examples: also time the langur package in DIR (another version), "
                         "example by example in the same run")
    ap.add_argument("--only", metavar="TEXT", help="with --examples: only the examples whose path contains TEXT")
    ap.add_argument("--dump", metavar="PATH", help="with --examples: also write every row (closed forms' text, "
                                                     "Theorem 8.1's verdict and how) as JSON to PATH")
    ap.add_argument("--repeat", type=int, default=1, metavar="N",
                    help="with --examples: N fresh processes per example (and version); the median CPU "
                         "seconds per partial derivative, with the runs' range")
    ap.add_argument("--one-shot", action="store_true",
                    help="with --examples: each partial derivative in a fresh process of its own, as one "
                         "`langur deriv FILE --wrt P` computes it")
    ap.add_argument("--campaign", type=int, metavar="N", help="time the exact engine on a campaign's programs")
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    if args.campaign:
        rows = bench_campaign(args.campaign, args.seed)
        cpu = [r["cpu"] for r in rows]
        closed = sum(m == "closed_form" for r in rows for m in r["methods"])
        print(f"{len(rows)} programs (--examples {args.campaign} --seed {args.seed}): CPU median "
              f"{statistics.median(cpu):.2f} s, mean {statistics.mean(cpu):.2f} s, max {max(cpu):.2f} s, total "
              f"{sum(cpu):.1f} s, {sum(c > 1 for c in cpu)} over 1 s; closed forms {closed} of "
              f"{sum(len(r['methods']) for r in rows)} answers; statuses "
              f"{ {s: sum(r['status'] == s for r in rows) for s in sorted({r['status'] for r in rows})} }")
        return
    if args.examples:
        rows = []
        runs = f" (median of {args.repeat}: min–max)" if args.repeat > 1 else ""
        print(f"| example | version | wrt | CPU s{runs} | method | value | Theorem 8.1 |")
        print("|---|---|---|---:|---|---:|---|")
        for r in bench_examples(args.limit, args.baseline, args.only, args.repeat, args.one_shot):
            rows.append(r)
            if r.get("wrt") is None:
                print(f"| {r['example']} | {r['version']} | — | — | {r.get('error', 'no parameters')} | | |", flush=True)
                continue
            spread = f" ({min(r['cpu_runs']):.2f}–{max(r['cpu_runs']):.2f})" if args.repeat > 1 else ""
            unstable = "" if r["stable"] else " (the runs printed different results)"
            print(f"| {r['example']} | {r['version']} | {r['wrt']} | {r['cpu']:.2f}{spread} | {r['method']}{unstable} "
                  f"| {r['value']!r} | {r['theorem']} |", flush=True)
        if args.dump:
            with open(args.dump, "w") as f:
                json.dump(rows, f)
        for version in ("baseline", "this"):
            cpu = [r["cpu"] for r in rows if r.get("wrt") is not None and r["version"] == version]
            failed = [r["example"] for r in rows if r.get("wrt") is None and r["version"] == version
                      and "error" in r]
            if cpu or failed:
                print(f"\n{version}: {len(cpu)} partial derivatives: median {statistics.median(cpu or [0]):.2f} s, "
                      f"max {max(cpu or [0]):.2f} s, {sum(c > 1.0 for c in cpu)} over 1 s; "
                      f"examples not finished: {failed or 'none'}")
        base = {(r["example"], r["wrt"]): r for r in rows if r.get("wrt") and r["version"] == "baseline"}
        same = compared = 0
        for r in rows:
            b = base.get((r["example"], r.get("wrt")))
            if r["version"] == "this" and b is not None and abs(r["value"] - b["value"]) > 1e-9 * max(1, abs(b["value"])):
                print(f"values differ: {r['example']} d/d{r['wrt']}: baseline {b['value']!r} ({b['method']}), "
                      f"this {r['value']!r} ({r['method']})")
            if r["version"] != "this" or b is None:
                continue
            compared += 1
            if (r["value"], r["method"], r["theorem"], r.get("how")) != \
                    (b["value"], b["method"], b["theorem"], b.get("how")):
                print(f"not bit-for-bit the same: {r['example']} d/d{r['wrt']}: baseline {b['value']!r} {b['method']} "
                      f"{b['theorem']} {b.get('how')}, this {r['value']!r} {r['method']} {r['theorem']} {r.get('how')}")
            elif r["expr"] != b["expr"]:
                print(f"closed forms printed differently: {r['example']} d/d{r['wrt']}")
            elif r.get("detail") != b.get("detail"):
                print(f"regular/boundary parts, notes or Theorem 8.1's numbers differ: {r['example']} d/d{r['wrt']}")
            else:
                same += 1
        if compared:
            print(f"{same} of {compared} partial derivatives the same in both versions (value, method, "
                  "Theorem 8.1's verdict, how and numbers, the closed form's text, notes)")
        return
    print("| jumps n | regular pieces | delta terms | ⟦p⟧ s | ⦇t⦈ normal form s | ⦇p⦈ s | method | values ok |")
    print("|---:|---:|---:|---:|---:|---:|---|---|")
    for r in bench_jumps(args.max):
        print(f"| {r['n']} | {r['pieces']} | {r['deltas']} | {r['denote_s']:.3f} | {r['ddenote_s']:.3f} "
              f"| {r['deriv_s']:.3f} | {r['method']} | {r['value_ok'] and r['deriv_ok']} |", flush=True)
    risk = bench_risk()
    if risk is not None:
        g = ", ".join(f"∂/∂{k} = {v:.10g}" for k, v in risk["gradient"].items())
        print(f"\nrisk.lgr exact gradient (3 partials): {risk['seconds']:.2f} s  ({g})")


if __name__ == "__main__":
    main()
