"""The `langur` command's contract (CLI.md): eval, deriv, show, reproduce; JSON shapes; exit codes.

Expected numbers are derived by hand in the comments, never taken from an engine's output.
`langur check` has its own tests (test_check_cli.py).
"""

import json
import subprocess
import sys

import pytest
from paths import DEGENERATE, EXAMPLES

from langur.cli import main

FIG1 = str(EXAMPLES / "fig1.lgr")


def run(capsys, *argv):
    status = main(list(argv))
    out = capsys.readouterr()
    return status, out.out, out.err


def run_json(capsys, *argv):
    status, out, err = run(capsys, *argv, "--json")
    assert status == 0, err
    return json.loads(out)


def test_eval_json_shape_and_values(capsys):
    r = run_json(capsys, "eval", FIG1, "--samples", "20000", "--seed", "3")
    assert r["params"] == {"theta": 0.5}
    # ∫₀¹ [x ≤ 1/2] dx = 1/2, in closed form
    assert r["exact"]["value"] == 0.5 and r["exact"]["method"] == "closed_form"
    assert isinstance(r["exact"]["expr"], str)
    mc = r["mc"]
    assert (mc["samples"], mc["seed"]) == (20000, 3)
    # Bernoulli(1/2) samples: stderr ≈ 0.5/√20000 ≈ 0.0035; agree within 5σ
    assert 0.002 < mc["stderr"] < 0.005
    assert abs(mc["value"] - 0.5) <= 5 * mc["stderr"]


def test_deriv_json_fig1(capsys):
    r = run_json(capsys, "deriv", FIG1, "--wrt", "theta")
    assert r["direction"] == {"theta": 1.0}
    ex = r["exact"]
    # D_θ θ = 1: regular part 0 (the integrand is piecewise constant), all of it from δ(θ − x)
    assert (ex["value"], ex["regular"], ex["boundary"]) == (1.0, 0.0, 1.0)
    # one sample on the jump is exact in one variable; standard AD differentiates samples: 0
    assert r["mc"]["value"] == 1.0 and r["mc"]["stderr"] == 0.0
    assert r["standard_ad"]["value"] == 0.0
    assert r["theorem_8_1"]["holds"] is True


def test_no_theorem_skips_the_check(capsys):
    r = run_json(capsys, "deriv", FIG1, "--wrt", "theta", "--no-theorem")
    assert r["theorem_8_1"] is None and r["exact"]["value"] == 1.0


def test_deriv_at_and_dir(capsys):
    # ∫₀¹[x ≤ θ] = θ for θ in [0, 1]: derivative 1 at θ = 0.25; outside the domain, at θ = 2, 0
    r = run_json(capsys, "deriv", FIG1, "--dir", "theta=2", "--at", "theta=0.25")
    assert r["exact"]["value"] == 2.0 and r["mc"]["value"] == 2.0
    r = run_json(capsys, "deriv", FIG1, "--wrt", "theta", "--at", "theta=2")
    assert r["exact"]["value"] == 0.0 and r["mc"]["value"] == 0.0


def test_deriv_at_a_degenerate_point_is_undefined(capsys):
    # ∫₀¹[x ≤ θ] = min(max(θ, 0), 1) has a corner at θ = 1 (the jump lies on the domain's end):
    # no derivative there (X305), although ⦇p⦈ would say 1 and standard AD 0; at θ = 0.5 it is 1.
    r = run(capsys, "deriv", str(DEGENERATE / "boundary.lgr"), "--wrt", "theta", "--json")
    assert r[0] == 1
    j = json.loads(r[1])
    assert j["exact"] is None and "does not exist" in j["undefined"] and "X305" in j["undefined"]
    assert [d["code"] for d in j["diagnostics"]] == ["X305"]
    r = run_json(capsys, "deriv", str(DEGENERATE / "boundary.lgr"), "--wrt", "theta", "--at", "theta=0.5")
    assert r["exact"]["value"] == 1.0 and r["undefined"] is None
    # The triangle abc with a = (ax, 0.1), b = (0.9, 0.3), c = (0.4, 0.8) has area (0.55 − 0.5·ax)/2
    # for ax < 1.1 (inside the pixel for ax ≤ 1), and is empty beyond (clockwise): at ax = 1.1 the
    # three vertices are collinear, the edges' jumps coincide, and the derivative (−13/56 on the
    # left, test_onesided.py; 0 on the right) does not exist.
    tri = str(EXAMPLES / "triangle.lgr")
    status, out, err = run(capsys, "deriv", tri, "--wrt", "ax", "--at", "ax=1.1", "--no-theorem")
    assert status == 1 and "undefined" in out and "error X305" in err
    r = run_json(capsys, "deriv", tri, "--wrt", "ax", "--at", "ax=0.5", "--no-theorem")
    assert abs(r["exact"]["value"] + 0.25) < 1e-9


def test_theorem_8_1_fails_on_the_coincident_program(capsys):
    # [x ≥ a]·[x ≥ a] on [0, 1]: ⟦p⟧ = 1 − a so D⟦p⟧ = −1; the product rule counts the jump
    # twice (each factor is 1 at x = a): ⦇p⦈ = −2 (paper §7.3.1, footnote 7).
    # `langur deriv` therefore presents no number (X301, exit 1; test_rewrite.py); the engines'
    # APIs still compute ⦇p⦈ as written, and Theorem 8.1's check shows it is not D⟦p⟧.
    from langur import frontend, operational
    from langur.exact import exact_deriv

    status, out, _ = run(capsys, "deriv", str(DEGENERATE / "coincident.lgr"), "--wrt", "a", "--json")
    assert status == 1 and json.loads(out)["exact"] is None
    loaded = frontend.load(str(DEGENERATE / "coincident.lgr"))
    t = exact_deriv(loaded.program, {"a": 0.5}, {"a": 1}).theorem_8_1
    assert t.holds is False
    assert t.d_denotation == pytest.approx(-1.0, abs=1e-6)
    assert t.derivative_denotation == pytest.approx(-2.0, abs=1e-12)
    assert operational.estimate_derivative(loaded, {"a": 0.5}, {"a": 1}).value == -2.0


