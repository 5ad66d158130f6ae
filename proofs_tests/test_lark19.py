"""A valid program is parsed without importing lark (issue 15, start-up; branch lark19).

``python -m langur.syntax.tables`` writes ``grammar_driver.py`` (``lalr.DATA``): the lexer, the
LALR table and each rule's callback with lark's shaping of its children, read out of the parser lark
builds; ``langur/syntax/lalr.py`` drives that data without lark, and ``parser.py`` imports lark only
when the driver fails (a syntax error, whose diagnostic lark's exception gives) or the data is stale.

* In a fresh process, parsing every valid example (and a whole ``langur eval … --engine mc``) leaves
  ``lark`` out of ``sys.modules``; a syntax error still gives lark's own diagnostic (the one lark
  alone gives, ``parser.FAST`` off), and imports lark to make it.
* The shipped data is what lark's parser gives: the same lexer and rules as the data read off a
  parser built from the grammar now, and the same trees (spans included) on every file.
* A missing, stale or malformed data module is never trusted: ``lalr.load`` or ``lalr.driver``
  refuses it, the data is read off lark's parser instead (same trees), ``tables --check`` fails on
  it; the lexer's shipped engine code is used only by the engine it was made for.
* The driver's token is lark's as ``lalr.token`` reads it (a tuple of ``lark.Token``'s slots: parse25).
"""

from __future__ import annotations

import json
import subprocess
import sys
import types

import pytest
from paths import REPO
from test_lalr import FILES, _tree  # (the example files, and a surface tree as nested tuples with its spans)

from langur.diagnostics import LangurError
from langur.syntax import lalr, larkload, parser, tables


def _outcome(parse, text: str, path: str = "f.lgr"):
    try:
        return ("ok", _tree(parse(text, path)))
    except LangurError as e:
        return ("error", [d.format() for d in e.diagnostics])


def _run(code: str) -> dict:
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


_VALID_FILES = r"""
import json, pathlib, sys
from langur.syntax import parser
from langur.diagnostics import LangurError
ok = 0
for p in sorted(pathlib.Path("examples").rglob("*.lgr")):
    try:
        parser.parse_module(p.read_text(encoding="utf-8"), str(p))
        ok += 1
    except LangurError as e:
        if any(d.code.startswith("E10") for d in e.diagnostics):
            continue  # (a syntax error on purpose: lark reports it; checked alone below)
        raise
    assert "lark" not in sys.modules, p
print(json.dumps({"ok": ok, "lark": "lark" in sys.modules}))
"""


def test_valid_examples_are_parsed_without_importing_lark():
    out = _run(_VALID_FILES)
    assert out["ok"] >= 20 and out["lark"] is False


def test_a_one_shot_eval_does_not_import_lark():
    code = ("import json, runpy, sys\nsys.argv = ['langur', 'eval', 'examples/fig1.lgr', '--engine', 'mc']\n"
            "try:\n    runpy.run_module('langur', run_name='__main__')\nexcept SystemExit as e:\n"
            "    assert not e.code, e.code\nprint()\nprint(json.dumps({'lark': 'lark' in sys.modules}))")
    assert _run(code) == {"lark": False}


_BROKEN = ["int ([0, 1]) x + d(x)\n", "param a = \n", "int ([0, 1]) x $ 2 d(x)\n", "int ([0, 1]) (x d(x)\n",
           "param a = 1\nint ([0, 1]) let in = 2 in x d(x)", "int ([0, 1]) x d(x) junk\n", "int",
           "int ([0, 1]) x ^ é d(x)\n", "def f(x: var) = \n"]


def test_a_syntax_error_gives_lark_s_diagnostic_and_imports_lark():
    code = ("import json, sys\nfrom langur.syntax import parser\nfrom langur.diagnostics import LangurError\n"
            f"out = []\nfor text in {_BROKEN!r}:\n"
            "    row = []\n"
            "    for fast in (True, False):\n"
            "        parser.FAST = fast\n"
            "        lark_before = 'lark' in sys.modules\n"
            "        try:\n            parser.parse_module(text, 'bad.lgr'); row.append(None)\n"
            "        except LangurError as e:\n            row.append([d.format() for d in e.diagnostics])\n"
            "        row.append(lark_before)\n"
            "    out.append(row)\n"
            "print(json.dumps({'out': out, 'lark': 'lark' in sys.modules}))")
    got = _run(code)
    assert got["lark"] is True
    for i, (text, (fast, before, slow, _)) in enumerate(zip(_BROKEN, got["out"])):
        assert fast is not None and fast == slow, text  # the driver's path gives lark's own diagnostic
        assert fast[0].startswith("bad.lgr:") and " error E10" in fast[0], fast
        if i == 0:
            assert before is False  # (lark not imported before the first error)


def test_the_shipped_data_is_read_off_lark_s_parser():
    shipped = lalr.load()
    assert shipped is not None
    fresh = tables.driver_data(tables.build())
    # lark numbers its states in set order (two generations differ there), not its lexer or rules
    for key in ("lexer", "rules", "terminal_names", "scanner", "symbols", "start_states", "end_states"):
        if key not in ("start_states", "end_states"):
            assert shipped[key] == fresh[key], key
    assert len(lalr.unpack(shipped["actions"], shipped["symbols"])) == len(fresh["states"])
    assert lalr.unpack(fresh["actions"], fresh["symbols"]) == fresh["states"]
    # the splicing of inlined rules and the single-child expansion are in the data (not vacuous)
    chains = [w[0] for rule in shipped["rules"] for w in rule[3]]
    assert "filter" in chains and "expand1" in chains
    drivers = []
    for data in (shipped, fresh):
        drivers.append(lalr.driver(data, lalr.callbacks(data, parser._BUILDER)))
    parsed = 0
    with parser._LOCK:
        for path in FILES:
            text = path.read_text(encoding="utf-8")
            outs = []
            for d in drivers:
                parser._BUILDER.path = str(path)
                try:
                    got = d(text, "start")
                    outs.append("failed" if got is lalr.FAILED else _tree(got))
                except LangurError as e:
                    outs.append([x.format() for x in e.diagnostics])
            assert outs[0] == outs[1], path
            parsed += outs[0] != "failed"
    assert parsed >= len(FILES) - 5


