"""A lean driver of lark's LALR(1) tables for the parser's successful path (issue 15, loading).

lark's ``Lark.parse`` runs the lexer as a generator of tokens, feeds each through its parser state
object (looking the reduction's callback up by its ``Rule``, whose hash and equality are Python
methods) and counts lines token by token: about two thirds of parsing a small program, the
callbacks that build the surface tree (``parser._Builder``) the last third.  :func:`driver` reads
the *same* objects out of the parser lark built from the shipped tables — the lexer's compiled
terminal patterns, its keyword callback, the ignored and newline-bearing terminals, the LALR
action table and the callbacks — and runs them in one loop: the same tokens (``lark.Token``, with
the same positions), the same shifts and reductions, the same callbacks called in the same order,
so the same result or the same exception from a callback (E105, E106).

Only success is handled here: at a character no terminal matches or a token the table has no
action for, :func:`driver`'s function returns :data:`FAILED` and the caller parses again with lark,
which raises the error the diagnostics are made from (the callbacks keep no state between calls
but the path, so running them again is harmless).  ``proofs_tests/test_lalr.py`` compares both on
every example file, the hostile corpus and random programs.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from typing import Any

from .larkload import Lark, Token

#: What the driver returns when lark must parse instead (an input with a syntax error).
FAILED = object()


def driver(lark: Lark, identities: tuple = ()) -> Callable[[str, str], Any] | None:
    """``parse(text, start)``: ``lark.parse(text, start=start)`` for a text without syntax errors,
    :data:`FAILED` otherwise; ``None`` when ``lark`` is not built as Langur's parser is (LALR, basic
    lexer, one compiled pattern, no post-lexer, only a keyword callback on terminals).

    ``identities``: callbacks that return their one argument's only element (``lambda c: c[0]``);
    a one-symbol rule reduced with one of them only changes state (its value stays on the stack,
    where the callback would have put it back): a unit rule of the precedence ladder (``term`` →
    ``sum`` → ``product`` → ``unary`` → ``power``) is most reductions of a program."""
    try:
        front = lark.parser
        lexer, parser = front.lexer, front.parser.parser
        scanner = lexer.scanner  # (builds the lexer's callbacks too)
        if (front.lexer_conf.postlex is not None or len(scanner._mres) != 1
                or any(type(cb).__name__ != "UnlessCallback" for cb in lexer.callback.values())):
            return None
        pattern = scanner._mres[0]
        # one match per token: any run of ignored text (white space, comments) as lark's lexer would
        # cut it — atomic, never backtracked into (a comment is never cut short for a name in it) —
        # then the same pattern, or nothing at the end of the text
        skip = "|".join(f"(?:{t.pattern.to_regexp()})" for t in lexer.terminals if t.name in lexer.ignore_types)
        glued = re.compile(f"(?>(?:{skip})*)(?:{pattern.pattern})?" if skip else f"(?:{pattern.pattern})?",
                           pattern.flags)
        keywords = {name: cb.scanner._mres for name, cb in lexer.callback.items()}
        table = parser.parse_table
        callbacks = parser.callbacks
        starts, ends = dict(table.start_states), dict(table.end_states)
        ignored, newlines = frozenset(lexer.ignore_types), frozenset(lexer.newline_types)
        states = table.states  # state → terminal or nonterminal → (Shift, state) or (Reduce, Rule)
        shift = next(a for row in states.values() for a, _ in row.values() if a.name == "Shift")
    except (AttributeError, KeyError, TypeError, StopIteration, re.error):
        return None
    token_callbacks = {k: v for k, v in callbacks.items() if isinstance(k, str)}
    # lark's table resolved once into what the loop reads (the same shifts, reductions and gotos):
    # per state (a list index), a terminal or nonterminal's action — the next state (an int) for a
    # shift, or (the rule's length, its callback, the goto of its nonterminal by state) for a
    # reduction, the length -1 for a unit rule whose callback returns its child
    try:
        gotos: dict[str, dict[int, int]] = {}  # by symbol (read for nonterminals only)
        for state, row in states.items():
            for symbol, (action, arg) in row.items():
                if action is shift:
                    gotos.setdefault(symbol, {})[state] = arg
        act: list[dict | None] = [None] * (max(states) + 1)
        rules: dict[int, tuple] = {}
        for state, row in states.items():
            out = act[state] = {}
            for symbol, (action, arg) in row.items():
                if action is shift:
                    out[symbol] = arg
                    continue
                found = rules.get(id(arg))
                if found is None:
                    size, callback = len(arg.expansion), callbacks[arg]
                    if size == 1 and any(callback == f for f in identities):
                        size = -1  # (below: a change of state only)
                    found = rules[id(arg)] = (size, callback, gotos.get(arg.origin.name, {}))
                out[symbol] = found
    except (AttributeError, KeyError, TypeError, ValueError):
        return None
    #: the state a run of unit reductions ends in, by (state below, state, lookahead symbol)
    units: dict[tuple, int] = {}

    new = str.__new__

    def parse(text: str, start: str) -> Any:
        match, end = glued.match, len(text)
        state_stack, value_stack = [starts[start]], []
        end_state = ends[start]
        pos, line, line_start = 0, 1, 0
        token = None
        while True:
            if pos < end:
                m = match(text, pos)  # (never None: it may match ignored text alone, or nothing)
                kind = m.lastgroup
                if kind is None:  # no terminal after the ignored text: the end, or a character none matches
                    if m.end() != end:
                        return FAILED
                    pos = end  # ($END takes the last token's position, as in lark)
                    continue
                value = m.group(kind)
                begin = m.start(kind)
                if begin != pos:  # ignored text first: its lines counted as lark's lexer counts them
                    k = text.count("\n", pos, begin)
                    if k:
                        line += k
                        line_start = text.rindex("\n", pos, begin) + 1
                    pos = begin
                column = pos - line_start + 1
                nxt = pos + len(value)
                if kind in newlines:
                    k = value.count("\n")
                    if k:
                        line0 = line
                        line += k
                        line_start = pos + value.rindex("\n") + 1
                        if kind in ignored:
                            pos = nxt
                            continue
                    elif kind in ignored:
                        pos = nxt
                        continue
                    else:
                        line0 = line
                elif kind in ignored:
                    pos = nxt
                    continue
                else:
                    line0 = line
                # Token(kind, value, pos, line0, column) with its end, without Token.__new__'s
                # two Python calls (the same slots set to the same values)
                token = new(Token, value)
                token.type, token.start_pos, token.value, token.line, token.column = kind, pos, value, line0, column
                token.end_line, token.end_column, token.end_pos = line, nxt - line_start + 1, nxt
                pos = nxt
                if kind in keywords:  # a name that is a keyword: its own terminal (lark's UnlessCallback)
                    for mre in keywords[kind]:
                        k = mre.fullmatch(value)
                        if k is not None:
                            token.type = k.lastgroup
                            break
                is_end = False
            else:
                token = (Token.new_borrow_pos("$END", "", token) if token  # (as lark: a str's truth)
                         else Token("$END", "", 0, 1, 1))
                is_end = True
            kind = token.type
            while True:
                code = act[state_stack[-1]].get(kind)
                if code is None:
                    return FAILED
                if type(code) is int:  # a shift
                    if is_end:
                        return FAILED
                    state_stack.append(code)
                    value_stack.append(token if kind not in token_callbacks else token_callbacks[kind](token))
                    break
                size, callback, goto = code
                if size < 0 and is_end:  # (at the end, one at a time: the end state is checked after each)
                    state_stack[-1] = goto[state_stack[-2]]
                elif size < 0:  # unit rules whose callbacks return their child: the value stays, the
                    # state after the whole run of them found once per (state below, state, symbol)
                    below = state_stack[-2]
                    key = (below, state_stack[-1], kind)
                    top = units.get(key)
                    if top is None:
                        top = goto[below]
                        while True:
                            nxt = act[top].get(kind)
                            if type(nxt) is not tuple or nxt[0] >= 0:
                                break
                            top = nxt[2][below]
                        units[key] = top
                    state_stack[-1] = top
                else:
                    if size:
                        s = value_stack[-size:]
                        del state_stack[-size:]
                        del value_stack[-size:]
                    else:
                        s = []
                    value_stack.append(callback(s))
                    state_stack.append(goto[state_stack[-1]])
                if is_end and state_stack[-1] == end_state:
                    return value_stack[-1]

    return parse


__all__ = ["FAILED", "driver"]
