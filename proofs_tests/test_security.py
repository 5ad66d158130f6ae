"""Nothing a user did not write runs (SECURITY.md): the parser's tables are data shipped with the
package, never a pickle read from a folder another user can write."""

from __future__ import annotations

import json
import os
import pickle
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from lark.exceptions import UnexpectedInput
from paths import EXAMPLES

from langur.frontend import load
from langur.syntax import parser, tables

FIG1 = EXAMPLES / "fig1.lgr"


class _Plant:
    """A pickle that, when loaded, creates the file ``marker``: proof that code ran."""

    def __init__(self, marker: Path):
        self.marker = str(marker)

    def __reduce__(self):
        return (open, (self.marker, "w"))


def _env(tmp: Path) -> dict[str, str]:
    env = dict(os.environ)
    env.update(TMPDIR=str(tmp), TEMP=str(tmp), TMP=str(tmp))
    return env


_OLD_WAY = textwrap.dedent(
    """
    from lark import Lark
    from langur.syntax import tables
    Lark(tables.grammar_text(), cache=True, **tables.OPTIONS)
    """
)


def test_a_file_planted_where_the_old_cache_lived_is_never_loaded(tmp_path):
    temp = tmp_path / "tmp"
    temp.mkdir()
    marker = tmp_path / "code-ran"
    env = _env(temp)
    # Control: lark's own cache (what Langur used before) writes its pickle in the temp folder ...
    subprocess.run([sys.executable, "-c", _OLD_WAY], env=env, check=True, timeout=120)
    planted = sorted(temp.glob(".lark_cache_*"))
    assert planted, "lark did not write its cache where expected: the control is broken"
    for f in planted:
        first_line = f.read_bytes().split(b"\n", 1)[0]
        f.write_bytes(first_line + b"\n" + pickle.dumps(_Plant(marker)))
    # ... and a file planted there runs its code at the next start of a cache=True parser.
    subprocess.run([sys.executable, "-c", _OLD_WAY], env=env, timeout=120)
    assert marker.exists(), "the planted file did not run under lark's cache: the control is broken"
    marker.unlink()
    # Langur never reads it.
    for command in (["check", str(FIG1)], ["eval", str(FIG1), "--samples", "100"]):
        r = subprocess.run([sys.executable, "-m", "langur", *command], env=env, capture_output=True,
                           text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert not marker.exists(), f"langur {command[0]} ran the planted file"


def test_the_parser_never_unpickles(monkeypatch):
    def refuse(*_a, **_k):
        raise AssertionError("pickle used")

    monkeypatch.setattr(pickle, "load", refuse)
    monkeypatch.setattr(pickle, "loads", refuse)
    monkeypatch.setattr(parser, "_PARSER", None)
    assert load(FIG1).program.variables == ("x",)


@pytest.mark.parametrize(
    "content",
    [
        pytest.param(None, id="a pickle"),
        pytest.param(b"\x00\x01 not json", id="garbage"),
        pytest.param(b'{"format": 1, "grammar_sha256": "0", "data": {}, "memo": {}}', id="another grammar"),
        pytest.param("right-digest", id="right digest, hostile data"),
        pytest.param(b"[" * 100_000, id="deeply nested json"),
    ],
)
def test_a_hostile_tables_file_is_refused_and_runs_nothing(tmp_path, content):
    marker = tmp_path / "code-ran"
    path = tmp_path / "grammar.tables.json"
    if content is None:
        content = pickle.dumps(_Plant(marker))
    elif content == "right-digest":
        hostile = {"__t": "dict", "items": [[{"__t": "tuple", "items": ["os", "system"]}, "touch x"]]}
        content = json.dumps({"format": tables.FORMAT, "grammar_sha256": tables.digest(tables.grammar_text()),
                              "data": hostile, "memo": hostile}).encode()
    path.write_bytes(content)
    assert tables.load(parser._BUILDER, path) is None
    assert not marker.exists()


def test_an_oversized_tables_file_is_not_read(tmp_path):
    path = tmp_path / "grammar.tables.json"
    path.write_bytes(b" " * (tables.MAX_TABLES_BYTES + 1))
    assert tables.load(parser._BUILDER, path) is None


def test_the_shipped_tables_are_the_grammar_s():
    # lark numbers its states in set order, so two generations differ in their numbering: the
    # digest says which grammar the tables were made from, the next test that they parse alike.
    assert tables.main(["--check"]) == 0
    shipped = json.loads(tables.TABLES.read_text(encoding="utf-8"))
    assert shipped["grammar_sha256"] == tables.digest(tables.grammar_text())


def test_the_shipped_parser_parses_like_one_built_from_the_grammar():
    shipped = tables.load(parser._FROM_LARK)  # (the builder as lark calls it: lark's tokens as tuples, parse25)
    assert shipped is not None
    fresh = tables.build(transformer=parser._FROM_LARK)
    for f in sorted(EXAMPLES.rglob("*.lgr")):
        text = f.read_text(encoding="utf-8")
        parser._BUILDER.path = str(f)
        assert repr(shipped.parse(text, start="start")) == repr(fresh.parse(text, start="start")), f
    for text in BROKEN:
        got = []
        for p in (shipped, fresh):
            try:
                p.parse(text, start="start")
                got.append(None)
            except UnexpectedInput as exc:
                got.append((type(exc).__name__, exc.line, exc.column, sorted(getattr(exc, "expected", ()) or ())))
        assert got[0] == got[1], text


BROKEN = [
    "param a = ",
    "int ([0, 1]) x + d(x)",
    "def f(x: var) = x *",
    "int ([0, 1]) [x <= ] d(x)",
    "from m import",
    "int ([0, 1]) let y = 2 in  d(x)",
    "int ([0, 1]) x ^ ^ 2 d(x)",
]
