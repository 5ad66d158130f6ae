"""The parser's lean driver of lark's tables (``langur/syntax/lalr.py``, issue 15) parses as lark does.

The driver runs the data shipped in ``grammar.driver.json`` (generated from lark's parser, read
without lark: branch lark19).  Every ``.lgr`` file of the repository, the hostile corpus of
``test_hostile.py``, grammar-generated modules and terms, and token-level mutations of the examples
(most of them syntax errors) are parsed with the driver and with lark alone (``parser.FAST`` off): the same surface tree *with the same spans* (equality of surface nodes
ignores spans, so they are compared field by field here), or the same diagnostics.  A counter of
the driver's successes checks that the comparison is not vacuous.
"""

from __future__ import annotations

import dataclasses
import random

import pytest
from grammar_strategies import module_texts, term_texts, tokenize
from hypothesis import HealthCheck, given, settings
from paths import REPO

from langur.diagnostics import LangurError, Span
from langur.syntax import lalr, parser

FILES = sorted(p for p in REPO.rglob("*.lgr") if ".venv" not in p.parts)


def _tree(x):
    """``x`` as nested tuples, spans and every field included."""
    if isinstance(x, Span):
        return ("Span", x.path, x.line, x.col, x.end_line, x.end_col)
    if dataclasses.is_dataclass(x) and not isinstance(x, type):
        return (type(x).__name__,) + tuple((f.name, _tree(getattr(x, f.name))) for f in dataclasses.fields(x))
    if isinstance(x, (tuple, list)):
        return (type(x).__name__,) + tuple(_tree(v) for v in x)
    return (type(x).__name__, x)


def _both(parse, text: str):
    out = []
    for fast in (True, False):
        parser.FAST = fast
        try:
            out.append(("ok", _tree(parse(text, "f.lgr"))))
        except LangurError as e:
            out.append(("error", [d.format() for d in e.diagnostics]))
        finally:
            parser.FAST = True
    return out


def _counting(monkeypatch) -> list:
    """A list that grows by one each time the driver parses an input itself."""
    seen: list = []
    assert lalr.load() is not None  # the shipped data is current: it is what is driven
    with parser._LOCK:
        parser._parser()
    driver = parser._DRIVER
    assert driver  # the shipped tables are driven

    def counted(text, start):
        result = driver(text, start)
        if result is not lalr.FAILED:
            seen.append(start)
        return result

    monkeypatch.setattr(parser, "_DRIVER", counted)
    return seen


def test_every_file_of_the_repository(monkeypatch):
    seen = _counting(monkeypatch)
    assert len(FILES) > 30
    for path in FILES:
        fast, slow = _both(parser.parse_module, path.read_text(encoding="utf-8"))
        assert fast == slow, path
    assert len(seen) >= len(FILES) - 5  # (a few files are syntax errors on purpose)


def test_the_hostile_corpus(monkeypatch):
    from test_hostile import CORPUS

    seen = _counting(monkeypatch)
    compared = 0
    for name, content in CORPUS.items():
        for text in content.values() if isinstance(content, dict) else [content]:
            parse = parser.parse_bytes if isinstance(text, bytes) else parser.parse_module
            fast, slow = _both(parse, text)
            assert fast == slow, name
            compared += 1
    assert compared >= len(CORPUS) and len(seen) >= len(CORPUS) // 2


def test_mutated_examples_give_the_same_diagnostics(monkeypatch):
    seen = _counting(monkeypatch)
    r = random.Random(7)
    texts = [p.read_text(encoding="utf-8") for p in FILES]
    errors = 0
    for _ in range(300):
        tokens = tokenize(r.choice(texts))
        if len(tokens) < 2:
            continue
        i, k = r.randrange(len(tokens)), r.randrange(4)
        if k == 0:
            del tokens[i]
        elif k == 1:
            tokens.insert(i, r.choice(tokens))
        elif k == 2:
            j = r.randrange(len(tokens))
            tokens[i], tokens[j] = tokens[j], tokens[i]
        else:
            tokens[i] = r.choice(["@", "1e99999", "((", "\n", "# c\n", "é", "d", "sum", "]"])
        text = " ".join(tokens)
        fast, slow = _both(parser.parse_module, text)
        assert fast == slow, text
        errors += fast[0] == "error"
    assert errors >= 100 and len(seen) >= 15  # both paths taken


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(module_texts())
def test_generated_modules(pair):
    _, text = pair
    fast, slow = _both(parser.parse_module, text)
    assert fast == slow


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(term_texts())
def test_generated_terms(pair):
    _, text = pair
    fast, slow = _both(parser.parse_term, text)
    assert fast == slow


@pytest.mark.parametrize("text", ["", "# only a comment\n", "\n\n  \t\n", "param a = 1\r\nint ([0, 1]) x d(x)\r\n",
                                  "int ([0, 1]) x d(x) # trailing", "param a = 1e400\n",
                                  "int ([0, 1]) " + "(" * 300 + "x" + ")" * 300 + " d(x)\n"])
def test_edge_texts(text):
    fast, slow = _both(parser.parse_module, text)
    assert fast == slow
