"""A lean driver of lark's LALR(1) tables for the parser's successful path (issue 15, loading).

lark's ``Lark.parse`` runs the lexer as a generator of tokens, feeds each through its parser state
object (looking the reduction's callback up by its ``Rule``, whose hash and equality are Python
methods) and counts lines token by token: about two thirds of parsing a small program, the
callbacks that build the surface tree (``parser._Builder``) the last third.  :func:`driver` reads
the *same* objects out of the parser lark built from the shipped tables — the lexer's terminals
in its order, its keyword callback's literals, the ignored and newline-bearing terminals, the LALR
action table and the callbacks — and runs them in one loop: the same tokens (``lark.Token``, with
the same positions), the same shifts and reductions, the same callbacks called in the same order,
so the same result or the same exception from a callback (E105, E106).  Two things are done
another way than lark's runtime does them, for speed (front11, issue 15: matching was a fifth of
parsing a small program): the one-character literal terminals are one character class of the
lexer's pattern (at most one of them matches anywhere, so lark's order among them is moot), and a
name is told from a keyword by a dict of the keywords' literals (what lark's ``UnlessCallback``
finds by a full match of their alternation).  ``proofs_tests/test_text_to_number11.py`` compares
every token with lark's.

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

#: The group of the lexer's pattern that holds the one-character literal terminals.
SINGLE = "_1CHAR"


def driver(lark: Lark, identities: tuple = ()) -> Callable[[str, str], Any] | None:
    """``parse(text, start)``: ``lark.parse(text, start=start)`` for a text without syntax errors,
    :data:`FAILED` otherwise; ``None`` when ``lark`` is not built as Langur's parser is (LALR, basic
    lexer, one compiled pattern, no post-lexer, only a keyword callback on terminals).

    ``identities``: callbacks that return their one argument's only element (``lambda c: c[0]``),
    or ``(callback, symbol)``: the callback does so for the rule whose one symbol is ``symbol``;
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
        ignored, newlines = frozenset(lexer.ignore_types), frozenset(lexer.newline_types)
        terminals = list(scanner.terminals)
        if "|".join(f"(?P<{t.name}>{t.pattern.to_regexp()})" for t in terminals) != pattern.pattern \
                or not newlines <= ignored or any(t.name == SINGLE for t in terminals):
            return None  # (not the scanner's pattern, or a token that may hold a line break)
        # one match per token: any run of ignored text (white space, comments) as lark's lexer would
        # cut it — atomic, never backtracked into (a comment is never cut short for a name in it) —
        # then the scanner's alternatives in its order, or nothing at the end of the text.  After
        # that run no ignored terminal can match (the run would have taken it), so they are left
        # out; a run of consecutive one-character literal terminals (``(``, ``+``, …: at most one
        # of them matches, whatever their order) is one character class, its terminal read off the
        # character (one failed alternative instead of one per terminal).
        skip = "|".join(f"(?:{t.pattern.to_regexp()})" for t in lexer.terminals if t.name in ignored)
        parts: list[str] = []
        singles: dict[str, str] = {}
        run: list = []

        def close() -> None:
            if len(run) > 1:
                singles.update((t.pattern.value, t.name) for t in run)
                parts.append(f"(?P<{SINGLE}>[{''.join(re.escape(t.pattern.value) for t in run)}])")
            else:
                parts.extend(f"(?P<{t.name}>{t.pattern.to_regexp()})" for t in run)
            run.clear()

        for t in terminals:
            if t.name in ignored:
                continue
            if t.pattern.type == "str" and len(t.pattern.value) == 1 and not t.pattern.flags:
                run.append(t)
                continue
            close()
            parts.append(f"(?P<{t.name}>{t.pattern.to_regexp()})")
        close()
        alternatives = "|".join(parts)
        glued = re.compile(f"(?>(?:{skip})*)(?:{alternatives})?" if skip else f"(?:{alternatives})?", pattern.flags)
        # a name that is a keyword: its own terminal, as lark's UnlessCallback finds it (a full match
        # of the keywords' literals: the one literal equal to the text)
        keywords: dict[str, dict[str, str]] = {}
        for name, cb in lexer.callback.items():
            words = keywords[name] = {}
            for t in cb.scanner.terminals:
                if t.pattern.type != "str" or t.pattern.flags:
                    return None
                words.setdefault(t.pattern.value, t.name)
        table = parser.parse_table
        callbacks = parser.callbacks
        starts, ends = dict(table.start_states), dict(table.end_states)
        states = table.states  # state → terminal or nonterminal → (Shift, state) or (Reduce, Rule)
        shift = next(a for row in states.values() for a, _ in row.values() if a.name == "Shift")
    except (AttributeError, KeyError, TypeError, StopIteration, re.error):
        return None
    token_callbacks = {k: v for k, v in callbacks.items() if isinstance(k, str)}
    if token_callbacks:
        return None  # (no terminal of Langur's grammar has a callback of its own)
    # lark's table resolved once into what the loop reads (the same shifts, reductions and gotos):
    # per state (a list index), a terminal or nonterminal's action — the next state (an int) for a
    # shift, (the rule's length, its callback, the goto of its nonterminal by state) for a
    # reduction, and for a unit rule whose callback returns its child a dict (filled as met): the
    # state a run of such reductions ends in and the look-ahead's action there, by the state below
    # (the value stays on the stack)
    try:
        gotos: dict[str, dict[int, int]] = {}  # by symbol (read for nonterminals only)
        for state, row in states.items():
            for symbol, (action, arg) in row.items():
                if action is shift:
                    gotos.setdefault(symbol, {})[state] = arg
        act: list[dict | None] = [None] * (max(states) + 1)
        unit_goto: dict[tuple[int, str], dict[int, int]] = {}  # a unit rule's goto, by (state, symbol)
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
                    if size == 1 and any(callback == f or f == (callback, arg.expansion[0].name) for f in identities):
                        size = -1
                    found = rules[id(arg)] = (size, callback, gotos.get(arg.origin.name, {}))
                if found[0] < 0:
                    unit_goto[state, symbol] = found[2]
                    out[symbol] = {}
                else:
                    out[symbol] = found
    except (AttributeError, KeyError, TypeError, ValueError):
        return None

    new = str.__new__
    Tuple, Dict = tuple, dict

    def parse(text: str, start: str) -> Any:
        match, end = glued.match, len(text)
        state_stack, value_stack = [starts[start]], []
        push_state, push_value = state_stack.append, value_stack.append
        pos, line, line_start = 0, 1, 0
        token = None
        while pos < end:
            m = match(text, pos)  # (never None: it may match ignored text alone, or nothing)
            kind = m.lastgroup
            if kind is None:  # no terminal after the ignored text: the end, or a character none matches
                if m.end() != end:
                    return FAILED
                break  # ($END takes the last token's position, as in lark)
            begin, nxt = m.span(kind)
            if begin != pos:  # ignored text first: its lines counted as lark's lexer counts them
                k = text.count("\n", pos, begin)
                if k:
                    line += k
                    line_start = text.rindex("\n", pos, begin) + 1
                pos = begin
            value = text[pos:nxt]
            if kind == SINGLE:
                kind = singles[value]
            elif kind in keywords:  # a name that is a keyword: its own terminal (lark's UnlessCallback)
                kind = keywords[kind].get(value, kind)
            # Token(kind, value, pos, line, column) with its end (no line break inside: checked
            # above), without Token.__new__'s two Python calls (the same slots set to the same values)
            token = new(Token, value)
            token.type, token.start_pos, token.value, token.line = kind, pos, value, line
            token.end_line, token.end_pos = line, nxt
            token.column, token.end_column = pos - line_start + 1, nxt - line_start + 1
            pos = nxt
            code = act[state_stack[-1]].get(kind)
            while True:  # the reductions this token's look-ahead calls for, then its shift
                if type(code) is Tuple:
                    size, callback, goto = code
                    if size:
                        s = value_stack[-size:]
                        del state_stack[-size:]
                        del value_stack[-size:]
                    else:
                        s = []
                    push_value(callback(s))
                    state = goto[state_stack[-1]]
                    push_state(state)
                    code = act[state].get(kind)
                elif type(code) is Dict:  # a run of unit reductions: the state after it and the action
                    # there, by the state below
                    below = state_stack[-2]
                    found = code.get(below)
                    if found is None:
                        top = unit_run(state_stack[-1], below, kind)
                        found = code[below] = (top, act[top].get(kind))
                    state_stack[-1], code = found
                elif code is None:
                    return FAILED
                else:  # a shift
                    push_state(code)
                    push_value(token)
                    break
        # the end of the input: its reductions one at a time, the end state checked after each
        token = (Token.new_borrow_pos("$END", "", token) if token  # (as lark: a str's truth)
                 else Token("$END", "", 0, 1, 1))
        end_state = ends[start]
        while True:
            state = state_stack[-1]
            code = act[state].get("$END")
            if type(code) is Tuple:
                size, callback, goto = code
                if size:
                    s = value_stack[-size:]
                    del state_stack[-size:]
                    del value_stack[-size:]
                else:
                    s = []
                push_value(callback(s))
                push_state(goto[state_stack[-1]])
            elif type(code) is Dict:
                state_stack[-1] = unit_goto[state, "$END"][state_stack[-2]]
            else:  # no action, or a shift of $END
                return FAILED
            if state_stack[-1] == end_state:
                return value_stack[-1]

    def unit_run(state: int, below: int, kind: str) -> int:
        """The state a run of unit reductions from ``state`` (``below`` under it) ends in before
        the look-ahead ``kind``'s next action."""
        top = unit_goto[state, kind][below]
        while type(act[top].get(kind)) is Dict:
            top = unit_goto[top, kind][below]
        return top

    return parse


__all__ = ["FAILED", "driver"]
