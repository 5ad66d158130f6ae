"""lark, imported without the third-party ``regex`` module (issue 15, start-up).

At import, ``lark`` tries ``import regex`` (needed only for ``Lark(regex=True)`` and for
terminals with Unicode categories ``\\p{…}``; Langur's grammar has neither: ``parser.py`` and
``tables.py`` build with Python's ``re``).  Where ``regex`` is installed that import alone costs
~15–20 ms of every process that parses a program.  So ``regex`` is hidden while lark is imported
(lark then records that it is absent) and visible again right after, for anyone else who imports it.
``proofs_tests/test_records.py`` checks that the grammar's terminals need no ``regex``.

It is also the one module that reads lark's private attributes, each through a public function of
its own (:func:`scanner_patterns`, :func:`rule_wrappers`, :func:`from_data`): lark (1.x) has no
public way to ask them, and the generator of the parser's tables (:mod:`langur.syntax.tables`)
needs them.  If a lark release renames one, the function raises ``AttributeError``, which the
generator and the loader of the shipped tables already take as "not a parser Langur can use"
(the driver's data is then not made; the parser is built from the grammar).
"""

from __future__ import annotations

import sys

_hidden = "regex" not in sys.modules
if _hidden:
    sys.modules["regex"] = None  # type: ignore[assignment]  (an import of it raises ImportError)
try:
    from lark import Lark, Token
    from lark.exceptions import UnexpectedCharacters, UnexpectedInput, UnexpectedToken
    from lark.grammar import Rule
    from lark.lexer import TerminalDef
    from lark.parse_tree_builder import ChildFilterLALR_NoPlaceholders, ExpandSingleChild
finally:
    if _hidden and sys.modules.get("regex", 0) is None:
        del sys.modules["regex"]



def scanner_patterns(scanner) -> list:
    """The compiled patterns a lark ``Scanner`` matches with (lark's ``Scanner._mres``): one, unless
    the terminals passed ``re``'s group limit and lark split them."""
    return scanner._mres


def rule_wrappers(lark: Lark) -> list:
    """Each rule of the parser ``lark`` with the wrappers lark puts around its callback, in lark's order
    (lark's ``Lark._parse_tree_builder.rule_builders``: ``(rule, [wrapper, …])``)."""
    return lark._parse_tree_builder.rule_builders


def from_data(data: dict, memo: dict, transformer) -> Lark:
    """The parser lark's ``Lark.save`` would have written as ``{"data": data, "memo": memo}``, with the
    inline ``transformer`` (lark's ``Lark._load_from_dict``: ``Lark.load`` reads only a pickle,
    which Langur never unpickles, SECURITY.md)."""
    return Lark._load_from_dict(data, memo, transformer=transformer)


__all__ = ["ChildFilterLALR_NoPlaceholders", "ExpandSingleChild", "Lark", "Rule", "TerminalDef", "Token",
           "UnexpectedCharacters", "UnexpectedInput", "UnexpectedToken", "from_data", "rule_wrappers",
           "scanner_patterns"]
