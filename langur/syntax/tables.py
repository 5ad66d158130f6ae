"""The parser's LALR tables, shipped with the package as JSON data (never a pickle).

lark's ``cache=True`` keeps its tables as a pickle at a predictable name in the system temp folder
and unpickles it at every start: anyone who can write there runs code as the next user of Langur
(SECURITY.md).  Instead the tables are generated from ``grammar.lark`` once, when the grammar
changes, and shipped as ``grammar.tables.json`` beside it.  JSON holds only data: loading it can
build a parser or fail, never run code.  The file records the SHA-256 of the grammar it was made
from; a file that does not match the grammar, or does not decode, is ignored and the parser is
built from the grammar (slower start-up, same parser).

The same run also writes ``grammar_driver.py`` (:data:`lalr.DATA`, a module of literals): what :mod:`langur.syntax.lalr`'s
driver needs to parse a valid program without importing lark (issue 15, start-up), read here out of
the parser lark builds (:func:`driver_data`) — never written by hand.  This module imports lark: it
is the generator's side, and at run time it is imported only on the parser's error path, or when
the shipped files are stale.

Regenerate after editing the grammar::

    python -m langur.syntax.tables          # writes grammar.tables.json and grammar_driver.py
    python -m langur.syntax.tables --check  # exit 1 if the shipped files do not match the grammar
"""

from __future__ import annotations

import hashlib
import json
import re
import sys
from functools import partial
from pathlib import Path
from pprint import pformat
from typing import Any

from . import lalr, larkload, scangen
from .lalr import grammar_text
from .larkload import ChildFilterLALR_NoPlaceholders, ExpandSingleChild, Lark, Rule, TerminalDef

TABLES = Path(__file__).with_name("grammar.tables.json")
FORMAT = 1
MAX_TABLES_BYTES = 4_000_000  # the shipped file is ~100 kB; anything far larger is not ours

# The options every Langur parser is built with (the transformer is attached at load time).
OPTIONS: dict[str, Any] = dict(
    parser="lalr",
    lexer="basic",
    start=["start", "term"],
    keep_all_tokens=True,
    maybe_placeholders=False,
)


# lark's serialized form is nested dicts, lists, tuples, strings, numbers and booleans; dicts may
# have integer keys (parse states).  JSON keeps all of that if tuples and non-string-keyed dicts are
# tagged.
def _encode(x: Any) -> Any:
    if isinstance(x, dict):
        if all(isinstance(k, str) for k in x) and "__t" not in x:
            return {k: _encode(v) for k, v in x.items()}
        return {"__t": "dict", "items": [[_encode(k), _encode(v)] for k, v in x.items()]}
    if isinstance(x, tuple):
        return {"__t": "tuple", "items": [_encode(v) for v in x]}
    if isinstance(x, list):
        return [_encode(v) for v in x]
    if x is None or isinstance(x, (str, int, float, bool)):
        return x
    raise TypeError(f"not plain data: {type(x).__name__}")


