"""Conformance to the contract (CLI.md, LANGUAGE.md), clauses found not honoured or not tested by
the spec27 audit.  Expected values are worked out by hand from the clause, in the comments.

Fixed here (each test fails on main at 1ca536d):

* an output path (``plot -o``, ``render -o/--npz``, ``reproduce --out``) in a folder that does not
  exist was an "internal error" after the whole computation; now a usage error (status 2) before it;
* ``render --npz`` over a file the program reads (an imported module not named ``.lgr``) overwrote it;
* ``render --npz OUT`` wrote ``OUT.npz`` and reported ``OUT``;
* ``plot --seed -1`` was accepted (the convergence plot then failed as an internal error);
* ``eval/deriv --json`` gave ``exact: null`` without the one-line reason on standard error;
* an endless input (``/dev/zero``, a pipe that never closes) was read until memory ran out;
* ``--module NAME=PATH`` naming a module the program does not import was silently ignored (a typo
  left the shader unswapped); now a usage error naming the modules imported;
* ``check --fix --in-place`` with ``FILE.bak`` a directory was an internal error;
* ``check --diff --json`` (or ``--fix`` of standard input with ``--json``) printed a diff or a program
  where ``--json`` promises one JSON object on standard output, nothing else.
"""

from __future__ import annotations

import io
import json
import math
import os

import pytest
from paths import DEGENERATE, EXAMPLES
from test_cli_contract import run  # (status, stdout, stderr) of ``langur ARGV`` in this process

from langur import cli, source

FIG1 = str(EXAMPLES / "fig1.lgr")
FIG9 = str(EXAMPLES / "fig9.lgr")


def one_line(err: str) -> str:
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert "Traceback" not in err and "internal error" not in err
    return lines[0]


def _no_work(monkeypatch):
    """Make the engines fail loudly: a refusal must come before any of them runs."""
    def work(*a, **k):
        raise AssertionError("the engine ran before the output path was checked")

    monkeypatch.setattr("langur.commands.render.estimate_batch", work)
    monkeypatch.setattr("langur.reproduce.run", work)


# -- outputs: checked before any work; never over a file the user wrote ---------------------------

def _scene(tmp_path, module_name="lib.npz"):
    """A two-parameter program importing its shading from a module whose file is not named .lgr."""
    lib = tmp_path / module_name
    lib.write_text("def shade(x: var, y: var) = 1\n")
    prog = tmp_path / "p.lgr"
    prog.write_text("from lib import shade\nparam a = 0.5, b = 0.5\n"
                    "int ([0, 1], [0, 1]) [x <= a] * [y <= b] * shade(x, y) d(x, y)\n")
    return prog, lib


def test_an_output_in_a_missing_folder_is_a_usage_error_before_any_work(capsys, tmp_path, monkeypatch):
    prog, _ = _scene(tmp_path)
    _no_work(monkeypatch)
    nowhere = tmp_path / "p.lgr" / "x"  # under a file: a folder that cannot exist
    for argv, says in [
        (["render", prog, "--module", f"lib={tmp_path / 'lib.npz'}", "--grid", "a=0:1:2,b=0:1:2", "--npz",
          f"{nowhere}.npz"], f"--npz {nowhere}.npz: no such folder"),
        (["render", prog, "--module", f"lib={tmp_path / 'lib.npz'}", "--grid", "a=0:1:2,b=0:1:2", "-o",
          f"{nowhere}.png"], f"-o {nowhere}.png: no such folder"),
        (["render", prog, "--module", f"lib={tmp_path / 'lib.npz'}", "--grid", "a=0:1:2,b=0:1:2", "-o", tmp_path],
         f"-o {tmp_path}: is a directory"),
        (["plot", FIG1, "-o", f"{nowhere}.png"], f"-o {nowhere}.png: no such folder"),
        (["reproduce", "fig1", "--out", nowhere], f"--out {nowhere}: cannot create the directory"),
    ]:
        status, out, err = run(capsys, *argv)
        assert status == 2 and out == "", (argv, err)
        assert says in one_line(err), argv


def test_render_never_writes_over_a_module_the_program_imports(capsys, tmp_path, monkeypatch):
    prog, lib = _scene(tmp_path)
    before = lib.read_bytes()
    _no_work(monkeypatch)
    grid = ["--module", f"lib={lib}", "--grid", "a=0:1:2,b=0:1:2"]
    for flag in ("--npz", "-o"):
        status, _, err = run(capsys, "render", prog, *grid, flag, lib)
        assert status == 2 and f"{lib}: refusing to write over a program" in one_line(err)
    os.symlink(lib, tmp_path / "link.npz")  # through a link too
    status, _, err = run(capsys, "render", prog, *grid, "--npz", tmp_path / "link.npz")
    assert status == 2 and "refusing to write over a program" in one_line(err)
    assert lib.read_bytes() == before


