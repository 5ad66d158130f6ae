"""lark, imported without the third-party ``regex`` module (issue 15, start-up).

At import, ``lark`` tries ``import regex`` (needed only for ``Lark(regex=True)`` and for
terminals with Unicode categories ``\\p{…}``; Langur's grammar has neither: ``parser.py`` and
``tables.py`` build with Python's ``re``).  Where ``regex`` is installed that import alone costs
~15–20 ms of every process that parses a program.  So ``regex`` is hidden while lark is imported
(lark then records that it is absent) and visible again right after, for anyone else who imports it.
``proofs_tests/test_records.py`` checks that the grammar's terminals need no ``regex``.
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

__all__ = ["ChildFilterLALR_NoPlaceholders", "ExpandSingleChild", "Lark", "Rule", "TerminalDef", "Token", "UnexpectedCharacters", "UnexpectedInput", "UnexpectedToken"]