def _decode(x: Any) -> Any:
    if isinstance(x, dict):
        tag = x.get("__t")
        if tag == "dict":
            return {_decode(k): _decode(v) for k, v in x["items"]}
        if tag == "tuple":
            return tuple(_decode(v) for v in x["items"])
        return {k: _decode(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_decode(v) for v in x]
    return x


def _tagged(x: dict) -> Any:
    """:func:`_decode` of one JSON object whose members are decoded already (``json``'s
    ``object_hook``: the whole file decoded in C but for the objects, at start-up)."""
    tag = x.get("__t")
    if tag == "dict":
        return {k: v for k, v in x["items"]}
    if tag == "tuple":
        return tuple(x["items"])
    return x


def build(text: str | None = None, **kwargs: Any) -> Lark:
    """The parser built from the grammar, without any cache."""
    return Lark(grammar_text() if text is None else text, cache=False, **OPTIONS, **kwargs)


def digest(text: str) -> str:
    """The grammar's SHA-256, which lark's tables (:data:`TABLES`) carry; the driver's module
    carries the grammar's text itself, compared as it is by :func:`lalr.load` (no digest — and no
    ``hashlib``, whose import loads OpenSSL — in a process that only parses)."""
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


def generate(text: str | None = None, lark: Lark | None = None) -> dict[str, Any]:
    """lark's tables (the contents of :data:`TABLES`) of the parser ``lark`` built from ``text``."""
    text = grammar_text() if text is None else text
    data, memo = (lark or build(text)).memo_serialize([TerminalDef, Rule])
    return {"format": FORMAT, "grammar_sha256": digest(text), "data": _encode(data), "memo": _encode(memo)}


def generate_driver(text: str | None = None, lark: Lark | None = None) -> dict[str, Any]:
    """The contents of :data:`lalr.DATA` for the parser ``lark`` built from ``text``."""
    text = grammar_text() if text is None else text
    return {"format": lalr.DATA_FORMAT, "grammar": text, "driver": driver_data(lark or build(text))}


def driver_module(doc: dict[str, Any]) -> str:
    """The source of :data:`lalr.DATA` for :func:`generate_driver`'s ``doc``: literals only, each
    printed by ``repr`` — a module Python compiles to a ``.pyc`` like every other, so that the
    data's load is an unmarshal, not a parse (issue 15).  The table is ``ACTIONS``, one ``bytes``
    constant (:func:`lalr.pack`; unmarshalled as one block, indexed by the driver as it is); the
    rows it packs (``states``) are not written again."""
    driver = {k: v for k, v in doc["driver"].items() if k not in ("states", "actions")}
    actions = doc["driver"]["actions"]
    lines = "".join(f"    {actions[i:i + 48]!r}\n" for i in range(0, len(actions), 48))
    return (
        "# Generated by `python -m langur.syntax.tables` from grammar.lark: do not edit.\n"
        "# The LALR driver's data (langur/syntax/lalr.py), read out of the parser lark builds; literals only.\n"
        "# fmt: off\n"
        f"FORMAT = {doc['format']!r}\n"
        f"GRAMMAR = {doc['grammar']!r}\n"
        f"BYTEORDER = {sys.byteorder!r}\n"
        f"DRIVER = {pformat(driver, width=120, sort_dicts=True)}\n"
        f"ACTIONS = (\n{lines})\n"
    )


def driver_data(lark: Lark) -> dict[str, Any] | None:
    """What :func:`lalr.driver` and :func:`lalr.callbacks` need, read out of the parser ``lark`` (built
    with :data:`OPTIONS`), as plain data; ``None`` when ``lark`` is not built as Langur's parser is
    (LALR, basic lexer, one compiled pattern, no post-lexer, only keyword callbacks on terminals,
    no token that may hold a line break, rule callbacks wrapped only by lark's single-child
    expansion and child filter without placeholders).

    * ``lexer``: the scanner's terminals in its order as ``[name, regexp, literal]`` (``literal``: the
      text of a string terminal without flags, else ``None``), the ignored terminals'
      names and patterns, the pattern's flags, and per terminal with a keyword callback (lark's
      ``UnlessCallback``: ``NAME``) the ``[literal, terminal]`` pairs it tries in order;
    * ``rules``: per rule ``[origin, symbols, callback name, wrapper chain]``, the chain in lark's
      order (``["expand1"]``, ``["filter", [[index, spliced], …]]``);
    * ``states``: per state (0, 1, …) its actions, ``symbol → next state`` for a shift (and a
      nonterminal's goto) or ``−1 − rule`` for a reduction, lark's with its unit reductions by
      identity callbacks folded in (:func:`fold_units`: more states, :data:`lalr.ACCEPT` at the
      end), then :func:`minimized`; ``start_states``, ``end_states``;
    * ``terminal_names``: every terminal's name (an inline transformer with a method of that name
      would get lark's token callback, which the driver does not make);
    * ``scanner``, ``symbols``, ``actions``: the lexer's pattern resolved from the above
      (:func:`scangen.scanner`), and the table packed by symbol (:func:`lalr.pack`): what the driver
      runs as it is, so that its start-up resolves nothing."""
    try:
        front = lark.parser
        lexer, parser = front.lexer, front.parser.parser
        scanner = lexer.scanner  # (builds the lexer's callbacks too)
        if (front.lexer_conf.postlex is not None or len(larkload.scanner_patterns(scanner)) != 1
                or any(type(cb).__name__ != "UnlessCallback" for cb in lexer.callback.values())):
            return None
        pattern = larkload.scanner_patterns(scanner)[0]
        ignored, newlines = frozenset(lexer.ignore_types), frozenset(lexer.newline_types)
        terminals = list(scanner.terminals)
        if "|".join(f"(?P<{t.name}>{t.pattern.to_regexp()})" for t in terminals) != pattern.pattern \
                or not newlines <= ignored:
            return None  # (not the scanner's pattern, or a token that may hold a line break)
        scan = [[t.name, t.pattern.to_regexp(),
                 t.pattern.value if t.pattern.type == "str" and not t.pattern.flags else None] for t in terminals]
        keywords: dict[str, list] = {}
        for name, cb in lexer.callback.items():
            for t in cb.scanner.terminals:
                if t.pattern.type != "str" or t.pattern.flags:
                    return None
            keywords[name] = [[t.pattern.value, t.name] for t in cb.scanner.terminals]
        lexer_data = {
            "flags": pattern.flags,
            "terminals": scan,
            "ignore": sorted(ignored),
            "ignored_patterns": [t.pattern.to_regexp() for t in lexer.terminals if t.name in ignored],
            "keywords": keywords,
        }
        table = parser.parse_table
        if any(isinstance(k, str) for k in parser.callbacks):
            return None  # (a terminal with a callback of its own)
        index = {}
        rules = []
        for rule, chain in larkload.rule_wrappers(lark):
            index[rule] = len(rules)
            rules.append([rule.origin.name, [s.name for s in rule.expansion],
                          rule.alias or rule.options.template_source or rule.origin.name, _chain(chain)])
            if rules[-1][3] is None:
                return None
        shift = next(a for row in table.states.values() for a, _ in row.values() if a.name == "Shift")
        if sorted(table.states) != list(range(len(table.states))):
            return None
        states = [{symbol: arg if action is shift else -1 - index[arg] for symbol, (action, arg) in row.items()}
                  for _, row in sorted(table.states.items())]
        # (as plain data: lark's names are its Token, a str subclass; JSON's round trip makes them str,
        # and every list a tuple: one constant of the generated module, not a list built at import)
        data = json.loads(json.dumps({
            "lexer": lexer_data, "rules": rules, "states": states,
            "start_states": dict(table.start_states), "end_states": dict(table.end_states),
            "terminal_names": sorted(t.name for t in lark.terminals)}), object_hook=_tuples)
        data = {**data, "states": [dict(row) for row in data["states"]]}
        symbols = tuple(sorted({"$END", *data["terminal_names"], *(rule[0] for rule in data["rules"]),
                          *(symbol for row in data["states"] for symbol in row)}))
        scan = scangen.scanner(data["lexer"])
        if scan is None:
            return None  # (a terminal the scanner cannot tell by its text)
        folded, number = minimized(fold_units(data["states"], data["rules"], {"$END", *data["terminal_names"]},
                                              set(data["end_states"].values())), list(data["start_states"].values()))
        return {**data, "states": folded, "scanner": scan, "symbols": symbols, "actions": lalr.pack(folded, symbols),
                "start_states": {start: number[state] for start, state in data["start_states"].items()},
                "end_states": {start: number[state] for start, state in data["end_states"].items()}}
    except (AttributeError, KeyError, TypeError, StopIteration, re.error):
        return None


#: The rules whose callback gives back its one child unchanged, by callback name (and, for ``name``,
#: the one symbol it does so for): ``builder.Builder``'s ``plain`` (the precedence ladder ``term`` →
#: ``sum`` → ``product`` → ``unary`` → ``power`` → ``atom``), ``cond_term``, ``cmp``, and ``name`` of a
#: ``NAME`` token (a ``D`` is made a ``NAME``).  lark's ``?rule`` of one symbol (its ``expand1``
#: wrapper gives back an only child) is one too.  :func:`fold_units` takes them out of the table.
IDENTITIES: dict[str, str | None] = {"plain": None, "cond_term": None, "cmp": None, "name": "NAME"}


def identity_rules(rules: list) -> set[int]:
    """The indices of the rules of ``rules`` (:func:`driver_data`'s) whose callback gives back its one
    child unchanged (:data:`IDENTITIES`)."""
    out = set()
    for i, (_origin, symbols, name, chain) in enumerate(rules):
        if len(symbols) != 1:
            continue
        expand1 = [tuple(w) for w in chain] == [("expand1",)]
        if expand1 or (not chain and name in IDENTITIES and IDENTITIES[name] in (None, symbols[0])):
            out.add(i)
    return out


def fold_units(states: list[dict[str, int]], rules: list, terminals: set[str], ends: set[int]) -> list[dict[str, int]]:
    """The LALR table ``states`` (:func:`driver_data`'s rows) with its unit reductions folded in: the
    standard elimination of chain rules from an LR table (Aho and Ullman, *The Theory of Parsing*,
    §7.3: a reduction by a rule ``A → B`` whose semantic action is the identity costs the parser
    only a change of state, which can be decided when the state is entered).

    A unit reduction by an identity rule (:func:`identity_rules`) in state ``t``, entered from
    ``s`` by symbol ``Y``, pops ``t`` and enters ``goto(s, A)`` from the same ``s``: where the run
    of such reductions ends depends on ``s`` and the look-ahead only.  So every entry ``s --Y--> t``
    of the table whose ``t`` has an identity reduction is redirected to a new state ``(s, Y)``
    whose action on each terminal is the one the run ends with (a shift — itself redirected —, a
    reduction by another rule or no action), and whose goto on a nonterminal is that of the state
    the run ends in before a shift (or an empty reduction).  When two such states have a goto on the
    same nonterminal, ``(s, Y)`` is left as it was (its unit reductions then run as reductions,
    their callbacks giving back the child).  The end states get :data:`lalr.ACCEPT` in their
    ``$END`` column (lark's parser accepts on entering one at the end of the input, after a
    reduction); a run at the end of the input stops there, as lark's does.

    The new table makes the parser call the same other callbacks on the same children in the same
    order, and stop at the same token when the input has an error (``proofs_tests/test_parse26.py``
    runs it beside lark's automaton).  The new states come after the old ones, in the order of
    ``(s, Y)``; the old states no entry leads to any longer are kept (not renumbered)."""
    units = identity_rules(rules)

    def run(s: int, t: int, a: str) -> tuple[int, int]:
        """The state the run of unit reductions from ``t`` (entered from ``s``) on ``a`` ends in, and
        the code of ``a`` there."""
        while True:
            if a == "$END" and t in ends:
                return t, lalr.ACCEPT
            code = states[t].get(a, lalr.NO_ACTION)
            if code >= 0 or code == lalr.NO_ACTION or ~code not in units:
                return t, code
            t = states[s][rules[~code][0]]

    def has_unit(t: int) -> bool:
        return any(code < 0 and ~code in units for symbol, code in states[t].items() if symbol in terminals)

    folds: dict[tuple[int, str], tuple[dict[str, tuple[int, int]], dict[str, int]]] = {}
    for s, row in enumerate(states):
        for symbol, t in row.items():
            if t < 0 or not has_unit(t):
                continue
            ends_in = {a: run(s, t, a) for a in sorted(terminals)}
            # the states a goto may be taken from later: where the run ends before a shift or an empty reduction
            bases = {u for u, code in ends_in.values()
                     if code >= 0 or (code != lalr.NO_ACTION and code != lalr.ACCEPT and not rules[~code][1])}
            gotos = _gotos(states, bases, terminals)
            if gotos is not None:
                folds[s, symbol] = ends_in, gotos
    number = {key: len(states) + i for i, key in enumerate(sorted(folds))}

    def entry(s: int, symbol: str, code: int) -> int:
        """The code of ``symbol`` in ``s`` once entries are redirected to the new states."""
        return number.get((s, symbol), code) if code >= 0 else code

    out = [{symbol: entry(s, symbol, code) for symbol, code in row.items()} for s, row in enumerate(states)]
    for e in ends:
        out[e]["$END"] = lalr.ACCEPT
    for s, symbol in sorted(folds):
        ends_in, gotos = folds[s, symbol]
        row = {a: entry(u, a, code) for a, (u, code) in ends_in.items() if code != lalr.NO_ACTION}
        row.update((z, entry(u, z, states[u][z])) for z, u in gotos.items())
        out.append(row)
    return out


def minimized(states: list[dict[str, int]], starts: list[int]) -> tuple[list[dict[str, int]], dict[int, int]]:
    """The table ``states`` with the states no entry reaches from ``starts`` dropped and the states
    that act alike merged — Moore's partition refinement: two states are one when each symbol has
    the same reduction (or none, or :data:`lalr.ACCEPT`) in both, or leads to states that are one —
    and each kept state's new number (:func:`fold_units` leaves many states that differ only by the
    state they were entered from, and some of lark's unreached).  The blocks are numbered in the
    order of their first state."""
    reached, todo = set(), list(starts)
    while todo:
        state = todo.pop()
        if state not in reached:
            reached.add(state)
            todo += [code for code in states[state].values() if code >= 0]
    order = sorted(reached)
    block = dict.fromkeys(order, 0)
    while True:
        keys: dict[tuple, int] = {}
        refined = {state: keys.setdefault(tuple(sorted(
            (symbol, code < 0, code if code < 0 else block[code]) for symbol, code in states[state].items())), len(keys))
            for state in order}
        if len(keys) == len(set(block.values())):
            break
        block = refined
    rows: list[dict[str, int]] = []
    for state in order:
        if block[state] == len(rows):
            rows.append({symbol: code if code < 0 else block[code] for symbol, code in states[state].items()})
    return rows, block


def _gotos(states: list[dict[str, int]], bases: set[int], terminals: set[str]) -> dict[str, int] | None:
    """For :func:`fold_units`: each nonterminal's state among ``bases`` with a goto on it, or ``None``
    when two of them have one on the same nonterminal."""
    gotos: dict[str, int] = {}
    for u in sorted(bases):
        for z, g in states[u].items():
            if z not in terminals and g >= 0 and gotos.setdefault(z, u) != u:
                return None
    return gotos


def _tuples(x: dict) -> dict:
    """``json``'s ``object_hook``: an object's arrays as tuples (nested ones too)."""
    return {k: _tuple(v) for k, v in x.items()}


def _tuple(x: Any) -> Any:
    return tuple(_tuple(v) for v in x) if isinstance(x, list) else x


def _chain(chain: list) -> list | None:
    """lark's wrapper chain of a rule's callback as data, or ``None`` for a wrapper the driver does
    not make (placeholders, positions, ambiguity: none is used under :data:`OPTIONS`)."""
    out: list = []
    for w in chain:
        if w is ExpandSingleChild:
            out.append(["expand1"])
        elif isinstance(w, partial) and w.func is ChildFilterLALR_NoPlaceholders and not w.keywords \
                and len(w.args) == 1:
            out.append(["filter", [[i, bool(spliced)] for i, spliced in w.args[0]]])
        else:
            return None
    return out


def load(transformer: Any, path: Path = TABLES) -> Lark | None:
    """The parser from the shipped tables, or ``None`` when they are missing, too large, malformed
    or made from another grammar (the caller then builds it from the grammar)."""
    try:
        if path.stat().st_size > MAX_TABLES_BYTES:
            return None
        doc = json.loads(path.read_text(encoding="utf-8"), object_hook=_tagged)
        if doc.get("format") != FORMAT or doc.get("grammar_sha256") != digest(grammar_text()):
            return None
        return larkload.from_data(doc["data"], doc["memo"], transformer)
    except Exception:  # noqa: BLE001 - any defect in the data file: fall back to the grammar
        return None


def _check(path: Path, fmt: int) -> str | None:
    """What is wrong with the shipped file ``path`` (layout ``fmt``), or ``None``."""
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return "missing or unreadable"
    if type(doc) is not dict or doc.get("format") != fmt:
        return "of another layout"
    if doc.get("grammar_sha256") != digest(grammar_text()):
        return "made from another grammar"
    return None


def _same_driver(data: dict) -> bool:
    """``data`` has what :func:`driver_data` reads off a parser built now: the same lexer, rules,
    symbols and number of states (lark numbers its states in set order: the tables themselves may
    differ between two generations by a renumbering)."""
    fresh = driver_data(build())
    keys = ("lexer", "rules", "terminal_names", "scanner", "symbols")
    return fresh is not None and all(data.get(k) == fresh[k] for k in keys) \
        and len(data["actions"]) == len(fresh["actions"])


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--check"]:
        status = 0
        wrongs = [(TABLES, _check(TABLES, FORMAT))]
        data = lalr.load()
        if data is None:
            wrongs.append((lalr.DATA, "missing, broken, of another layout or made from another grammar"))
        elif lalr.driver(data, lalr.callbacks(data, object()) or []) is None or not _same_driver(data):
            wrongs.append((lalr.DATA, "not the driver's data of lark's parser"))
        for path, wrong in wrongs:
            if wrong is not None:
                print(f"{path}: {wrong}; run python -m langur.syntax.tables", file=sys.stderr)
                status = 1
        return status
    if argv:
        print("usage: python -m langur.syntax.tables [--check]", file=sys.stderr)
        return 2
    lark = build()  # (both files from one parser)
    driver = generate_driver(lark=lark)
    if driver["driver"] is None:
        print("lark's parser is not one langur.syntax.lalr can drive: only lark's tables written", file=sys.stderr)
    TABLES.write_text(json.dumps(generate(lark=lark), separators=(",", ":"), sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {TABLES}")
    lalr.DATA.write_text(driver_module(driver), encoding="utf-8")
    print(f"wrote {lalr.DATA}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
