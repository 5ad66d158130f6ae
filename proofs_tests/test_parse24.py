"""The driver's lexer by one ``findall`` and tokens named by their text (issue 15, branch parse24).

``langur/syntax/lalr.py`` cuts the text with one pattern of three groups (ignored run, token, a
character no terminal matches) and names each token by its text: a dict of the literal texts
(string terminals, alternations of literals such as ``<=|≤``, the keywords of ``NAME``) and, for
the other terminals, a dict of first characters read off their regular expressions by the
generator (:func:`scangen.first_chars`, a superset of what each can start with; the sets must be
disjoint).  Checked here against independent references: the regular expression engine itself
(what a pattern matches starts with a character of its set; a finite pattern matches exactly its
texts), lark's parser (trees with every span and diagnostics, on texts with random ignored runs,
stray characters and texts longer than the lexer's piece), and the generator's refusals.
"""

from __future__ import annotations

import random
import re

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from paths import REPO
from test_lalr import _tree  # (surface trees as nested tuples, spans included)

from langur.diagnostics import LangurError
from langur.syntax import lalr, parser, scangen

FILES = sorted(p for p in REPO.rglob("*.lgr") if ".venv" not in p.parts)
NAME = "[A-Za-z_][A-Za-z0-9_]*"
NUMBER = r"(?:[0-9]+(?:\.(?!\.)[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"


def _outcome(text: str, fast: bool):
    parser.FAST = fast
    try:
        return ("ok", _tree(parser.parse_module(text, "p.lgr")))
    except LangurError as e:
        return ("error", [d.format() for d in e.diagnostics])
    finally:
        parser.FAST = True


def _driven(monkeypatch) -> list:
    """A list that grows by one each time the driver parses an input itself (not lark)."""
    with parser._LOCK:
        parser._parser()
    driver = parser._DRIVER
    assert driver
    seen: list = []

    def counted(text, start):
        result = driver(text, start)
        if result is not lalr.FAILED:
            seen.append(len(text))
        return result

    monkeypatch.setattr(parser, "_DRIVER", counted)
    return seen


# -- the generator's reading of the terminals' expressions ------------------------------------------


def test_first_characters_of_the_grammar_s_expressions():
    assert scangen.first_chars(NAME) == set("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz_")
    assert scangen.first_chars(NUMBER) == set("0123456789.")
    assert scangen.first_chars("(?:>=|≥)") == {">", "≥"}
    assert scangen.first_chars("a?b*c") == {"a", "b", "c"}
    assert scangen.first_chars("(?!x)[xy]z") == {"x", "y"}  # (a look-ahead only narrows: a superset)
    assert scangen.first_chars(r"\t\.") == {"\t"}
    assert scangen.first_chars("#[^\n]*") == {"#"}
    for beyond in (".", r"\d+", "[^a]", "(a)", "(?P<x>a)", "a|", "x*", "(?:a)?", r"\1", "a{0,2}"):
        assert scangen.first_chars(beyond) is None, beyond  # (beyond the reading, or matches "")


def test_finite_patterns_are_their_texts():
    assert scangen.finite("(?:<=|≤)") == {"<=", "≤"}
    assert scangen.finite(r"\.\.") == {".."}
    assert scangen.finite("a(?:b|cd)") == {"ab", "acd"}
    for infinite in (NAME, NUMBER, "a?", "a+", "[ab]", "(?=a)a"):
        assert scangen.finite(infinite) is None, infinite


_PATTERNS = [NAME, NUMBER, "(?:>=|≥)", "(?:<=|≤)", r"\.\.", "a(?:b|cd)", "x?[0-3]+y*", "(?:ab|b)+c?"]


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(_PATTERNS), st.text(alphabet="abcdxy0123.<=>≤≥_eE+-Z \n", min_size=1, max_size=12))
def test_what_a_pattern_matches_starts_with_one_of_its_first_characters(pattern, text):
    m = re.match(pattern, text)
    if m is not None and m.end() > 0:
        assert text[0] in scangen.first_chars(pattern)
    texts = scangen.finite(pattern)
    if texts is not None:  # a finite pattern matches exactly its texts
        assert (re.fullmatch(pattern, text) is not None) == (text in texts)


def _lexer(terminals, keywords=None) -> dict:
    return {"flags": 32, "terminals": terminals, "ignore": ["WS"], "ignored_patterns": ["[ ]+"],
            "keywords": keywords or {}}


def test_the_scanner_refuses_what_it_cannot_name_by_the_text():
    fine = scangen.scanner(_lexer([["NAME", NAME, None], ["PLUS", r"\+", "+"], ["WS", "[ ]+", None]],
                               {"NAME": [["if", "IF"]]}))
    assert fine is not None and fine["literals"] == {"+": "PLUS", "if": "IF"} and fine["first"]["q"] == "NAME"
    assert re.findall(fine["pattern"], "a +if ?") == [("", "a", ""), (" ", "+", ""), ("", "if", ""), (" ", "", "?"),
                                                     ("", "", "")]
    refused = [
        [["A", "[a-c]+", None], ["B", "[c-e]+", None]],  # two expressions that may start alike
        [["A", ".+", None]],  # beyond the reading
        [["NAME", NAME, None], ["KW", "for", "for"]],  # a literal that NAME cuts first (not its keyword)
        [["LT", "<", "<"], ["LE", "<=", "<="]],  # "<=" never cut as one token: LT comes first
    ]
    for terminals in refused:
        assert scangen.scanner(_lexer(terminals)) is None, terminals
    assert scangen.scanner({**_lexer([["NAME", NAME, None]]), "flags": re.IGNORECASE}) is None
    # a keyword whose first character NAME cannot start with
    assert scangen.scanner(_lexer([["NAME", NAME, None]], {"NAME": [["1f", "IF"]]})) is None


