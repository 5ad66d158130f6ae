"""The parser's successful path without lark: a lean LALR(1) driver of tables generated from lark
(issue 15, start-up and loading; the grammar of LANGUAGE.md §6 is ``grammar.lark``).

lark is the single source of the grammar, but importing it (~25 ms), deserializing its parser
(~10 ms) and reading that parser's objects back into a driver (~4 ms) cost about 40 ms of every
one-shot process for a parse that takes well under a millisecond.  So ``python -m
langur.syntax.tables`` — run when the grammar changes — also reads, out of the parser lark builds,
everything a successful parse needs and writes it as plain data (literals, never a pickle: SECURITY.md)
to the module ``grammar_driver.py`` (:data:`DATA`), stamped with the grammar's text (compared as it is on load: a stale module is not read): the lexer's terminals
in the order lark's scanner tries them and their regular expressions, the keywords lark's
``UnlessCallback`` tells from names, the ignored and newline-bearing terminals, the LALR action
table (lark's, with its unit reductions by rules whose callback gives back its child folded in:
``tables.fold_units``, parse26), and for every rule the callback lark calls on its reduction and how lark's parse-tree
builder shapes the children first (``_rule`` inlining, ``?rule``'s single child: its wrapper chain
under ``tables.OPTIONS``).  This module loads that data and runs it with ``builder.Builder``'s
callbacks; it never imports lark.  A token is a tuple of lark's token's attributes (:data:`TOKEN`;
not a ``str`` since parse24, not an object since parse25).

:func:`driver` runs the data in one loop: the same tokens as lark's lexer (type, text, positions),
the same shifts and reductions, the same callbacks called in the same order on the same children,
so the same result or the same exception from a callback (E105, E106).  The lexer is done another
way than lark's runtime does it, for speed (front11, parse24): one ``findall`` of the generator's
pattern cuts the text into ignored runs and tokens (the one-character literal terminals one
character class: at most one of them matches anywhere), and a token's terminal is read off its text
(``scangen``: a dict of the literal texts and keywords, what lark's ``UnlessCallback`` finds by a
full match of their alternation, and a dict of first characters for ``NAME`` and ``NUMBER``).

The data is left as the generator wrote it, so that a process's start-up resolves nothing (issue 15,
parser23: the JSON file's decoding and the table's resolution were 14 M instructions of the
one-shot ``langur eval``): the module is literals compiled to its ``.pyc`` like any module (its load
an unmarshal); the table is one ``bytes`` constant, a column of 16-bit codes per symbol, indexed
as it is (:func:`pack`); the lexer's pattern is glued by the generator and compiled by ``re`` once
per process (:func:`glued`; shipping the engine's compiled code instead would save ~2.5 M
instructions through the private ``_sre.compile``, whose code is not promised to be the same across
patch releases of one interpreter: not done).

Only success is handled here: at a character no terminal matches or a token the table has no action
for, :func:`driver`'s function returns :data:`FAILED`, and ``parser.py`` then imports lark and parses
again with it, which raises the error the diagnostics are made from (the callbacks keep no state
between calls but the path, so running them again is harmless).  That lazy import is the point (a
valid program never pays for lark), not a way around an import cycle.  A missing, stale or
malformed data module makes :func:`load` return ``None``: ``parser.py`` then builds lark's parser from
the grammar and derives the same data from it in the process (``tables.driver_data``), slower, same
behaviour.  ``proofs_tests/test_lalr.py`` and ``test_text_to_number11.py`` compare the driver with
lark on every example file, the hostile corpus and random programs, token by token and tree by tree.
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

GRAMMAR = Path(__file__).with_name("grammar.lark")
#: The driver's data: a Python module of literals (compiled to a ``.pyc`` like every module: its load
#: is an unmarshal), generated from lark by ``python -m langur.syntax.tables``, never edited by hand.
DATA = Path(__file__).with_name("grammar_driver.py")
#: The layout of :data:`DATA` (a module of another layout is not read; 5: the table's unit reductions
#: folded, :data:`ACCEPT` at its end states).
DATA_FORMAT = 5

#: What the driver returns when lark must parse instead (an input with a syntax error).
FAILED = object()

def grammar_text() -> str:
    with open(GRAMMAR, encoding="utf-8") as f:
        return f.read()


#: A token as the callbacks receive it: a tuple of lark's token's attributes, in this order (the
#: driver makes one with one tuple display per token: parse25 — a slotted ``Token`` object cost
#: ≈ 1.9 k instructions a token, a tuple ≈ 0.3 k; lark's own tokens are given to the callbacks as
#: such tuples too, by :func:`token`).  The callbacks index it: ``t[0]`` its terminal, ``t[1]`` its
#: text, ``t[2]``, ``t[3]`` its first line and column, ``t[4]``, ``t[5]`` its last line and the
#: column after it (1-based), ``t[6]``, ``t[7]`` its offsets in the text (start, end).
TOKEN = ("type", "value", "line", "column", "end_line", "end_column", "start_pos", "end_pos")


def token(t: Any) -> tuple:
    """lark's token ``t`` (or any object with :data:`TOKEN`'s attributes) as the driver's tuple."""
    return (t.type, t.value, t.line, t.column, t.end_line, t.end_column, t.start_pos, t.end_pos)


