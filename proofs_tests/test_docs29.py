"""What a fresh user of the clone reads stays true (docs29).

* Every relative link of README.md, SECURITY.md, examples/**/README.md and docs/*.md leads
  to a file of the repository and, with ``#anchor``, to a heading of that page (GitHub's anchors).
* ``LANGUAGE.md §N`` and ``CLI.md`` — the project's specification, cited by messages, by
  ``show --steps``'s rule names and by the docs, but not a file of the repository — are each
  explained by a row of docs/README.md's map, which names the user documentation to read instead.
* Every ``pip install -e '.[EXTRA,…]'`` the pages show installs extras pyproject.toml declares.
* The time budgets of ``show``/``eval``/``deriv``/``plot``/``render`` are wall-clock time, as
  commands.md and README.md say (a busy machine reaches them sooner): a command that waits
  without using the CPU is stopped at its ``--timeout``; ``check``'s counts CPU seconds (determ30).
"""

from __future__ import annotations

import re
import time
import tomllib

import pytest
from paths import REPO

from langur.timebox import run_with_timeout

PAGES = [REPO / "README.md", REPO / "SECURITY.md", *sorted((REPO / "examples").rglob("README.md")),
         *sorted((REPO / "docs").glob("*.md"))]  # examples/README.md since fresh32
FENCE = re.compile(r"^```.*?^```", re.S | re.M)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation dropped, spaces as hyphens."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(page) -> set[str]:
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    return {slug(h) for h in re.findall(r"^#{1,6} (.*)$", text, re.M)}


def links(page) -> list[str]:
    text = FENCE.sub("", page.read_text(encoding="utf-8"))
    return [t for t in re.findall(r"\]\(([^)\s]+)\)", text) if not re.match(r"[a-z]+:", t)]


def test_the_slug_is_githubs():
    assert slug("The program format: `langur-core` version 1") == "the-program-format-langur-core-version-1"
    assert slug("Typing (T2xx, `langur/typesys.py`; paper Fig. 6 and Fig. 11)") == \
        "typing-t2xx-langurtypesyspy-paper-fig-6-and-fig-11"
    assert slug("3. Its derivative") == "3-its-derivative"


def test_every_relative_link_leads_somewhere():
    checked, broken = 0, []
    for page in PAGES:
        for target in links(page):
            file, _, anchor = target.partition("#")
            dest = (page.parent / file).resolve() if file else page
            checked += 1
            if not dest.exists():
                broken.append(f"{page.relative_to(REPO)}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
                broken.append(f"{page.relative_to(REPO)}: {target} (no such heading)")
    assert checked >= 40 and not broken, "\n".join(broken)


def _map() -> dict[str, str]:
    text = (REPO / "docs/README.md").read_text(encoding="utf-8")
    section = text.split("## LANGUAGE.md and CLI.md", 1)[1].split("\n## ", 1)[0]
    return {m.group(1): m.group(2) for m in re.finditer(r"^\| (LANGUAGE\.md §\d|CLI\.md) \|(.*)$", section, re.M)}


def _cited() -> set[str]:
    """Every specification section the shipped text cites: messages and rule names in langur/, the docs."""
    files = [*sorted((REPO / "langur").rglob("*.py")), *PAGES]
    cited = set()
    for path in files:
        text = path.read_text(encoding="utf-8")
        cited |= {f"LANGUAGE.md §{n}" for n in re.findall(r"LANGUAGE\.md,? §(\d)", text)}
        cited |= {"CLI.md"} if "CLI.md" in text else set()
    return cited


def test_every_cited_section_of_the_specification_is_explained():
    rows = _map()
    cited = _cited()
    assert {"LANGUAGE.md §1", "LANGUAGE.md §5", "CLI.md"} <= cited  # what messages and CODES.md cite today
    missing = sorted(cited - set(rows))
    assert not missing, f"docs/README.md's map does not explain {missing}"
    for name, row in rows.items():  # each row points at a page of the user documentation
        assert re.search(r"\]\([\w.]+\.md", row) or "`examples/`" in row, f"{name}: {row}"
    # the specification is not shipped: the map must say so, and no page may link to it as a file
    assert not any((REPO / p).exists() for p in ("LANGUAGE.md", "CLI.md", "docs/LANGUAGE.md", "docs/CLI.md"))
    for page in PAGES:
        assert not [t for t in links(page) if t.split("#")[0].endswith(("LANGUAGE.md", "CLI.md"))], page


def test_the_specification_section_for_typing_is_the_one_cited_for_type_directed_drawing():
    # strategies.md draws programs "type-directed": typing is LANGUAGE.md §2 (and the syntax §6)
    rows = _map()
    assert "typing" in rows["LANGUAGE.md §2"] and "syntax" in rows["LANGUAGE.md §6"]
    text = " ".join((REPO / "docs/strategies.md").read_text(encoding="utf-8").split())
    cited = re.search(r"type-directed \(LANGUAGE\.md ([^)]*)\)", text).group(1)
    assert set(re.findall(r"§(\d)", cited)) == {"2", "6"}


def test_every_install_of_extras_on_the_pages_names_declared_extras():
    extras = set(tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))["project"]
                 ["optional-dependencies"])
    shown = []
    for page in PAGES:
        text = " ".join(page.read_text(encoding="utf-8").split())  # an install may be broken over two lines
        for group in re.findall(r"pip install -e '\.\[([\w,]+)\]'", text):
            shown += [(page.name, e) for e in group.split(",")]
    assert len(shown) >= 8
    assert not [s for s in shown if s[1] not in extras], shown