def test_same_seed_same_numbers_other_seed_other_numbers(capsys):
    fig9 = str(EXAMPLES / "fig9.lgr")
    a = run_json(capsys, "deriv", fig9, "--wrt", "theta", "--engine", "mc", "--samples", "2000", "--seed", "7")
    b = run_json(capsys, "deriv", fig9, "--wrt", "theta", "--engine", "mc", "--samples", "2000", "--seed", "7")
    c = run_json(capsys, "deriv", fig9, "--wrt", "theta", "--engine", "mc", "--samples", "2000", "--seed", "8")
    assert a == b
    assert a["mc"]["value"] != c["mc"]["value"]
    assert a["exact"] is None and a["theorem_8_1"] is None


def test_nan_is_written_as_a_string(tmp_path, capsys):
    # log(x − 2) < 0 argument everywhere on [0, 1]: undefined, NaN in both engines
    f = tmp_path / "logneg.lgr"
    f.write_text("int ([0, 1]) log(x - 2) d(x)\n")
    status, out, _ = run(capsys, "eval", str(f), "--engine", "mc", "--json")
    assert status == 1  # undefined is an answer (X311), with the Monte Carlo number still printed
    r = json.loads(out)
    assert r["mc"]["value"] == "nan" and r["undefined"] and r["diagnostics"][0]["code"] == "X311"


def test_text_output_names_the_parts(capsys):
    status, out, _ = run(capsys, "deriv", FIG1, "--wrt", "theta")
    assert status == 0
    assert "regular 0 + boundary 1" in out and "standard AD" in out and "Theorem 8.1 : holds" in out


def test_show_core_denotation_and_derivative(capsys):
    status, out, _ = run(capsys, "show", str(EXAMPLES / "fig9.lgr"), "--wrt", "theta")
    assert status == 0
    assert "int ([-1, 1], [-1, 1])" in out  # the core program, domain printed back
    assert "δ(" in out  # the delta term of the normal form
    status, out, _ = run(capsys, "show", str(EXAMPLES / "fig9.lgr"), "--wrt", "theta", "--latex")
    assert status == 0 and "\\delta" in out


def test_show_library_module(capsys):
    status, out, _ = run(capsys, "show", str(EXAMPLES / "densities.lgr"))
    assert status == 0
    assert "def normal(x: var, m: param)" in out and "def window" in out


@pytest.mark.parametrize("argv", [
    ["eval", "no/such/file.lgr"],
    ["eval", FIG1, "--at", "zeta=1"],
    ["eval", FIG1, "--at", "theta"],
    ["eval", FIG1, "--samples", "0"],
    ["deriv", str(EXAMPLES / "risk.lgr")],  # three parameters: which derivative?
    ["deriv", FIG1, "--wrt", "nope"],
    ["eval", str(EXAMPLES / "densities.lgr")],  # no program to evaluate
    ["eval", FIG1, "--no-such-option"],
    ["reproduce", "nope"],
])
def test_usage_errors_exit_2(capsys, argv):
    try:
        status = main(argv)
    except SystemExit as e:  # argparse's own usage errors
        status = e.code
    err = capsys.readouterr().err
    assert status == 2
    assert "Traceback" not in err and err.strip()


def test_bad_program_exits_1_with_located_diagnostic(tmp_path, capsys):
    f = tmp_path / "bad.lgr"
    f.write_text("param a = 1\nint ([0, 1]) [x <= a d(x)\n")
    status, _, err = run(capsys, "eval", str(f))
    assert status == 1
    assert err.startswith(f"{f}:2:") and " error E1" in err


def test_module_override_swaps_the_shader(capsys):
    # constant shader: ∫∫[x + y ≥ s] over the unit square is (2 − s)²/2 for s = −c ∈ [1, 2], so
    # D_c = (2 − s) = 1 at c = −1;
    # linear shader: the boundary term is ∫₀¹ s(x, 1 − x) dx = 1/(√2·0 + 2) = 1/2.
    r = run_json(capsys, "deriv", str(EXAMPLES / "renderer.lgr"), "--wrt", "c", "--engine", "mc")
    assert r["mc"]["value"] == pytest.approx(1.0, abs=1e-12)
    r = run_json(capsys, "deriv", str(EXAMPLES / "renderer.lgr"), "--wrt", "c", "--engine", "mc",
                 "--module", f"shader={EXAMPLES / 'lin_shader.lgr'}")
    assert r["mc"]["boundary"]["value"] == pytest.approx(0.5, abs=1e-12)


def test_reproduce_fig1(capsys):
    status, out, _ = run(capsys, "reproduce", "fig1", "--samples", "2000")
    assert status == 0 and out.startswith("PASS  fig1")


def test_console_script_runs_without_traceback(tmp_path):
    f = tmp_path / "x.lgr"
    f.write_bytes(b"\xff\xfe not utf-8")
    p = subprocess.run([sys.executable, "-m", "langur.cli", "check", str(f)], capture_output=True, text=True)
    assert p.returncode == 1 and "E101" in p.stderr + p.stdout and "Traceback" not in p.stderr