def test_plot_never_writes_over_a_module_given_with_module(capsys, tmp_path):
    lib = tmp_path / "shade.png"  # a module file, named as a picture would be
    lib.write_text("def shade(x: var, y: var, c: param) = 1\n")
    status, _, err = run(capsys, "plot", str(EXAMPLES / "renderer.lgr"), "--module", f"shader={lib}", "-o", lib)
    assert status == 2 and f"-o {lib}: refusing to write a picture over a program" in one_line(err)
    assert lib.read_text() == "def shade(x: var, y: var, c: param) = 1\n"


def test_render_reports_the_npz_file_it_wrote(capsys, tmp_path):
    # numpy.savez_compressed appends .npz to a name without it: that is the file written
    prog = tmp_path / "q.lgr"
    prog.write_text("param a = 0.5, b = 0.5\nint ([0, 1]) [x <= a] * b d(x)\n")
    status, out, _ = run(capsys, "render", prog, "--grid", "a=0:1:2,b=0:1:2", "--samples", "8", "--npz",
                         tmp_path / "arrays", "--json")
    assert status == 0
    assert json.loads(out)["written"] == [str(tmp_path / "arrays.npz")]
    assert (tmp_path / "arrays.npz").is_file() and not (tmp_path / "arrays").exists()


def test_plot_seed_is_a_seed(capsys, tmp_path):
    status, out, err = run(capsys, "plot", FIG9, "--kind", "convergence", "--seed", "-1", "-o", tmp_path / "c.png")
    assert status == 2 and out == ""
    assert "argument --seed: a seed must be between 0 and" in one_line(err)
    assert not (tmp_path / "c.png").exists()


def test_a_module_option_nothing_imports_is_a_usage_error(capsys):
    renderer, lin = EXAMPLES / "renderer.lgr", EXAMPLES / "lin_shader.lgr"
    status, out, err = run(capsys, "eval", renderer, "--module", f"shadr={lin}", "--samples", "100")
    assert status == 2 and out == ""
    assert one_line(err) == f"langur eval: error: --module shadr={lin}: {renderer} imports no module shadr " \
                            "(it imports: shader)"
    status, _, err = run(capsys, "deriv", FIG1, "--module", f"shader={lin}")
    assert status == 2 and "imports no module shader (it imports: none)" in one_line(err)
    # the name it does import swaps the shader: at c = −1 the lit half x + y ≥ 1 of the pixel (area ½) is
    # shaded 1 by the constant shader (value ½) and 1/(√2·(x + y − 1) + 2) ≤ ½ by the linear one (value ≤ ¼)
    status, out, _ = run(capsys, "eval", renderer, "--module", f"shader={lin}", "--engine", "exact", "--json")
    assert status == 0 and 0 < json.loads(out)["exact"]["value"] < 0.25


def test_fix_in_place_with_a_backup_that_is_a_directory_is_refused(capsys, tmp_path):
    f = tmp_path / "co.lgr"
    f.write_text("param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n")  # X301: a rewrite to write
    (tmp_path / "co.lgr.bak").mkdir()
    status, out, err = run(capsys, "check", f, "--isolated", "--fix", "--in-place")
    assert status == 2 and out == ""
    assert one_line(err) == f"langur check: error: {f}.bak: Is a directory: not overwritten"
    assert f.read_text() == "param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n"


@pytest.mark.parametrize("argv, says", [
    (["--diff", "--json"], "--diff prints a diff on standard output: it does not go with --json"),
    (["--diff", "--format", "sarif"], "--diff prints a diff on standard output: it does not go with --format sarif"),
    (["--fix", "--format", "json"], "--fix of standard input prints the program on standard output: it does not "
     "go with --format json"),
])
def test_check_json_is_never_mixed_with_a_rewrite_on_standard_output(capsys, monkeypatch, argv, says):
    text = b"param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n"  # X301: there is a rewrite
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(text)))
    status, out, err = run(capsys, "check", "-", "--isolated", *argv)
    assert status == 2 and out == "" and says in one_line(err)


# -- JSON: exact is null only with a one-line reason on standard error -----------------------------