def test_the_commands_budget_is_wall_clock_time(tmp_path, monkeypatch, capsys):
    # a computation that sleeps uses no CPU: only a wall-clock budget stops it
    start = time.monotonic()
    with pytest.raises(TimeoutError):
        run_with_timeout(lambda: time.sleep(5), 0.5)  # how cli.py runs show/eval/deriv/render
    assert time.monotonic() - start < 4
    from langur.cli import main
    from langur.commands import check

    # check's budget counts CPU seconds (determ30: a busy machine does not change its findings)
    program = tmp_path / "p.lgr"
    program.write_text("param a = 0.5\nint ([0, 1]) [x <= a] d(x)\n", encoding="utf-8")
    monkeypatch.setattr(check, "_check_one", lambda *args: _spin(5.0))
    start = time.process_time()
    status = main(["check", str(program), "--timeout", "0.5"])
    out = capsys.readouterr().out
    assert status == 1 and " error X399 the check did not finish within 0.5 CPU s" in out, out
    assert time.process_time() - start < 4


def _spin(seconds: float) -> None:
    end = time.process_time() + seconds
    while time.process_time() < end:
        pass


def test_the_docs_say_which_budgets_are_wall_clock():
    text = (REPO / "docs/commands.md").read_text(encoding="utf-8")
    row = re.search(r"^\| `--timeout SECONDS` \|.*$", text, re.M).group(0)
    assert "wall-clock" in row and "fuzz counts CPU seconds" in row
    readme = " ".join((REPO / "README.md").read_text(encoding="utf-8").split())
    assert "600 s of wall clock for `show`/`eval`/`deriv`/`plot`/`render`" in readme
    assert "60 s per file for `check` and 20 per program for `fuzz`, CPU seconds" in readme  # (determ30)


def test_plots_default_picture_is_written_in_the_current_folder(tmp_path, monkeypatch):
    from types import SimpleNamespace

    from langur.commands import plot

    monkeypatch.chdir(tmp_path)
    args = SimpleNamespace(out=None, file=str(REPO / "examples/fig9.lgr"))
    assert plot._outputs(args, "surfaces", []) == [("surfaces", "fig9.png")]
    assert [o for _, o in plot._outputs(args, "all", [])] == ["fig9_surfaces.png", "fig9_flat.png",
                                                             "fig9_convergence.png"]
    text = " ".join((REPO / "docs/commands.md").read_text(encoding="utf-8").split())
    assert "(default: the file's name with `.png`, in the current folder)" in text


def test_deriv_without_wrt_differentiates_in_the_only_parameter_as_commands_md_says():
    from types import SimpleNamespace

    from langur.cli import UsageError
    from langur.commands._common import direction
    from langur.frontend import load

    none = SimpleNamespace(wrt=None, dir=None)
    assert direction(none, load(str(REPO / "examples/fig1.lgr"))) == {"theta": 1.0}
    with pytest.raises(UsageError, match="which derivative"):
        direction(none, load(str(REPO / "examples/risk.lgr")))  # a, b, mu
    text = " ".join((REPO / "docs/commands.md").read_text(encoding="utf-8").split())
    assert "with neither, a program of one parameter is differentiated in it" in text


