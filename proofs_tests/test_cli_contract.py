"""The command-line contract (docs/commands.md; issue 9): exit statuses 0, 1, 2 only, never a
traceback; every option validated up front with a one-line usage error; every readable file
checked and each unreadable one located; numeric warnings turned into one note; the Python API
raises a typed error (``langur.values.ParameterError``) where it used to answer 0.0.

Most tests go through ``langur.cli.main`` in process; a few run ``python -m langur`` in a
subprocess, where a traceback, a signal or a MemoryError would show as they would to a user.
"""

import json
import os
import subprocess
import sys
import warnings

import numpy as np
import pytest
from paths import EXAMPLES

from langur import cli, frontend, operational
from langur.cli import main
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.values import ParameterError

FIG1 = str(EXAMPLES / "fig1.lgr")
RISK = str(EXAMPLES / "risk.lgr")


def run(capsys, *argv):
    """(status, stdout, stderr) of ``langur ARGV``; argparse's own refusals exit through SystemExit."""
    try:
        status = main([str(a) for a in argv])
    except SystemExit as e:
        status = e.code
    out = capsys.readouterr()
    return status, out.out, out.err


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err
    return lines[0]


# -- options are validated before any work ----------------------------------------------------------

@pytest.mark.parametrize("argv, says", [
    (["eval", FIG1, "--seed", "-1"], "argument --seed: a seed must be between 0 and"),
    (["deriv", FIG1, "--seed", "-5"], "argument --seed"),
    (["reproduce", "fig1", "--seed", "-1"], "argument --seed"),
    (["eval", FIG1, "--seed", str(2**64)], "argument --seed"),
    (["eval", FIG1, "--samples", "1"], "a standard error needs 2 or more"),
    (["eval", FIG1, "--samples", "0"], "got 0"),
    (["deriv", FIG1, "--samples", "-3"], "got -3"),
    (["eval", FIG1, "--samples", "1000000000"], "must be between 2 and 10,000,000, got 1,000,000,000"),
    (["reproduce", "fig1", "--samples", "99"], "must be between 100 and"),
    (["eval", FIG1, "--samples", "many"], "'many' is not an integer"),
    (["eval", FIG1, "--at", "theta=nan"], "--at theta=nan: not a finite number"),
    (["eval", FIG1, "--at", "theta=inf"], "--at theta=inf: not a finite number"),
    (["eval", FIG1, "--at", "theta=-Infinity"], "not a finite number"),
    (["eval", FIG1, "--at", "theta=1e400"], "--at theta=1e400: out of range"),
    (["deriv", FIG1, "--dir", "theta=nan"], "--dir theta=nan: not a finite number"),
    (["deriv", FIG1, "--at", "theta=-1e999"], "out of range"),
    (["show", FIG1, "--wrt", "theta", "--at", "theta=inf"], "not a finite number"),
    (["check", FIG1, "--at", "theta=nan"], "--at theta=nan: not a finite number"),
    (["check", FIG1, "--select", "ZZZ"], "--select ZZZ: 'ZZZ' matches no diagnostic code"),
    (["check", FIG1, "--ignore", "X301,Q"], "--ignore X301,Q: 'Q' matches no diagnostic code"),
    (["check", FIG1, "--select", "X398"], "'X398' matches no diagnostic code"),
])
def test_a_bad_option_is_one_line_and_status_2(capsys, argv, says):
    status, out, err = run(capsys, *argv)
    assert status == 2 and out == ""
    assert says in one_line(err)


def test_absurd_sample_counts_are_refused_before_anything_is_allocated(capsys, monkeypatch):
    def allocate(*a, **k):
        raise AssertionError("the engine was called")

    monkeypatch.setattr(operational, "estimate_value", allocate)
    monkeypatch.setattr(operational, "estimate_derivative", allocate)
    for argv in (["eval", FIG1, "--engine", "mc", "--samples", str(10**12)],
                 ["deriv", FIG1, "--engine", "mc", "--samples", str(cli.MAX_SAMPLES + 1)]):
        status, _, err = run(capsys, *argv)
        assert status == 2 and "10,000,000" in one_line(err)
    monkeypatch.undo()
    status, out, _ = run(capsys, "eval", FIG1, "--engine", "mc", "--samples", "2", "--json")
    assert status == 0 and json.loads(out)["mc"]["samples"] == 2  # two samples: the smallest count


