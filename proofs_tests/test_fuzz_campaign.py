"""`langur fuzz` at campaign scale (issue 13): the worker pool (same seed, same programs and
verdicts whatever the number of workers; a unit past its time limit is killed and counted apart),
hypothesis's files kept out of the current folder, timing in --json."""

import json
import os
import time

import pytest

from langur import fuzz
from langur.cli import main
from langur.fuzz import pool


def _verdicts(summary):
    return [(r.text, r.status, [(w.quantity, w.wrt, w.ok, w.mc, w.exact) for w in r.rows])
            for r in summary.results]


# seed 13: three 1-D programs (a kink from min, a window of two conditions): the verdicts compare
# 33 rows in a few seconds (seed 6's 2-D diffeo programs took ~40 s per campaign)
KW = dict(examples=3, seed=13, samples=2000, timeout=60.0, light=True)


@pytest.fixture(scope="module")
def one_worker(tmp_path_factory):
    """The tiny campaign run by one worker (shared by the comparisons below), from an empty
    current folder, which must stay empty (hypothesis's files go to ``storage``)."""
    cwd, storage = tmp_path_factory.mktemp("cwd"), tmp_path_factory.mktemp("hyp")
    before = os.getcwd()
    os.chdir(cwd)
    try:
        summary = fuzz.run_fuzz(workers=1, storage=str(storage), **KW)
    finally:
        os.chdir(before)
    assert list(cwd.iterdir()) == []
    return summary


def test_one_and_two_workers_give_the_same_programs_and_verdicts(one_worker, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    one = one_worker
    two = fuzz.run_fuzz(workers=2, storage=str(tmp_path / "hyp"), **KW)
    assert [r.text for r in one.results] == fuzz.generated(KW["examples"], KW["seed"], light=True)
    assert _verdicts(one) == _verdicts(two)
    assert all(r.status == "agree" for r in one.results), [(r.status, r.reason) for r in one.results]
    assert all(r.rows and r.seconds > 0 for r in one.results)  # both engines ran, in a worker
    assert not (tmp_path / ".hypothesis").exists()  # hypothesis's files went to `storage`


def _slow_or_fast(text):
    if text.startswith("slow"):  # burns CPU: the limit counts the unit's CPU seconds
        end = time.monotonic() + 60
        while time.monotonic() < end:
            pass
    if text.startswith("crash"):
        os._exit(3)
    return fuzz.ProgramResult(text, "agree")


def test_a_unit_past_its_time_limit_is_killed_and_reported_apart(monkeypatch):
    monkeypatch.setattr(pool, "GRACE", 0.0)
    seen = []
    t0 = time.monotonic()
    out = pool.run_units(["fast 1", "slow", "crash", "fast 2"], _slow_or_fast, workers=2, limit=1.0,
                         on_time_limit=lambda t, why, last=None: fuzz.ProgramResult(t, "timeout", reason=why),
                         on_error=lambda t, why: fuzz.ProgramResult(t, "exact_error", reason=why),
                         progress=seen.append)
    assert time.monotonic() - t0 < 30  # the spinning unit did not run its 60 s
    assert [(r.text, r.status) for r in out] == [("fast 1", "agree"), ("slow", "timeout"),
                                                 ("crash", "exact_error"), ("fast 2", "agree")]
    assert "killed" in out[1].reason and "exit code 3" in out[2].reason
    assert sorted(r.text for r in seen) == sorted(r.text for r in out)


def test_json_keeps_its_shape_and_adds_timing(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    status = main(["fuzz", "--examples", "2", "--seed", "5", "--json", "--samples", "2000", "--workers", "1",
                   "--hypothesis-dir", str(tmp_path / "h")])
    r = json.loads(capsys.readouterr().out)
    assert status == 0
    assert {"examples", "seed", "samples", "programs", "comparisons", "counts", "status", "minimal",
            "failures", "results", "kept"} <= set(r)
    assert r["workers"] == 1 and r["seconds"] > 0 and r["programs_per_minute"] > 0
    # (exact_seconds can be ~0: the exact answers are remembered per program within a process)
    assert all(p["seconds"] >= p["exact_seconds"] >= 0 and p["seconds"] > 0 for p in r["results"])
    assert not (tmp_path / ".hypothesis").exists()


def test_a_local_dask_cluster_gives_the_same_verdicts_as_one_process(one_worker, tmp_path):
    distributed = pytest.importorskip("distributed", reason="the cluster extra (dask.distributed) is not installed")
    local = one_worker
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=False,
                                  dashboard_address=None) as cluster:
        remote = fuzz.run_fuzz(scheduler=cluster.scheduler_address, storage=str(tmp_path), **KW)
    assert _verdicts(remote) == _verdicts(local)
    # coverage gathered from the cluster's units too: the same rules fire; a long-lived local worker
    # may count a few applications fewer (typing results kept on nodes shared with its earlier units),
    # never more than a unit forked afresh on the cluster
    fired = {(f, r): n for f, r, n in local.coverage()}
    assert {k for k, n in fired.items() if n} == {(f, r) for f, r, n in remote.coverage() if n}
    assert all(n >= fired[f, r] for f, r, n in remote.coverage())
