"""The parser's tables as a generated module, indexed as they are (issue 15, one-shot start-up; branch parser23).

``python -m langur.syntax.tables`` writes ``langur/syntax/grammar_driver.py``: literals only, the LALR
table packed by symbol into one ``bytes`` constant (``lalr.pack``), the lexer's pattern glued.
Checked here, each against something computed apart from the code under test:

* the shipped table is lark's automaton: walked from the start states side by side with the parse
  table of a parser lark builds now (read off lark's own objects, not through ``tables.driver_data``),
  every shift, goto and reduction agrees (lark numbers its states in set order: the walk pairs them);
* ``lalr.unpack(lalr.pack(rows))`` gives the rows back, for random rows with extreme codes;
* the module is data: every statement assigns a literal (``ast.literal_eval``), no import, no call;
* parsing a valid program imports neither ``json`` nor ``lark``.
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys

from hypothesis import given, settings
from hypothesis import strategies as st
from paths import REPO

from langur.syntax import lalr, tables


def _shipped() -> dict:
    data = lalr.load()
    assert data is not None
    return data


def test_the_shipped_table_is_lark_s_automaton():
    data = _shipped()
    rows = lalr.unpack(data["actions"], data["symbols"])
    lark = tables.build()
    table = lark.parser.parser.parser.parse_table
    rule_index = {}
    for i, (origin, expansion, _, _) in enumerate(data["rules"]):
        rule_index[(origin, tuple(expansion))] = i
    assert len(rule_index) == len(data["rules"])
    pairs = {}  # shipped state → lark's state
    todo = []
    for start, lark_state in table.start_states.items():
        todo.append((data["start_states"][start], lark_state))
    while todo:
        ours, theirs = todo.pop()
        if ours in pairs:
            assert pairs[ours] == theirs
            continue
        pairs[ours] = theirs
        lark_row = table.states[theirs]
        assert set(rows[ours]) == {str(symbol) for symbol in lark_row}, ours
        for symbol, (action, arg) in lark_row.items():
            code = rows[ours][str(symbol)]
            if action.name == "Shift":
                assert code >= 0
                todo.append((code, arg))
            else:
                rule = (str(arg.origin.name), tuple(str(s.name) for s in arg.expansion))
                assert code == -1 - rule_index[rule], (ours, symbol)
    assert len(pairs) == len(rows) == len(table.states)  # every state met, one for one
    assert len(set(pairs.values())) == len(pairs)
    for start, lark_state in table.end_states.items():
        assert pairs[data["end_states"][start]] == lark_state


@settings(max_examples=60, deadline=None)
@given(st.lists(st.dictionaries(st.sampled_from(["A", "B", "c", "$END", "d_e"]),
                                st.one_of(st.integers(-32767, 32767), st.sampled_from([-32767, 32767, 0, -1]))),
                max_size=12))
def test_pack_and_unpack_give_the_rows_back(rows):
    symbols = ["$END", "A", "B", "c", "d_e"]
    packed = lalr.pack(rows, symbols)
    assert len(packed) == 2 * len(rows) * len(symbols)
    assert lalr.unpack(packed, symbols) == rows


def test_the_data_module_is_literals_only():
    source = lalr.DATA.read_text(encoding="utf-8")
    names = set()
    for statement in ast.parse(source).body:
        assert isinstance(statement, ast.Assign) and len(statement.targets) == 1, ast.dump(statement)[:80]
        names.add(statement.targets[0].id)
        ast.literal_eval(statement.value)  # (raises on anything but a literal)
    assert names == {"FORMAT", "GRAMMAR", "BYTEORDER", "DRIVER", "ACTIONS"}


def test_a_valid_parse_imports_neither_json_nor_lark():
    code = ("import sys\nfrom langur.syntax import parser\n"
            "parser.parse_module(open('examples/fig1.lgr', encoding='utf-8').read(), 'fig1.lgr')\n"
            "print(repr(['json' in sys.modules, 'lark' in sys.modules]))")
    r = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert json.loads(r.stdout.strip().splitlines()[-1].lower()) == [False, False]
