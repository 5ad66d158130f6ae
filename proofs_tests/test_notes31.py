"""bench/RESULTS.md and its history in bench/history/ (notes31): every reference leads to its section.

* Every link of RESULTS.md and of bench/history/*.md leads to a file of the repository and, with
  ``#anchor``, to a heading (GitHub's anchor) or a short ``<a id>`` anchor of that page.
* Every citation ``bench/history/<day>.md#<anchor>`` in the code, tests, benchmarks and docs leads to its
  section; a section is cited by the file's name, a comma and its branch only while it is still in
  RESULTS.md (below the marker, where this session's branches append theirs).
* RESULTS.md's index lists every section of the history, in order, each linking its day's file; a
  section's short anchor names the branch its title names.
* ``python3 bench/history.py move`` (how the coordinator files the sections branches append) moves them
  verbatim to their day's file, indexes them, drops their TOC lines and relinks what pointed at them; the
  code's citations of them by branch are then reported, and rewritten with ``--rewrite-citations`` — run
  on a copy of the real files in a temporary folder.
"""

from __future__ import annotations

import importlib.util
import re
import shutil

import pytest
from paths import REPO

SPEC = importlib.util.spec_from_file_location("bench_history", REPO / "bench/history.py")
history = importlib.util.module_from_spec(SPEC)
SPEC.loader.exec_module(history)


def test_the_slug_is_githubs():
    # the anchors test_docs29 checks README.md's links against, and GitHub's
    assert history.slug("Exact engine: time against the number of discontinuities") == \
        "exact-engine-time-against-the-number-of-discontinuities"
    assert history.slug("Sections not yet moved to bench/history/") == "sections-not-yet-moved-to-benchhistory"
    assert history.anchors("## A\n\n## A\n\n<a id=\"x1\"></a>\n\n## B `c`\n") == {"a", "a-1", "x1", "b-c"}


def test_every_link_of_results_and_the_history_leads_to_its_section():
    links = sum(len(history.links(p.read_text(encoding="utf-8"))) for p in history.pages())
    assert links >= 170  # the index alone has 157 lines
    assert history.broken_links() == []


def test_every_citation_leads_to_its_section_and_none_by_words_to_a_moved_one():
    assert history.broken_citations() == []
    cited = sum(len(history.CITATION.findall(p.read_text(encoding="utf-8"))) for p in history.citing_files())
    assert cited >= 25
    assert history.stale_citations() == []


def _sections_of_the_history():
    for page in sorted((REPO / "bench/history").glob("*.md")):
        _, sections = history.split(page.read_text(encoding="utf-8"))
        for s in sections:
            yield page.name, s


def test_the_index_lists_every_section_of_the_history_in_order():
    text = (REPO / "bench/RESULTS.md").read_text(encoding="utf-8")
    index = text.split(history.INDEX_START, 1)[1].split(history.INDEX_END, 1)[0]
    listed = re.findall(r"^- \[(.*)\]\(history/([\d-]+\.md)#([^)]+)\)$", index, re.M)
    expected = [(s.title, day, history.slug(s.title)) for day, s in _sections_of_the_history()]
    assert len(expected) >= 157 and listed == expected


def test_a_sections_short_anchor_names_the_branch_of_its_title():
    named = 0
    for page in sorted((REPO / "bench/history").glob("*.md")):
        for ident, title in re.findall(r'^<a id="([^"]+)"></a>\n\n## (.*)$', page.read_text(encoding="utf-8"), re.M):
            assert history.short_id(title) == ident and ident in title, (page.name, ident, title)
            named += 1
    assert named >= 120


@pytest.fixture
def copy(tmp_path):
    """Copies of bench/history/, bench/RESULTS.md and the pictures it links, in a temporary folder."""
    bench = tmp_path / "bench"
    shutil.copytree(REPO / "bench/history", bench / "history")
    shutil.copy(REPO / "bench/RESULTS.md", bench / "RESULTS.md")
    for png in (REPO / "bench").glob("*.png"):
        shutil.copy(png, bench / png.name)
    return bench


