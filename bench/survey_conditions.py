"""Conditions a user writes, in one and two variables: does the front end complete them, how, and
do the two engines agree (branch front29; bench/history/2026-11-29.md#front29, "Conditions the front end refused …").

For each condition of :data:`C` (``param a``, the box ``[-1, 1]`` or ``[-1, 1]²``, an optional weight):
load it (refused: the diagnostic codes), the kind of completion of its condition (``closed/v/kbr``:
solved for ``v`` in closed form with k inverse branches; ``implicit/v/kbr``: implicit roots, ``/moving``
when the pieces' ends are moving turning points; ``+n ifge0``: kinks split), then
``langur eval --json`` and ``langur deriv --wrt a --json`` (both engines, 10,000 samples, seed 0):
agree when |exact − MC| ≤ 5 MC standard errors + the exact engine's error bound, and the Theorem
8.1 line.  Not a test (the expected values are in proofs_tests/test_front29.py); prints a table.

Run:  PYTHONPATH=TREE python -P bench/survey_conditions.py [OUT.jsonl] [--ids c01 d11 …] [--table OUT.jsonl …]
"""

import json
import os
import subprocess
import sys
import tempfile
import time

from langur.core import IfDiffeo, IfGe0, ImplicitRoot, subterms
from langur.diagnostics import LangurError
from langur.frontend import load_text

