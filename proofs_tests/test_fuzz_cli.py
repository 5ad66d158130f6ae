"""`langur fuzz` (CLI.md): JSON shape, exit status, --keep, missing hypothesis, usage errors."""

import json

from langur import fuzz
from langur.cli import main


def run(capsys, *argv):
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out, out.err


def test_fuzz_json_exits_0_when_engines_agree(capsys):
    status, out, err = run(capsys, "fuzz", "--examples", "3", "--seed", "1", "--json")
    assert status == 0, err
    r = json.loads(out)
    assert (r["examples"], r["seed"], r["status"]) == (3, 1, "agree")
    assert r["programs"] >= 1 and r["comparisons"] >= 1
    assert r["minimal"] is None and r["failures"] == [] and r["kept"] == []
    assert sum(r["counts"].values()) == r["programs"]


def test_json_timing_and_profile_say_where_the_time_went(capsys):
    # each program's phases (front end, lint, exact symbolic / quadrature / rest, Monte Carlo) are
    # parts of its unit's time, and the campaign's timing is their sum over the programs
    status, out, err = run(capsys, "fuzz", "--examples", "1", "--seed", "1", "--json", "--profile",
                           "--samples", "2000", "--workers", "0")
    assert status == 0, err
    r = json.loads(out)
    phases = fuzz.compare.PHASES
    assert set(r["timing"]) == set(phases)
    for res in r["results"]:
        t = res["timing"]
        assert set(t) == set(phases) and all(v >= 0 for v in t.values())
        assert sum(t.values()) <= res["seconds"] + 0.01
        assert t["exact_symbolic"] + t["exact_quadrature"] + t["exact_other"] <= res["exact_seconds"] + 0.01
    for k in phases:
        assert abs(r["timing"][k] - sum(res["timing"][k] for res in r["results"])) <= 0.002 * len(r["results"])
    assert "time per phase" in err and all(k in err for k in phases)  # --profile, on stderr with --json


def test_fuzz_is_reproducible(capsys):
    # same seed, same programs (statuses may differ only by the exact engine's time limit)
    argv = ("fuzz", "--examples", "2", "--seed", "5", "--json", "--samples", "2000", "--timeout", "3")
    r1, r2 = (json.loads(run(capsys, *argv)[1]) for _ in range(2))
    assert [p["program"] for p in r1["results"]] == [p["program"] for p in r2["results"]]
    assert len(r1["results"]) == r1["programs"] >= 1


def test_keep_writes_nothing_when_all_agree(capsys, tmp_path):
    keep = tmp_path / "kept"
    status, out, err = run(capsys, "fuzz", "--examples", "2", "--seed", "1", "--keep", str(keep),
                           "--samples", "2000", "--timeout", "3")
    assert status == 0, err
    assert not keep.exists() or list(keep.iterdir()) == []
    assert "all comparisons agree" in out


def test_discrepancy_exits_1_prints_and_keeps_the_minimal_program(capsys, tmp_path, monkeypatch):
    # A fake comparison that fails on every program with an Iverson bracket: the driver must
    # report the failure, print the (shrunk) program as .lgr text and write it with --keep.
    def fake(text, **kw):
        res = fuzz.ProgramResult(text, "agree")
        ok = "[" not in text
        res.rows.append(fuzz.Row("value", None, 1.0, 0.0, 1.0 if ok else 2.0, 0.01, ok))
        res.status = "agree" if ok else "discrepancy"
        return res

    monkeypatch.setattr(fuzz.campaign, "compare_text", fake)  # the driver's own reference
    keep = tmp_path / "kept"
    status, out, err = run(capsys, "fuzz", "--examples", "10", "--seed", "2", "--keep", str(keep))
    assert status == 1, err
    assert "minimal failing program (discrepancy)" in out and "DISCREPANCY" in out
    files = sorted(keep.iterdir())
    assert files and all(f.suffix == ".lgr" for f in files)
    minimal = (keep / "fuzz_2_minimal.lgr").read_text()
    assert "[" in minimal and minimal.startswith("# langur fuzz: discrepancy")
    # the kept file is a valid program (comments first)
    from langur.frontend import load_text

    assert load_text(minimal).program is not None


def test_missing_hypothesis_says_how_to_install(capsys, monkeypatch):
    def missing():
        raise fuzz.MissingHypothesis("`langur fuzz` needs hypothesis: pip install hypothesis")

    monkeypatch.setattr(fuzz.campaign, "_hypothesis", missing)
    monkeypatch.setattr(fuzz.generate, "_hypothesis", missing)
    status, out, err = run(capsys, "fuzz", "--examples", "1")
    assert status == 2 and "pip install hypothesis" in err and out == ""


def usage(capsys, *argv):
    """The status and standard error of a command line argparse or the command refuses."""
    try:
        status = main(list(argv))
    except SystemExit as e:  # argparse's own usage errors
        status = e.code
    return status, capsys.readouterr().err


def test_usage_errors(capsys, tmp_path):
    for argv, says in [(["--examples", "0"], "--examples"), (["--samples", "1"], "--samples"),
                       (["--seed", "-1"], "--seed"), (["--timeout", "nan"], "--timeout"),
                       (["--timeout", "0"], "--timeout"), (["--samples", "10000000000"], "--samples")]:
        status, err = usage(capsys, "fuzz", *argv)
        assert status == 2 and says in err and len(err.strip().splitlines()) == 1, (argv, err)
    mine = tmp_path / "notes.lgr"
    mine.write_text("# mine\n")
    status, err = usage(capsys, "fuzz", "--examples", "1", "--keep", str(mine))
    assert status == 2 and f"--out {mine}: exists and is not a directory" in err
    assert mine.read_text() == "# mine\n"


def test_keep_never_overwrites_a_file_in_its_directory(capsys, tmp_path, monkeypatch):
    def fake(text, **kw):  # every program with a bracket "fails" (as in the test above)
        res = fuzz.ProgramResult(text, "agree")
        ok = "[" not in text
        res.rows.append(fuzz.Row("value", None, 1.0, 0.0, 1.0 if ok else 2.0, 0.01, ok))
        res.status = "agree" if ok else "discrepancy"
        return res

    monkeypatch.setattr(fuzz.campaign, "compare_text", fake)
    keep = tmp_path / "kept"
    keep.mkdir()
    (keep / "fuzz_2_minimal.lgr").write_text("# the user's own file\n")
    status, out, err = run(capsys, "fuzz", "--examples", "10", "--seed", "2", "--keep", str(keep), "--json")
    assert status == 1, err
    assert (keep / "fuzz_2_minimal.lgr").read_text() == "# the user's own file\n"
    kept = json.loads(out)["kept"]
    assert str(keep / "fuzz_2_minimal-1.lgr") in kept
    assert (keep / "fuzz_2_minimal-1.lgr").read_text().startswith("# langur fuzz: discrepancy")