class Tree:
    """What lark's parse-tree builder makes for a rule without a callback (``Tree(name, children)``):
    only the inlined ``_rule``s of Langur's grammar, whose children the parent's filter splices in."""

    __slots__ = ("children", "data")

    def __init__(self, data: str, children: list) -> None:
        self.data, self.children = data, children

    def __repr__(self) -> str:
        return f"Tree({self.data!r}, {self.children!r})"


def load(module: Any = None) -> dict | None:
    """The driver's data — ``DRIVER`` of the generated module :data:`DATA` (or of ``module``), its
    table ``ACTIONS`` included — or ``None`` when the module is missing or broken, of another layout,
    made from another grammar or for another byte order (the caller then derives the data from
    lark)."""
    try:
        if module is None:
            from . import grammar_driver as module  # (the generated data, read on the first parse)
        if (module.FORMAT != DATA_FORMAT or module.BYTEORDER != sys.byteorder
                or module.GRAMMAR != grammar_text()):
            return None
        return {**module.DRIVER, "actions": module.ACTIONS}
    except Exception:  # noqa: BLE001 - a missing or broken module: the data is derived from lark instead
        return None


def glued(lexer: dict) -> re.Pattern:
    """The lexer's pattern (``scangen.scanner``'s), compiled."""
    return re.compile(lexer["pattern"], lexer["flags"])


#: About how many characters of the text the driver's lexer cuts at a time (a piece ends after a
#: line break: no token holds one), so that a huge file is not held as one list of all its tokens.
CHUNK = 1 << 16

#: A table's code for "no action" (an input with a syntax error there).
NO_ACTION = -32768
#: A table's code, in the ``$END`` column only, for "the input is parsed": the end states' (lark's
#: parser accepts on entering one at the end of the input) and the folded states' whose unit
#: reductions lead to one (``tables.fold_units``).
ACCEPT = -32767

#: What the driver's lexer adds after the last piece ``findall`` cuts (``ignored`` None: not one of
#: them): the look-ahead ``$END``, whose reductions the driver makes as a token's, then accepts.
_END_OF_INPUT = (None, "", "")


def pack(states: list[dict[str, int]], symbols: list[str]) -> bytes:
    """The table's rows (per state, ``symbol → code``: the next state for a shift or a goto,
    ``-1 - rule`` for a reduction) as one column per symbol of ``symbols``, each a run of 16-bit
    codes by state (:data:`NO_ACTION` where the row has none), in this machine's byte order: the
    generator's form of the table, which the driver indexes as it is (:func:`driver`)."""
    index = {symbol: i for i, symbol in enumerate(symbols)}
    codes = [NO_ACTION] * (len(symbols) * len(states))
    for state, row in enumerate(states):
        for symbol, code in row.items():
            if not NO_ACTION < code < -NO_ACTION:
                raise ValueError(f"a code beyond 16 bits: {code}")
            codes[index[symbol] * len(states) + state] = code
    return b"".join(code.to_bytes(2, sys.byteorder, signed=True) for code in codes)


