"""bench/RESULTS.md's history in bench/history/DAY.md: move new sections there, check every link (not a test).

``bench/RESULTS.md`` says what the project measures now (issue 15's targets, each benchmark's command and
latest table) and indexes the history; the history itself, every section a branch or the coordinator
wrote, lives verbatim in ``bench/history/DAY.md``, one file per day, in the order it was written, each
section under its exact title (so its GitHub anchor is the one it had in RESULTS.md), with a short anchor
``<a id="BRANCH"></a>`` above it where the title names a branch (``bench/history/2026-11-29.md#qmc29``: how
code and tests cite a section).

Branches append their section at the end of RESULTS.md, below the line :data:`MARKER`, and its TOC line
to the list "Sections not yet moved to bench/history/" at the top; while there, code may cite it as
``bench/RESULTS.md, BRANCH``.  After merging them::

    python3 bench/history.py move --rewrite-citations   # every section below MARKER into bench/history/
    python3 bench/history.py check                      # every link and every citation leads to its section

``move`` takes DAY from the first date in a section's title (``--day`` for a title without one), appends
the section verbatim to that day's file (only its relative links are rewritten to lead where they led
from RESULTS.md), adds its line to the day's list in RESULTS.md's index, drops the section's TOC line and
points RESULTS.md's other links to it at its new place; ``--rewrite-citations`` turns the code's
``bench/RESULTS.md, BRANCH`` of a moved section into ``bench/history/DAY.md#BRANCH`` (``check`` lists the
ones left, e.g. a section cited by its words).  What the current-measurements part says is written by hand.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
from pathlib import Path
from typing import NamedTuple

BENCH = Path(__file__).resolve().parent
RESULTS = BENCH / "RESULTS.md"
HISTORY = BENCH / "history"
#: the line below which branches append their sections (everything after it is moved by ``move``)
MARKER = "<!-- Append new sections below this line; `python3 bench/history.py move` moves them to bench/history/. -->"
#: the lines around the index of the history in RESULTS.md (``move`` adds its lines between them)
INDEX_START = "<!-- index of bench/history/: `python3 bench/history.py move` keeps it -->"
INDEX_END = "<!-- end of the index -->"
#: where a citation of a section may stand: the code, tests, benchmarks and documentation
CITING = ("langur", "viz", "proofs_tests", "bench", "docs", "examples", "README.md")
FENCE = re.compile(r"^```.*?^```", re.S | re.M)
DATE = re.compile(r"20\d\d-\d\d-\d\d")


class Section(NamedTuple):
    """One ``## `` section: its title (the heading without ``## ``) and its text, heading included."""

    title: str
    text: str


def slug(heading: str) -> str:
    """GitHub's anchor of a heading (as proofs_tests/test_docs29.py computes it)."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def split(text: str) -> tuple[str, list[Section]]:
    """The text before the first ``## `` heading outside a code fence, and the sections from there on."""
    lines = text.splitlines(keepends=True)
    starts, fenced = [], False
    for i, line in enumerate(lines):
        if line.startswith("```"):
            fenced = not fenced
        elif not fenced and line.startswith("## "):
            starts.append(i)
    if not starts:
        return text, []
    bounds = [*starts, len(lines)]
    return "".join(lines[:starts[0]]), [Section(lines[a][3:].strip(), "".join(lines[a:b]))
                                        for a, b in zip(bounds, bounds[1:])]


def short_id(title: str) -> str | None:
    """The branch a title names (``branch `roots3```, ``(exact5, 2026-…``, ``undef12 — …``), or None."""
    m = (re.search(r"branch `?([\w-]+)`?", title) or re.search(r"\((\w*\d\w*), 20\d\d-", title)
         or re.match(r"(\w+\d+) —", title))
    return m.group(1) if m else None


