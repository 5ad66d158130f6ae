"""Issue 15's targets (its "Targets" section) against measured numbers: the table that
``bench/bench_issue15.py`` prints last (not a test; ``proofs_tests/test_bench18_targets.py`` and
``test_bench23_steady.py`` test it).  No measurement here: only the comparison, from the dictionaries
the benchmark's sections return.

A measurement taken once (a number) gets ✓ or ✗.  One taken in rounds (the keys ``rounds``,
``paired``, ``instructions``, ``slowdown`` below, which ``bench_issue15`` fills) gets ✓, ✗ or
*borderline* from ``steady``'s bands: the least and the typical value over the rounds (the least
divided by the host's measured slowdown), the instructions where the target compares two parts or
two programs; borderline when the limit lies inside what was measured."""

from __future__ import annotations

import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # (steady, beside this file, run as a script with -P)

from steady import all_of, band, combine, verdict  # noqa: E402

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


def _within(values, limit: float, slowdown: float, scale: float, unit: str, digits: int) -> tuple[str, str, str]:
    """(measured, ratio, verdict) of an upper ``limit`` from values over rounds: the band is
    [least ÷ slowdown, typical] (``steady``); shown × ``scale`` in ``unit``."""
    least, typical = band(values)
    low = least / slowdown
    shown = f"least {scale * least:.{digits}f} {unit}, typical {scale * typical:.{digits}f} {unit} of {len(values)}"
    if slowdown > 1:
        shown += f"; host {slowdown:.2f}× slower than the reference: least ÷ {slowdown:.2f} = {scale * low:.{digits}f} {unit}"
    return shown, f"{low / limit:.2f}–{typical / limit:.2f} of the target", verdict(low, typical, limit)


def _share_rows(langur: dict) -> tuple[str, str, str]:
    """Loading ≤ ½ (link + eval) at every n from rounds: per n, the band of the rounds' paired ratios
    (least, typical) and, if counted, the ratio of the instructions; each n's verdict combines both."""
    per_n, parts, worst = [], [], 0.0
    for n, r in sorted(langur.items()):
        low, high = band(r["share_rounds"])
        worst = max(worst, low)
        by_cpu = verdict(low, high, LOAD_SHARE)
        counted = r.get("share_instructions")
        by_count = None if counted is None else verdict(counted, counted, LOAD_SHARE)
        per_n.append(combine(by_cpu, by_count))
        parts.append(f"n = {n}: {low:.2f}–{high:.2f}" + ("" if counted is None else f" (instructions {counted:.3f})")
                     + f" {per_n[-1]}")
    return "; ".join(parts), f"least over n's worst {worst:.2f}", all_of(per_n)