def test_json_exact_null_comes_with_one_line_on_stderr(capsys, tmp_path):
    # 1/a at a = 0: the integrand is undefined on all of [0, 1], so is the integral (LANGUAGE.md §1)
    f = tmp_path / "div.lgr"
    f.write_text("param a = 0\nint ([0, 1]) 1/a + 0*x d(x)\n")
    status, out, err = run(capsys, "eval", f, "--json", "--samples", "100")
    r = json.loads(out)
    assert status == 1 and r["exact"] is None and r["undefined"]
    assert one_line(err) == f"langur eval: no exact value: undefined: {r['undefined']}"
    # [x ≥ a]·[x ≥ a]: not transverse (X301), no derivative presented
    status, out, err = run(capsys, "deriv", DEGENERATE / "coincident.lgr", "--wrt", "a", "--json")
    r = json.loads(out)
    assert status == 1 and r["exact"] is None
    line = one_line(err)
    assert line.startswith("langur deriv: no exact value: undefined: the program is not transverse (X301 at 5:25)")
    # ∫₀¹[x ≤ θ] has a corner at θ = 1 (X305): no derivative
    status, out, err = run(capsys, "deriv", DEGENERATE / "boundary.lgr", "--wrt", "theta", "--json")
    assert status == 1 and json.loads(out)["exact"] is None and "X305" in one_line(err)
    # where exact has a value, standard error stays empty
    status, out, err = run(capsys, "eval", FIG1, "--json", "--samples", "100")
    assert status == 0 and json.loads(out)["exact"]["value"] == 0.5 and err == ""


def test_non_finite_values_are_strings_with_a_reason_for_the_missing_exact_value(capsys, tmp_path):
    # a² (x + 1) with a = 10³⁰⁰: every sample is 10⁶⁰⁰·(x + 1), beyond a double: "inf" (CLI.md)
    f = tmp_path / "big.lgr"
    f.write_text("param a = 1e300\nint ([0, 1]) a * a * (x + 1) d(x)\n")
    status, out, err = run(capsys, "eval", f, "--json", "--samples", "100")
    r = json.loads(out)
    assert r["mc"]["value"] == "inf" and r["mc"]["stderr"] == "nan" and r["exact"] is None
    assert one_line(err).startswith("langur eval: no exact value: ")


# -- inputs: an endless one is refused, not read until memory runs out -----------------------------

class _Endless(io.RawIOBase):
    """Standard input that never ends (``yes |``, ``/dev/zero``): refuses a read without a limit."""

    def fileno(self):
        raise io.UnsupportedOperation("fileno")

    def read(self, n=-1):
        if n is None or n < 0:
            raise AssertionError("an endless input read without a limit")
        return b"#" * n


class _Stdin:
    buffer = _Endless()


@pytest.mark.parametrize("command", ["eval", "check"])
def test_an_endless_standard_input_is_E108(capsys, monkeypatch, command):
    monkeypatch.setattr("sys.stdin", _Stdin())
    status, out, err = run(capsys, command, "-", "--isolated") if command == "check" else run(capsys, command, "-")
    assert status == 1
    text = out if command == "check" else err
    assert text.startswith(f"<stdin>:1:1: error E108 source too large: more than {source.MAX_SOURCE_BYTES:,} bytes")


def test_a_file_over_the_limit_is_E108_without_reading_it(capsys, tmp_path):
    big = tmp_path / "big.lgr"
    with open(big, "wb") as fh:  # sparse: its size says it all
        fh.truncate(source.MAX_SOURCE_BYTES + 1)
    status, _, err = run(capsys, "eval", big)
    assert status == 1 and one_line(err).startswith(f"{big}:1:1: error E108 source too large")
    status, out, _ = run(capsys, "check", big, DEGENERATE / "coincident.lgr", "--isolated")
    codes = [ln.split()[2] for ln in out.splitlines()]
    assert status == 1 and codes == ["E108", "X301"]  # the other file is still checked


# -- clauses honoured but not tested before ---------------------------------------------------------

def test_the_completion_example_of_language_md(capsys):
    # LANGUAGE.md §6: [y < x + θ] completes to Ψ̂(x, y; θ) = (x + θ − y, x), inverse
    # (u₀, u₁) ↦ (u₁, u₁ + θ − u₀); fig9.lgr is that condition
    status, out, _ = run(capsys, "show", FIG9, "--wrt", "theta")
    assert status == 0
    assert "Psi(x, y) = (theta + x - y, x)" in out
    assert "inverse branch 1 in (u0, u1): x = u1, y = theta - u0 + u1" in out


def test_at_and_dir_take_comma_separated_assignments(capsys, tmp_path):
    # ⟦p⟧ = ∫₀¹ [x ≤ a] + [x ≤ b] + c dx = a + b + c for a, b in [0, 1]
    f = tmp_path / "abc.lgr"
    f.write_text("param a = 0, b = 0, c = 0\nint ([0, 1]) [x <= a] + [x <= b] + c d(x)\n")
    for at in (["--at", "a=0.25,b=0.5,c=-1"], ["--at", "a=0.25", "--at", "b=0.5,c=-1"]):
        status, out, _ = run(capsys, "eval", f, *at, "--json", "--samples", "100")
        r = json.loads(out)
        assert status == 0 and r["params"] == {"a": 0.25, "b": 0.5, "c": -1.0}
        assert r["exact"]["value"] == -0.25
    # direction γ' = (1, 0.5, 2): D⟦p⟧·γ' = 1·1 + 1·0.5 + 1·2 = 3.5, of which the deltas give 1.5
    status, out, _ = run(capsys, "deriv", f, "--at", "a=0.25,b=0.5", "--dir", "a=1,b=0.5,c=2", "--json",
                         "--no-theorem", "--samples", "100")
    r = json.loads(out)
    assert status == 0 and r["direction"] == {"a": 1.0, "b": 0.5, "c": 2.0}
    assert (r["exact"]["value"], r["exact"]["regular"], r["exact"]["boundary"]) == (3.5, 2.0, 1.5)
    assert r["mc"]["boundary"]["value"] == 1.5  # one variable: each delta sampled at its root, exactly