def anchors(text: str) -> set[str]:
    """Every anchor of a page: its headings' (GitHub numbers repeated ones -1, -2, …) and its ``<a id>``s."""
    text = FENCE.sub("", text)
    seen: dict[str, int] = {}
    found = set(re.findall(r'<a id="([^"]+)"></a>', text))
    for heading in re.findall(r"^#{1,6} (.*)$", text, re.M):
        s = slug(heading)
        found.add(s if s not in seen else f"{s}-{seen[s]}")
        seen[s] = seen.get(s, 0) + 1
    return found


def links(text: str) -> list[str]:
    """The relative link targets of a page (outside code fences and inline code)."""
    text = re.sub(r"`[^`]+`", "", FENCE.sub("", text))
    return [t for t in re.findall(r"\]\(([^)\s]+)\)", text) if not re.match(r"[a-z]+:", t)]


def day_of(section: Section, default: str) -> str:
    m = DATE.search(section.title)
    return m.group(0) if m else default


def relink(text: str, source: Path, dest: Path, where: dict[str, Path]) -> str:
    """``text`` written in the folder of ``source`` moved to ``dest``: each relative link leads where it
    led; an in-page ``#anchor`` whose section is now in another file (``where``) names that file."""
    def fix(m: re.Match) -> str:
        target = m.group(1)
        if re.match(r"[a-z]+:", target):
            return m.group(0)
        file, _, anchor = target.partition("#")
        if not file:
            home = where.get(anchor, dest)
            if home == dest:
                return m.group(0)
            file_path = home
        else:
            file_path = (source.parent / file).resolve()
        new = os.path.relpath(file_path, dest.parent) + (f"#{anchor}" if anchor else "")
        return f"]({new})"
    # code (fenced, or in backticks) is left as it is: a link quoted there is text, not a link
    parts = re.split(r"(^```.*?^```|`[^`]+`)", text, flags=re.S | re.M)
    return "".join(part if i % 2 else re.sub(r"\]\(([^)\s]+)\)", fix, part) for i, part in enumerate(parts))


def history_header(day: str) -> str:
    return (f"# Benchmark history: {day}\n\n"
            f"Sections of [bench/RESULTS.md](../RESULTS.md) written on {day} (UTC; a section is filed under the "
            "first date of its title, else the day it was committed), moved here verbatim in the order they were "
            "written (only a relative link to a file beside RESULTS.md rewritten to lead there from this folder): "
            "the same titles, so the same anchors. What the project measures now is in RESULTS.md; its index "
            "lists every section of every day.\n")


def append_sections(sections: list[Section], days: list[str], history: Path, results: Path,
                    staying: str = "") -> list[str]:
    """Append each section to its day's file (made if new); return the index line of each.  ``staying``:
    the text that stays in RESULTS.md (a moved section's link to it names RESULTS.md)."""
    history.mkdir(exist_ok=True)
    texts = {p: p.read_text(encoding="utf-8") for p in history.glob("*.md")}
    where = {a: results for a in anchors(staying)}
    where.update({a: p for p, t in texts.items() for a in anchors(t)})
    for s, d in zip(sections, days):
        where.setdefault(slug(s.title), history / f"{d}.md")
    taken = {a for t in texts.values() for a in re.findall(r'<a id="([^"]+)"></a>', t)}
    index = []
    for s, d in zip(sections, days):
        path = history / f"{d}.md"
        text = texts.get(path) or history_header(d)
        ident = short_id(s.title)
        anchor_line = ""
        if ident and ident not in taken and ident not in anchors(text):
            taken.add(ident)
            anchor_line = f'<a id="{ident}"></a>\n\n'
        body = relink(s.text, results, path, where).rstrip("\n") + "\n"
        texts[path] = text.rstrip("\n") + "\n\n" + anchor_line + body
        index.append(f"- [{s.title}](history/{d}.md#{slug(s.title)})")
    for path, text in texts.items():
        path.write_text(text, encoding="utf-8")
    return index


