"""bench/steady.py and issue15_targets' verdicts from rounds (branch bench23).

No timing here: the numbers are made up, and every band, verdict and instruction difference below
is worked out by hand from them and issue 15's targets (MB1 n = 49 ≤ 20 ms, loading ≤ ½ (link +
eval), ≥ 100× Potto, MB2 ≤ 1 s, one-shot ≤ 0.3 s wall and faster than the peers', exact deriv ≤ 1 s).
A limit inside the measured band is "borderline", never ✓ or ✗; a host slower than the reference
widens the band's low end only.
"""

import os
import sys

import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bench"))

import steady  # noqa: E402
from issue15_targets import targets  # noqa: E402

# -- steady's arithmetic -------------------------------------------------------------------------------------

def test_verdict_of_a_band_against_an_upper_and_a_lower_limit():
    assert steady.verdict(0.010, 0.015, 0.020) == "✓"  # all of [10, 15] ms under 20
    assert steady.verdict(0.021, 0.030, 0.020) == "✗"  # all over
    assert steady.verdict(0.015, 0.025, 0.020) == "borderline"  # 20 inside [15, 25]
    assert steady.verdict(0.025, 0.015, 0.020) == "borderline"  # (ends given in either order)
    assert steady.verdict(0.020, 0.020, 0.020) == "✓"  # at the limit is within it
    # a ratio to reach (≥ 100×)
    assert steady.verdict(120, 180, 100, at_most=False) == "✓"
    assert steady.verdict(60, 90, 100, at_most=False) == "✗"
    assert steady.verdict(80, 130, 100, at_most=False) == "borderline"


def test_band_is_least_and_median():
    assert steady.band([0.030, 0.010, 0.020, 0.050]) == (0.010, 0.025)
    assert steady.band([7.0]) == (7.0, 7.0)


def test_slowdown_against_the_reference_never_below_one():
    ref = 0.004
    assert steady.slowdown([0.010, 0.006, 0.008], ref) == pytest.approx(1.5)  # least 6 ms ÷ 4 ms
    assert steady.slowdown([0.003, 0.005], ref) == 1.0  # a faster host: no correction


def test_combine_and_all_of():
    assert steady.combine("✓", "✓") == "✓"
    assert steady.combine("✗", None) == "✗"
    assert steady.combine("✓", "✗") == "borderline"
    assert steady.combine(None, None) == "—"
    assert steady.all_of(["✓", "borderline", "✗"]) == "✗"
    assert steady.all_of(["✓", "borderline"]) == "borderline"
    assert steady.all_of(["✓", "✓"]) == "✓"


def test_per_operation_is_the_difference_over_k():
    # a process doing 3 loads: 620,168,030 instructions; the same doing none: 604,160,962
    assert steady.per_operation(620_168_030, 604_160_962, 3) == pytest.approx(16_007_068 / 3)
    with pytest.raises(ValueError):
        steady.per_operation(600, 604, 3)  # fewer with k calls than with none: a broken measurement
    with pytest.raises(ValueError):
        steady.per_operation(604, 600, 0)


def test_parse_refs_reads_cachegrind_summary():
    err = "==22209== Cachegrind, a cache and branch-prediction profiler\n==22209== \n==22209== I   refs:      518,462,418\n"
    assert steady.parse_refs(err) == 518_462_418
    with pytest.raises(ValueError):
        steady.parse_refs("no summary")


def test_instructions_without_valgrind_is_none(monkeypatch):
    monkeypatch.setattr(steady.shutil, "which", lambda name: None)
    assert steady.instructions(["python", "-c", "pass"], {}, ".") is None


def test_calibrate_is_the_least_of_its_calls():
    ticks = iter([0.0, 0.5, 1.0, 1.2, 2.0, 2.9])  # calls of 0.5, 0.2, 0.9 s
    assert steady.calibrate(3, clock=lambda: next(ticks)) == pytest.approx(0.2)


# -- the targets from rounds ------------------------------------------------------------------------------------

def _row(m, start):
    (row,) = [r for r in targets(m) if r[0].startswith(start)]
    return row


