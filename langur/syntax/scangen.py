"""The driver's lexer as data, made by the generator (``python -m langur.syntax.tables``, issue 15,
branch parse24): the pattern that cuts a text into ignored runs and tokens, and the two dicts that
name a token by its text, read off lark's terminals (``tables.driver_data``'s ``lexer``).

Only the generator and the tests import this module: a process that parses reads its results from
the generated ``grammar_driver.py`` (``lalr.load``), and ``lalr.driver`` runs them.  The reading of
regular expressions here (:func:`first_chars`, :func:`finite`) is the generator's: it covers the
forms lark writes for Langur's terminals and refuses anything else (the driver then does not run,
lark parses), so that a token's terminal is what lark's own lexer gives it.
"""

from __future__ import annotations

import re


def scanner(lexer: dict) -> dict | None:
    """What the driver's lexer runs, made from the lexer's data (``tables.driver_data``'s
    ``lexer``) once, by the generator (parse24: the whole text cut by one ``findall``, each token's
    terminal told from its text by two dicts, no match object per token):

    * ``pattern``: per token three groups — any run of ignored text (white space, comments) as
      lark's lexer would cut it (atomic, never backtracked into: a comment is never cut short for a
      name in it); the token, by the scanner's alternatives in its order (no group per terminal:
      the text names it, below); or one character no terminal matches (the input is not valid) —
      at the end of the text, nothing (``\\Z``).  After the ignored run no ignored terminal can match,
      so they are left out of the alternatives.
    * ``literals``: a token's text → its terminal, for the terminals whose texts are a fixed set
      (lark's string terminals, a regular expression that is an alternation of literals such as
      ``LE``'s ``<=|≤``) and the keywords lark's ``UnlessCallback`` tells from a ``NAME`` (a full
      match of the keywords' literals: the first literal equal to the text).  A text is one
      terminal's only: two terminals with one text make the data ``None``.
    * ``first``: for the other terminals (``NAME``, ``NUMBER``), a token's first character → its
      terminal, from a superset of the characters each can start with (:func:`first_chars`); the
      sets must be disjoint (else ``None``): a token whose text is no literal came from the one
      terminal that can start with its first character.

    ``None`` when a terminal's expression is beyond :func:`first_chars`' reading, or flags other
    than ``re.UNICODE`` are set: the driver then does not run (lark parses)."""
    ignored = frozenset(lexer["ignore"])
    flags = int(lexer["flags"])
    if flags & ~re.UNICODE:
        return None
    skip = f"(?:{'|'.join(f'(?:{regexp})' for regexp in lexer['ignored_patterns'])})*"
    runs = [r for r in lexer["ignored_patterns"] if r.endswith("+") and _one_class(r[:-1])]
    others = [r for r in lexer["ignored_patterns"] if r not in runs[:1]]
    if runs and all(first_chars(r) is not None and not _alternatives(r) for r in others):
        # ``(?:C+|O|…)*`` as ``C*(?:(?:O|…)C*)*`` (C a character class, each O never empty): the same
        # texts, the same greedy extent, and the common run of white space one quick repeat of a class;
        # that ``(?:X)*`` written ``(?:X(?:X)*|)`` (the same matches in the same order of preference: the
        # engine then tries a comment's first character without entering a repeat, parse25)
        c = runs[0][:-1]
        o = f"(?:{'|'.join(others)}){c}*"
        skip = f"{c}*(?:{o}(?:{o})*|)" if others else f"{c}*"
    parts: list[str] = []
    literals: dict[str, str] = {}
    first: dict[str, str] = {}

    def literal(text: str, name: str) -> bool:
        return literals.setdefault(text, name) == name

    run: list[str] = []  # consecutive one-character literals: one character class (at most one of them
    # matches anywhere, whatever their order: one failed alternative instead of one per terminal)

    def close() -> None:
        parts.append(f"[{''.join(re.escape(c) for c in run)}]" if len(run) > 1 else f"(?:{re.escape(run[0])})")
        run.clear()

    for name, regexp, value in lexer["terminals"]:  # (lark's scanner's order)
        if name in ignored:
            continue
        if value is not None and len(value) == 1:
            run.append(value)
        else:
            if run:
                close()
            parts.append(f"(?:{regexp})" if _alternatives(regexp) else regexp)
        texts = {value} if value is not None else finite(regexp)
        if texts is not None:
            if not all(literal(text, name) for text in texts):
                return None
            continue
        chars = first_chars(regexp)
        if chars is None or any(first.setdefault(c, name) != name for c in chars):
            return None
    if run:
        close()
    for name, words in lexer["keywords"].items():
        for text, terminal in words:
            if first.get(text[:1]) != name or (text in literals and literals[text] != terminal):
                return None
            literals.setdefault(text, terminal)
    # each literal text alone is cut and named so by the scanner's alternatives in their order (its
    # first alternative that matches there matches all of it: the literal's terminal, or the one
    # whose keyword it is)
    keyword_of = {text: name for name, words in lexer["keywords"].items() for text, _ in words}
    order = [(name, re.compile(regexp, flags)) for name, regexp, _ in lexer["terminals"] if name not in ignored]
    for text, terminal in literals.items():
        found = next(((name, m.end()) for name, r in order if (m := r.match(text))), None)
        if found != (keyword_of.get(text, terminal), len(text)):
            return None
    token = "|".join(parts)
    # (the end of the text an alternative of its own, not ``(…)?``: the same matches, and the regular
    # expression engine makes no repeat of the group per token — parse25: ≈ −17 % of ``findall``)
    pattern = f"((?>{skip}))(?:({token})|([\\s\\S])|\\Z)"
    return {"pattern": pattern, "flags": flags, "literals": literals, "first": first}


