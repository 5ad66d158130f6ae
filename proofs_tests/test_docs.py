"""The user documentation tells the truth: every example program in docs/language.md loads (or is
refused with the code it names), every command line in docs/ names a real command and real
options, and every code the docs cite is in the catalogue."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest
from paths import REPO

from langur.diagnostics import LangurError
from langur.frontend import load_text
from langur.lint.formats import known_codes

DOCS = REPO / "docs"
BLOCK = re.compile(r"```(lgr(?:-error (\w+))?)\n(.*?)```", re.S)


def _blocks():
    text = (DOCS / "language.md").read_text(encoding="utf-8")
    return [(m.group(2), m.group(3)) for m in BLOCK.finditer(text)]


@pytest.mark.parametrize("code, program", _blocks(), ids=lambda v: (v or "ok")[:20] if isinstance(v, str) and len(v) < 8 else None)
def test_language_examples_do_what_the_page_says(code, program):
    try:
        load_text(program, "doc.lgr")
    except LangurError as e:
        codes = [d.code for d in e.diagnostics]
        assert code is not None and code in codes, f"refused with {codes}:\n{program}"
    else:
        assert code is None, f"expected {code}, but it loads:\n{program}"


def test_there_are_examples_of_both_kinds():
    kinds = [code is None for code, _ in _blocks()]
    assert sum(kinds) >= 6 and len(kinds) - sum(kinds) >= 6


def _help(command: str) -> str:
    return subprocess.run([sys.executable, "-m", "langur", command, "--help"], capture_output=True, text=True,
                          timeout=120).stdout


def test_every_command_line_in_the_docs_is_real():
    helps: dict[str, str] = {}
    lines = []
    for page in ("commands.md", "README.md"):
        for line in (DOCS / page).read_text(encoding="utf-8").splitlines():
            if line.startswith("$ langur "):
                lines.append(line[2:].split("#")[0].split())
    assert len(lines) >= 12
    for argv in lines:
        command = argv[1]
        helps.setdefault(command, _help(command))
        assert helps[command], f"no such command: {' '.join(argv)}"
        for word in argv[2:]:
            if word.startswith("--"):
                assert word.split("=")[0] in helps[command], f"{word} is not an option of {command}"


def test_every_code_the_docs_cite_exists():
    known = known_codes()
    for page in ("language.md", "commands.md", "CODES.md"):
        text = (DOCS / page).read_text(encoding="utf-8")
        for code in set(re.findall(r"\b([ETX][1-3]\d\d)\b", text)):
            reserved = code == "X309" and "X309 is unused (reserved)" in text
            assert code in known or reserved, f"{page} cites {code}, which no diagnostic has"


def test_every_code_is_documented():
    text = (DOCS / "CODES.md").read_text(encoding="utf-8")
    missing = sorted(c for c in known_codes() if f"| {c} |" not in text)
    assert not missing, f"docs/CODES.md does not document {missing}"