@settings(max_examples=300, deadline=None)
@given(st.text(alphabet=" \t\f\r\n#ab1(", max_size=30), st.integers(0, 30))
def test_the_ignored_run_is_cut_as_lark_cuts_it(text, at):
    """The scanner's run of ignored text (white space as one class repeated, then comments each
    followed by white space) ends where lark's alternation of the ignored terminals ends."""
    data = lalr.load()
    assert data is not None
    at = min(at, len(text))
    lark_s = re.compile("(?>(?:" + "|".join(f"(?:{r})" for r in data["lexer"]["ignored_patterns"]) + ")*)")
    ours = re.compile(data["scanner"]["pattern"], data["scanner"]["flags"])
    assert ours.match(text, at).end(1) == lark_s.match(text, at).end()


def test_the_shipped_scanner_is_read_off_the_grammar():
    data = lalr.load()
    assert data is not None
    sc = data["scanner"]
    assert sc == scangen.scanner(data["lexer"])
    assert set(sc["first"].values()) == {"NAME", "NUMBER"}
    assert {sc["literals"][t] for t in ("<=", "≤", ">=", "≥", "..", "d", "sum", "(")} == \
        {"LE", "GE", "DOTDOT", "D", "SUM", "LPAR"}


# -- the driver against lark ------------------------------------------------------------------------

_RUNS = ["", " ", "\t", "\n", "\r\n", "\f", "  # c d(x) sum\n", "#\n\n", "\n\t ", "# ≤ é\r\n"]
_PIECES = re.compile(r"\s+|#[^\n]*")
_TEXTS = [p.read_text(encoding="utf-8") for p in FILES]


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.randoms(use_true_random=False))
def test_trees_and_spans_are_larks_with_random_ignored_runs_and_stray_characters(rng):
    words = [w for w in _PIECES.split(rng.choice(_TEXTS)) if w]
    if words and rng.random() < 0.3:  # a stray character, or one the lexer names differently
        words.insert(rng.randrange(len(words) + 1), rng.choice(["@", "$", "\x0b", "é", "≤", "..", ".", "1.", ".5e3"]))
    text = "".join(w + rng.choice(_RUNS) for w in words)
    assert _outcome(text, True) == _outcome(text, False)


def test_the_text_in_pieces_is_the_text_whole(monkeypatch):
    """The lexer cuts a text longer than :data:`lalr.CHUNK` in pieces after line breaks: with pieces
    of a few characters the trees, spans and diagnostics are those of the whole text in one piece."""
    seen = _driven(monkeypatch)
    texts = [t for t in _TEXTS if t.count("\n") > 3][:12]
    texts.append("param a = 1\n# c\n\n\nint ([0, 1])\n x\n +\n a\n d(x)\n\n# end")
    texts.append("int ([0, 1]) x +\n\n @ d(x)\n")
    whole = [_outcome(t, True) for t in texts]
    for chunk in (1, 3, 17):
        monkeypatch.setattr(lalr, "CHUNK", chunk)
        assert [_outcome(t, True) for t in texts] == whole, chunk
    assert len(seen) >= 3 * len(texts) - 6


def test_a_text_longer_than_a_piece_is_parsed_as_lark_parses_it(monkeypatch):
    seen = _driven(monkeypatch)
    body = "".join(f"[x >= {i / 1000}] * (x - {i}) + # {i}\n" for i in range(2400))
    text = f"param a = 1\nint ([0, 1]) {body} x d(x)\n"
    assert len(text) > lalr.CHUNK + 1000
    ours = _outcome(text, True)
    assert ours[0] == "ok" and seen == [len(text)]
    assert ours == _outcome(text, False)
    bad = text[: lalr.CHUNK + 500] + "@" + text[lalr.CHUNK + 500:]
    assert _outcome(bad, True) == _outcome(bad, False)
    assert _outcome(bad, True)[1][0].split(" error ")[1].startswith("E104")


@pytest.mark.parametrize("text", ["@", "int ([0, 1]) x d(x) @", "\x0bint", "param a = 1\n  $", "int ([0,1]) x ≤≥ d(x)",
                                  "int ([0, 1]) 1..2 d(x)", "int ([0, 1]) x # é\r\n\f d(x)\f"])
def test_edges_are_larks(text):
    assert _outcome(text, True) == _outcome(text, False)


def test_a_token_s_positions_from_its_offset():
    """Every token the driver hands a callback has the line and columns of its offset in the text,
    computed here from scratch (the line breaks before it counted)."""
    data = lalr.load()
    tokens: list = []
    callbacks = []
    for f in lalr.callbacks(data, parser._BUILDER):
        def recording(c, f=f):
            tokens.extend(dict(zip(lalr.TOKEN, x)) for x in c  # (a token: a tuple of TOKEN's fields, parse25)
                          if type(x) is tuple and len(x) == len(lalr.TOKEN) and type(x[0]) is str)
            return f(c)
        callbacks.append(recording)
    drive = lalr.driver(data, callbacks)
    rng = random.Random(24)
    for text in _TEXTS:
        words = [w for w in _PIECES.split(text) if w]
        text = "".join(w + rng.choice(_RUNS) for w in words)
        tokens.clear()
        parser._BUILDER.path = "p.lgr"
        try:
            drive(text, "start")
        except LangurError:
            pass
        for t in tokens:
            assert text[t["start_pos"]:t["end_pos"]] == t["value"] and "\n" not in t["value"]
            line = text.count("\n", 0, t["start_pos"]) + 1
            column = t["start_pos"] - (text.rfind("\n", 0, t["start_pos"]) + 1) + 1
            assert (t["line"], t["column"], t["end_line"], t["end_column"]) == (line, column, line,
                                                                                column + len(t["value"]))
