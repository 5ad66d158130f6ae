"""Command output that tells the whole truth (session 33, bench/history/2026-11-29.md#honest33.

(1) ``langur check`` reports one finding once per run, in every format: a finding inside an
imported module is reported at the module's place by the importer's check and by the module's own
check (``langur check examples``: shader.lgr's X306 twice).  (2) ``langur deriv`` says when
D⟦p⟧ in the Theorem 8.1 line is a finite difference of quadratures, with its error estimate.
(3) ``check``'s X399 says which limit stopped it: its CPU budget or the wall-clock backstop.
"""

import json
import os
import re
import time
from contextlib import redirect_stderr, redirect_stdout
from io import StringIO

import pytest
from paths import DEGENERATE, EXAMPLES

from langur import timebox
from langur.cli import main
from langur.commands import check
from langur.diagnostics import Diagnostic, Span
from langur.lint.formats import Report, distinct, github_lines, json_document, sarif_document, text_lines

RAYTRACE = EXAMPLES / "raytrace"
# shader.lgr's X306 that scene.lgr's check reports at shader.lgr's place, as shader.lgr's own check
# does (checked by hand in the output of `langur check examples` on main: the same line twice)
TWICE = ("6:20: warning X306 the part `nz + nx * x + ny * y >= 0` of `[zth - k / (nx * x + ny * y + nz) >= 0]` "
         "stops being a diffeomorphism when nx = 0 and ny = 0")


def run(capsys, *argv):
    status = main([*map(str, argv)])
    out, err = capsys.readouterr()
    return status, out, err


# -- (1) one finding once -------------------------------------------------------------------------

@pytest.fixture(scope="module")
def raytrace_json():
    """``check --format json`` of scene.lgr and shader.lgr, shader.lgr named a second way (``./…``
    relative to the repository) so that its place is one file under two spellings."""
    cwd = os.getcwd()
    os.chdir(EXAMPLES.parent)
    try:
        out, err = StringIO(), StringIO()
        with redirect_stdout(out), redirect_stderr(err):
            status = main(["check", "--format", "json", "examples/raytrace/scene.lgr",
                           "./examples/raytrace/shader.lgr"])
    finally:
        os.chdir(cwd)
    return status, json.loads(out.getvalue())["diagnostics"]


def test_a_finding_in_an_imported_module_is_reported_once(raytrace_json):
    status, diags = raytrace_json
    assert status == 0
    lines = [f"{d['line']}:{d['col']}: {d['severity']} {d['code']} {d['message']}" for d in diags
             if d["path"].endswith("shader.lgr")]
    assert sum(1 for line in lines if line.startswith(TWICE)) == 1, lines  # main: 2
    # every distinct finding is kept: each (place, message) appears exactly once, and there are
    # several of shader.lgr's (X304 and X306 at 6:20 and 7:25, as `langur check examples` prints)
    keys = [(os.path.realpath(d["path"]), d["line"], d["col"], d["code"], d["message"]) for d in diags]
    assert len(keys) == len(set(keys))
    assert {(d["line"], d["col"], d["code"]) for d in diags if d["path"].endswith("shader.lgr")} == {
        (6, 20, "X304"), (6, 20, "X306"), (7, 25, "X304"), (7, 25, "X306")}


def _report(path="m.lgr", line=1, message="the finding", code="X306", prove=None, related=()):
    return Report(Diagnostic(Span(path, line, 3, line, 9), "warning", code, message, related), prove)


def test_distinct_keeps_every_distinct_finding_in_order():
    a, b, c = _report(line=1), _report(line=2), _report(line=1, code="X304")
    d = _report(line=1, message="another")
    e = _report(line=1, related=(Span("n.lgr", 4, 1, 4, 2),))
    assert distinct([a, b, a, c, b, d, e, a]) == [a, b, c, d, e]


