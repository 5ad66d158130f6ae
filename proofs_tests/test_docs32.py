"""What a fresh user reads stays true, on every page (fresh32; bench/history/2026-11-29.md#fresh32.

* examples/README.md lists every example in examples/ (each ``.lgr`` outside ``adapters/``, which
  has its own README, the notebook and the strategies example), names only files that exist, and
  the codes it says ``langur check`` reports on each ``degenerate/`` file are the ones it reports.
* Every ``langur COMMAND … --option`` a page shows — in a code span of its prose as well as on a
  ``$ langur`` line, on every page: README.md, SECURITY.md, docs/*.md, examples/**/README.md —
  names a command ``langur --help`` offers and options that command's ``--help`` offers (test_docs
  checks the ``$ langur`` lines of README.md and commands.md only).
* Every statement of ``check``'s default budget says CPU seconds: SECURITY.md still said "60 s of
  wall-clock time per file" after determ30 made it CPU time.
* commands.md's campaign size is what a campaign checks: ``--examples 50`` gave 45 programs, which
  the page's "fewer than N only when it runs out of new ones" did not explain.
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from functools import cache

from paths import EXAMPLES, REPO

PAGES = [REPO / "README.md", REPO / "SECURITY.md", *sorted((REPO / "docs").glob("*.md")),
         *sorted(EXAMPLES.rglob("README.md"))]
FENCE = re.compile(r"^ *```.*?^ *```", re.S | re.M)


def _readme_rows() -> list[list[str]]:
    text = (EXAMPLES / "README.md").read_text(encoding="utf-8")
    return [[c.strip() for c in line.strip("|").split("|")] for line in text.splitlines()
            if line.startswith("| `")]


def test_examples_readme_lists_every_example_and_only_files_that_exist():
    rows = _readme_rows()
    named = [n for row in rows for n in re.findall(r"`([^`\s]+)`", row[0])]
    assert len(rows) >= 20
    missing = [n for n in named if not (EXAMPLES / n).exists()]
    assert not missing, missing
    shipped = {p.relative_to(EXAMPLES).as_posix() for p in EXAMPLES.rglob("*")
               if p.suffix in (".lgr", ".py", ".ipynb") and p.parts[len(EXAMPLES.parts)] != "adapters"}
    assert shipped, "no examples found"
    assert not shipped - set(named), sorted(shipped - set(named))
    assert "adapters/" in named


def test_the_codes_examples_readme_names_for_degenerate_files_are_what_check_reports():
    said = {}
    for row in _readme_rows():
        names = re.findall(r"`([^`\s]+)`", row[0])
        if len(names) == 1 and names[0].startswith("degenerate/"):
            said[names[0]] = set(re.findall(r"\bX3\d\d\b", row[2]))
    assert sorted(said) == sorted(p.relative_to(EXAMPLES).as_posix() for p in (EXAMPLES / "degenerate").glob("*.lgr"))
    run = subprocess.run([sys.executable, "-m", "langur", "check", "examples/degenerate", "--format", "json"],
                         cwd=REPO, capture_output=True, text=True, timeout=600)
    found: dict[str, set[str]] = {name: set() for name in said}
    for d in json.loads(run.stdout)["diagnostics"]:
        found[d["path"].removeprefix("examples/")].add(d["code"])
    assert found == said


@cache
def _help(command: str) -> str:
    return subprocess.run([sys.executable, "-m", "langur", *([command] if command else []), "--help"],
                          cwd=REPO, capture_output=True, text=True, timeout=120).stdout


def _shown_commands() -> list[tuple[str, str]]:
    """(page, command line) for every ``langur …`` in a code span or on a ``$ langur`` line of a page."""
    out = []
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        for block in FENCE.findall(text):
            out += [(page.name, m) for m in re.findall(r"^\s*\$ (langur [^\n#]*)", block, re.M)]
        prose = FENCE.sub("", text)
        out += [(page.name, m) for m in re.findall(r"`(langur [^`]*)`", prose)]
    return out


def test_every_command_a_page_shows_has_the_options_it_uses():
    shown = _shown_commands()
    assert len(shown) >= 80
    wrong = []
    for page, line in shown:
        words = line.split()
        if len(words) < 2 or words[1].isupper():  # `langur COMMAND …`
            continue
        for command in words[1].split("/"):  # `langur eval/deriv/fuzz --engine …`
            if f"\n    {command} " not in _help("") and f"\n    {command}\n" not in _help(""):
                wrong.append(f"{page}: no command {command!r} in `{line}`")
                continue
            for word in words[2:]:
                option = re.match(r"--[a-z][a-z0-9-]*", word)
                if option and not re.search(rf"(?<![\w-]){option.group(0)}(?![\w-])", _help(command)):
                    wrong.append(f"{page}: {option.group(0)} is not an option of {command} in `{line}`")
    assert not wrong, "\n".join(wrong)


def test_every_page_states_checks_default_budget_in_cpu_seconds():
    stated = []
    for page in PAGES:
        text = FENCE.sub("", page.read_text(encoding="utf-8"))
        # a table row or a sentence that gives check's default of 60 (seconds)
        for part in [*re.findall(r"^\|.*\|$", text, re.M), *re.split(r"(?<=\.)\s", re.sub(r"^\|.*\|$", "", text, flags=re.M))]:
            part = " ".join(part.split())
            if re.search(r"\bcheck\b", part) and re.search(r"\b60\b", part) and "timeout" in part:
                stated.append((page.name, part))
    assert len(stated) >= 4, stated  # README, SECURITY, commands.md, CODES.md
    wall = [s for s in stated if "CPU" not in s[1]]
    assert not wall, wall


def test_the_campaign_size_commands_md_gives_is_what_a_campaign_checks():
    from langur.fuzz.campaign import draws, generated

    text = " ".join((REPO / "docs/commands.md").read_text(encoding="utf-8").split())
    shown = re.search(r"`langur fuzz --examples (\d+)` checks (\d+) programs with seed (\d+)", text)
    asked, checked, seed = map(int, shown.groups())
    assert checked < asked  # the page's point: fewer than asked when the draws repeat
    assert draws(asked) == 10 * (asked // 10) + 9 and draws(500) == 5000  # the bound the page states
    texts = generated(asked, seed)  # the CLI's default shape (no --kinks/--turning/--wide)
    assert len(texts) == len(set(texts)) == checked
