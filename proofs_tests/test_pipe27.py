"""Standard output closed before a command finishes (``langur check FILE | head``): status 1 and
nothing printed — never 0 (the report was not all read; ``set -o pipefail`` must see it), never a
traceback, never "internal error" (docs/commands.md, exit status; CLI.md: 0, 1 or 2 only).

The pipe's read end is closed before the command starts, so every write to standard output fails
(Python ignores SIGPIPE: the write raises BrokenPipeError): no race with the reader."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FIG1 = os.path.join(ROOT, "examples", "fig1.lgr")


def _closed_stdout(args: list[str], tmp_path) -> subprocess.CompletedProcess:
    r, w = os.pipe()
    os.close(r)
    try:
        return subprocess.run([sys.executable, "-P", "-m", "langur", *args], stdout=w, stderr=subprocess.PIPE,
                              cwd=tmp_path, env={**os.environ, "PYTHONPATH": ROOT}, text=True, timeout=300)
    finally:
        os.close(w)


@pytest.fixture
def programs(tmp_path):
    (tmp_path / "twice.lgr").write_text("param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] * x d(x)\n")
    (tmp_path / "bad.lgr").write_text("int ([0, 1]) x +* d(x)\n")
    return tmp_path


@pytest.mark.parametrize("args", [
    ["check", "twice.lgr"],                    # an X301 error whose report is not read
    ["check", "--json", "twice.lgr"],
    ["check", "--json", "bad.lgr"],            # a parse error, reported as JSON on standard output
    ["eval", "--json", "bad.lgr"],             # the diagnostics' JSON printed after the error
    ["eval", "--engine", "mc", "--samples", "100", FIG1],   # a successful answer not read
    ["show", FIG1],
])
def test_closed_stdout_is_status_1_and_silent(args, programs):
    p = _closed_stdout(args, programs)
    assert p.returncode == 1, (p.returncode, p.stderr)
    assert "Traceback" not in p.stderr and "internal error" not in p.stderr and "Exception ignored" not in p.stderr
    assert "BrokenPipeError" not in p.stderr


def test_open_stdout_unchanged(programs):
    """The same commands with standard output read: check's status is its findings' (1 for X301,
    0 for a clean program), eval's 0."""
    run = lambda *a: subprocess.run([sys.executable, "-P", "-m", "langur", *a], capture_output=True, text=True,
                                    cwd=programs, env={**os.environ, "PYTHONPATH": ROOT}, timeout=300)
    assert run("check", "twice.lgr").returncode == 1
    assert run("check", FIG1).returncode == 0
    assert run("eval", "--engine", "mc", "--samples", "100", FIG1).returncode == 0


def test_in_process_caller_keeps_its_stdout(monkeypatch):
    """``cli.main(argv)`` called in a caller's process returns 1 on a closed pipe but does not point
    the caller's standard output at /dev/null (only the console script's own process does)."""
    from langur import cli

    class Closed:
        def write(self, s):
            raise BrokenPipeError(32, "Broken pipe")

        def flush(self):
            raise BrokenPipeError(32, "Broken pipe")

    before = os.fstat(1)
    monkeypatch.setattr(sys, "stdout", Closed())
    assert cli.main(["eval", "--engine", "mc", "--samples", "100", FIG1]) == 1
    after = os.fstat(1)
    assert (before.st_dev, before.st_ino) == (after.st_dev, after.st_ino)


# -- an imported module is read bounded too (E108), as FILE and standard input are -----------------

def test_an_imported_module_over_the_limit_is_E108(tmp_path):
    """``from big import f`` where big.lgr is a sparse file over the limit, and where it is a link
    to /dev/zero (endless): E108 at big.lgr:1:1, status 1, in bounded memory (the process is given
    1 GB of address space: reading /dev/zero to the end would exceed it)."""
    from langur import source

    (tmp_path / "main.lgr").write_text("from big import f\nint ([0, 1]) f(x) d(x)\n")
    with open(tmp_path / "big.lgr", "wb") as fh:
        fh.truncate(source.MAX_SOURCE_BYTES + 1)
    (tmp_path / "zero").mkdir()
    (tmp_path / "zero" / "main.lgr").write_text("from big import f\nint ([0, 1]) f(x) d(x)\n")
    os.symlink("/dev/zero", tmp_path / "zero" / "big.lgr")

    def limited():
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (1 << 30, 1 << 30))

    for folder in (tmp_path, tmp_path / "zero"):
        for command in (["eval", "main.lgr"], ["check", "--isolated", "main.lgr"]):
            p = subprocess.run([sys.executable, "-P", "-m", "langur", *command], capture_output=True, text=True,
                               cwd=folder, env={**os.environ, "PYTHONPATH": ROOT}, timeout=300, preexec_fn=limited)
            report = p.stdout if command[0] == "check" else p.stderr
            assert p.returncode == 1, (command, p.returncode, p.stderr)
            assert f"big.lgr:1:1: error E108 source too large: more than {source.MAX_SOURCE_BYTES:,} bytes" in report, report
            assert "Traceback" not in p.stderr and "out of memory" not in p.stderr and "internal error" not in p.stderr


# -- --module's PATH: a regular file, or a usage error saying what it is (check and the others alike) --

@pytest.mark.parametrize("command", ["check", "eval", "show"])
def test_module_path_must_be_a_regular_file(capsys, tmp_path, command):
    from test_cli_contract import run

    main_file = tmp_path / "main.lgr"
    main_file.write_text("from shade import f\nparam a = 0.5\nint ([0, 1]) f(x) * [x <= a] d(x)\n")
    for path, says in (("/dev/zero", "not a regular file"), (str(tmp_path), "not a regular file"),
                       (str(tmp_path / "missing.lgr"), "no such file")):
        status, out, err = run(capsys, command, main_file, "--module", f"shade={path}")
        assert status == 2, (path, status, out, err)
        assert err.strip() == f"langur {command}: error: --module shade={path}: {says}", err