def add_to_index(head: str, lines: list[str], days: list[str]) -> str:
    """RESULTS.md's text above MARKER with each index line added to its day's list (days in order)."""
    before, start, rest = head.partition(INDEX_START + "\n")
    body, end, after = rest.partition(INDEX_END)
    if not start or not end:
        sys.exit(f"RESULTS.md has no index between {INDEX_START!r} and {INDEX_END!r}")
    listed: dict[str, list[str]] = {}
    day = None
    for line in body.splitlines():
        if line.startswith("### "):
            day = DATE.search(line).group(0)
            listed.setdefault(day, [])
        elif line.startswith("- [") and day:
            listed[day].append(line)
    for line, d in zip(lines, days):
        listed.setdefault(d, []).append(line)
    body = "".join(f"### {d} ([bench/history/{d}.md](history/{d}.md))\n\n" + "\n".join(listed[d]) + "\n\n"
                   for d in sorted(listed))
    return before + start + "\n" + body + end + after


def move(results: Path = RESULTS, history: Path = HISTORY, default_day: str | None = None) -> int:
    """Move every section below MARKER into bench/history/; return how many were moved."""
    text = results.read_text(encoding="utf-8")
    head, marker, tail = text.partition(MARKER + "\n")
    if not marker:
        sys.exit(f"{results}: no line {MARKER!r}")
    loose, sections = split(tail)
    if loose.strip():
        sys.exit(f"{results}: text below the marker that is not under a ## heading: {loose.strip()[:80]!r}")
    undated = [s.title for s in sections if not DATE.search(s.title)]
    if undated and not default_day:
        sys.exit(f"no date in the title of {undated}: say which day with --day YYYY-MM-DD")
    days = [day_of(s, default_day or "") for s in sections]
    index = append_sections(sections, days, history, results, head)
    moved = {slug(s.title): d for s, d in zip(sections, days)}
    head = "".join(line for line in head.splitlines(keepends=True)  # the moved sections' TOC lines
                   if not (line.startswith("- [") and re.search(r"\]\(#([^)]+)\)$", line.rstrip())
                           and re.search(r"\]\(#([^)]+)\)$", line.rstrip()).group(1) in moved))
    head = re.sub(r"\]\(#([^)\s]+)\)",  # other links to them lead to their new place
                  lambda m: f"](history/{moved[m.group(1)]}.md#{m.group(1)})" if m.group(1) in moved else m.group(0),
                  head)
    head = re.sub(r"\n{3,}", "\n\n", add_to_index(head, index, days))  # the dropped TOC lines leave gaps
    results.write_text(head + marker, encoding="utf-8")
    return len(sections)


def pages(bench: Path = BENCH) -> list[Path]:
    return [bench / "RESULTS.md", *sorted((bench / "history").glob("*.md"))]


