"""``langur check`` as linters behave (CLI.md, Diagnostics): formats, exit codes, suppression,
configuration, several files, standard input, --prove, the pre-commit hook."""

import io
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import jsonschema
import pytest
import yaml
from paths import DEGENERATE, EXAMPLES, REPO

from langur.cli import main
from langur.diagnostics import Diagnostic, Span
from langur.lint.formats import Report, github_lines
from langur.lint.noqa import directive

SCHEMA = Path(__file__).parent / "data" / "sarif-2.1.0.schema.json"
COINCIDENT = "param a = 0.5\nint ([0, 1]) [x >= a] * [x >= a] d(x){tail}\n"
LINE = re.compile(
    r"^(?P<path>.+):(?P<line>\d+):(?P<col>\d+): (?P<sev>error|warning) (?P<code>[ETX]\d{3}) .+$"
)


def run(capsys, *argv, stdin: bytes | None = None, monkeypatch=None):
    if stdin is not None:
        monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(stdin)))
    status = main(["check", *map(str, argv)])
    out, err = capsys.readouterr()
    return status, out, err


def codes_in(out: str) -> list[str]:
    return [m.group("code") for m in map(LINE.match, out.splitlines()) if m]


# ---------------------------------------------------------------------------------------------
# Exit status and the text format


@pytest.mark.parametrize(
    "name,status,expected",
    [
        ("coincident.lgr", 1, ["X301"]),
        ("nested.lgr", 1, ["X301"]),
        ("tangent.lgr", 0, ["X302"]),
        ("three_lines.lgr", 0, ["X303"]),
        ("boundary.lgr", 0, ["X304"]),
        ("equal_params.lgr", 0, ["X304"]),
    ],
)
def test_degenerate_examples(capsys, name, status, expected):
    code, out, _ = run(capsys, DEGENERATE / name, "--isolated")
    assert code == status
    assert codes_in(out) == expected
    for line in out.splitlines():
        m = LINE.match(line)
        assert m and m.group("path") == str(DEGENERATE / name)


@pytest.mark.parametrize(
    "name,at,expected",
    [
        ("boundary.lgr", "theta=1", "X305"),
        ("equal_params.lgr", "a=0.3,b=0.3", "X305"),
    ],
)
def test_at_a_degenerate_point_is_an_error(capsys, name, at, expected):
    code, out, _ = run(capsys, DEGENERATE / name, "--isolated", "--at", at)
    assert code == 1 and codes_in(out) == [expected]
    assert " error X305 " in out


def test_clean_examples_exit_zero_and_print_nothing(capsys):
    files = sorted(EXAMPLES.glob("*.lgr"))
    code, out, _ = run(capsys, *files, "--isolated")
    assert code == 0 and out == ""


def test_several_files_and_directories_are_all_reported(capsys):
    code, out, _ = run(capsys, DEGENERATE / "coincident.lgr", DEGENERATE / "tangent.lgr", "--isolated")
    assert code == 1 and codes_in(out) == ["X301", "X302"]
    code, out, _ = run(capsys, DEGENERATE, "--isolated")
    assert code == 1 and sorted(codes_in(out)) == ["X301", "X301", "X302", "X303", "X304", "X304"]


def test_usage_errors_exit_two(capsys, tmp_path):
    code, _, err = run(capsys, tmp_path / "missing.lgr")
    assert code == 2 and "missing.lgr: no such file" in err
    with pytest.raises(SystemExit) as e:
        main(["check", "--no-such-option", str(DEGENERATE / "coincident.lgr")])
    assert e.value.code == 2
    code, _, err = run(capsys, DEGENERATE / "boundary.lgr", "--at", "nope=1")
    assert code == 2 and "nope" in err
    code, _, err = run(capsys, DEGENERATE / "boundary.lgr", "--at", "theta=one")
    assert code == 2
    code, _, err = run(capsys, DEGENERATE / "boundary.lgr", "--json", "--format", "sarif")
    assert code == 2


