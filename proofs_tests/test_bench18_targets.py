"""bench/issue15_targets.py: issue 15's targets table from given numbers (branch bench18).

No timing here: the numbers are made up, and every verdict and ratio below is worked out by hand
from them and the issue's targets (MB1 n = 49 ≤ 20 ms, n = 100 ≤ 45 ms, ≥ 100× Potto, ≥ 300× Teg,
loading ≤ ½ (link + eval) at every n; MB2 50 swaps ≤ 1 s; one-shot ≤ 0.3 s wall and faster than
both peers; import ≤ 0.1 s beyond numpy; exact deriv ≤ 1 s on every example).
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "bench"))

from issue15_targets import targets  # noqa: E402


def _langur(n, load, link, eval_):
    return {"n": n, "load": load, "link": link, "eval": eval_, "total": load + link + eval_}


MEASURED = {
    "mb1": {
        # n = 1: load 3 ms > ½ (1 + 1) ms; n = 49: 4 ≤ ½ (5 + 6); n = 100: 10 ≤ ½ (20 + 20)
        "langur": [_langur(1, 0.003, 0.001, 0.001), _langur(49, 0.004, 0.005, 0.006), _langur(100, 0.010, 0.020, 0.020)],
        "potto": [{"n": 49, "total": 2.0}],  # 2.0 / 0.015 = 133.3× ≥ 100
        "teg": [{"n": 49, "total": 3.0}],  # 3.0 / 0.015 = 200× < 300
    },
    "swaps": 50,
    "mb2": {"langur": {"total": 0.9}},
    "one_shot": {"langur eval --engine mc": {"wall": 0.25, "cpu": 0.2},
                 "potto": {"wall": 0.36, "cpu": 0.3},  # slower than Langur's
                 "teg": {"wall": 0.20, "cpu": 0.16},  # faster than Langur's
                 "loads": [1.5, 2.5]},
    "import": {"beyond": 0.12},
    "exact": {"count": 97, "median": 0.2, "max": 1.2, "over": 1, "failed": []},
}


def _by_target(m):
    return {row[0]: row for row in targets(m)}


def test_each_target_against_given_numbers():
    rows = _by_target(MEASURED)
    assert rows["MB1 n = 49, text to number ≤ 20 ms CPU"][1:] == ("15.0 ms", "0.75 of the target", "✓")
    assert rows["MB1 n = 100, text to number ≤ 45 ms CPU"][1:] == ("50.0 ms", "1.11 of the target", "✗")
    assert rows["MB1 n = 49, ≥ 100× potto (text to number)"][2:] == ("133×", "✓")
    assert rows["MB1 n = 49, ≥ 300× teg (text to number)"][2:] == ("200×", "✗")
    assert rows["MB1 loading ≤ 0.5 × (link + eval) at every n"][1:] == ("over at n = 1", "worst 1.50", "✗")
    assert rows["MB2 50 swaps, text to number ≤ 1 s CPU"][1:] == ("0.900 s", "0.90 of the target", "✓")
    one_shot = rows["one-shot `langur eval examples/fig1.lgr --engine mc` ≤ 0.3 s wall"]
    assert one_shot[3] == "✓" and "load 1.5–2.5" in one_shot[1]
    assert rows["one-shot faster than potto's (wall)"][2:] == ("1.44× (CPU 1.50×)", "✓")
    assert rows["one-shot faster than teg's (wall)"][2:] == ("0.80× (CPU 0.80×)", "✗")
    assert rows["import of the Monte Carlo path ≤ 0.1 s beyond numpy"][3] == "✗"
    assert rows["exact `deriv` ≤ 1 s on every example"][2:] == ("1 over", "✗")


def test_an_unfinished_example_fails_the_exact_target_even_under_one_second():
    m = {**MEASURED, "exact": {"count": 3, "median": 0.2, "max": 0.9, "over": 0, "failed": ["slow.lgr"]}}
    assert _by_target(m)["exact `deriv` ≤ 1 s on every example"][3] == "✗"
    m["exact"]["failed"] = []
    assert _by_target(m)["exact `deriv` ≤ 1 s on every example"][3] == "✓"


def test_nothing_measured_is_never_a_verdict():
    rows = targets({})
    assert len(rows) == 11  # every target of the issue has a row
    assert {row[3] for row in rows} == {"—"}
    # microbenchmark 2 at another number of swaps than the target's is shown, not judged
    row = _by_target({"swaps": 5, "mb2": {"langur": {"total": 0.1}}})["MB2 50 swaps, text to number ≤ 1 s CPU"]
    assert row[1:] == ("0.100 s at 5 swaps", "", "—")