def test_code_prefixes_that_exist_are_accepted(capsys):
    degenerate = EXAMPLES / "degenerate" / "coincident.lgr"
    status, out, _ = run(capsys, "check", degenerate, "--isolated", "--select", "x30")  # case-insensitive
    assert status == 1 and " X301 " in out
    status, out, _ = run(capsys, "check", degenerate, "--isolated", "--ignore", "X301", "--select", "ALL")
    assert status == 0 and "X301" not in out


def test_a_configured_code_prefix_that_matches_nothing_is_a_usage_error(capsys, tmp_path):
    (tmp_path / "pyproject.toml").write_text('[tool.langur]\nignore = ["X3O1"]\n')  # a letter O
    f = tmp_path / "a.lgr"
    f.write_text("param a = 0.5\nint ([0, 1]) [x <= a] d(x)\n")
    status, _, err = run(capsys, "check", f)
    line = one_line(err)
    assert status == 2 and "pyproject.toml: [tool.langur] ignore: 'X3O1' matches no diagnostic code" in line


# -- files that cannot be read ---------------------------------------------------------------------

def _unreadable_tree(tmp_path):
    d = tmp_path / "progs"
    d.mkdir()
    (d / "good.lgr").write_text("param a = 0.5\nint ([0, 1]) [x <= a] d(x)\n")
    (d / "bad.lgr").write_text("param a = 0.5\nint ([0, 1]) [x <= a] * [x <= a] d(x)\n")  # X301
    os.symlink("loop.lgr", d / "loop.lgr")  # unreadable even for root: ELOOP
    os.symlink("nowhere.lgr", d / "dangling.lgr")  # ENOENT through the link
    return d


def test_check_dir_reports_every_readable_file_and_locates_each_unreadable_one(capsys, tmp_path):
    d = _unreadable_tree(tmp_path)
    status, out, err = run(capsys, "check", d, "--isolated")
    assert status == 2  # the worst: a file could not be read
    lines = out.splitlines()
    assert f"{d / 'loop.lgr'}:1:1: error E109 cannot read this file: Too many levels of symbolic links" in lines
    assert f"{d / 'dangling.lgr'}:1:1: error E109 cannot read this file: No such file or directory" in lines
    assert any(ln.startswith(f"{d / 'bad.lgr'}:2:") and " X301 " in ln for ln in lines)  # still checked
    assert "2 files checked" in err and "2 file(s) could not be read" in err
    status, out, _ = run(capsys, "check", d, "--isolated", "--format", "json")
    found = {(x["path"].rsplit("/", 1)[-1], x["code"]) for x in json.loads(out)["diagnostics"]}
    assert found == {("loop.lgr", "E109"), ("dangling.lgr", "E109"), ("bad.lgr", "X301")}
    status, _, _ = run(capsys, "check", d, "--isolated", "--exit-zero")
    assert status == 2  # --exit-zero is about findings; an unreadable file is not one


def test_a_file_that_cannot_be_read_is_a_usage_error_for_the_other_commands(capsys, tmp_path):
    d = _unreadable_tree(tmp_path)
    for command in ("eval", "deriv", "show"):
        status, _, err = run(capsys, command, d / "loop.lgr")
        assert status == 2 and "loop.lgr: cannot read this file (Too many levels of symbolic links)" in one_line(err)


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0, reason="root reads every file")
def test_permission_denied_is_located(capsys, tmp_path):
    d = _unreadable_tree(tmp_path)
    (d / "secret.lgr").write_text("int ([0, 1]) x d(x)\n")
    (d / "secret.lgr").chmod(0)
    status, out, _ = run(capsys, "check", d, "--isolated")
    assert status == 2 and f"{d / 'secret.lgr'}:1:1: error E109 cannot read this file: Permission denied" in out


def test_an_unreadable_import_is_not_reported_as_missing(capsys, tmp_path):
    os.symlink("lib.lgr", tmp_path / "lib.lgr")  # exists as a name, cannot be opened
    main_file = tmp_path / "main.lgr"
    main_file.write_text("from lib import f\nint ([0, 1]) f(x) d(x)\n")
    status, out, _ = run(capsys, "check", main_file, "--isolated")
    assert status == 1
    assert out.startswith(f"{main_file}:1:6: error T223 module `lib`: cannot read {tmp_path / 'lib.lgr'} "
                          "(beside the importing file): Too many levels of symbolic links")
    status, _, err = run(capsys, "eval", main_file)
    assert status == 1 and " T223 " in err and "not found" not in err
    (tmp_path / "lib.lgr").unlink()  # now really missing: T218
    status, out, _ = run(capsys, "check", main_file, "--isolated")
    assert status == 1 and " T218 module `lib` not found" in out


