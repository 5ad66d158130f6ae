"""One-shot start-up, fourth round (issue 15): a plain command line read without argparse.

``langur.arguments.Arguments`` records a command's ``add_arguments`` and reads a plain command line
itself; anything else goes to argparse as before.  The two readings are compared here on random
command lines of every command (the direct one either declines or gives argparse's attributes, in
argparse's order, for a command line argparse accepts), and the one-shot process is checked not to
import argparse, gettext or locale.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from langur import cli
from langur.arguments import Arguments

ROOT = Path(__file__).resolve().parents[1]


def _argparse(argv: list[str]):
    """(attributes, None) as argparse reads ``argv``, or (None, status) when it exits."""
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            return cli.build_parser(argv).parse_args(argv), None
    except SystemExit as e:
        return None, e.code


def _options(command: str) -> list[str]:
    parser = cli.build_parser([command])
    (sub,) = [a for a in parser._actions if a.dest == "command"]
    return [s for a in sub.choices[command]._actions for s in a.option_strings]


VALUES = ["1", "0", "-1", "10", "2.5", "1e3", "abc", "", "qmc", "uniform", "stratified", "mc", "exact", "both",
          "a=1", "theta=0.5,b=2", "x=inf", "600", "0.0", "86401", "18446744073709551616", "-", "--", "f.lgr"]


@st.composite
def command_lines(draw):
    command = draw(st.sampled_from(list(cli.COMMANDS)))
    options = _options(command)
    word = st.one_of(
        st.sampled_from(options),
        st.builds(lambda o, v: f"{o}={v}", st.sampled_from(options), st.sampled_from(VALUES)),
        st.sampled_from(VALUES),
        st.sampled_from(["--help", "-h", "--version", "--vers", "--eng", "--sam", "-v", "--bogus", "eval"]),
    )
    return [command, *draw(st.lists(word, max_size=7))]


@settings(max_examples=400, deadline=None)
@given(command_lines())
def test_a_plain_command_line_is_read_as_argparse_reads_it(argv):
    direct = cli.read_plain(argv)
    parsed, status = _argparse(argv)
    if direct is None:
        return
    assert status is None, (argv, status)  # argparse accepts what is read directly
    assert list(vars(direct).items()) == list(vars(parsed).items()), argv


@pytest.mark.parametrize("argv", [
    ["eval", "examples/fig1.lgr", "--engine", "mc"],
    ["eval", "f.lgr", "--engine=mc", "--seed", "3", "--samples=500", "--method", "qmc", "--at", "a=1", "--at=b=2",
     "--json", "--timeout", "5", "--module", "m=x.lgr"],
    ["deriv", "f.lgr", "--wrt", "theta", "--dir", "theta=1", "--no-theorem", "--rewrite", "--engine", "mc"],
    ["show", "f.lgr", "--core", "--latex-fragment"],
    ["plot", "f.lgr"],
])
def test_the_command_lines_a_user_types_are_read_directly(argv):
    direct = cli.read_plain(argv)
    parsed, status = _argparse(argv)
    assert direct is not None and status is None
    assert list(vars(direct).items()) == list(vars(parsed).items())


@pytest.mark.parametrize("argv", [
    ["eval", "--help"], ["eval", "f.lgr", "-h"], ["eval", "f.lgr", "--eng", "mc"], ["eval", "f.lgr", "--engine"],
    ["eval", "f.lgr", "--engine", "-x"], ["eval", "f.lgr", "--samples", "1"], ["eval", "f.lgr", "--method", "x"],
    ["eval", "f.lgr", "--seed", "-1"], ["eval", "f.lgr", "--json=1"], ["eval"], ["eval", "a", "b"],
    ["eval", "f.lgr", "--"], ["eval", "-"], ["eval", "f.lgr", "--version"], ["--help", "eval"], ["-x", "eval", "f"],
    ["check", "f.lgr"], ["reproduce"], ["fuzz", "-v"], [], ["nosuch"],
])
def test_anything_else_is_left_to_argparse(argv):
    assert cli.read_plain(argv) is None


def test_declarations_the_direct_reading_does_not_cover_leave_the_command_to_argparse():
    for declare in (
        lambda p: p.add_argument("files", nargs="+"),
        lambda p: p.add_argument("--x", required=True),
        lambda p: p.add_argument("--x", dest="y"),
        lambda p: p.add_argument("--x", action="count"),
        lambda p: p.add_argument("-x"),
        lambda p: p.add_argument("a", action="append"),
        lambda p: (p.set_defaults(x=1), p.add_argument("--x")),
        lambda p: (p.add_argument("--x", default="a"), p.set_defaults(x=1)),
    ):
        arguments = Arguments()
        declare(arguments)
        assert arguments.parse(["--x", "1"], {}) is None


def test_a_string_default_goes_through_the_type_as_argparse_does():
    arguments = Arguments()
    arguments.add_argument("--n", type=int, default="7")
    arguments.add_argument("--m", type=int, default="x")
    assert arguments.parse(["--m", "2"], {}).__dict__ == {"n": 7, "m": 2}
    assert arguments.parse([], {}) is None  # (argparse refuses the default "x": its error, not ours)


ONE_SHOT = """
import json, sys
from langur.cli import main
status = main(sys.argv[1:])
print(json.dumps({"status": status, "imported": [m for m in ("argparse", "gettext", "locale", "langur.cliparser")
                                                  if m in sys.modules]}))
"""


def test_the_one_shot_process_imports_no_argparse():
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    out = subprocess.run([sys.executable, "-P", "-c", ONE_SHOT, "eval", "examples/fig1.lgr", "--engine", "mc"],
                         capture_output=True, text=True, env=env, cwd=ROOT, timeout=120, check=True).stdout
    lines = out.strip().splitlines()
    assert json.loads(lines[-1]) == {"status": 0, "imported": []}
    assert lines[1].strip().startswith("MC") and "10000 samples, uniform, seed 0" in lines[1]


def test_help_and_usage_errors_still_come_from_argparse():
    env = {**os.environ, "PYTHONPATH": str(ROOT), "COLUMNS": "100"}

    def run(*argv):
        return subprocess.run([sys.executable, "-P", "-m", "langur", *argv], capture_output=True, text=True, env=env,
                              cwd=ROOT, timeout=120)

    r = run("eval", "--help")
    assert r.returncode == 0 and r.stdout.startswith("usage: langur eval [-h]") and "--engine NAME" in r.stdout
    r = run("eval", "examples/fig1.lgr", "--engine", "mc", "--samples", "1")
    assert r.returncode == 2 and r.stdout == ""
    assert r.stderr.splitlines()[-1] == ("langur eval: error: argument --samples: the number of samples (a standard "
                                         "error needs 2 or more; memory grows with it) must be between 2 and "
                                         "10,000,000, got 1 (see `langur eval --help`)")
    r = run("eval", "examples/fig1.lgr", "--engine", "mc", "--bogus")
    assert r.returncode == 2
    assert r.stderr.splitlines()[-1] == "langur: error: unrecognized arguments: --bogus (see `langur --help`)"
