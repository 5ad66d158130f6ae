"""Issue 15's targets (its "Targets" section) against measured numbers: the table that
``bench/bench_issue15.py`` prints last (not a test; ``proofs_tests/test_bench18_targets.py`` tests it).
No measurement here: only the comparison, from the dictionaries the benchmark's sections return."""

from __future__ import annotations

PEERS = ("potto", "teg")

#: Issue 15's targets (its "Targets" section).
MB1_49_MS, MB1_100_MS = 20.0, 45.0
MB1_RATIO = {"potto": 100.0, "teg": 300.0}
LOAD_SHARE = 0.5
MB2_S = 1.0
ONE_SHOT_S = 0.3
IMPORT_S = 0.1
EXACT_S = 1.0


def _mark(ok: bool | None) -> str:
    return "—" if ok is None else ("✓" if ok else "✗")


def targets(m: dict) -> list[tuple[str, str, str, str]]:
    """Issue 15's targets against the measurements ``m`` (the dictionaries ``bench_issue15``'s
    ``run_*`` functions return, under "mb1", "mb2", "swaps", "one_shot", "import", "exact"; any may be missing): rows of
    (target, measured, ratio or margin, ✓ / ✗ / — for not measured)."""
    rows: list[tuple[str, str, str, str]] = []
    mb1 = m.get("mb1") or {}
    langur = {r["n"]: r for r in mb1.get("langur", [])}
    for n, limit in ((49, MB1_49_MS), (100, MB1_100_MS)):
        r = langur.get(n)
        ms = None if r is None else 1e3 * r["total"]
        rows.append((f"MB1 n = {n}, text to number ≤ {limit:g} ms CPU", "not measured" if ms is None else f"{ms:.1f} ms",
                     "" if ms is None else f"{ms / limit:.2f} of the target", _mark(None if ms is None else ms <= limit)))
    for p, ratio in MB1_RATIO.items():
        q = {r["n"]: r for r in mb1.get(p, [])}.get(49)
        r = langur.get(49)
        if q is None or r is None:
            rows.append((f"MB1 n = 49, ≥ {ratio:g}× {p} (text to number)", "not measured", "", _mark(None)))
            continue
        got = q["total"] / r["total"]
        rows.append((f"MB1 n = 49, ≥ {ratio:g}× {p} (text to number)",
                     f"{1e3 * q['total']:.0f} ms / {1e3 * r['total']:.1f} ms", f"{got:.0f}×", _mark(got >= ratio)))
    if langur:
        over = [n for n, r in sorted(langur.items()) if r["load"] > LOAD_SHARE * (r["link"] + r["eval"])]
        worst = max(r["load"] / (r["link"] + r["eval"]) for r in langur.values())
        rows.append((f"MB1 loading ≤ {LOAD_SHARE:g} × (link + eval) at every n",
                     "over at n = " + ", ".join(map(str, over)) if over else "at every n", f"worst {worst:.2f}",
                     _mark(not over)))
    else:
        rows.append((f"MB1 loading ≤ {LOAD_SHARE:g} × (link + eval) at every n", "not measured", "", _mark(None)))
    mb2 = (m.get("mb2") or {}).get("langur")
    if mb2 is None or m.get("swaps") != 50:
        rows.append((f"MB2 50 swaps, text to number ≤ {MB2_S:g} s CPU",
                     "not measured" if mb2 is None else f"{mb2['total']:.3f} s at {m.get('swaps')} swaps", "", _mark(None)))
    else:
        rows.append((f"MB2 50 swaps, text to number ≤ {MB2_S:g} s CPU", f"{mb2['total']:.3f} s",
                     f"{mb2['total'] / MB2_S:.2f} of the target", _mark(mb2["total"] <= MB2_S)))
    shots = m.get("one_shot") or {}
    mine = shots.get("langur eval --engine mc")
    if mine is None:
        rows.append((f"one-shot `langur eval examples/fig1.lgr --engine mc` ≤ {ONE_SHOT_S:g} s wall", "not measured",
                     "", _mark(None)))
    else:
        loads = shots.get("loads")
        at = f" (load {loads[0]:.1f}–{loads[1]:.1f})" if loads else ""
        rows.append((f"one-shot `langur eval examples/fig1.lgr --engine mc` ≤ {ONE_SHOT_S:g} s wall",
                     f"{mine['wall']:.3f} s wall{at}, {mine['cpu']:.3f} s CPU", f"{mine['wall'] / ONE_SHOT_S:.2f} of the target",
                     _mark(mine["wall"] <= ONE_SHOT_S)))
    for p in PEERS:
        theirs = shots.get(p)
        if mine is None or theirs is None:
            rows.append((f"one-shot faster than {p}'s (wall)", "not measured", "", _mark(None)))
            continue
        rows.append((f"one-shot faster than {p}'s (wall)", f"{mine['wall']:.3f} s against {theirs['wall']:.3f} s wall",
                     f"{theirs['wall'] / mine['wall']:.2f}× (CPU {theirs['cpu'] / mine['cpu']:.2f}×)",
                     _mark(mine["wall"] < theirs["wall"])))
    imp = m.get("import")
    rows.append((f"import of the Monte Carlo path ≤ {IMPORT_S:g} s beyond numpy",
                 "not measured" if imp is None else f"{imp['beyond']:.3f} s CPU",
                 "" if imp is None else f"{imp['beyond'] / IMPORT_S:.2f} of the target",
                 _mark(None if imp is None else imp["beyond"] <= IMPORT_S)))
    ex = m.get("exact")
    if ex is None or ex.get("max") is None:
        rows.append((f"exact `deriv` ≤ {EXACT_S:g} s on every example", "not measured", "", _mark(None)))
    else:
        rows.append((f"exact `deriv` ≤ {EXACT_S:g} s on every example",
                     f"max {ex['max']:.2f} s, median {ex['median']:.2f} s of {ex['count']}",
                     f"{ex['over']} over", _mark(ex["max"] <= EXACT_S and not ex["failed"])))
    return rows