#: (id, box, condition, weight, a): box "1" is ([-1, 1]) d(x), "2" is ([-1, 1], [-1, 1]) d(x, y)
C = [
 ("c01", "1", "x <= a", "1", 0.3),
 ("c02", "1", "2*x + 1 <= 3*a", "1 + x", 0.3),
 ("c03", "1", "exp(x) <= a + 1", "1", 0.3),
 ("c04", "1", "exp(2*x - 1) <= a + 0.5", "1 + x", 0.3),
 ("c05", "1", "log(x + 2) <= a + 0.5", "1", 0.3),
 ("c06", "1", "sqrt(x + 1) <= a + 0.8", "1", 0.3),
 ("c07", "1", "x^3 <= a", "1", 0.3),
 ("c08", "1", "tanh(3*x) <= a", "1", 0.3),
 ("c09", "1", "atan(2*x) <= a", "1 + x", 0.3),
 ("c10", "1", "erf(x) <= a - 0.5", "1", 0.3),
 ("c11", "1", "erf(2*x + 0.1) <= a", "1 + x", 0.3),
 ("c12", "1", "asin(x) <= a", "1", 0.3),
 ("c13", "1", "acos(x) <= a + 1", "1", 0.3),
 ("c14", "1", "atanh(x/2) <= a", "1", 0.3),
 ("c15", "1", "tan(x) <= a", "1", 0.3),
 ("c16", "1", "sin(x) <= a", "1", 0.3),
 ("c17", "1", "cos(2*x) >= a", "1", 0.3),
 ("c18", "1", "exp(atan(x)) <= a + 1", "1", 0.3),
 ("c19", "1", "log(exp(x) + 1) <= a + 0.5", "1", 0.3),
 ("c20", "1", "sqrt(x^2 + 1) <= a + 1", "1", 0.3),
 ("c21", "1", "1/(x + 2) <= a", "1", 0.5),
 ("c22", "1", "1/(erf(x) + 2) <= a", "1", 0.4),
 ("c23", "1", "sqrt(erf(x) + 2) >= a + 1", "1", 0.3),
 ("c24", "1", "1/(exp(x) + 1) <= a", "1", 0.4),
 ("c25", "1", "x/(1 + x^2) <= a", "1", 0.3),
 ("c26", "1", "1/(tanh(x) + 2) <= a", "1", 0.5),
 ("c27", "1", "sqrt(atan(x) + 2) <= a + 1.1", "1", 0.3),
 ("c28", "1", "exp(x) + x <= a + 1", "1", 0.3),
 ("c29", "1", "x^3 - x <= a", "exp(x/2)", 0.2),
 ("c30", "1", "erf(x) + x <= a", "1", 0.3),
 ("c31", "1", "erf(x)^2 <= a", "1", 0.3),
 ("c32", "1", "abs(x - a) <= 0.3", "1 + x", 0.3),
 ("c33", "1", "max(x, 0.2) <= a + 0.3", "1", 0.3),
 ("c34", "1", "min(exp(x), 2) <= a + 1", "1", 0.3),
 ("c35", "1", "abs(erf(x)) <= a", "1", 0.3),
 ("c36", "1", "x * exp(x) <= a", "1", 0.3),
 ("c37", "1", "exp(-x^2) >= a + 0.5", "1", 0.3),
 ("c38", "1", "log(1 + x^2) <= a", "1", 0.3),
 ("c39", "1", "sqrt(1 - x^2) >= a + 0.5", "1", 0.3),
 ("c40", "1", "erf(x)/(erf(x) + 2) <= a", "1", 0.2),
 ("c41", "1", "atan2(1, x) <= a + 1", "1", 0.3),
 ("c42", "1", "1/sqrt(x + 2) <= a + 0.5", "1", 0.3),
 ("c43", "1", "exp(sqrt(x + 1)) <= a + 2", "1", 0.3),
 ("c44", "1", "erf(erf(x)) <= a", "1", 0.3),
 ("c45", "1", "asin(x/2) + x <= a", "1", 0.3),
 ("c46", "1", "exp(erf(x)) <= a + 1", "1", 0.3),
 ("c47", "1", "log(erf(x) + 2) <= a + 0.5", "1", 0.3),
 ("c48", "1", "erf(x) * exp(x) <= a", "1", 0.3),
 ("c49", "1", "1/(erf(x) + 2)^2 <= a", "1", 0.2),
 ("c50", "1", "(erf(x) + 2)^(1/3) <= a + 1", "1", 0.3),
 ("d01", "2", "y <= x + a", "1", 0.3),
 ("d02", "2", "y - x^2 <= a", "1 + x*y", 0.3),
 ("d03", "2", "y - exp(x) + 1 <= a", "1", 0.3),
 ("d04", "2", "y - erf(x) <= a", "1 + x", 0.3),
 ("d05", "2", "x^2 + y^2 <= a + 0.5", "1", 0.3),
 ("d06", "2", "x * y <= a", "1", 0.3),
 ("d07", "2", "exp(x) * y <= a + 0.5", "1", 0.3),
 ("d08", "2", "(x + 2) * (y + 2) <= a + 4", "1", 0.3),
 ("d09", "2", "min(x, y) >= a", "1", 0.3),
 ("d10", "2", "max(abs(x), abs(y)) <= a + 0.2", "1", 0.3),
 ("d11", "2", "atan2(y, x) <= a", "1", 0.3),
 ("d12", "2", "erf(x) + erf(y) <= a", "1", 0.3),
 ("d13", "2", "1/(erf(x) + 2) + y <= a + 0.5", "1", 0.3),
 ("d14", "2", "sqrt(x + y + 3) <= a + 1.5", "1", 0.3),
 ("d15", "2", "exp(x + y) <= a + 1", "1", 0.3),
 ("d16", "2", "y - 1/(x + 2) <= a", "1", 0.3),
 ("d17", "2", "log(x + 2) + log(y + 2) <= a + 1", "1", 0.3),
 ("d18", "2", "tanh(x) + tanh(y) <= a", "1", 0.3),
 ("d19", "2", "x^3 + x + y^3 + y - a >= 0", "1", 0.3),
 ("d20", "2", "y * exp(y) + x <= a", "1", 0.3),
 ("d21", "2", "y - sqrt(erf(x) + 2) <= a - 1.5", "1", 0.3),
 ("d22", "2", "erf(x + y) <= a", "1", 0.3),
 ("d23", "2", "asin(x * y) <= a", "1", 0.3),
 ("d24", "2", "x / (y + 2) <= a", "1", 0.3),
 ("d25", "2", "erf(x) * y <= a", "1", 0.1),
 ("d26", "2", "y + x / (erf(y) + 2) <= a", "1", 0.3),
 ("d27", "2", "atan2(y - a, x + 2) <= 0.2", "1", 0.3),
 ("d28", "2", "y * (erf(x) + 2) <= a + 1", "1", 0.3),
 ("d29", "2", "erf(x) + y^3 <= a", "1", 0.3),
 ("d30", "2", "exp(erf(x) + y) <= a + 1", "1", 0.3),
]

def text(box, cond, weight, a):
    if box == "1":
        dom, dv = "([-1, 1])", "d(x)"
    else:
        dom, dv = "([-1, 1], [-1, 1])", "d(x, y)"
    w = "" if weight == "1" else f" * ({weight})"
    return f"param a = {a}\nint {dom} [{cond}]{w} {dv}\n"
C += [
 ("d31", "2", "sqrt(x + 2) + x + sqrt(y + 2) + y <= a + 0.5", "1", 0.3),
 ("d32", "2", "tanh(x) + x + tanh(y) + y <= a", "1", 0.3),
 ("d33", "2", "x + y + erf(x + y) <= a", "1", 0.3),
 ("d34", "2", "erf(x)*erf(y) + x + y <= a", "1", 0.3),
 ("d35", "2", "y + atan(y) + x^3 <= a", "1", 0.3),
]


