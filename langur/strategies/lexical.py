"""Lexical variants of a printed program (``programs(wide=True)``, fuzz31): the same module
spelled as a person might write it, which the parser must read to the same surface AST
(LANGUAGE.md §6; the decisions at the head of ``langur/syntax/grammar.lark``):

* comments (``#`` to the end of a line): a line of its own before the first item, after a line's
  last token with or without a space, and blank lines between items;
* CRLF line ends, and a tab instead of the body's two spaces of indentation;
* numbers in another decimal spelling: ``.5`` for ``0.5``, an exponent (``37e-2``, ``2E0``),
  trailing zeros (``0.370``, ``2.0``) — all read exactly as the same fraction;
* the Unicode comparison signs ``≤`` and ``≥`` for ``<=`` and ``>=``;
* extra parentheses: the whole integrand, and each number outside the ``param`` line (``x ^ (2)``,
  ``[(0), 1]``).

:func:`spell` applies a :class:`Spelling` to text :func:`~.programs.render` printed; it only ever
rewrites tokens the printer writes, so it needs no parser (a test parses every variant back).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from fractions import Fraction

from hypothesis import strategies as st

#: A number token as the printer writes it, not part of a name, a loop's ``1..3`` or a component.
_NUMBER = re.compile(r"(?<![\w.])(\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)(?![\w.])")
#: Comments a person might write (not ``# noqa``, nothing the fuzz harness's bundles mean:
#: :mod:`langur.fuzz.bundle`); one with an unbalanced bracket, one with non-ASCII text.
COMMENTS = ("# a comment", "#no space after the hash", "# brackets ( [ that never close", "# θ ≤ 1, Fig. 1")


@dataclass(frozen=True)
class Spelling:
    """How :func:`spell` writes a program: ``numbers`` 0 as printed, 1 without a leading ``0``, 2
    with an exponent, 3 with a trailing zero, 4 each number in turn one of those; ``comments`` 0
    none, 1 a line before and one at the end of the ``int`` line, 2 also one after every line and
    blank lines; ``unicode``: ``≤``/``≥``; ``parens``: 1 the integrand in parentheses, 2 also
    every number outside the ``param`` line; ``crlf``; ``tab``: the integrand indented by a tab."""

    numbers: int = 0
    comments: int = 0
    unicode: bool = False
    parens: int = 0
    crlf: bool = False
    tab: bool = False


def spellings():
    """A strategy of :class:`Spelling` (shrinks to the printer's own spelling)."""
    return st.builds(Spelling, st.integers(0, 4), st.integers(0, 2), st.booleans(), st.integers(0, 2),
                     st.booleans(), st.booleans())


def respell(token: str, form: int) -> str:
    """``token`` (a number as printed) in spelling ``form`` (:attr:`Spelling.numbers`, 1–3), the
    same fraction."""
    whole, _, frac = token.partition(".")
    if "e" in token.lower():
        return token
    if form == 1:
        return token[1:] if whole == "0" and frac else token
    if form == 2:
        digits = (whole + frac).lstrip("0") or "0"
        return f"{digits}{'e' if len(frac) % 2 else 'E'}-{len(frac)}" if frac else f"{digits}e0"
    if form == 3:
        return f"{token}0" if frac else f"{token}.0"
    return token


def _numbers(line: str, s: Spelling, count: list[int]) -> str:
    def one(m: re.Match) -> str:
        token = m.group(1)
        form = s.numbers if s.numbers < 4 else 1 + count[0] % 3
        count[0] += 1
        out = respell(token, form)
        assert Fraction(out) == Fraction(token), (token, out)
        return f"({out})" if s.parens == 2 and not line.startswith("param") else out
    return _NUMBER.sub(one, line)


def spell(text: str, s: Spelling) -> str:
    """``text`` (a module :func:`~.programs.render` printed: items, then ``int …``, the integrand
    indented by two spaces, ``d(…)``) written as ``s`` says."""
    count = [0]
    lines = text.splitlines()
    out: list[str] = [COMMENTS[0]] if s.comments else []
    for i, line in enumerate(lines):
        if s.numbers or s.parens == 2:
            line = _numbers(line, s, count)
        if s.unicode:
            line = line.replace(" <= ", " ≤ ").replace(" >= ", " ≥ ")
        if line.startswith("  ") and i > 0 and lines[i - 1].startswith("int"):  # the integrand
            body = line[2:]
            line = ("\t" if s.tab else "  ") + (f"({body})" if s.parens else body)
        if s.comments == 2 or (s.comments and line.startswith("int")):
            line += ("  " if i % 2 else "") + COMMENTS[1 + i % 3]
        out.append(line)
        if s.comments == 2 and not line.startswith(("int", " ", "\t")):
            out.append("")
    return ("\r\n" if s.crlf else "\n").join(out) + ("\r\n" if s.crlf else "\n")