def test_front_end_errors_are_reported_in_the_same_formats(capsys, tmp_path):
    bad = tmp_path / "bad.lgr"
    bad.write_text("int ([0, 1]) [x >= ] d(x)\n")
    code, out, _ = run(capsys, bad)
    assert code == 1 and codes_in(out) == ["E102"] and out.startswith(f"{bad}:1:")
    code, out, _ = run(capsys, bad, "--json")
    (d,) = json.loads(out)["diagnostics"]
    assert (d["code"], d["severity"], d["line"]) == ("E102", "error", 1)
    unbound = tmp_path / "unbound.lgr"
    unbound.write_text("int ([0, 1]) [x >= q] d(x)  # noqa\n")
    code, out, _ = run(capsys, unbound, "--exit-zero")
    assert codes_in(out) == ["T201"] and code == 0  # front-end errors are never silenced by noqa


def test_stdin(capsys, monkeypatch):
    code, out, _ = run(capsys, "-", stdin=COINCIDENT.format(tail="").encode(), monkeypatch=monkeypatch)
    assert code == 1 and codes_in(out) == ["X301"] and out.startswith("<stdin>:2:25:")


# ---------------------------------------------------------------------------------------------
# JSON, SARIF, GitHub


def test_json_shape(capsys):
    code, out, _ = run(capsys, DEGENERATE / "coincident.lgr", "--isolated", "--json")
    doc = json.loads(out)
    (d,) = doc["diagnostics"]
    assert code == 1
    assert {k: d[k] for k in ("line", "col", "end_line", "end_col", "severity", "code")} == {
        "line": 5,
        "col": 25,
        "end_line": 5,
        "end_col": 33,
        "severity": "error",
        "code": "X301",
    }
    assert d["path"] == str(DEGENERATE / "coincident.lgr") and d["related"][0]["col"] == 14


def test_sarif_validates_against_the_schema(capsys):
    schema = json.loads(SCHEMA.read_text())
    code, out, _ = run(capsys, DEGENERATE, "--isolated", "--format", "sarif")
    doc = json.loads(out)
    jsonschema.validators.validator_for(schema)(schema).validate(doc)
    (run_,) = doc["runs"]
    assert doc["version"] == "2.1.0" and code == 1
    results = run_["results"]
    assert sorted(r["ruleId"] for r in results) == ["X301", "X301", "X302", "X303", "X304", "X304"]
    rules = run_["tool"]["driver"]["rules"]
    for r in results:
        assert rules[r["ruleIndex"]]["id"] == r["ruleId"]
        assert r["level"] == ("error" if r["ruleId"] == "X301" else "warning")
    coincident = next(
        r for r in results if "coincident" in r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"]
    )
    assert coincident["locations"][0]["physicalLocation"]["region"]["startLine"] == 5
    assert coincident["relatedLocations"][0]["physicalLocation"]["region"]["startColumn"] == 14


def test_sarif_of_a_clean_run_and_of_a_syntax_error_validates(capsys, tmp_path):
    schema = json.loads(SCHEMA.read_text())
    validator = jsonschema.validators.validator_for(schema)(schema)
    _, out, _ = run(capsys, EXAMPLES / "fig1.lgr", "--format", "sarif")
    validator.validate(json.loads(out))
    bad = tmp_path / "bad file.lgr"
    bad.write_text("int (\n")
    _, out, _ = run(capsys, bad, "--format", "sarif")
    doc = json.loads(out)
    validator.validate(doc)
    assert doc["runs"][0]["results"][0]["ruleId"].startswith("E1")


def test_github_format(capsys):
    code, out, _ = run(
        capsys, DEGENERATE / "coincident.lgr", DEGENERATE / "tangent.lgr", "--isolated", "--format", "github"
    )
    first, second = out.splitlines()
    assert first.startswith(
        f"::error file={DEGENERATE / 'coincident.lgr'},line=5,col=25,endLine=5,endColumn=33,title=X301::X301 "
    )
    assert second.startswith("::warning file=") and ",line=5,col=41," in second and "::X302 " in second
    assert code == 1


def test_github_escaping():
    d = Diagnostic(Span("a,b:c.lgr", 1, 2, 1, 3), "warning", "X304", "100% sure\nsecond line")
    (line,) = github_lines([Report(d)])
    assert (
        line
        == "::warning file=a%2Cb%3Ac.lgr,line=1,col=2,endLine=1,endColumn=3,title=X304::X304 100%25 sure%0Asecond line"
    )


# ---------------------------------------------------------------------------------------------
# noqa