# -- never 3, never a traceback, never a raw warning ------------------------------------------------

def test_an_internal_error_is_one_line_and_status_1(capsys, monkeypatch):
    def broken(args):
        raise RuntimeError("boom")

    monkeypatch.setattr("langur.commands.eval.run", broken)
    monkeypatch.delenv("LANGUR_DEBUG", raising=False)
    status, _, err = run(capsys, "eval", FIG1)
    assert status == 1 and "internal error: RuntimeError: boom" in one_line(err)


def test_numeric_warnings_become_one_note(capsys, monkeypatch):
    def noisy(args):
        with np.errstate(divide="warn", invalid="warn"):
            for _ in range(80):
                np.divide(np.ones(3), np.zeros(3))
            np.log(-np.ones(2))
        warnings.warn("a deprecated API", DeprecationWarning, stacklevel=1)  # not the user's numbers
        print("done")
        return 0

    monkeypatch.setattr("langur.commands.eval.run", noisy)
    status, out, err = run(capsys, "eval", FIG1)
    assert status == 0 and out == "done\n"
    line = one_line(err)
    assert line.startswith("langur eval: note: warnings while computing: ")
    assert "RuntimeWarning: divide by zero encountered in divide (×80)" in line
    assert "invalid value encountered in log" in line and "deprecated" not in line


def _python_m_langur(*argv, timeout=120):
    env = {k: v for k, v in os.environ.items() if k != "LANGUR_DEBUG"}
    return subprocess.run([sys.executable, "-m", "langur", *map(str, argv)], capture_output=True, text=True,
                          timeout=timeout, env=env)


def test_in_a_subprocess_misuse_ends_with_status_2_and_one_line():
    for argv, says in [(["eval", FIG1, "--seed", "-1"], "--seed"),
                       (["eval", FIG1, "--samples", "1000000000"], "--samples"),
                       (["deriv", FIG1, "--at", "theta=nan"], "not a finite number"),
                       (["check", FIG1, "--select", "ZZZ"], "matches no diagnostic code")]:
        r = _python_m_langur(*argv)
        assert r.returncode == 2 and r.stdout == "", (argv, r.returncode, r.stderr)
        assert says in one_line(r.stderr)


# -- the Python API: a typed error, never 0.0, for both engines alike -------------------------------

@pytest.fixture(scope="module")
def fig1():
    return frontend.load(FIG1)


def _both_raise(call_exact, call_mc, says):
    for call in (call_exact, call_mc):
        with pytest.raises(ParameterError, match=says):
            call()


def test_missing_parameter_values_raise_in_both_engines(fig1):
    p = fig1.program
    _both_raise(lambda: ddenote_program(p, {}, {"theta": 1}),
                lambda: operational.estimate_derivative(p, {}, {"theta": 1}), "no value for parameter.* theta")
    _both_raise(lambda: ddenote_program(p, None, {"theta": 1}),
                lambda: operational.estimate_value(p, {}), "no value for parameter.* theta")
    _both_raise(lambda: denote_program(p),  # the default arguments
                lambda: operational.estimate_value(p, {}), "theta")
    assert issubclass(ParameterError, KeyError)  # what the Monte Carlo engine raised before


def test_a_direction_naming_an_unknown_parameter_raises_in_both_engines(fig1):
    p = fig1.program
    _both_raise(lambda: ddenote_program(p, {"theta": 0.5}, {"zeta": 1}),
                lambda: operational.estimate_derivative(p, {"theta": 0.5}, {"zeta": 1}), "direction names .*zeta")
    _both_raise(lambda: ddenote_program(p, {"theta": 0.5}, {"theta": 1, "zeta": 0}),
                lambda: operational.estimate_derivative(fig1, {"theta": 0.5}, {"zeta": 1}), "zeta")