def targets(m: dict) -> list[tuple[str, str, str, str]]:
    """Issue 15's targets against the measurements ``m`` (the dictionaries ``bench_issue15``'s
    ``run_*`` functions return, under "mb1", "mb2", "swaps", "one_shot", "import", "exact"; any may be missing): rows of
    (target, measured, ratio or margin, ✓ / ✗ / — for not measured)."""
    rows: list[tuple[str, str, str, str]] = []
    mb1 = m.get("mb1") or {}
    langur = {r["n"]: r for r in mb1.get("langur", [])}
    slow = m.get("slowdown", 1.0)
    for n, limit in ((49, MB1_49_MS), (100, MB1_100_MS)):
        r = langur.get(n)
        if r is not None and r.get("total_rounds"):
            rows.append((f"MB1 n = {n}, text to number ≤ {limit:g} ms CPU",
                         *_within(r["total_rounds"], limit / 1e3, slow, 1e3, "ms", 1)))
            continue
        ms = None if r is None else 1e3 * r["total"]
        rows.append((f"MB1 n = {n}, text to number ≤ {limit:g} ms CPU", "not measured" if ms is None else f"{ms:.1f} ms",
                     "" if ms is None else f"{ms / limit:.2f} of the target", _mark(None if ms is None else ms <= limit)))
    for p, ratio in MB1_RATIO.items():
        q = {r["n"]: r for r in mb1.get(p, [])}.get(49)
        r = langur.get(49)
        if q is None or r is None:
            rows.append((f"MB1 n = 49, ≥ {ratio:g}× {p} (text to number)", "not measured", "", _mark(None)))
            continue
        if q.get("paired") and r.get("total_rounds"):
            rows.append((f"MB1 n = 49, ≥ {ratio:g}× {p} (text to number)", *_peer_ratio(q, r, ratio)))
            continue
        got = q["total"] / r["total"]
        rows.append((f"MB1 n = 49, ≥ {ratio:g}× {p} (text to number)",
                     f"{1e3 * q['total']:.0f} ms / {1e3 * r['total']:.1f} ms", f"{got:.0f}×", _mark(got >= ratio)))
    if langur and all(r.get("share_rounds") for r in langur.values()):
        rows.append((f"MB1 loading ≤ {LOAD_SHARE:g} × (link + eval) at every n", *_share_rows(langur)))
    elif langur:
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
    elif mb2.get("rounds"):
        rows.append((f"MB2 50 swaps, text to number ≤ {MB2_S:g} s CPU", *_within(mb2["rounds"], MB2_S, slow, 1, "s", 3)))
    else:
        rows.append((f"MB2 50 swaps, text to number ≤ {MB2_S:g} s CPU", f"{mb2['total']:.3f} s",
                     f"{mb2['total'] / MB2_S:.2f} of the target", _mark(mb2["total"] <= MB2_S)))
    shots = m.get("one_shot") or {}
    mine = shots.get("langur eval --engine mc")
    if mine is None:
        rows.append((f"one-shot `langur eval examples/fig1.lgr --engine mc` ≤ {ONE_SHOT_S:g} s wall", "not measured",
                     "", _mark(None)))
    elif mine.get("walls"):
        rows.append((f"one-shot `langur eval examples/fig1.lgr --engine mc` ≤ {ONE_SHOT_S:g} s wall",
                     *_one_shot(mine, shots.get("loads"), slow)))
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
        if theirs.get("paired"):
            rows.append((f"one-shot faster than {p}'s (wall)", *_faster(p, theirs, shots.get("instructions") or {})))
            continue
        rows.append((f"one-shot faster than {p}'s (wall)", f"{mine['wall']:.3f} s against {theirs['wall']:.3f} s wall",
                     f"{theirs['wall'] / mine['wall']:.2f}× (CPU {theirs['cpu'] / mine['cpu']:.2f}×)",
                     _mark(mine["wall"] < theirs["wall"])))
    imp = m.get("import")
    if imp is not None and imp.get("rounds"):
        rows.append((f"import of the Monte Carlo path ≤ {IMPORT_S:g} s beyond numpy",
                     *_within(imp["rounds"], IMPORT_S, slow, 1, "s CPU", 3)))
    else:
        rows.append((f"import of the Monte Carlo path ≤ {IMPORT_S:g} s beyond numpy",
                     "not measured" if imp is None else f"{imp['beyond']:.3f} s CPU",
                     "" if imp is None else f"{imp['beyond'] / IMPORT_S:.2f} of the target",
                     _mark(None if imp is None else imp["beyond"] <= IMPORT_S)))
    ex = m.get("exact")
    if ex is None or ex.get("max") is None:
        rows.append((f"exact `deriv` ≤ {EXACT_S:g} s on every example", "not measured", "", _mark(None)))
    elif ex.get("again"):
        rows.append((f"exact `deriv` ≤ {EXACT_S:g} s on every example", *_exact(ex, slow)))
    else:
        rows.append((f"exact `deriv` ≤ {EXACT_S:g} s on every example",
                     f"max {ex['max']:.2f} s, median {ex['median']:.2f} s of {ex['count']}",
                     f"{ex['over']} over", _mark(ex["max"] <= EXACT_S and not ex["failed"])))
    return rows


def _one_shot(mine: dict, loads, slowdown: float) -> tuple[str, str, str]:
    """≤ 0.3 s wall from rounds: the band runs from the least CPU seconds (÷ the host's slowdown: on an
    idle host a process's wall time is its CPU time and little more, and never less) to the typical
    wall time (the median over rounds: on a loaded host the process also waits for a core)."""
    low = min(mine.get("cpus") or [mine["cpu"]]) / slowdown
    typical = statistics.median(mine["walls"])
    at = f" (load {loads[0]:.1f}–{loads[1]:.1f})" if loads else ""
    shown = (f"least {min(mine['walls']):.3f} s, typical {typical:.3f} s wall of {len(mine['walls'])}{at}; "
             f"least CPU {low * slowdown:.3f} s" + (f" ÷ host slowdown {slowdown:.2f} = {low:.3f} s" if slowdown > 1 else ""))
    return shown, f"{low / ONE_SHOT_S:.2f}–{typical / ONE_SHOT_S:.2f} of the target", verdict(low, typical, ONE_SHOT_S)