def test_move_files_appended_sections_verbatim_and_keeps_every_link(copy):
    results = copy / "RESULTS.md"
    text = results.read_text(encoding="utf-8")
    # what a branch does: its TOC line after the last one of the list at the top, its section at the end
    last_toc = [line for line in text.split("\n## How this file is kept", 1)[0].splitlines() if line.startswith("- [")][-1]
    title = "A new measurement (branch zz31, 2026-11-30 09:00–10:00 UTC)"
    section = (f"## {title}\n\nMeasured with [a picture](issue15.png), after "
               "[the operational engine's first run](history/2026-11-22.md#operational-engine-languroperational-benchmark-results).\n\n"
               "| a | b |\n|---|---|\n| 1 | 2 |\n")
    text = text.replace(last_toc + "\n", f"{last_toc}\n- [{title}](#{history.slug(title)})\n", 1) + "\n" + section
    results.write_text(text, encoding="utf-8")
    below = history.split(text.partition(history.MARKER + "\n")[2])[1]  # this session's, not yet moved
    kept = below[0]  # the coordinator's 08:31 section, dated 2026-11-29

    code = copy.parent / "langur/module.py"
    code.parent.mkdir()
    code.write_text('"""What it does (bench/RESULTS.md, zz31; the file\'s numbers: bench/RESULTS.md (zz31))."""\n',
                    encoding="utf-8")
    assert history.stale_citations(copy.parent) == []  # its section is in RESULTS.md: the citation leads there

    assert len(below) >= 2 and history.move(results, copy / "history") == len(below)
    after = results.read_text(encoding="utf-8")
    assert after.endswith(history.MARKER + "\n") and "## A new measurement" not in after
    assert f"(#{history.slug(title)})" not in after and f"(#{history.slug(kept.title)})" not in after  # TOC lines dropped
    # the link of "Where issue 15 stands" to the coordinator's section now leads to its new place
    assert f"[its section](history/2026-11-29.md#{history.slug(kept.title)})" in after
    assert f"- [{title}](history/2026-11-30.md#{history.slug(title)})" in after
    assert f"- [{kept.title}](history/2026-11-29.md#{history.slug(kept.title)})" in after
    new_day = (copy / "history/2026-11-30.md").read_text(encoding="utf-8")
    assert new_day.startswith("# Benchmark history: 2026-11-30\n")
    assert '<a id="zz31"></a>\n\n' + section.replace("](issue15.png)", "](../issue15.png)").replace(
        "](history/2026-11-22.md", "](2026-11-22.md") in new_day  # verbatim, relative links leading where they led
    day = (copy / "history/2026-11-29.md").read_text(encoding="utf-8")
    # verbatim, but a link to a part of RESULTS.md that stays there (this session's sections link its head)
    session = [s for s in below if "2026-11-29" in s.title]
    assert all(s.text.rstrip("\n").replace("](#", "](../RESULTS.md#") + "\n" in day for s in session)
    moved = kept.text.rstrip("\n").replace("](#", "](../RESULTS.md#")  # (as above: its links to RESULTS.md's head)
    assert day.index(moved) < day.index(session[-1].title)  # in their order
    assert history.broken_links(copy) == []
    index = after.split(history.INDEX_START, 1)[1].split(history.INDEX_END, 1)[0]
    assert re.findall(r"^### ([\d-]+)", index, re.M)[-2:] == ["2026-11-29", "2026-11-30"]

    stale = history.stale_citations(copy.parent)
    assert len(stale) == 2 and all(s.endswith("(cite bench/history/2026-11-30.md#zz31)") for s in stale), stale
    history.stale_citations(copy.parent, rewrite=True)
    assert code.read_text(encoding="utf-8") == ('"""What it does (bench/history/2026-11-30.md#zz31; the file\'s '
                                                'numbers: bench/history/2026-11-30.md#zz31)."""\n')
    assert history.stale_citations(copy.parent) == [] and history.broken_citations(copy.parent) == []

    assert history.move(results, copy / "history") == 0  # nothing left to move: nothing changes
    assert results.read_text(encoding="utf-8") == after


def test_move_asks_for_the_day_of_a_section_whose_title_has_none(copy):
    results = copy / "RESULTS.md"
    text = results.read_text(encoding="utf-8").partition(history.MARKER + "\n")[0] + history.MARKER + "\n"
    results.write_text(text + "\n## Undated notes (branch zz31)\n\nText.\n", encoding="utf-8")
    with pytest.raises(SystemExit, match="--day"):
        history.move(results, copy / "history")
    assert history.move(results, copy / "history", default_day="2026-11-29") == 1
    assert (copy / "history/2026-11-29.md").read_text(encoding="utf-8").endswith(
        '<a id="zz31"></a>\n\n## Undated notes (branch zz31)\n\nText.\n')
