"""What README.md and docs/ show a new user stays true (docs27).

* Every ``$ langur …`` command in a console block of README.md and docs/commands.md is run as a
  user runs it (a process, from the repository's root) and its output (standard output, then
  standard error) must match the lines the page prints after it, where ``…`` stands for text the
  page leaves out (inside a line: any text; alone on a line: any lines).  docs/tutorial.md has
  its own, exact, test (test_tutorial.py).
* Every path README.md's map from the paper to the code names exists.
* commands.md's table of shared options lists, for each option, exactly the commands whose
  ``--help`` offers it; README.md's table of commands lists exactly the commands ``langur --help``
  offers.
* The campaign commands.md and engines.md show end as they say, checked against values computed
  here by hand.
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import pytest
from paths import REPO

DOCS = REPO / "docs"
CONSOLE = re.compile(r"^```console\n(.*?)^```", re.S | re.M)


def langur(*argv: str, cwd: Path = REPO, timeout: float = 600) -> subprocess.CompletedProcess:
    env = dict(os.environ, COLUMNS="100")
    return subprocess.run([sys.executable, "-m", "langur", *argv], cwd=cwd, capture_output=True, text=True,
                          timeout=timeout, env=env)


def console_commands(page: str) -> list[tuple[str, list[str]]]:
    """(command, the lines printed after it) for every ``$ langur`` line of the page's console blocks."""
    out = []
    for block in CONSOLE.findall((REPO / page).read_text(encoding="utf-8")):
        current, lines = None, []
        for line in block.splitlines():
            if line.startswith("$ "):
                if current is not None:
                    out.append((current, lines))
                current, lines = line[2:], []
            elif current is not None:
                lines.append(line)
        if current is not None:
            out.append((current, lines))
    return [(c.split("  #")[0].strip(), lines) for c, lines in out if c.startswith("langur ")]


def pattern(lines: list[str]) -> re.Pattern:
    """The page's lines as a pattern: ``…`` inside a line is any text, a line of ``…`` any lines."""
    parts = []
    for line in lines:
        if line.strip() == "…":
            parts.append(r"(?:.*\n)*?")
        else:
            parts.append(".*?".join(re.escape(p) for p in line.split("…")) + r"\n")
    return re.compile("".join(parts))


def test_the_pattern_reads_the_ellipsis_as_the_page_means_it():
    p = pattern(["a: 1 … s", "…", "end"])
    assert p.fullmatch("a: 1 0.5 s\nx\ny\nend\n") and p.fullmatch("a: 1 2 s\nend\n")
    assert not p.fullmatch("a: 2 0.5 s\nend\n") and not p.fullmatch("a: 1 0.5 s\nend\nmore\n")


CASES = [(page, c, lines) for page in ("README.md", "docs/commands.md") for c, lines in console_commands(page)]
# ones that print nothing to compare: the campaigns of engines.md need the peers, the five-minute
# engine a module of the reader's; both are run below or in test_engines.py


def test_the_pages_show_commands_with_their_output():
    pages = {page for page, _, lines in CASES if lines}
    assert pages == {"README.md", "docs/commands.md"}
    assert len([c for _, c, _ in CASES if c.startswith("langur deriv")]) >= 5


@pytest.mark.parametrize("page, command, lines", CASES, ids=[f"{p}: {c}" for p, c, _ in CASES])
def test_a_command_on_the_page_prints_what_the_page_shows(page, command, lines, tmp_path):
    argv = shlex.split(command)[1:]
    if argv[0] == "fuzz":  # campaigns keep hypothesis's files where they are told
        argv += ["--hypothesis-dir", str(tmp_path / "hyp")]
    r = langur(*argv)
    got = r.stdout + r.stderr
    if argv[0] == "deriv" and "X305" in got:
        # the diagnostic goes to standard error before the report (a terminal shows it first)
        diag = [x for x in r.stderr.splitlines() if " X305 " in x]
        got = "\n".join(diag) + "\n" + r.stdout + "".join(x + "\n" for x in r.stderr.splitlines() if x not in diag)
    assert r.returncode in (0, 1), r.stderr
    assert pattern(lines).fullmatch(got), f"{page}: `{command}` printed\n{got}"


MAP_PATH = re.compile(r"`([\w./-]+(?:\.py|\.lark|\.json|\.lgr|\.md|\.yaml|\.ipynb|/))`")
# a name inside a row is relative to the folder the row names first (`langur/core/` … `terms.py`)
ROOTS = ["", "langur/", "langur/core/", "langur/syntax/", "langur/symbolic/", "langur/operational/",
         "langur/implicit/", "langur/lint/", "langur/fuzz/", "viz/", "examples/adapters/"]