def _peer_ratio(q: dict, r: dict, ratio: float) -> tuple[str, str, str]:
    """≥ ``ratio``× a peer at n = 49 from rounds: the band spans the ratio of the two least times, the
    median of the rounds' paired ratios (the peer's run over Langur's least just before it), and the
    same with the peer's time divided by the host's slowdown beside it (the calibration measured next
    to the peer's run over the run's fastest: a run of seconds cannot dodge a slow minute as Langur's
    least of milliseconds can)."""
    least = min(q["paired"], key=lambda x: x["peer"])["peer"] / min(r["total_rounds"])
    raw = statistics.median(x["peer"] / x["langur"] for x in q["paired"])
    corrected = statistics.median(x["peer"] / x["langur"] / x.get("host", 1.0) for x in q["paired"])
    low, high = min(least, raw, corrected), max(least, raw, corrected)
    return (f"{len(q['paired'])} paired rounds: {low:.0f}×–{high:.0f}× (least ÷ least {least:.0f}×, paired median "
            f"{raw:.0f}×, host-corrected {corrected:.0f}×)", f"{low:.0f}×–{high:.0f}×", verdict(low, high, ratio, at_most=False))


def _faster(p: str, theirs: dict, counts: dict) -> tuple[str, str, str]:
    """Faster than a peer's one-shot process: the rounds' paired ratios (their wall over ours, and their
    CPU over ours, each round's processes run one after the other) give a band, its ends the medians of
    the wall and of the CPU ratios; the instructions' ratio, if counted, a second verdict."""
    walls = statistics.median(x["wall"] for x in theirs["paired"])
    cpus = statistics.median(x["cpu"] for x in theirs["paired"])
    low, high = min(walls, cpus), max(walls, cpus)
    by_time = verdict(low, high, 1.0, at_most=False)
    mine, others = counts.get("langur eval --engine mc"), counts.get(p)
    shown = f"{p}'s time ÷ ours, paired over {len(theirs['paired'])} rounds: wall {walls:.2f}×, CPU {cpus:.2f}×"
    if mine and others:
        by_count = verdict(others / mine, others / mine, 1.0, at_most=False)
        shown += f"; instructions {others / 1e6:,.0f} M ÷ {mine / 1e6:,.0f} M = {others / mine:.3f}× {by_count}"
    else:
        by_count = None
    return shown, f"{low:.2f}×–{high:.2f}×", combine(by_time, by_count)


def _exact(ex: dict, slowdown: float) -> tuple[str, str, str]:
    """Exact ``deriv`` ≤ 1 s per example, the slowest partials measured again (``again``: their CPU
    seconds in every run, the first included): the band's high end is the largest typical value, its low
    end the largest least value ÷ the host's slowdown; the partials not measured again were under the
    threshold of a second look, far from the limit."""
    typical = {name: statistics.median(runs) for name, runs in ex["again"].items()}
    least = {name: min(runs) for name, runs in ex["again"].items()}
    high = max(typical.values())
    low = max(least.values()) / slowdown
    over = [name for name, t in typical.items() if min(least[name] / slowdown, t) > EXACT_S]
    worst = max(typical, key=typical.get)
    shown = (f"max typical {high:.2f} s ({worst}), max least {max(least.values()):.2f} s"
             + (f" ÷ host slowdown {slowdown:.2f} = {low:.2f} s" if slowdown > 1 else "")
             + f"; median {ex['median']:.2f} s of {ex['count']}; {len(ex['again'])} slowest measured "
             f"{len(next(iter(ex['again'].values())))} times")
    mark = "✗" if ex["failed"] else verdict(low, high, EXACT_S)
    return shown, f"{len(over)} over in every run" + (f", not finished: {', '.join(ex['failed'])}" if ex["failed"] else ""), mark


def main(argv=None) -> None:
    """``python bench/issue15_targets.py RUN.json``: the targets table again from a run's ``--json`` (with
    this version's verdicts; the host's slowdown recomputed from the run's calibrations)."""
    import argparse
    import json

    from steady import slowdown

    ap = argparse.ArgumentParser(description=main.__doc__)
    ap.add_argument("json", help="the file bench_issue15.py --json wrote")
    m = json.load(open(ap.parse_args(argv).json))
    if m.get("calibrations"):
        m["slowdown"] = slowdown(m["calibrations"])
    print("| target | measured | ratio | |\n|---|---|---|---|")
    for row in targets(m):
        print("| " + " | ".join(row) + " |")


if __name__ == "__main__":
    main()
