"""The parser's tables as a generated module, indexed as they are (issue 15, one-shot start-up; branch parser23).

``python -m langur.syntax.tables`` writes ``langur/syntax/grammar_driver.py``: literals only, the LALR
table packed by symbol into one ``bytes`` constant (``lalr.pack``), the lexer's pattern glued.
Checked here, each against something computed apart from the code under test:

* the shipped table is lark's automaton: walked from the start states side by side with the parse
  table of a parser lark builds now (read off lark's own objects, not through ``tables.driver_data``),
  every shift, goto and reduction agrees (lark numbers its states in set order: the walk pairs them;
  since parse26 with lark's unit reductions by identity callbacks folded in, ``tables.fold_units``,
  and states that act alike merged, ``tables.minimized``);
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
    """Walked beside lark's table from the start states.  Since parse26 the table has lark's unit
    reductions by rules whose callback gives back its one child folded in (``tables.fold_units``):
    an entry ``s --Y--> t`` where ``t`` has such a reduction leads to a state of ours paired with
    ``(s, t)``, whose action on a terminal is lark's after those reductions (each one: pop ``t``,
    goto from ``s``), and lark's end states accept at the end of the input; and states that act
    alike are one (``tables.minimized``): a state of ours may be paired with several, each
    checked."""
    data = _shipped()
    rows = lalr.unpack(data["actions"], data["symbols"])
    lark = tables.build()
    table = lark.parser.parser.parser.parse_table
    rule_index = {}
    for i, (origin, expansion, _, _) in enumerate(data["rules"]):
        rule_index[(origin, tuple(expansion))] = i
    assert len(rule_index) == len(data["rules"])
    units = {(data["rules"][i][0], tuple(data["rules"][i][1])) for i in tables.identity_rules(data["rules"])}
    assert {("power", ("atom",)), ("name", ("NAME",)), ("cmp", ("GE",))} <= units
    terminals = {"$END", *data["terminal_names"]}
    ends = set(table.end_states.values())

    def key(rule):
        return (str(rule.origin.name), tuple(str(s.name) for s in rule.expansion))

    def unit(action, arg) -> bool:
        return action.name != "Shift" and key(arg) in units

    def entered(below, state):  # what an entry of lark's from `below` to `state` is paired with
        folded = any(unit(*act) for symbol, act in table.states[state].items() if str(symbol) in terminals)
        return (below, state) if folded else (None, state)

    pairs: set = set()  # (shipped state, (lark's state below, lark's state) or (None, lark's state))
    todo = []
    for start, lark_state in table.start_states.items():
        todo.append((data["start_states"][start], (None, lark_state)))
    while todo:
        ours, theirs = todo.pop()
        if (ours, theirs) in pairs:
            continue
        pairs.add((ours, theirs))
        below, entry = theirs
        bases = set()
        for a in terminals:  # lark's action on `a` after the unit reductions, with its state then
            state = entry
            while True:
                act = table.states[state].get(a)
                if a == "$END" and state in ends:
                    act = "accept"
                elif act is not None and unit(*act):
                    assert below is not None, (ours, a)  # (every such reduction folded)
                    state = table.states[below][act[1].origin.name][1]
                    continue
                break
            code = rows[ours].get(a)
            if act is None:
                assert code is None, (ours, a)
            elif act == "accept":
                assert code == lalr.ACCEPT
            elif act[0].name == "Shift":
                assert code >= 0
                bases.add(state)
                todo.append((code, entered(state, act[1])))
            else:
                assert code == -1 - rule_index[key(act[1])], (ours, a)
                if not act[1].expansion:
                    bases.add(state)
        gotos = {str(z): (u, act[1]) for u in bases for z, act in table.states[u].items() if str(z) not in terminals}
        assert set(rows[ours]) - terminals == set(gotos), ours
        for z, (u, goto) in gotos.items():
            todo.append((rows[ours][z], entered(u, goto)))
    assert {state for _, (_, state) in pairs} == set(table.states)  # every state of lark's met
    assert {ours for ours, _ in pairs} == set(range(len(rows)))  # and every one of ours
    for start, lark_state in table.end_states.items():
        assert (data["end_states"][start], (None, lark_state)) in pairs


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