def test_every_path_the_readme_names_exists():
    text = (REPO / "README.md").read_text(encoding="utf-8")
    named = set(MAP_PATH.findall(text))
    assert {"langur/core/", "langur/ddenote.py", "langur/syntax/grammar.lark", "examples/raytrace/"} <= named
    missing = sorted(p for p in named if not any((REPO / (root + p)).exists() for root in ROOTS))
    assert not missing, f"README.md names {missing}, which are not in the repository"


def _helps() -> dict[str, set[str]]:
    top = langur("--help").stdout
    commands = re.findall(r"^    (\w+)(?:\s|$)", top, re.M)
    assert {"check", "deriv", "fuzz", "render"} <= set(commands), top
    return {c: set(re.findall(r"(?<![\w-])(--[a-z][a-z-]*)", langur(c, "--help").stdout)) for c in commands}


@pytest.fixture(scope="module")
def helps():
    return _helps()


def test_readme_lists_every_command_and_no_other(helps):
    text = (REPO / "README.md").read_text(encoding="utf-8")
    listed = set(re.findall(r"^\| `langur (\w+)", text, re.M))
    assert listed == set(helps)


def test_the_shared_options_table_names_the_commands_that_have_them(helps):
    text = (DOCS / "commands.md").read_text(encoding="utf-8")
    table = text.split("## Options shared by several commands", 1)[1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| `(--[a-z-]+)[^`]*` \| ([^|]+) \|", table, re.M)
    assert len(rows) >= 8
    for option, where in rows:
        listed = set(helps) if where.strip() == "all" else set(re.findall(r"\b(" + "|".join(helps) + r")\b", where))
        offering = {c for c, opts in helps.items() if option in opts}
        assert listed == offering, f"{option}: the table says {sorted(listed)}, --help says {sorted(offering)}"


def test_the_broken_engine_campaign_writes_the_file_commands_md_shows(tmp_path):
    text = (DOCS / "commands.md").read_text(encoding="utf-8")
    shown = text.split("wrote `found/fuzz_1_000.lgr`:\n\n```text\n", 1)[1].split("```", 1)[0]
    # by hand: d/dc ∫₋₁¹ [c·x ≤ 0.55] dx = d/dc (0.55/c + 1) = −0.55/c² at c = 0.79; the value 0.55/c + 1
    c = Fraction(79, 100)
    assert f"# derivative | c | {float(-Fraction(55, 100) / c**2)!r} |" in shown
    assert f"# value | - | {float(Fraction(55, 100) / c + 1)!r} |" in shown
    r = langur("fuzz", "--engine", "langur.fuzz.mutants:drop_delta", "--examples", "3", "--seed", "1", "--no-shrink",
               "--out", "found", "--hypothesis-dir", str(tmp_path / "hyp"), cwd=tmp_path)
    assert r.returncode == 1 and "DISCREPANCY" in r.stdout
    got = (tmp_path / "found" / "fuzz_1_000.lgr").read_text(encoding="utf-8")
    # the Monte Carlo value's digits are the engine's; the rest is as shown
    value_row = re.compile(r"^# value \| - \| (\S+) \| 0\.0 \| mc-drop_delta \| \S+ \| \S+ \| ok$", re.M)
    assert value_row.sub("V", got) == value_row.sub("V", shown)


def test_the_standard_ad_campaign_of_engines_md_shrinks_to_the_program_it_shows(tmp_path):
    text = (DOCS / "engines.md").read_text(encoding="utf-8")
    section = text.split("## What a campaign finds", 1)[1].split("\n## ", 1)[0]
    command = re.search(r"`(langur fuzz --engine standard-ad[^`]*)`", section.replace("\n", " ")).group(1)
    program = re.search(r"```\n(.*?)```", section, re.S).group(1)
    r = langur(*shlex.split(command)[1:], "--hypothesis-dir", str(tmp_path / "hyp"), cwd=tmp_path)
    assert r.returncode == 1
    assert f"minimal failing program (discrepancy):\n{program}" in r.stdout, r.stdout
    # by hand: ∫₀¹ [x ≤ a] dx = a, so its derivative in a is 1; standard AD, deltas dropped, says 0
    assert program == "param a = 0.37\nint ([0, 1])\n  [x <= a]\nd(x)\n"
    assert "derivative wrt a: exact 1 (error 0), standard-ad 0 ± 0" in r.stdout
    counts = {k: int(v) for k, v in re.findall(r"^  (agree|discrepancy|timeout)\s+(\d+)$", r.stdout, re.M)}
    # three agree, three disagree; a unit killed on a starved machine is a timeout instead (commands.md)
    assert sum(counts.values()) == 6 and counts["discrepancy"] >= 1, r.stdout
    if counts["timeout"] == 0:
        assert counts == {"agree": 3, "discrepancy": 3, "timeout": 0}, r.stdout


def test_reproduce_help_names_every_figure_its_out_folder_gets(helps):
    # commands.md names the pictures `reproduce --out` writes; their figure numbers, read off the
    # names (fig1_abcd.png, risk_fig2.png, …), are the ones `--help` must announce
    text = (DOCS / "commands.md").read_text(encoding="utf-8")
    section = text.split("## langur reproduce", 1)[1].split("\n## ", 1)[0]
    pictures = set(re.findall(r"`(\w+\.png)`", section))
    assert {"fig1_abcd.png", "renderer_fig13.png", "raytrace_fig14.png"} <= pictures
    figures = {int(n) for p in pictures for n in re.findall(r"fig(\d+)", p)}
    usage = " ".join(langur("reproduce", "--help").stdout.split())
    announced = re.search(r"--out DIR also write each experiment's pictures \(Fig\. ([\d, ]+)\)", usage).group(1)
    assert {int(n) for n in announced.split(", ")} == figures


def test_the_readmes_python_example_gives_the_numbers_its_comment_says():
    text = (REPO / "README.md").read_text(encoding="utf-8")
    code = re.search(r"### From Python\n\n```python\n(.*?)```", text, re.S).group(1)
    assert "# 1, 0, 1, 0" in code
    cwd = os.getcwd()
    os.chdir(REPO)
    try:
        scope: dict = {}
        exec(compile(code, "README.md", "exec"), scope)  # the page's own example
    finally:
        os.chdir(cwd)
    d = scope["d"]
    # by hand (Fig. 1): ⟦p⟧ = θ on [0, 1], so ⦇p⦈ = 1, all of it the delta at x = θ; standard AD 0
    assert (d.value, d.regular.value, d.boundary.value, d.standard_ad) == (1, 0, 1, 0)
    from langur import operational
    from langur.frontend import load

    mc = operational.estimate_derivative(load(str(REPO / "examples/fig1.lgr")), {"theta": 0.5}, {"theta": 1},
                                         samples=10_000, seed=0)
    assert mc.value == 1 and mc.boundary.value == 1 and mc.regular.value == 0


def test_the_readmes_check_of_the_degenerate_folder_finds_x301_in_coincident_and_nested():
    text = (REPO / "README.md").read_text(encoding="utf-8")
    assert "langur check examples/degenerate/*.lgr        # coincident and nested: X301 errors" in text
    files = sorted(str(p.relative_to(REPO)) for p in (REPO / "examples/degenerate").glob("*.lgr"))
    r = langur("check", *files)
    errors = {line.split(":")[0] for line in r.stdout.splitlines() if " error X301 " in line}
    assert r.returncode == 1 and errors == {"examples/degenerate/coincident.lgr", "examples/degenerate/nested.lgr"}
    assert not [line for line in r.stdout.splitlines() if " error " in line and " X301 " not in line]


def test_the_tour_says_check_is_silent_on_a_clean_program():
    assert "langur check examples/fig1.lgr                 # parse, type (Fig. 6, 11), lint (Def. 7.2): silent when clean" \
        in (DOCS / "README.md").read_text(encoding="utf-8")
    r = langur("check", "examples/fig1.lgr")
    assert (r.returncode, r.stdout, r.stderr) == (0, "", "")


def test_security_md_counts_the_hostile_corpus_test_hostile_runs():
    import test_hostile

    said = re.search(r"runs a corpus of (\d+)\s+hostile files", (REPO / "SECURITY.md").read_text(encoding="utf-8"))
    assert said and int(said.group(1)) == len(test_hostile.CORPUS)


def test_every_install_hint_installs_from_the_clone_as_the_readme_does():
    # README.md's set-up installs the clone (`pip install -e .`, extras as `-e '.[NAME]'`); a hint
    # naming the distribution (`pip install 'langur-workbench[…]'`) would ask a package index instead
    import tomllib

    extras = set(tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]["optional-dependencies"])
    hints = []
    for path in sorted((REPO / "langur").rglob("*.py")):
        for hint in re.findall(r"pip install ([^\"'`)]*(?:'[^']*')?)", path.read_text(encoding="utf-8")):
            hints.append((path.relative_to(REPO).as_posix(), hint.strip()))
    assert len(hints) >= 6
    for where, hint in hints:
        assert "langur-workbench" not in hint, f"{where}: pip install {hint}"
        for extra in re.findall(r"-e '\.\[(\w+)\]'", hint):
            assert extra in extras, f"{where}: pip install {hint}: no such extra"