# The regular expressions of terminals as far as the scanner reads them (:func:`first_chars`,
# :func:`finite`): characters, escaped punctuation and control characters, character classes (a
# negated one only after the first character), groups ``(?:…)``, look-aheads ``(?=…)``/``(?!…)``
# (read as matching nothing: they only narrow), alternation and the quantifiers ``* + ? {m,n}``
# (lazy or not).  Anything else
# (``.``, ``\\d``, a back-reference, a capturing or named group) is beyond it: ``None``.
_ESCAPES = {"t": "\t", "n": "\n", "r": "\r", "f": "\f", "v": "\v", "a": "\a"}


class _Beyond(Exception):
    """A regular expression beyond what the scanner reads."""


def _read(regexp: str) -> list:
    """The alternation ``regexp`` as ``[sequence, …]``, each ``[(atom, at_least, at_most), …]``, an
    atom ``("chars", set)``, ``("other", set)`` (a negated class), ``("group", alternation)`` or
    ``("look",)``."""
    pos = 0

    def char() -> str:
        nonlocal pos
        c = regexp[pos]
        pos += 1
        if c != "\\":
            return c
        e = regexp[pos]
        pos += 1
        if e in _ESCAPES:
            return _ESCAPES[e]
        if e.isalnum():
            raise _Beyond(regexp)
        return e

    def klass() -> tuple:
        nonlocal pos
        negated = regexp[pos] == "^"
        pos += negated
        out: set = set()
        while regexp[pos] != "]" or not out:
            lo = char()
            if regexp[pos] == "-" and regexp[pos + 1] != "]":
                pos += 1
                hi = char()
                if ord(hi) - ord(lo) > 1024:
                    raise _Beyond(regexp)
                out.update(map(chr, range(ord(lo), ord(hi) + 1)))
            else:
                out.add(lo)
        pos += 1
        return ("other", out) if negated else ("chars", out)

    def alternation() -> list:
        nonlocal pos
        seqs = [sequence()]
        while pos < len(regexp) and regexp[pos] == "|":
            pos += 1
            seqs.append(sequence())
        return seqs

    def sequence() -> list:
        nonlocal pos
        items: list = []
        while pos < len(regexp) and regexp[pos] not in "|)":
            c = regexp[pos]
            if c == "(":
                head = regexp[pos:pos + 3]
                if head not in ("(?:", "(?=", "(?!"):
                    raise _Beyond(regexp)
                pos += 3
                inner = alternation()
                if regexp[pos] != ")":
                    raise _Beyond(regexp)
                pos += 1
                atom = ("group", inner) if head == "(?:" else ("look",)
            elif c == "[":
                pos += 1
                atom = klass()
            elif c in ".^$*+?{":
                raise _Beyond(regexp)
            else:
                atom = ("chars", {char()})
            low, high = 1, 1
            if pos < len(regexp) and regexp[pos] in "*+?{":
                q = regexp[pos]
                pos += 1
                if q == "{":
                    close = regexp.index("}", pos)
                    lo_hi = regexp[pos:close].split(",")
                    pos = close + 1
                    low = int(lo_hi[0] or 0)
                    high = int(lo_hi[-1]) if lo_hi[-1] else None
                else:
                    low, high = (0, None) if q == "*" else (1, None) if q == "+" else (0, 1)
                if pos < len(regexp) and regexp[pos] == "?":
                    pos += 1
            items.append((atom, low, high))
        return items

    try:
        out = alternation()
    except (IndexError, ValueError) as e:
        raise _Beyond(regexp) from e
    if pos != len(regexp):
        raise _Beyond(regexp)
    return out


def _first(seqs: list) -> tuple[set, bool]:
    """A superset of the first characters of what ``seqs`` matches, and whether it matches ``""``."""
    chars: set = set()
    empty = False
    for seq in seqs:
        for atom, low, _ in seq:
            if atom[0] == "look":
                continue
            if atom[0] == "other":  # (a negated class: its characters are not listed)
                raise _Beyond("a negated class first")
            c, e = (atom[1], False) if atom[0] == "chars" else _first(atom[1])
            chars |= c
            if not e and low > 0:
                break
        else:
            empty = True
    return chars, empty


def _alternatives(regexp: str) -> bool:
    """``regexp`` has an alternation at its top (or is beyond the reading): it needs a group of its
    own beside other expressions."""
    try:
        return len(_read(regexp)) > 1
    except _Beyond:
        return True


def _one_class(regexp: str) -> bool:
    """``regexp`` is one character class (or one character), matched once."""
    try:
        seqs = _read(regexp)
    except _Beyond:
        return False
    return len(seqs) == 1 and len(seqs[0]) == 1 and seqs[0][0][0][0] == "chars" and seqs[0][0][1:] == (1, 1)


def first_chars(regexp: str) -> set | None:
    """A superset of the characters a non-empty match of ``regexp`` starts with, or ``None`` (an
    expression beyond the scanner's reading, or one that matches the empty text)."""
    try:
        chars, empty = _first(_read(regexp))
    except _Beyond:
        return None
    return None if empty else chars


def finite(regexp: str) -> set | None:
    """The texts ``regexp`` matches when it is an alternation of literals (``<=|≤``), else ``None``."""
    def texts(seqs: list) -> set | None:
        out: set = set()
        for seq in seqs:
            words = {""}
            for atom, low, high in seq:
                if low != 1 or high != 1 or atom[0] in ("look", "other"):
                    return None
                if atom[0] == "chars":
                    if len(atom[1]) != 1:
                        return None
                    inner = set(atom[1])
                else:
                    inner = texts(atom[1])
                    if inner is None:
                        return None
                words = {w + x for w in words for x in inner}
            out |= words
        return out

    try:
        return texts(_read(regexp))
    except _Beyond:
        return None
