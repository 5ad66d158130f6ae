"""The parse per token, third cut (issue 15, branch parse26): lark's unit reductions folded into the
generated LALR table (``tables.fold_units``), the table then minimized (``tables.minimized``).

A reduction by a rule ``A → B`` whose callback gives back its one child (the precedence ladder
``term`` → ``sum`` → ``product`` → ``unary`` → ``power`` → ``atom``, ``cond → term``, ``cmp``, ``name →
NAME``, lark's ``?rule`` of one symbol) only changes the parser's state; the generator decides that
change when the state is entered, so the driver never reduces by such a rule.  Checked here against
things computed apart from the generator:

* the builder's callbacks of the folded rules (``tables.identity_rules``) give back their child;
* the shipped table, walked from its start states, never reduces by one, and its end states accept;
* the driver run on the shipped table calls the other rules' callbacks in the order lark's own
  automaton (run here on lark's parse table and lark's tokens, unit reductions and all) reduces by
  them, and stops where it stops: on every file, truncations and token deletions of them and random
  token sequences, for both start symbols;
* ``fold_units`` on small tables written out by hand (a fold, a fold refused: two gotos on one symbol);
* ``minimized`` (states that act alike merged, unreached ones dropped) by hand, and the shipped table
  minimal.
"""

from __future__ import annotations

import random

import pytest
from paths import REPO

from langur.syntax import lalr, parser, tables

FILES = sorted(p for p in REPO.rglob("*.lgr") if ".venv" not in p.parts)


def _data() -> dict:
    data = lalr.load()
    assert data is not None
    return data


def _lark():
    with parser._LOCK:
        return parser._lark()


# -- the contract: the folded rules' callbacks give back their child ------------------------------


def test_the_folded_rules_callbacks_give_back_their_child():
    data = _data()
    rules = data["rules"]
    folded = tables.identity_rules(rules)
    keys = {(rules[i][0], tuple(rules[i][1])) for i in folded}
    assert {("power", ("atom",)), ("unary", ("power",)), ("product", ("unary",)), ("sum", ("product",)),
            ("term", ("sum",)), ("cond", ("term",)), ("name", ("NAME",)), ("cmp", ("GE",)),
            ("item", ("param_item",))} <= keys
    assert ("name", ("D",)) not in keys and ("atom", ("NUMBER",)) not in keys and ("atom", ("name",)) not in keys
    callbacks = lalr.callbacks(data, parser._BUILDER)
    for i in folded:
        symbol = rules[i][1][0]
        child = (symbol, "x", 1, 1, 1, 2, 0, 1) if symbol.isupper() else object()
        assert callbacks[i]([child]) is child, rules[i]
    # and a D made a name is not given back as it is (not folded)
    d = next(i for i, r in enumerate(rules) if r[0] == "name" and tuple(r[1]) == ("D",))
    assert callbacks[d]([("D", "d", 1, 1, 1, 2, 0, 1)])[0] == "NAME"


# -- the shipped table -----------------------------------------------------------------------------


def test_the_shipped_table_reduces_by_no_folded_rule_and_accepts_at_its_end_states():
    data = _data()
    rows = lalr.unpack(data["actions"], data["symbols"])
    folded = tables.identity_rules(data["rules"])
    assert folded
    seen, todo = set(), list(data["start_states"].values())
    while todo:
        state = todo.pop()
        if state in seen:
            continue
        seen.add(state)
        for symbol, code in rows[state].items():
            if code >= 0:
                todo.append(code)
            elif code == lalr.ACCEPT:
                assert symbol == "$END"
            else:
                assert ~code not in folded, (state, symbol, data["rules"][~code])
    for end in data["end_states"].values():
        assert end in seen and rows[end]["$END"] == lalr.ACCEPT
    assert len(seen) > 258  # (lark's 258 states and the folded ones)


# -- the driver beside lark's automaton ------------------------------------------------------------


