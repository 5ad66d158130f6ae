"""docs/tutorial.md cannot rot (issue 14): every ``$ …`` command in its console blocks is run and
its output (standard output, then standard error) compared with the lines that follow it.

``python proofs_tests/test_tutorial.py --write`` fills in the outputs after an intended change."""

from __future__ import annotations

import contextlib
import io
import os
import re
import shlex
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
TUTORIAL = ROOT / "docs" / "tutorial.md"
BLOCK = re.compile(r"```console\n(.*?)```", re.S)


def commands(text: str) -> list[tuple[str, str]]:
    """(command, expected output) for every ``$ `` line of every console block."""
    out = []
    for block in BLOCK.findall(text):
        current, lines = None, []
        for line in block.splitlines():
            if line.startswith("$ "):
                if current is not None:
                    out.append((current, "\n".join(lines)))
                current, lines = line[2:], []
            else:
                lines.append(line)
        if current is not None:
            out.append((current, "\n".join(lines)))
    return out


def run(command: str) -> str:
    """Run one tutorial command from the repository's root, in this process."""
    from langur.cli import main

    argv = shlex.split(command)
    old = os.getcwd()
    os.chdir(ROOT)
    try:
        if argv[0] == "cat":
            return Path(argv[1]).read_text().rstrip("\n")
        assert argv[0] == "langur", command
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            main(argv[1:])
        return (out.getvalue() + err.getvalue()).rstrip("\n")
    finally:
        os.chdir(old)


CASES = commands(TUTORIAL.read_text())


def test_the_tutorial_has_commands_of_every_kind():
    kinds = {shlex.split(c)[:2][-1] for c, _ in CASES}
    assert {"show", "eval", "deriv", "check"} <= kinds
    assert any("--steps" in c for c, _ in CASES) and any("--rewrite" in c for c, _ in CASES)


@pytest.mark.parametrize("command, expected", CASES, ids=[c for c, _ in CASES])
def test_tutorial_command_prints_what_the_page_says(command, expected):
    assert run(command) == expected


def write() -> None:
    """Fill in each command's output (after an intended change of the output)."""
    text = TUTORIAL.read_text()

    def fill(m):
        lines = []
        for command, _ in commands(m.group(0)):
            lines.append("$ " + command)
            got = run(command)
            if got:
                lines.append(got)
        return "```console\n" + "\n".join(lines) + "\n```"

    TUTORIAL.write_text(BLOCK.sub(fill, text))


if __name__ == "__main__" and "--write" in sys.argv:
    write()