@pytest.mark.parametrize(
    "tail,status,remaining",
    [
        ("  # noqa: X301", 0, []),
        ("  # noqa", 0, []),
        ("  # noqa:X301,X304", 0, []),
        ("  # NOQA: x304, X301", 0, []),
        ("  # noqa: X304", 1, ["X301"]),  # another code does not silence X301
        ("  # why: the jump is meant twice  # noqa: X301", 0, []),
        ("  # a comment without the directive", 1, ["X301"]),
    ],
)
def test_noqa(capsys, tmp_path, tail, status, remaining):
    f = tmp_path / "c.lgr"
    f.write_text(COINCIDENT.format(tail=tail))
    code, out, _ = run(capsys, f, "--isolated")
    assert code == status and codes_in(out) == remaining


def test_noqa_only_on_the_primary_line(capsys, tmp_path):
    f = tmp_path / "two.lgr"
    f.write_text("param a = 0.5  # noqa\nint ([0, 1]) [x >= a] * [x >= a] d(x)\n")
    code, out, _ = run(capsys, f, "--isolated")
    assert code == 1 and codes_in(out) == ["X301"]


def test_noqa_directive_parsing():
    assert directive("x # noqa") == frozenset()
    assert directive("x # noqa: X301, X304") == {"X301", "X304"}
    assert directive("x # noqa: X301 because it is meant") == {"X301"}
    assert directive("no comment here") is None
    assert directive("x # something else") is None


# ---------------------------------------------------------------------------------------------
# Configuration


def write_config(root: Path, body: str):
    (root / "pyproject.toml").write_text("[project]\nname = 'x'\n\n[tool.langur]\n" + body)


def copy_degenerate(root: Path, sub="degenerate") -> Path:
    d = root / sub
    shutil.copytree(DEGENERATE, d)
    return d


def test_select_and_ignore(capsys, tmp_path):
    d = copy_degenerate(tmp_path)
    write_config(tmp_path, 'select = ["X302"]\n')
    code, out, _ = run(capsys, d)
    assert code == 0 and codes_in(out) == ["X302"]
    write_config(tmp_path, 'select = ["X3"]\nignore = ["X301", "X30"]\n')
    code, out, _ = run(capsys, d)
    assert code == 0 and out == ""
    write_config(tmp_path, 'ignore = ["X301"]\n')
    code, out, _ = run(capsys, d)
    assert code == 0 and sorted(codes_in(out)) == ["X302", "X303", "X304", "X304"]
    # the command line: --select replaces select, --ignore adds to ignore, --isolated drops the file
    code, out, _ = run(capsys, d, "--select", "X301")
    assert code == 0 and out == ""  # X301 selected but still ignored by the file
    code, out, _ = run(capsys, d, "--isolated", "--select", "X301,X303")
    assert code == 1 and sorted(codes_in(out)) == ["X301", "X301", "X303"]
    code, out, _ = run(capsys, d, "--isolated", "--ignore", "X3")
    assert code == 0 and out == ""


def test_per_file_ignores_and_nearest_pyproject(capsys, tmp_path):
    d = copy_degenerate(tmp_path)
    other = tmp_path / "other"
    other.mkdir()
    shutil.copy(DEGENERATE / "coincident.lgr", other / "coincident.lgr")
    write_config(tmp_path, '[tool.langur.per-file-ignores]\n"degenerate/*.lgr" = ["X301"]\n')
    code, out, _ = run(capsys, d / "coincident.lgr", other / "coincident.lgr")
    assert code == 1 and codes_in(out) == ["X301"] and str(other) in out
    # a nearer pyproject.toml with [tool.langur] wins over the outer one
    write_config(other, 'ignore = ["X3"]\n')
    code, out, _ = run(capsys, d / "coincident.lgr", other / "coincident.lgr")
    assert code == 0 and out == ""
    # a pyproject.toml without [tool.langur] is skipped over
    (d / "pyproject.toml").write_text("[project]\nname = 'y'\n")
    code, out, _ = run(capsys, d / "coincident.lgr")
    assert code == 0 and out == ""


def test_malformed_configuration_is_a_usage_error(capsys, tmp_path):
    d = copy_degenerate(tmp_path)
    write_config(tmp_path, "select = 3\n")
    code, _, err = run(capsys, d / "coincident.lgr")
    assert code == 2 and "select" in err
    write_config(tmp_path, 'selekt = ["X3"]\n')
    code, _, err = run(capsys, d / "coincident.lgr")
    assert code == 2 and "selekt" in err