def test_distinct_one_file_under_two_spellings(tmp_path):
    f = tmp_path / "m.lgr"
    f.write_text("")
    one, two = _report(str(f)), _report(str(tmp_path / "." / "m.lgr"))
    assert distinct([one, two]) == [one]
    # a path that is no file is compared as written
    assert len(distinct([_report("<stdin>"), _report("<stdin>"), _report("./<stdin>")])) == 2


def test_distinct_keeps_each_programs_proof_and_drops_a_copy_without_one():
    unproved = _report()
    at_a = _report(prove={"verdict": "right", "summary": "at a = 0: …"})
    at_b = _report(prove={"verdict": "wrong", "summary": "at a = 1: …"})
    assert distinct([unproved, at_a, at_b, at_a]) == [at_a, at_b]
    assert distinct([unproved, unproved]) == [unproved]


@pytest.mark.parametrize("render", [
    lambda rs: text_lines(rs),
    lambda rs: github_lines(rs),
    lambda rs: json_document(rs)["diagnostics"],
    lambda rs: sarif_document(rs)["runs"][0]["results"],
])
def test_every_format_shows_a_finding_once(render):
    reports = [_report(line=1), _report(line=2), _report(line=1)]
    assert len(render(distinct(reports))) == 2 and len(render(reports)) == 3


def test_the_text_summary_counts_each_finding_once(tmp_path, capsys, monkeypatch):
    # two FILEs whose checks report the same finding (the check is replaced: only the run's
    # bookkeeping is under test here)
    for name in ("a.lgr", "b.lgr"):
        (tmp_path / name).write_text("param a = 0.5\nint ([0, 1]) [x <= a] d(x)\n", encoding="utf-8")
    same = _report(str(tmp_path / "a.lgr"))

    def one(args, name, data, cfg, modules, at, used_at, fixes, reports, loaded_files):
        loaded_files.append((name, None))
        reports.append(same)

    monkeypatch.setattr(check, "_check_one", one)
    monkeypatch.setattr(check, "refuse_unimported_modules", lambda *a: None)
    status, out, err = run(capsys, "check", tmp_path / "a.lgr", tmp_path / "b.lgr")
    assert out.count("X306") == 1, out
    assert "2 files checked: 0 error(s), 1 warning(s)" in err


# -- (2) the Theorem 8.1 line says what a finite difference is --------------------------------------

def test_deriv_says_the_theorem_check_used_finite_differences_with_their_error(capsys):
    status, out, _ = run(capsys, "deriv", DEGENERATE / "tangent.lgr", "--engine", "exact")
    assert status == 0
    line = next(x for x in out.splitlines() if x.lstrip().startswith("Theorem 8.1"))
    m = re.search(r"D⟦p⟧ ≈ (\S+) ± (\S+) \(finite differences of quadratures", line)
    assert m, line  # main: "holds: D⟦p⟧ = -0.585769771, ⦇p⦈ = -0.5857864376", no error
    # by hand: with c = 1 − a, ⟦p⟧ = 2∫₀^√(c/2) x² dx + 2∫_√(c/2)^√c (c − x²) dx = (4/3)(1 − 1/√2)c^(3/2),
    # so D⟦p⟧ = −2(1 − 1/√2)√c = −(2 − √2) at a = 0; the finite difference is within its error of it
    hand = -(2 - 2 ** 0.5)
    fd, error = float(m.group(1)), float(m.group(2))
    assert abs(fd - hand) <= error and 0 < error < 1e-3
    assert f"⦇p⦈ = {hand:.10g}" in line


def test_deriv_json_carries_the_same_error(capsys):
    status, out, _ = run(capsys, "deriv", DEGENERATE / "tangent.lgr", "--engine", "exact", "--json")
    th = json.loads(out)["theorem_8_1"]
    assert th["how"] == "finite_difference" and th["holds"] is True
    assert abs(th["d_denotation"] - -(2 - 2 ** 0.5)) <= th["error"]