def broken_links(bench: Path = BENCH) -> list[str]:
    """Every link of RESULTS.md and the history that leads to no file or to no heading of its page."""
    broken = []
    for page in pages(bench):
        text = page.read_text(encoding="utf-8")
        for target in links(text):
            file, _, anchor = target.partition("#")
            dest = (page.parent / file).resolve() if file else page
            if not dest.exists():
                broken.append(f"{page.name}: {target} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in anchors(dest.read_text(encoding="utf-8")):
                broken.append(f"{page.name}: {target} (no such heading)")
    return broken


#: a citation of a section: ``bench/history/<day>.md#<anchor>`` (or ``bench/RESULTS.md#<anchor>``)
CITATION = re.compile(r"bench/(history/[\w-]+\.md|RESULTS\.md)#([\w-]+)")
#: how branches cite a section while it is in RESULTS.md: ``bench/RESULTS.md, qmc29`` (or ``RESULTS.md
#: (fold28)``, ``RESULTS.md, branch qmc29``, ``RESULTS.md qmc29``); NAME is the branch, the section's short id
OLD_CITATION = re.compile(r"(?:bench/)?RESULTS\.md(?:``)?(?:,? \(|, | )(?:branch )?(?P<name>[a-z][\w-]*\d[\w-]*)\)?")
#: anything that looks like a citation of a section of RESULTS.md by words, not by an anchor
OLD_LOOK = re.compile(r"RESULTS\.md(?:``)?(?:,| \(| [a-z]+\d)")


def citing_files(root: Path = BENCH.parent) -> list[Path]:
    """The files where a citation may stand (not RESULTS.md, the history, this script or its test, whose
    examples of citations lead nowhere on purpose)."""
    files = [p for name in CITING for p in ([root / name] if name.endswith(".md") else sorted((root / name).rglob("*")))
             if p.is_file() and p.suffix in (".py", ".md", ".lgr", ".ipynb", ".toml", ".txt")]
    return [p for p in files if p not in (root / "bench/RESULTS.md", root / "bench/history.py")
            and root / "bench/history" not in p.parents and p.name != "test_notes31.py"]


def broken_citations(root: Path = BENCH.parent) -> list[str]:
    """Every ``bench/history/<day>.md#<anchor>`` in the code, tests and docs that leads to no section."""
    found = []
    cache: dict[str, set[str]] = {}
    for path in citing_files(root):
        for m in CITATION.finditer(path.read_text(encoding="utf-8", errors="replace")):
            target = root / "bench" / m.group(1)
            if m.group(1) not in cache:
                cache[m.group(1)] = anchors(target.read_text(encoding="utf-8")) if target.exists() else set()
            if m.group(2) not in cache[m.group(1)]:
                found.append(f"{path.relative_to(root)}: {m.group(0)}")
    return found


def _short_ids(root: Path) -> tuple[set[str], dict[str, str]]:
    """The short ids of the sections below RESULTS.md's marker, and where each moved one is."""
    below = (root / "bench/RESULTS.md").read_text(encoding="utf-8").partition(MARKER)[2]
    here = {i for s in split(below)[1] if (i := short_id(s.title))}
    moved = {i: f"bench/history/{p.name}#{i}" for p in sorted((root / "bench/history").glob("*.md"))
             for i in re.findall(r'<a id="([^"]+)"></a>', p.read_text(encoding="utf-8"))}
    return here, moved


def stale_citations(root: Path = BENCH.parent, rewrite: bool = False) -> list[str]:
    """Citations of a section of RESULTS.md by words that no longer lead to it: every one but
    ``RESULTS.md, NAME`` for a section NAME still below the marker.  With ``rewrite``, each
    ``RESULTS.md, NAME`` of a moved section becomes ``bench/history/DAY.md#NAME`` (what `move` asks)."""
    here, moved = _short_ids(root)
    stale = []
    for path in citing_files(root):
        text = path.read_text(encoding="utf-8", errors="replace")
        for m in OLD_LOOK.finditer(text):
            old = OLD_CITATION.match(text, max(m.start() - 6, 0) if text[max(m.start() - 6, 0):m.start()] == "bench/"
                                     else m.start())
            name = old.group("name") if old else None
            if name not in here:
                hint = f" (cite {moved[name]})" if name in moved else ""
                stale.append(f"{path.relative_to(root)}: {text[m.start():m.start() + 60].splitlines()[0]}…{hint}")
        if rewrite:
            new = OLD_CITATION.sub(lambda m: moved[m.group("name")] if m.group("name") in moved
                                   and m.group("name") not in here else m.group(0), text)
            if new != text:
                path.write_text(new, encoding="utf-8")
    return stale


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    mv = sub.add_parser("move", help="move every section below the marker into bench/history/DAY.md")
    mv.add_argument("--day", help="YYYY-MM-DD for a section whose title has no date")
    mv.add_argument("--rewrite-citations", action="store_true",
                    help="rewrite `bench/RESULTS.md, NAME` of a moved section to bench/history/DAY.md#NAME")
    sub.add_parser("check", help="every link of RESULTS.md and bench/history/, every citation in the code")
    args = parser.parse_args(argv)
    if args.command == "move":
        print(f"moved {move(default_day=args.day)} section(s) to {HISTORY}")
        if args.rewrite_citations:
            stale_citations(rewrite=True)
    problems = broken_links() + broken_citations() + stale_citations()
    print("\n".join(problems) or "every link and citation leads to its section")
    return 1 if problems else 0


if __name__ == "__main__":
    raise SystemExit(main())