def _larks_reductions(lk, text: str, start: str) -> tuple[list, str]:
    """lark's LALR automaton run here on its parse table and its lexer's tokens: the rules it
    reduces by (but the folded ones), in order, and how it ends ("accept" or "error")."""
    table = lk.parser.parser.parser.parse_table
    folded = _folded_keys()
    reduced: list = []
    stack = [table.start_states[start]]
    end_state = table.end_states[start]
    tokens = [t.type for t in lk.lex(text)] + ["$END"]
    for kind in tokens:
        while True:
            action = table.states[stack[-1]].get(kind)
            if action is None:
                return reduced, "error"
            what, arg = action
            if what.name == "Shift":
                stack.append(arg)
                break
            key = (arg.origin.name, tuple(s.name for s in arg.expansion))
            if key not in folded:
                reduced.append(key)
            if arg.expansion:
                del stack[-len(arg.expansion):]
            stack.append(table.states[stack[-1]][arg.origin.name][1])
            if kind == "$END" and stack[-1] == end_state:
                return reduced, "accept"
    return reduced, "error"


def _folded_keys() -> set:
    rules = _data()["rules"]
    return {(rules[i][0], tuple(rules[i][1])) for i in tables.identity_rules(rules)}


def _drivers_reductions(text: str, start: str) -> tuple[list, str]:
    """The driver on the shipped data, every callback recording its rule and returning ``None``."""
    data = _data()
    reduced: list = []
    callbacks = [(lambda key: lambda c: reduced.append(key))((origin, tuple(symbols)))
                 for origin, symbols, _, _ in data["rules"]]
    drive = lalr.driver(data, callbacks)
    assert drive is not None
    return reduced, "error" if drive(text, start) is lalr.FAILED else "accept"


def _texts() -> list[tuple[str, str]]:
    rng = random.Random(26)
    lk = _lark()
    texts = []
    for path in FILES:
        text = path.read_text(encoding="utf-8")
        texts.append((text, "start"))
        tokens = list(lk.lex(text))
        for t in rng.sample(tokens, min(6, len(tokens))):
            texts.append((text[:t.start_pos], "start"))  # truncated before a token
            texts.append((text[:t.start_pos] + " " + text[t.end_pos:], "start"))  # a token deleted
    words = ["x", "d", "1", "2.5", "(", ")", "[", "]", ",", ";", ":", "=", "+", "-", "*", "/", "^", "<", "<=",
             ">=", ">", "&", "|", ".", "..", "int", "let", "in", "if", "then", "else", "ifge0", "not", "sum",
             "prod", "param", "def", "var", "from", "import", "as", "diffeo", "inverse"]
    operand = ["x", "1", "d", "(x)", "-x", "f(x)", "[x < 1]", "(x, 1).y"]
    for _ in range(300):  # random token sequences: mostly errors, in every corner of the table
        texts.append((" ".join(rng.choice(words) for _ in range(rng.randrange(1, 12))),
                      rng.choice(("start", "term"))))
    for _ in range(300):  # random terms, mostly valid
        out = rng.choice(operand)
        for _ in range(rng.randrange(0, 8)):
            out += f" {rng.choice(['+', '-', '*', '/', '^', '<=', '>'])} {rng.choice(operand)}"
        texts.append((out, "term"))
        texts.append((f"int ([0, 1]) {out} d(x)", "start"))
    return texts


def test_the_driver_reduces_as_lark_s_automaton():
    lk = _lark()
    outcomes = {"accept": 0, "error": 0}
    for text, start in _texts():
        theirs = _larks_reductions(lk, text, start)
        ours = _drivers_reductions(text, start)
        assert ours == theirs, (text, start)
        outcomes[theirs[1]] += 1
    assert outcomes["accept"] >= 300 and outcomes["error"] >= 200, outcomes  # (both kinds, many)


#: Microbenchmark 1's text at n = 1 (bench/bench_peers.py's ``langur_text(1)``).
_MB1 = ("param a = 1\nint ([-1, 1]) (sum i in 10..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x)) + "
        "(sum i in 10..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")