def _mb1(n, totals, shares, **extra):
    return {"n": n, "load": 0.001, "link": 0.001, "eval": 0.001, "total": sorted(totals)[len(totals) // 2],
            "total_rounds": totals, "share_rounds": shares, **extra}


def test_mb1_absolute_target_is_borderline_when_the_limit_is_inside_the_rounds():
    # n = 49 in 3 rounds: 18, 22, 25 ms: least 18 ≤ 20 < typical 22 → borderline (old code: the median 22, ✗)
    m = {"mb1": {"langur": [_mb1(49, [0.018, 0.022, 0.025], [0.3, 0.3, 0.3])]}}
    row = _row(m, "MB1 n = 49, text")
    assert row[3] == "borderline"
    assert row[2] == "0.90–1.10 of the target"
    # the same rounds all under 20 ms: ✓; all over 20 ms: ✗
    assert _row({"mb1": {"langur": [_mb1(49, [0.015, 0.016, 0.019], [0.3] * 3)]}}, "MB1 n = 49, text")[3] == "✓"
    assert _row({"mb1": {"langur": [_mb1(49, [0.021, 0.024, 0.030], [0.3] * 3)]}}, "MB1 n = 49, text")[3] == "✗"


def test_a_slow_host_widens_the_low_end_only():
    rounds = [0.021, 0.024, 0.030]  # all over 20 ms: ✗ on a host as fast as the reference
    m = {"mb1": {"langur": [_mb1(49, rounds, [0.3] * 3)]}, "slowdown": 1.2}
    row = _row(m, "MB1 n = 49, text")
    # least 21 ms ÷ 1.2 = 17.5 ms ≤ 20 < typical 24 ms: borderline; never ✓ from a slow host
    assert row[3] == "borderline" and "17.5 ms" in row[1]
    assert row[2] == "0.88–1.20 of the target"
    m["slowdown"] = 1.04  # 21 ÷ 1.04 = 20.2 ms, still over: ✗
    assert _row(m, "MB1 n = 49, text")[3] == "✗"


def test_loading_share_combines_the_rounds_and_the_instructions_at_every_n():
    rows = [_mb1(1, [0.002] * 3, [1.6, 1.9, 2.9], share_instructions=1.608),  # ✗ both ways
            _mb1(10, [0.005] * 3, [0.33, 0.51, 0.78], share_instructions=0.528),  # CPU band 0.33–0.51: borderline
            _mb1(49, [0.015] * 3, [0.22, 0.25, 0.28])]  # ✓, not counted
    row = _row({"mb1": {"langur": rows}}, "MB1 loading")
    assert row[3] == "✗"  # n = 1 is over by both measures
    assert "n = 1: 1.60–1.90 (instructions 1.608) ✗" in row[1]
    assert "n = 10: 0.33–0.51 (instructions 0.528) borderline" in row[1]
    assert "n = 49: 0.22–0.25 ✓" in row[1]
    # without n = 1: borderline (n = 10), not a coin flip between ✓ and ✗
    assert _row({"mb1": {"langur": rows[1:]}}, "MB1 loading")[3] == "borderline"
    # instructions under ½ and every round under ½: ✓
    ok = [_mb1(10, [0.005] * 3, [0.40, 0.45, 0.48], share_instructions=0.46)]
    assert _row({"mb1": {"langur": ok}}, "MB1 loading")[3] == "✓"
    # instructions over ½ while the rounds are under it: the two measures disagree, borderline
    split = [_mb1(10, [0.005] * 3, [0.40, 0.45, 0.48], share_instructions=0.53)]
    assert _row({"mb1": {"langur": split}}, "MB1 loading")[3] == "borderline"


def test_peer_ratio_from_paired_rounds():
    langur = _mb1(49, [0.015, 0.020, 0.025], [0.3] * 3)
    # Potto's rounds 2.4, 1.8, 2.1 s beside Langur's leasts 0.020, 0.015, 0.016 s, the host 1.0, 1.5, 1.0× slower:
    # paired 120, 120, 131.25 → median 120; host-corrected 120, 80, 131.25 → 120; least ÷ least 1.8 / 0.015 = 120
    paired = [{"peer": 2.4, "langur": 0.020, "host": 1.0}, {"peer": 1.8, "langur": 0.015, "host": 1.5},
              {"peer": 2.1, "langur": 0.016, "host": 1.0}]
    m = {"mb1": {"langur": [langur], "potto": [{"n": 49, "total": 2.1, "paired": paired}]}}
    row = _row(m, "MB1 n = 49, ≥ 100× potto")
    assert row[2:] == ("120×–120×", "✓")
    # against 300× (Teg's target) the same numbers are ✗; a band across 300 is borderline
    m = {"mb1": {"langur": [langur], "teg": [{"n": 49, "total": 2.1, "paired": paired}]}}
    assert _row(m, "MB1 n = 49, ≥ 300× teg")[3] == "✗"
    wide = [{"peer": 6.0, "langur": 0.020, "host": 1.0}, {"peer": 5.0, "langur": 0.015, "host": 1.5},
            {"peer": 4.8, "langur": 0.016, "host": 1.0}]
    # paired 300, 333.3, 300 → 300; host-corrected 300, 222.2, 300 → 300; least ÷ least 4.8 / 0.015 = 320
    m = {"mb1": {"langur": [langur], "teg": [{"n": 49, "total": 5.0, "paired": wide}]}}
    assert _row(m, "MB1 n = 49, ≥ 300× teg")[2:] == ("300×–320×", "✓")
    wide[0]["peer"] = 5.0  # paired 250, 333.3, 300 → 300; corrected 250, 222.2, 300 → 250: band 250–320, borderline
    assert _row(m, "MB1 n = 49, ≥ 300× teg")[2:] == ("250×–320×", "borderline")


def test_mb2_import_and_one_shot_from_rounds():
    m = {"swaps": 50, "mb2": {"langur": {"total": 0.9, "rounds": [0.8, 0.9, 1.3]}},
         "import": {"beyond": 0.03, "rounds": [0.02, 0.03, 0.05]},
         "one_shot": {"langur eval --engine mc": {"wall": 0.35, "cpu": 0.2, "walls": [0.25, 0.35, 0.7],
                                                  "cpus": [0.2, 0.22, 0.21]}}}
    assert _row(m, "MB2")[3] == "✓"  # typical 0.9 s ≤ 1 s (the old code said ✓ from its one run too)
    m["mb2"]["langur"]["rounds"] = [0.8, 1.1, 1.3]
    assert _row(m, "MB2")[2:] == ("0.80–1.10 of the target", "borderline")
    assert _row(m, "import")[3] == "✓"
    # one-shot: least CPU 0.2 s ≤ 0.3 < typical 0.35 s wall: borderline (the old code: median 0.35, ✗)
    assert _row(m, "one-shot `langur eval")[2:] == ("0.67–1.17 of the target", "borderline")
    shot = m["one_shot"]["langur eval --engine mc"]
    shot["walls"] = [0.2, 0.25, 0.28]  # typical 0.25 s wall: ✓
    assert _row(m, "one-shot `langur eval")[3] == "✓"
    shot["walls"], shot["cpus"] = [0.5, 0.6, 0.7], [0.32, 0.33, 0.4]  # even the least CPU over 0.3 s: ✗
    assert _row(m, "one-shot `langur eval")[3] == "✗"


def test_faster_than_a_peer_combines_paired_rounds_and_instructions():
    mine = {"wall": 0.20, "cpu": 0.18, "walls": [0.2, 0.2, 0.2]}
    # Teg's wall over ours in three rounds 0.9, 1.1, 1.2 (median 1.1), CPU 0.95, 0.97, 1.05 (median 0.97): band 0.97–1.1
    teg = {"wall": 0.2, "cpu": 0.18, "paired": [{"wall": 0.9, "cpu": 0.95}, {"wall": 1.1, "cpu": 0.97},
                                                {"wall": 1.2, "cpu": 1.05}]}
    m = {"one_shot": {"langur eval --engine mc": mine, "teg": teg}}
    row = _row(m, "one-shot faster than teg")
    assert row[2:] == ("0.97×–1.10×", "borderline")
    # instructions 520 M (Teg) ÷ 533 M (ours) = 0.976: ✗ by count; with a time band all above 1: ✓ by time → borderline
    teg["paired"] = [{"wall": 1.2, "cpu": 1.1}] * 3
    m["one_shot"]["instructions"] = {"langur eval --engine mc": 533e6, "teg": 520e6}
    row = _row(m, "one-shot faster than teg")
    assert row[3] == "borderline" and "0.976×" in row[1]
    # both say slower: ✗
    teg["paired"] = [{"wall": 0.8, "cpu": 0.9}] * 3
    assert _row(m, "one-shot faster than teg")[3] == "✗"


def test_exact_deriv_from_the_slowest_partials_measured_again():
    ex = {"count": 97, "median": 0.2, "max": 1.25, "over": 1, "failed": [],
          "again": {"quadratic ∂ax": [1.25, 0.95, 0.97], "turning2d ∂a": [0.8, 0.85, 0.9]}}
    # typical: 0.97 and 0.85 → max 0.97 ≤ 1: ✓ (the old code: its one max 1.25, ✗)
    row = _row({"exact": ex}, "exact")
    assert row[3] == "✓" and "0 over in every run" == row[2]
    ex["again"]["quadratic ∂ax"] = [1.25, 0.95, 1.05]  # typical 1.05 > 1 ≥ least 0.95: borderline
    assert _row({"exact": ex}, "exact")[3] == "borderline"
    ex["again"]["quadratic ∂ax"] = [1.25, 1.1, 1.05]  # least 1.05 > 1: ✗, one over in every run
    assert _row({"exact": ex}, "exact")[2:] == ("1 over in every run", "✗")
    assert _row({"exact": ex, "slowdown": 1.1}, "exact")[3] == "borderline"  # 1.05 ÷ 1.1 = 0.95
    ex["again"]["quadratic ∂ax"] = [0.5, 0.5, 0.5]
    ex["failed"] = ["slow.lgr"]  # an unfinished example fails the target whatever the rest
    assert _row({"exact": ex}, "exact")[3] == "✗"


def test_targets_table_again_from_a_runs_json(tmp_path, capsys):
    import json

    import issue15_targets

    # MB1 n = 49 in rounds 18, 22, 25 ms; the run's calibrations: least 6.72 ms = 1.2 × the reference 5.6 ms
    run = {"mb1": {"langur": [_mb1(49, [0.018, 0.022, 0.025], [0.3] * 3)]},
           "calibrations": [0.0070, 1.2 * steady.REFERENCE_CALIBRATION_S, 0.0090]}
    path = tmp_path / "run.json"
    path.write_text(json.dumps(run))
    issue15_targets.main([str(path)])
    (line,) = [x for x in capsys.readouterr().out.splitlines() if x.startswith("| MB1 n = 49, text")]
    # least 18 ms ÷ 1.2 = 15.0 ms, typical 22 ms: 0.75–1.10 of the target, borderline
    assert "least ÷ 1.20 = 15.0 ms" in line and line.endswith("| 0.75–1.10 of the target | borderline |")