def test_deriv_says_how_a_closed_form_check_compared(capsys):
    # fig1: D⟦p⟧ from the closed form Max(0, Min(1, θ)) is 1 at θ = 0.5, exactly (no ≈, no ±)
    status, out, _ = run(capsys, "deriv", EXAMPLES / "fig1.lgr", "--engine", "exact")
    line = next(x for x in out.splitlines() if x.lstrip().startswith("Theorem 8.1"))
    assert "D⟦p⟧ = 1, ⦇p⦈ = 1" in line and "≈" not in line and "compared" in line, line


def test_check_prove_says_the_finite_difference_too(capsys):
    status, out, _ = run(capsys, "check", "--prove", DEGENERATE / "tangent.lgr")
    assert "D_a⟦p⟧ ≈ -0.58577 ± " in out and "(finite differences of quadratures" in out, out


# -- (3) which limit stopped the check -----------------------------------------------------------

def _program(tmp_path):
    program = tmp_path / "p.lgr"
    program.write_text("param a = 0.5\nint ([0, 1]) [x <= a] d(x)\n", encoding="utf-8")
    return program


def test_x399_says_the_wall_clock_backstop_stopped_it(tmp_path, monkeypatch, capsys):
    # a check that waits uses no CPU: only the backstop (here 1 × 0.3 + 0.2 = 0.5 s) stops it
    monkeypatch.setattr(timebox, "BACKSTOP_FACTOR", 1.0)
    monkeypatch.setattr(timebox, "BACKSTOP_SLACK", 0.2)
    monkeypatch.setattr(check, "_check_one", lambda *args: time.sleep(20))
    start = time.monotonic()
    status, out, _ = run(capsys, "check", _program(tmp_path), "--timeout", "0.3")
    assert time.monotonic() - start < 10
    assert status == 1
    assert "error X399 the check was stopped by its wall-clock backstop after 0.5 s (1 × 0.3 + 0.2), having used " in out, out
    assert "CPU budget" not in out and "a larger one raises both limits" in out


def _spin(*args):
    end = time.process_time() + 5
    while time.process_time() < end:
        pass


