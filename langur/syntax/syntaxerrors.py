"""Syntax errors in words (LANGUAGE.md §6; codes E102–E104, E107 of :mod:`langur.codes`): lark's
exception for the first token or character that cannot follow, made a located diagnostic that says
what was found and what was expected ("unexpected 'in'; expected a name ('in' is a reserved word,
never a name)").  Every terminal of ``grammar.lark`` is named so that it can be described here.

lark is imported only for a syntax error to report (``langur.lazy``, issue 15: parsing a valid
program never imports it).
"""

from __future__ import annotations

from .. import lazy
from ..diagnostics import LangurError, Span, error

#: lark's exceptions (:mod:`langur.syntax.larkload`), imported with the first syntax error to report.
larkload = lazy.module("langur.syntax.larkload")

#: Reserved words (``d`` is only a keyword right after the integrand: see grammar.lark).
KEYWORDS: frozenset[str] = frozenset(
    "param diffeo inverse def from import as int d let in ifge0 if then else var not sum prod".split()  # noqa: SIM905
)

_TERM_START = ("NAME", "NUMBER", "LPAR", "LSQB", "MINUS")
_OPERATORS = ("PLUS", "MINUS", "STAR", "SLASH", "CARET")
_CMPS = ("LE", "GE", "LT", "GT")
_PUNCT = {
    "LPAR": "(", "RPAR": ")", "LSQB": "[", "RSQB": "]", "COMMA": ",", "SEMI": ";", "COLON": ":",
    "DOT": ".", "DOTDOT": "..",
    "EQUAL": "=", "PLUS": "+", "MINUS": "-", "STAR": "*", "SLASH": "/", "CARET": "^",
    "LE": "<=", "GE": ">=", "LT": "<", "GT": ">",
}  # fmt: skip
_ORDER = [
    "TERM", "NAME", "NUMBER", "OPERATOR", "CMP", *_PUNCT, "PARAM", "DIFFEO", "DEF", "FROM", "INT",
    "D", "LET", "IN", "IFGE0", "IF", "THEN", "ELSE", "INVERSE", "IMPORT", "AS", "VAR", "SUM", "PROD",
    "$END",
]  # fmt: skip


def _describe_expected(expected: set[str]) -> str:
    exp = set(expected)
    words: dict[str, str] = {}
    if all(t in exp for t in _TERM_START):
        words["TERM"] = "a term" if "LET" in exp else "an operand"
        exp -= {*_TERM_START, "D", "LET", "IF", "IFGE0", "INT", "SUM", "PROD"}
    elif "NAME" in exp:
        exp.discard("D")
        words["NAME"] = "a name"
    if sum(t in exp for t in _OPERATORS) >= 3:
        exp -= set(_OPERATORS)
        words["OPERATOR"] = "an operator"
    if all(t in exp for t in _CMPS):
        exp -= set(_CMPS)
        words["CMP"] = "a comparison (<=, >=, <, >)"
    for t in exp:
        if t in words:
            continue
        if t == "$END":
            words[t] = "end of input"
        elif t == "NUMBER":
            words[t] = "a number"
        elif t == "D":
            words[t] = "'d' (closing the program: d(variables))"
        elif t in _PUNCT:
            words[t] = f"'{_PUNCT[t]}'"
        else:
            words[t] = f"'{t.lower()}'"
    keys = sorted(words, key=lambda k: (_ORDER.index(k) if k in _ORDER else len(_ORDER), k))
    parts = [words[k] for k in keys]
    if not parts:
        return "nothing here"
    if len(parts) == 1:
        return parts[0]
    return ", ".join(parts[:-1]) + " or " + parts[-1]


def _describe_found(tok) -> str:  # (lark's token: the error is lark's)
    if tok.type == "$END":
        return "end of input"
    if tok.type == "NAME":
        return f"name '{tok}'"
    if tok.type == "NUMBER":
        text = str(tok)
        return f"number '{text if len(text) <= 20 else text[:17] + '...'}'"
    return f"'{tok}'"


def convert(exc, path: str) -> LangurError:
    """The diagnostic of lark's syntax error ``exc`` (a ``lark.exceptions.UnexpectedInput``)."""
    UnexpectedToken, UnexpectedCharacters = larkload.UnexpectedToken, larkload.UnexpectedCharacters
    if isinstance(exc, UnexpectedToken):
        tok = exc.token
        expected = set(exc.accepts or exc.expected or ())
        if tok.type == "$END":
            sp = Span(path, tok.end_line or 1, tok.end_column or 1, tok.end_line or 1, tok.end_column or 1)
            return error(sp, "E103", f"unexpected end of input; expected {_describe_expected(expected)}")
        sp = Span(path, tok.line, tok.column, tok.end_line, tok.end_column)
        if expected == {"$END"}:
            return error(
                sp,
                "E107",
                f"unexpected {_describe_found(tok)} after the program: a file holds its items, "
                "then at most one program, and nothing after it",
            )
        hint = ""
        if tok.type == "SEMI":
            hint = " (NAME(variables; params) applies a declared diffeo only as the condition of ifge0)"
        elif tok.type in ("LET", "IF", "IFGE0", "SUM", "PROD") and "NAME" in expected and "NUMBER" in expected:
            hint = f" ('{tok}' must be in parentheses inside arithmetic)"
        elif tok.type == "NUMBER" and str(tok).startswith(".") and "DOT" in expected:
            hint = " (a vector's components are .x, .y, .z, .w)"
        elif str(tok) in KEYWORDS and "NAME" in expected:
            hint = f" ('{tok}' is a reserved word, never a name)"
        return error(
            sp, "E102", f"unexpected {_describe_found(tok)}; expected {_describe_expected(expected)}{hint}"
        )
    if isinstance(exc, UnexpectedCharacters):
        ch = exc.char
        shown = repr(ch)[1:-1] if not ch.isprintable() else ch
        sp = Span(path, exc.line, exc.column, exc.line, exc.column + 1)
        return error(sp, "E104", f"unexpected character '{shown}' (U+{ord(ch):04X})")
    line = getattr(exc, "line", 1) or 1
    col = getattr(exc, "column", 1) or 1
    return error(Span(path, line, col, line, col + 1), "E102", "syntax error")



__all__ = ["KEYWORDS", "convert"]