def test_exit_zero(capsys):
    code, out, _ = run(capsys, DEGENERATE / "coincident.lgr", "--isolated", "--exit-zero")
    assert code == 0 and codes_in(out) == ["X301"]


# ---------------------------------------------------------------------------------------------
# --prove, the console script, the pre-commit hook


def test_prove_adds_the_theorem_check(capsys):
    code, out, _ = run(capsys, DEGENERATE / "coincident.lgr", "--isolated", "--json", "--prove")
    (d,) = json.loads(out)["diagnostics"]
    assert code == 1 and d["prove"]["verdict"] == "wrong"
    assert d["prove"]["directions"]["a"]["derivative_denotation"] == pytest.approx(-2.0)
    assert "--prove" in d["message"]


def test_console_script():
    exe = shutil.which("langur")
    cmd = [exe] if exe else [sys.executable, "-m", "langur.cli"]
    p = subprocess.run(
        cmd + ["check", "--isolated", str(DEGENERATE / "coincident.lgr")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert p.returncode == 1 and " error X301 " in p.stdout and "Traceback" not in p.stderr


def test_pre_commit_hook():
    hooks = yaml.safe_load((REPO / ".pre-commit-hooks.yaml").read_text())
    (hook,) = [h for h in hooks if h["id"] == "langur-check"]
    assert hook["entry"].split()[:2] == ["langur", "check"]
    assert re.search(hook["files"], "examples/fig1.lgr") and not re.search(hook["files"], "fig1.py")


def test_every_code_is_documented():
    """One catalogue (langur.codes): every code the package emits is in it, every code in it is
    emitted somewhere, and docs/CODES.md documents each."""
    from langur.codes import CODES

    doc = (REPO / "docs" / "CODES.md").read_text()
    emitted = set()
    for f in (REPO / "langur").rglob("*.py"):
        if f.name != "codes.py":
            emitted |= set(re.findall(r'"([ETX][0-9]{3})"', f.read_text()))
    assert emitted == set(CODES)
    for code in sorted(CODES):
        assert re.search(rf"^\| {code} \|", doc, re.MULTILINE), code


def test_modules_and_imported_defs(capsys, tmp_path):
    # --module swaps the shader of renderer.lgr (CLI.md): still transverse, exit 0
    code, out, _ = run(
        capsys, EXAMPLES / "renderer.lgr", "--isolated", "--module", f"shader={EXAMPLES / 'lin_shader.lgr'}"
    )
    assert code == 0 and out == ""
    code, _, err = run(capsys, EXAMPLES / "renderer.lgr", "--module", f"shader={tmp_path / 'none.lgr'}")
    assert code == 2 and "no such file" in err
    # a degenerate def in an imported module: the finding points at the call in the checked file
    (tmp_path / "lib.lgr").write_text("def sq(x: var, a: param) = [x >= a] * [x >= a]\n")
    main_file = tmp_path / "main.lgr"
    main_file.write_text("from lib import sq\nparam a = 0.5\nint ([0, 1]) 2 * sq(x, a) d(x)\n")
    code, out, _ = run(capsys, main_file, "--isolated", "--json")
    (d,) = json.loads(out)["diagnostics"]
    assert code == 1 and d["code"] == "X301"
    assert (d["path"], d["line"], d["col"]) == (str(main_file), 3, 18)
    assert "lib.lgr:1:" in d["message"]


def test_library_modules_lint_each_def(capsys, tmp_path):
    lib = tmp_path / "lib.lgr"
    lib.write_text(
        "def sq(x: var, a: param) = [x >= a] * [x >= a]\n"
        "def win(x: var, a: param, b: param) = [a <= x <= b]\n"
        "def two(x: var, a: param, b: param) = [x >= a] * [x >= b]\n"
        "def uses(x: var, a: param) = sq(x, a) + 1\n"
    )
    code, out, _ = run(capsys, lib, "--isolated")
    # sq: coincident for every a (reported once, also through `uses`); two: when a = b; win: a
    # window closing at a = b is only a kink (no parameter values to be at): nothing
    assert code == 1 and codes_in(out) == ["X301", "X304"]
    assert out.startswith(f"{lib}:1:39: error X301") and "when a = b" in out
    code, out, _ = run(capsys, EXAMPLES / "densities.lgr", "--isolated")
    assert code == 0 and out == ""