def unpack(actions: bytes, symbols: list[str]) -> list[dict[str, int]]:
    """The rows :func:`pack` packed (for the tests and the generator's check)."""
    table = memoryview(actions).cast("h")
    n_states = len(table) // len(symbols) if symbols else 0
    return [{symbol: table[i * n_states + state] for i, symbol in enumerate(symbols)
             if table[i * n_states + state] != NO_ACTION} for state in range(n_states)]


# How lark's parse-tree builder wraps a rule's callback (lark.parse_tree_builder, as read by
# tables.driver_data): ``expand1`` — a ``?rule`` returns its only child without calling it;
# ``filter`` — the children are filtered first, an inlined ``_rule``'s own children spliced in.
def _expand_single_child(f: Callable) -> Callable:
    def expand(children):
        return children[0] if len(children) == 1 else f(children)
    return expand


def _child_filter(include: list, f: Callable) -> Callable:
    include = [(int(i), bool(spliced)) for i, spliced in include]

    def filtered(children):
        out: list = []
        for i, spliced in include:
            if spliced:
                if out:
                    out += children[i].children
                else:  # (lark's: the left recursion's list taken over)
                    out = children[i].children
            else:
                out.append(children[i])
        return f(out)
    return filtered


def callbacks(data: dict, builder: Any) -> list[Callable] | None:
    """Each rule's callback, as lark's ``ParseTreeBuilder.create_callback`` makes it for the inline
    transformer ``builder``: its method named by the rule (``None`` when ``builder`` has a method
    named as a terminal: lark would call it on every such token, which the driver does not)."""
    try:
        if any(hasattr(builder, name) for name in data["terminal_names"]):
            return None
        out = []
        for _origin, _symbols, name, chain in data["rules"]:
            f = getattr(builder, name, None)
            if f is None:
                f = (lambda data: lambda children: Tree(data, children))(name)
            for wrapper in chain:
                if wrapper[0] == "expand1":
                    f = _expand_single_child(f)
                elif wrapper[0] == "filter":
                    f = _child_filter(wrapper[1], f)
                else:
                    return None
            out.append(f)
        return out
    except (KeyError, TypeError, ValueError, IndexError):
        return None