def kinds(psi):
    roots = [r for b in psi.branches for c in (*b.components, *b.guards) for r in subterms(c) if isinstance(r, ImplicitRoot)]
    if psi.name:
        return "declared"
    if not roots:
        return f"closed/{psi.solved_for}/{len(psi.branches)}br"
    moving = any(r.index is not None for r in roots)
    return f"implicit/{psi.solved_for}/{len(psi.branches)}br" + ("/moving" if moving else "")


def classify(src):
    """The completion of the condition (the box's bounds left out), or "refused CODES"."""
    try:
        p = load_text(src)
    except LangurError as e:
        return "refused " + ",".join(d.code for d in e.diagnostics)
    ks, kinks = [], 0
    for t in subterms(p.program.body):
        if isinstance(t, IfDiffeo):
            ks.append(kinds(t.psi))
        elif isinstance(t, IfGe0):
            kinks += 1
    for v in ("x", "y"):  # each variable's two bounds are affine conditions solved for it
        for _ in range(2):
            if f"closed/{v}/1br" in ks and len(ks) > 1:
                ks.remove(f"closed/{v}/1br")
    return " + ".join(sorted(ks)) + (f" (+{kinks} ifge0)" if kinks else "")


def cli(args, path, timeout=240):
    t0 = time.time()
    try:
        r = subprocess.run([sys.executable, "-P", "-m", "langur", *args, path, "--json"], capture_output=True,
                           text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {"timeout": True, "secs": timeout}
    try:
        out = json.loads(r.stdout)
    except ValueError:
        out = {"rc": r.returncode, "stdout": r.stdout[-500:], "stderr": r.stderr[-800:]}
    out["secs"] = round(time.time() - t0, 1)
    return out


def survey(out, ids):
    folder = tempfile.mkdtemp(prefix="survey_conditions_")
    with open(out, "a") as f:
        for cid, box, cond, weight, a in C:
            if ids and cid not in ids:
                continue
            src = text(box, cond, weight, a)
            path = os.path.join(folder, f"{cid}.lgr")
            with open(path, "w") as g:
                g.write(src)
            kind = classify(src)
            rec = {"id": cid, "cond": cond, "weight": weight, "a": a, "kind": kind}
            if not kind.startswith("refused"):
                rec["eval"] = cli(["eval"], path)
                rec["deriv"] = cli(["deriv", "--wrt", "a"], path)
            f.write(json.dumps(rec) + "\n")
            f.flush()
            print(cid, kind, flush=True)


def agree(rec):
    if not rec or rec.get("timeout"):
        return "timeout", ""
    if "exact" not in rec:
        return "error", (rec.get("stdout", "") + rec.get("stderr", ""))[-200:].replace("\n", " ")
    ex, mc = rec.get("exact") or {}, rec.get("mc") or {}
    if rec.get("undefined"):
        return "undefined", str(rec["undefined"])[:80]
    ev, mv, se = ex.get("value"), mc.get("value"), mc.get("stderr")
    if ev is None or mv is None:
        return "novalue", f"exact={ev} mc={mv} {json.dumps(rec.get('diagnostics'))[:150]}"
    err = ex.get("error") or 0
    tol = 5 * (se or 0) + (err or 0) + 1e-9 * (1 + abs(ev))
    ok = abs(ev - mv) <= tol
    return ("agree" if ok else "DISAGREE"), f"{ev:.6g} vs {mv:.6g}±{se:.2g} [{ex.get('method')}]"


def table(paths):
    rows = sorted((json.loads(line) for p in paths for line in open(p)), key=lambda r: r["id"])
    print("| id | condition | completion | ⟦p⟧: exact vs MC | ⦇p⦈ d/da: exact vs MC | Thm 8.1, CPU-loaded wall s |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        if r["kind"].startswith("refused"):
            print(f"| {r['id']} | `[{r['cond']}]` | {r['kind']} | — | — | — |")
            continue
        e, ed = agree(r.get("eval"))
        d, dd = agree(r.get("deriv"))
        th = ((r.get("deriv") or {}).get("theorem_8_1") or {}).get("holds")
        secs = f"{(r.get('eval') or {}).get('secs')}+{(r.get('deriv') or {}).get('secs')}"
        print(f"| {r['id']} | `[{r['cond']}]` | {r['kind']} | {e}: {ed} | {d}: {dd} | {th}, {secs} |")


if __name__ == "__main__":
    args = sys.argv[1:]
    if args and args[0] == "--table":
        table(args[1:])
    else:
        out = args[0] if args and not args[0].startswith("--") else "survey_conditions.jsonl"
        survey(out, set(args[args.index("--ids") + 1:]) if "--ids" in args else set())
        table([out])