def test_agreement_within_rounding_prints_the_raw_ratio_as_commands_md_says():
    from langur.commands._common import AGREE_SE, agreement

    text = " ".join((REPO / "docs/commands.md").read_text(encoding="utf-8").split())
    shown = re.search(r"reads `(engines agree: \|exact − MC\| = ([\d.]+) SE)`.*?Monte Carlo ([\de.+-]+) ± ([\de.+-]+)\)",
                      text)
    ratio, mc, se = float(shown.group(2)), float(shown.group(3)), float(shown.group(4))
    assert ratio > AGREE_SE and abs(mc / se - ratio) < 0.5  # the page's numbers are one another's
    line = agreement(0.0, 0.0, mc, se)  # exact 0: the difference is rounding, 1e-12 of slack
    assert line.startswith("engines agree: |exact − MC| = ") and float(line.split("= ")[1].split()[0]) > AGREE_SE
    assert agreement(0.0, 0.0, 2e-9, 1e-10).startswith("engines DISAGREE")  # beyond rounding it does not


def _budgeted_in_cli() -> set[str]:
    """The commands cli.py runs under one whole-command budget, with the terminal's status line."""
    source = (REPO / "langur/cli.py").read_text(encoding="utf-8")
    return set(re.findall(r'"(\w+)"', re.search(r"if args\.command in \(([^)]*)\):  # one budget", source).group(1)))


def test_the_commands_with_a_status_line_are_the_ones_the_docs_name():
    text = " ".join((REPO / "docs/commands.md").read_text(encoding="utf-8").split())
    named = re.search(r"On a terminal, ((?:`\w+`,? (?:and )?)+)keep a status line", text).group(1)
    assert set(re.findall(r"`(\w+)`", named)) == _budgeted_in_cli() == {"show", "eval", "deriv", "render", "plot"}


def test_plots_timeout_stops_it_as_the_docs_say(tmp_path, monkeypatch):
    from langur.cli import main
    from langur.commands import plot

    monkeypatch.setattr(plot, "run", lambda args: time.sleep(3) or 0)  # a drawing that takes its time
    start = time.monotonic()
    status = main(["plot", str(REPO / "examples/fig1.lgr"), "--timeout", "0.5", "-o", str(tmp_path / "f.png")])
    assert status == 1 and time.monotonic() - start < 2.5


def test_every_program_a_command_on_the_pages_names_exists_from_the_repositorys_root():
    # a reader runs them from the root (tutorial.md says so); CODES.md once wrote `degenerate/boundary.lgr`
    pages = [*PAGES, *sorted((REPO / "examples").rglob("*.lgr"))]
    named, missing = 0, []
    for page in pages:
        text = page.read_text(encoding="utf-8")
        for command in re.findall(r"langur (?:check|show|eval|deriv|fuzz|reproduce|plot|render)\b[^`\n]*", text):
            for path in re.findall(r"[\w./=-]+\.lgr", command):
                named += 1
                path = path.split("=")[-1]  # --module shader=examples/lin_shader.lgr
                if not (REPO / path).is_file():
                    missing.append(f"{page.relative_to(REPO)}: {path} in `{command.strip()}`")
    assert named >= 50 and not missing, "\n".join(missing)


def test_language_mds_pole_examples_are_refused_and_accepted_as_it_says():
    from langur.diagnostics import LangurError
    from langur.frontend import load_text

    text = " ".join((REPO / "docs/language.md").read_text(encoding="utf-8").split())
    refused = re.search(r"\(a pole inside the box: `(\[[^`]*\])` on `\[-1, 1\]²`\)", text).group(1)
    accepted = re.search(r"in closed form, `(\[[^`]*\])`, is completed by that formula instead and accepted", text).group(1)
    program = "param a = 0.5\nint ([-1, 1], [-1, 1]) {} d(x, y)\n"
    with pytest.raises(LangurError) as e:
        load_text(program.format(refused), "pole.lgr")
    assert [d.code for d in e.value.diagnostics] == ["T207"]
    assert "not on its whole interval" in e.value.diagnostics[0].message  # refused for the pole, as the page says
    assert load_text(program.format(accepted), "pole.lgr").program is not None