def test_x399_says_the_cpu_budget_stopped_it(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(check, "_check_one", _spin)
    status, out, _ = run(capsys, "check", _program(tmp_path), "--timeout", "0.3")
    assert status == 1
    assert "error X399 the check did not finish within 0.3 CPU s, its CPU budget (--timeout 0.3; a larger " \
           "--timeout raises it)" in out, out
    assert "backstop" not in out


def test_a_limit_says_which_clock_ended_it(monkeypatch):
    with pytest.raises(timebox.TimeLimit) as cpu:
        timebox.run_with_timeout(_spin, 0.2, cpu=True)
    assert timebox.stopped_by(cpu.value) is timebox.Clock.CPU
    monkeypatch.setattr(timebox, "BACKSTOP_FACTOR", 1.0)
    monkeypatch.setattr(timebox, "BACKSTOP_SLACK", 0.1)
    with pytest.raises(timebox.TimeLimit) as wall:
        timebox.run_with_timeout(lambda: time.sleep(20), 0.2, cpu=True)
    assert timebox.stopped_by(wall.value) is timebox.Clock.BACKSTOP
    assert str(wall.value) == "call took longer than 0.3 s (wall clock)"
    with pytest.raises(timebox.TimeLimit) as plain:
        timebox.run_with_timeout(lambda: time.sleep(20), 0.2)
    assert timebox.stopped_by(plain.value) is timebox.Clock.WALL
    assert timebox.stopped_by(TimeoutError("elsewhere")) is None


# -- (4) render's comparison says where the Monte Carlo standard error was 0 ---------------------------

def test_render_counts_points_whose_mc_samples_all_missed(tmp_path, capsys):
    # ∫₀¹ [x ≤ a + b] dx = a + b (by hand) is 1e-4 … 3e-4 on this grid: 64 samples (seed 0) all miss
    # it, so MC says 0 with SE 0 at every point; main left these points out and printed
    # "value: MC within 0 SE (beyond 5 SE: 0)"
    program = tmp_path / "tiny.lgr"
    program.write_text("param a = 0.0001, b = 0\nint ([0, 1]) [x <= a + b] d(x)\n", encoding="utf-8")
    grid = ["--grid", "a=0.0001:0.0002:2,b=0:0.0001:2", "--exact", "--wrt", "a"]
    status, out, _ = run(capsys, "render", program, *grid, "--json")
    ex = json.loads(out)["exact"]
    assert ex["value"]["min"] == pytest.approx(1e-4) and ex["value"]["max"] == pytest.approx(3e-4)
    assert (ex["value_compared_se"], ex["value_se_zero"], ex["value_se_zero_differ"]) == (0, 4, 4)
    # the derivative's boundary part is the delta at x = a + b: 1 for every sample, as exactly
    assert (ex["derivative_se_zero"], ex["derivative_se_zero_differ"]) == (4, 0)
    status, out, _ = run(capsys, "render", program, *grid)
    assert "value: MC's SE is 0 at 4 point(s) (every sample alike), compared for equality: 4 differ" in out, out
    assert "within 0 SE" not in out


# -- (4) show says what eval says of a quadrature's error: an estimate, and what is proved ------------

def test_show_says_a_quadratures_error_is_an_estimate(capsys):
    # implicit2d has no closed form: main's show printed "2.15293234983 ± 6.3e-10 (quadrature)", an
    # unqualified ± where eval says "error estimate 6.31e-10, proved ≤ 0.773" (only 0.773 is proved)
    status, out, _ = run(capsys, "eval", EXAMPLES / "implicit2d.lgr", "--engine", "exact", "--json")
    ex = json.loads(out)["exact"]
    assert ex["method"] == "quadrature"
    status, out, _ = run(capsys, "eval", EXAMPLES / "implicit2d.lgr", "--engine", "exact")
    said = re.search(r"exact : \S+ +(\(quadrature, [^)]*\))", out).group(1)
    assert said.startswith(f"(quadrature, error estimate {ex['error']:.3g}") or "error ≤" in said, said
    status, out, _ = run(capsys, "show", EXAMPLES / "implicit2d.lgr")
    line = next(x for x in out.splitlines() if "value at a = 1/2" in x)
    assert line.endswith(f"{ex['value']:.12g} {said}"), (line, said)


def test_an_analysis_budget_says_when_the_backstop_ended_it(monkeypatch):
    # X310's "stopped after S CPU s (its budget)" was said whichever limit ended the budget
    from langur.lint.findings import PerCondition
    from langur.transversality import _stopped

    assert timebox.Deadline(0.0).stopped_by() is timebox.Clock.CPU
    assert timebox.Deadline(60.0).stopped_by() is None
    monkeypatch.setattr(timebox, "BACKSTOP_FACTOR", 0.0)
    monkeypatch.setattr(timebox, "BACKSTOP_SLACK", 0.05)
    clock = timebox.Deadline(60.0)
    per = PerCondition("turning points", 1.0, 60.0)
    time.sleep(0.2)  # wall clock passes, hardly any CPU
    assert clock.stopped_by() is timebox.Clock.BACKSTOP
    assert per.run("c", None, lambda: "decided") is None
    (finding,) = per.unchecked(Span("p.lgr", 1, 1, 1, 2))
    assert "the analysis was stopped by its wall-clock backstop after 0.05 s (0 × 60 + 0.05), before its 60 CPU s " \
           "were used" in finding.message, finding.message
    assert "stopped after 60 CPU s" not in finding.message

    class P:
        span = Span("p.lgr", 1, 1, 1, 2)

    assert "analysis was stopped by its wall-clock backstop" in _stopped(P, 60.0, "x", timebox.Clock.BACKSTOP).message
    assert "analysis stopped after 60 CPU s (its budget)" in _stopped(P, 60.0, "x", timebox.Clock.CPU).message