@pytest.mark.parametrize("start", ["start", "term"])
def test_the_driver_reduces_as_lark_s_automaton_on_mb1(start):
    text = _MB1 if start == "start" else "(sum i in 10..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x))"
    ours, theirs = _drivers_reductions(text, start), _larks_reductions(_lark(), text, start)
    assert ours == theirs and ours[1] == "accept"
    assert ("sum", ("sum", "PLUS", "product")) in ours[0]


# -- fold_units by hand ----------------------------------------------------------------------------

# rules: 0  B → A (an identity: "plain")   1  S → B b   2  A → a   3  C → B c
_RULES = [("B", ("A",), "plain", ()), ("S", ("B", "b"), "s", ()), ("A", ("a",), "num", ()), ("C", ("B", "c"), "c", ())]
_TERMINALS = {"a", "b", "c", "$END"}


def _table() -> list[dict[str, int]]:
    return [
        {"a": 1, "A": 2, "B": 3, "S": 5},  # 0: the start
        {"b": -1 - 2, "c": -1 - 2},  # 1: A → a .
        {"b": -1 - 0, "c": -1 - 0},  # 2: B → A .  (an identity reduction: folded)
        {"b": 4},  # 3: S → B . b
        {"$END": -1 - 1},  # 4: S → B b .
        {},  # 5: the end state
    ]


def test_fold_units_folds_a_unit_reduction_into_a_new_state():
    got = tables.fold_units(_table(), _RULES, _TERMINALS, {5})
    # (0, A) → 6: on b the reduction B → A leads to 3, which shifts b (to 4); on c to 3, no action
    assert got == [
        {"a": 1, "A": 6, "B": 3, "S": 5},
        {"b": -3, "c": -3},
        {"b": -1, "c": -1},
        {"b": 4},
        {"$END": -2},
        {"$END": lalr.ACCEPT},
        {"b": 4},
    ]


def test_fold_units_keeps_its_gotos_and_refuses_two_on_one_symbol():
    table = _table()
    table[2] = {"b": -1 - 0, "c": 6, "Z": 7}  # 2 shifts c itself, and has a goto on Z
    table += [{"$END": -1 - 3}, {}]  # 6, 7
    got = tables.fold_units(table, _RULES, _TERMINALS, {5})
    assert got[0]["A"] == 8 and got[8] == {"b": 4, "c": 6, "Z": 7}  # the goto on Z taken from 2
    table[3] = {"b": 4, "Z": 7}  # 3 too has a goto on Z: which one depends on the look-ahead
    got = tables.fold_units(table, _RULES, _TERMINALS, {5})
    assert got[0]["A"] == 2 and len(got) == len(table)  # (0, A) left as it is
    assert got[2] == table[2]


def test_minimized_merges_states_that_act_alike_and_drops_unreached_ones():
    table = [
        {"a": 1, "b": 2, "A": 3},  # 0
        {"c": 4},  # 1 ─┐ alike only if 4 and 5 are: they are (both reduce by rule 0 on $END)
        {"c": 5},  # 2 ─┘
        {"c": 6},  # 3: leads to 6, which acts otherwise
        {"$END": -1},  # 4
        {"$END": -1},  # 5
        {"$END": -2},  # 6
        {"a": 0},  # 7: reached from nowhere
    ]
    rows, number = tables.minimized(table, [0])
    assert number == {0: 0, 1: 1, 2: 1, 3: 2, 4: 3, 5: 3, 6: 4}
    assert rows == [{"a": 1, "b": 1, "A": 2}, {"c": 3}, {"c": 4}, {"$END": -1}, {"$END": -2}]
    assert tables.minimized(rows, [0]) == (rows, {i: i for i in range(5)})  # (already minimal)


def test_the_shipped_table_is_minimal():
    data = _data()
    rows = lalr.unpack(data["actions"], data["symbols"])
    again, number = tables.minimized(rows, list(data["start_states"].values()))
    assert again == rows and len(set(number.values())) == len(rows)