@pytest.mark.parametrize("argv, key, expected", [
    (["eval", "-", "--json", "--samples", "100"], ("exact", "value"), 0.5),  # ∫₀¹[x ≤ ½] = ½
    (["deriv", "-", "--json", "--samples", "100"], ("exact", "boundary"), 1.0),  # δ(θ − x) at x = ½
])
def test_a_file_of_dash_reads_standard_input(capsys, monkeypatch, argv, key, expected):
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(open(FIG1, "rb").read())))
    status, out, _ = run(capsys, *argv)
    r = json.loads(out)
    assert status == 0 and r[key[0]][key[1]] == expected


def test_a_diagnostic_from_standard_input_is_located(capsys, monkeypatch):
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(b"param a = 1\nint ([0, 1]) x + q d(x)\n")))
    status, _, err = run(capsys, "show", "-")
    assert status == 1 and one_line(err).startswith("<stdin>:2:18: error T201 unbound name `q`")


def test_ifge0_tests_greater_or_equal(capsys, tmp_path):
    # LANGUAGE.md §1: `ifge0` tests ≥ 0, so at a = 0 it takes the then branch: ∫₀¹ 1 = 1; below, 2
    f = tmp_path / "ge.lgr"
    f.write_text("param a = 0\nint ([0, 1]) ifge0 a then 1 else 2 d(x)\n")
    for a, value in (("0", 1.0), ("-0.001", 2.0)):
        status, out, _ = run(capsys, "eval", f, "--at", f"a={a}", "--json", "--samples", "100")
        r = json.loads(out)
        assert status == 0 and r["exact"]["value"] == value and r["mc"]["value"] == value


@pytest.mark.parametrize("command", list(cli.COMMANDS))
def test_every_subcommand_has_help(capsys, command):
    status, out, _ = run(capsys, command, "--help")
    assert status == 0 and out.startswith(f"usage: langur {command}")


def test_a_quadrature_answer_carries_its_error_bound(capsys, tmp_path):
    # CLI.md: method "quadrature", then an "error" field bounds the estimate.  [sin(10xy) ≥ 0] on the
    # unit square: 10xy ∈ [0, π] ∪ [2π, 3π] (10xy ≤ 10 < 4π), so the value is A(π/10) − A(2π/10) + A(3π/10)
    # with A(t) = |{xy ≤ t}| = t − t·ln t (t ≤ 1); sympy cannot solve sin(10xy) ≥ 0 for y in closed form
    f = tmp_path / "sin.lgr"
    f.write_text("int ([0, 1], [0, 1]) ifge0 sin(x * y * 10) then 1 else 0 d(x, y)\n")
    status, out, _ = run(capsys, "eval", f, "--engine", "exact", "--json")
    ex = json.loads(out)["exact"]
    area = lambda t: t - t * math.log(t)  # noqa: E731
    by_hand = area(math.pi / 10) - area(2 * math.pi / 10) + area(3 * math.pi / 10)
    assert status == 0 and ex["method"] == "quadrature"
    assert 0 < ex["error"] < 1e-6 and abs(ex["value"] - by_hand) <= ex["error"] + 1e-12


def test_regular_plus_boundary_is_the_value(capsys):
    # Fig. 9 at θ = 0: ⦇p⦈ of [y < x + θ]·(1 + θ + x + y) on [−1, 1]².  Regular part: ∂θ of the weight is 1,
    # over {y < x}: area 2.  Boundary: the line y = x (|∂Φ/∂y| = 1) carries 1 + 2x, ∫₋₁¹ (1 + 2x) dx = 2.
    status, out, _ = run(capsys, "deriv", FIG9, "--json", "--no-theorem", "--samples", "4000")
    r = json.loads(out)
    ex, mc = r["exact"], r["mc"]
    assert status == 0 and (ex["value"], ex["regular"], ex["boundary"]) == (4.0, 2.0, 2.0)
    assert mc["value"] == mc["regular"]["value"] + mc["boundary"]["value"]
    assert abs(mc["value"] - 4.0) <= 5 * mc["stderr"]