@pytest.fixture
def stale(monkeypatch):
    """A function that puts a module in place of the generated ``grammar_driver`` (``None``: no
    such module), with the parser's driver and lark parser made again."""
    import langur.syntax

    monkeypatch.setattr(parser, "_DRIVER", None)
    monkeypatch.setattr(parser, "_PARSER", None)

    def put(module):
        monkeypatch.delattr(langur.syntax, "grammar_driver", raising=False)
        monkeypatch.setitem(sys.modules, "langur.syntax.grammar_driver", module)
        if module is not None:
            monkeypatch.setattr(langur.syntax, "grammar_driver", module, raising=False)
    return put


def _module(**changes) -> types.ModuleType:
    """The generated module's source with ``changes`` to its data, run as a module."""
    import langur.syntax.grammar_driver as shipped

    module = types.ModuleType("langur.syntax.grammar_driver")
    for name in ("FORMAT", "GRAMMAR", "BYTEORDER", "DRIVER", "ACTIONS"):
        setattr(module, name, changes.get(name, getattr(shipped, name)))
    for name, value in changes.items():
        if value is _GONE:
            delattr(module, name)
    return module


_GONE = object()


def _hostile() -> dict:
    import langur.syntax.grammar_driver as shipped

    good = shipped.DRIVER
    return {
        "no module": None,
        "another grammar": _module(GRAMMAR="0"),
        "another layout": _module(FORMAT=99),
        "another byte order": _module(BYTEORDER="middle"),
        "no table": _module(ACTIONS=_GONE),
        "right grammar, hostile data": _module(DRIVER={"lexer": ("os", "system"), "rules": "touch x"}),
        "right grammar, a table cut short": _module(ACTIONS=shipped.ACTIONS[:-2]),
        "right grammar, no rules (every parse fails: lark parses)": _module(DRIVER={**good, "rules": []}),
        "right grammar, a start state that is not there": _module(DRIVER={**good, "start_states": {"start": 10**6}}),
    }


@pytest.mark.parametrize("kind", list(_hostile()))
def test_a_stale_or_broken_data_module_is_refused_and_the_parse_is_the_same(stale, kind):
    stale(_hostile()[kind])
    data = lalr.load()
    if data is not None:  # (the grammar is right: the driver refuses the data, or fails every parse)
        callbacks = lalr.callbacks(data, parser._BUILDER)
        drive = None if callbacks is None else lalr.driver(data, callbacks)
        text = FILES[0].read_text(encoding="utf-8")
        assert drive is None or drive(text, "start") is lalr.FAILED, kind
    text = FILES[0].read_text(encoding="utf-8")
    with parser._LOCK:
        d = parser._driver()
    assert d, "no driver"
    ours = _outcome(parser.parse_module, text)
    parser.FAST = False
    try:
        theirs = _outcome(parser.parse_module, text)
    finally:
        parser.FAST = True
    assert ours == theirs
    assert tables.main(["--check"]) == 1


def test_tables_check_covers_the_driver_data(stale, capsys):
    stale(_module(GRAMMAR=tables.grammar_text() + " "))
    assert tables.main(["--check"]) == 1
    assert "grammar_driver.py" in capsys.readouterr().err
    doc = tables.generate_driver()
    module = types.ModuleType("generated")
    exec(compile(tables.driver_module(doc), "generated", "exec"), module.__dict__)
    stale(module)
    assert tables.main(["--check"]) == 0


def test_the_driver_token_is_read_as_lark_s():
    """The callbacks read a token by index (``lalr.TOKEN``: every slot of lark's token, parse25): the
    driver hands them, for every token lark's lexer makes, that token as ``lalr.token`` reads it —
    the same type, text (a ``str``) and positions (parse24: not a ``str``; parse25: a tuple)."""
    assert sorted(lalr.TOKEN) == sorted(larkload.Token.__slots__)
    text = "param a = 1\r\nint ([0, 1])\t[x ≤ a] * x ^ 2 + d # c\n d(x)"
    data = lalr.load()
    seen: list = []
    callbacks = []
    for f in lalr.callbacks(data, parser._BUILDER):
        def recording(c, f=f):
            seen.extend(x for x in c if type(x) is tuple and len(x) == len(lalr.TOKEN) and type(x[0]) is str)
            return f(c)
        callbacks.append(recording)
    with parser._LOCK:
        lk = parser._parser()
        parser._BUILDER.path = "t.lgr"
        assert lalr.driver(data, callbacks)(text, "start") is not lalr.FAILED
    theirs = [lalr.token(t) for t in lk.lex(text)]
    assert all(type(t[1]) is str and t[1] == str(lark) for t, lark in zip(theirs, lk.lex(text)))
    first: dict = {}
    for t in seen:  # (each token as first handed over: `d`, a name here, is handed on as NAME)
        first.setdefault(t[6], t)
    assert sorted(first.values(), key=lambda t: t[6]) == theirs
    named = [t for t in seen if t[1] == "d"]
    assert [t[0] for t in named] == ["D", "NAME", "D"] and named[0][1:] == named[1][1:]  # (the last: `d(x)`)