def test_non_finite_values_raise_in_both_engines(fig1):
    p = fig1.program
    _both_raise(lambda: denote_program(p, {"theta": float("nan")}),
                lambda: operational.estimate_value(p, {"theta": float("nan")}), "theta = nan: not a finite")
    _both_raise(lambda: ddenote_program(p, {"theta": 0.5}, {"theta": float("inf")}),
                lambda: operational.estimate_derivative(p, {"theta": 0.5}, {"theta": float("inf")}),
                "direction theta = inf")


def test_the_api_still_answers_where_values_are_given(fig1):
    # ∫₀¹ [x ≤ θ] dx = θ and its derivative is 1 (Fig. 1); a declared parameter the program does not
    # read may be given a value and a direction (the CLI passes every declared parameter)
    assert denote_program(fig1.program, {"theta": 0.25}).value == pytest.approx(0.25, abs=1e-12)
    d = ddenote_program(fig1.program, {"theta": 0.25, "unused": 3}, {"theta": 1, "unused": 1})
    assert d.value == pytest.approx(1.0, abs=1e-12)
    risk = frontend.load(RISK)
    with pytest.raises(ParameterError, match="unknown parameter.* zeta"):
        operational.estimate_value(risk, {"zeta": 1.0})


def test_one_sample_is_refused_by_the_api_too(fig1):
    with pytest.raises(ValueError, match="at least 2"):
        operational.estimate_value(fig1, {"theta": 0.5}, samples=1)
    assert operational.estimate_value(fig1, {"theta": 0.5}, samples=2).samples == 2


# -- diagnostics the contract adds: a reversed interval (X314), a nested int (T208) -----------------

def test_a_reversed_interval_is_a_located_warning_and_the_value_is_0(capsys, tmp_path):
    # int ([1, 0]) x d(x) is int [x >= 1]·[0 >= x]·x d(x) (§6): no x satisfies both, so 0, not −1/2
    f = tmp_path / "reversed.lgr"
    f.write_text("# a reversed interval\nint ([1, 0]) x d(x)\n")
    status, out, _ = run(capsys, "check", f, "--isolated")
    assert status == 0  # a warning: 0 is the language's answer
    (line,) = out.splitlines()
    assert line.startswith(f"{f}:2:7: warning X314 the interval [1, 0] of x is empty")
    assert "the integral is 0" in line
    status, out, err = run(capsys, "eval", f, "--json", "--samples", "200")
    r = json.loads(out)
    assert status == 0 and r["exact"]["value"] == 0.0 and r["mc"]["value"] == 0.0
    assert [(d["code"], d["line"], d["col"]) for d in r["diagnostics"]] == [("X314", 2, 7)]
    status, _, err = run(capsys, "eval", f, "--samples", "200")
    assert status == 0 and f"{f}:2:7: warning X314 " in err


def test_a_parametric_interval_is_judged_at_the_values_in_force(capsys, tmp_path):
    f = tmp_path / "moving.lgr"
    f.write_text("param a = 0.5\nint ([0, a]) x d(x)\n")
    status, out, _ = run(capsys, "check", f, "--isolated")
    assert status == 0 and out == ""  # [0, 1/2]: nothing to say
    status, out, _ = run(capsys, "check", f, "--isolated", "--at", "a=-1")
    assert status == 0 and " X314 the interval [0, a] of x is empty at a = -1 (0 > -1)" in out
    # the value is 0 there and so is the derivative, in both engines (∫₀^a x dx = a²/2 only for a ≥ 0)
    status, out, _ = run(capsys, "deriv", f, "--at", "a=-1", "--json", "--samples", "200", "--no-theorem")
    r = json.loads(out)
    assert status == 0 and r["exact"]["value"] == 0.0 and r["mc"]["value"] == 0.0
    assert [d["code"] for d in r["diagnostics"]] == ["X314"]


def test_a_nested_int_has_its_own_typing_diagnostic(capsys, tmp_path):
    f = tmp_path / "nested.lgr"
    f.write_text("param a = 1\nint ([0, 1]) x * int ([0, a]) y d(y) d(x)\n")
    status, out, _ = run(capsys, "check", f, "--isolated")
    assert status == 1
    assert out.startswith(f"{f}:2:18: error T208 no nested integration")
    for command in ("eval", "deriv", "show"):
        status, _, err = run(capsys, command, f)
        assert status == 1 and err.startswith(f"{f}:2:18: error T208 "), command