def driver(data: dict, rule_callbacks: list[Callable]) -> Callable[[str, str], Any] | None:
    """``parse(text, start)``: what lark's ``parse(text, start=start)`` returns for a text without
    syntax errors, :data:`FAILED` otherwise; ``None`` when ``data`` is malformed.
    ``rule_callbacks``: :func:`callbacks`'s list (one per rule of ``data``).

    The data is read as the generator left it (``scangen.scanner``, :func:`pack`): the table is one
    column of 16-bit codes per symbol (``symbols``), indexed by state as it is — the next state
    (≥ 0) for a shift or a goto, ``-1 - rule`` (``~rule``) for a reduction, :data:`NO_ACTION` for
    none, :data:`ACCEPT` at the end of the input — and only the rules are joined to their callbacks
    here (one pass over the rules, none over the table).  The table has no reduction by a rule whose
    callback gives back its one child (``tables.fold_units``: the precedence ladder ``term`` → ``sum``
    → ``product`` → ``unary`` → ``power``, most reductions of a program, costs no step here).
    The end of the input is read as one more look-ahead, ``$END`` (:data:`_END_OF_INPUT`): its
    reductions are made by the same loop as a token's, until its column says :data:`ACCEPT`."""
    try:
        lexer = data["scanner"]
        findall = glued(lexer).findall
        literals, first = lexer["literals"], lexer["first"]
        starts = data["start_states"]
        rules, symbols = data["rules"], data["symbols"]
        table = memoryview(data["actions"]).cast("h")
        n_rules, n_states = len(rules), len(table) // len(symbols)
        if len(rule_callbacks) != n_rules or len(table) != n_states * len(symbols):
            return None
        # a symbol's column: its code by state
        columns = {symbol: table[i * n_states:(i + 1) * n_states] for i, symbol in enumerate(symbols)}
        # per rule: its length, its callback, its nonterminal's goto by state
        reductions = [(len(expansion), callback, columns[origin])
                      for (origin, expansion, _, _), callback in zip(rules, rule_callbacks)]
        # (the table's codes are not checked one by one here — a pass over them cost more than the
        # rest of the start-up: the table is the package's own generated module, which ``tables
        # --check`` and the tests check, or the one packed from lark's parser in this process; a
        # code naming a rule or a state that is not there makes the parse FAILED: lark parses)
        if "$END" not in columns or not all(type(s) is int and 0 <= s < n_states for s in starts.values()):
            return None
    except (KeyError, TypeError, ValueError, IndexError, AttributeError, re.error):
        return None

    def parse(text: str, start: str) -> Any:
        try:
            return run(text, start)
        except (IndexError, KeyError):  # a table that names a rule or a state not there: lark parses
            return FAILED

    def run(text: str, start: str) -> Any:
        accept = ACCEPT
        end = len(text)
        state = starts[start]
        state_stack, value_stack = [state], []
        push_state, push_value = state_stack.append, value_stack.append
        pos, line, line_start, begin = 0, 1, 0, 0
        while True:  # the text in pieces of about CHUNK characters cut after a line break
            if end - begin <= CHUNK:
                stop = end
            else:
                stop = text.find("\n", begin + CHUNK) + 1 or end
            # (the pieces ``findall`` cuts tile the text: ignored run, token or bad character)
            pieces = findall(text, begin, stop)
            if stop == end:
                pieces.append(_END_OF_INPUT)
            for ignored, value, bad in pieces:
                if ignored:  # its lines counted as lark's lexer counts them
                    if "\n" in ignored:
                        line += ignored.count("\n")
                        line_start = pos + ignored.rindex("\n") + 1
                    pos += len(ignored)
                if value:
                    kind = literals.get(value) or first[value[0]]
                    # the token (TOKEN's fields; no line break inside: checked by tables.driver_data)
                    after = pos + len(value)
                    token = (kind, value, line, pos - line_start + 1, line, after - line_start + 1, pos, after)
                    pos = after
                elif bad:  # a character no terminal matches
                    return FAILED
                elif ignored is None:  # the end of the input: $END, a look-ahead like a token's
                    kind = token = "$END"
                else:
                    continue  # (the end of a piece)
                column = columns[kind]
                code = column[state]
                while code < 0:  # the reductions this look-ahead calls for, then its shift
                    if code <= accept:  # no action or, at $END only, accepted (the two codes below every rule's)
                        return value_stack[-1] if code == ACCEPT and kind == "$END" else FAILED
                    size, callback, goto = reductions[~code]
                    if size == 1:  # (a leaf: most reductions of a program; the top replaced)
                        value_stack[-1] = callback([value_stack[-1]])
                        state_stack[-1] = state = goto[state_stack[-2]]
                    else:
                        if size:
                            s = value_stack[-size:]
                            del state_stack[-size:]
                            del value_stack[-size:]
                            push_value(callback(s))
                        else:
                            push_value(callback([]))
                        state = goto[state_stack[-1]]
                        push_state(state)
                    code = column[state]
                push_state(code)  # its shift (of $END: the input ends where the grammar does not)
                push_value(token)
                state = code
            if stop == end:
                return FAILED  # (not accepted: $END was shifted)
            begin = stop

    return parse


__all__ = ["ACCEPT", "CHUNK", "DATA", "FAILED", "TOKEN", "Tree", "callbacks", "driver", "glued", "grammar_text", "load", "pack", "token", "unpack"]
