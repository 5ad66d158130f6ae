"""Fuzzing the parser: whatever the input, it parses or raises LangurError with an E1xx code at a
position inside the input, never anything else (CLI.md: "a traceback is a bug").

(a) random text and bytes, (b) grammar-generated text (grammar_strategies) and its mutations,
(c) mutations of the shipped examples (delete / insert / duplicate / swap a token).  Whatever
parses is also printed and parsed again, which must give the same AST.
"""

from grammar_strategies import NAMES, module_texts, tokenize
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from paths import DEGENERATE, EXAMPLES

from langur.diagnostics import LangurError
from langur.syntax.parser import parse_bytes, parse_module, parse_term
from langur.syntax.printer import print_module_surface

FUZZ = settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.too_slow])
GRAMMAR_FUZZ = settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])

EXAMPLE_TEXTS = [p.read_text() for p in sorted(EXAMPLES.glob("*.lgr")) + sorted(DEGENERATE.glob("*.lgr"))]
EXAMPLE_TOKENS = [tokenize(t) for t in EXAMPLE_TEXTS]
VOCABULARY = sorted(
    {tok for toks in EXAMPLE_TOKENS for tok in toks}
    | set(
        [
            "param",
            "diffeo",
            "inverse",
            "def",
            "from",
            "import",
            "as",
            "int",
            "d",
            "let",
            "in",
            "ifge0",
            "if",
            "then",
            "else",
            "var",
        ]
    )
    | set(NAMES)
    | {
        "(",
        ")",
        "[",
        "]",
        ",",
        ";",
        ":",
        "=",
        "+",
        "-",
        "*",
        "/",
        "^",
        "<=",
        ">=",
        "<",
        ">",
        "≤",
        "0.5",
        "1e-3",
    }
)


def check(text_or_bytes, path="fuzz.lgr"):
    """Parse; on failure every diagnostic is a located E1xx inside the input."""
    text = None if isinstance(text_or_bytes, bytes) else text_or_bytes
    try:
        if text is None:
            m = parse_bytes(text_or_bytes, path)
        else:
            m = parse_module(text, path)
    except LangurError as e:
        assert e.diagnostics
        for d in e.diagnostics:
            assert d.code.startswith("E1") and len(d.code) == 4, d.format()
            assert d.severity == "error"
            assert d.span is not None and d.span.path == path
            assert d.span.line >= 1 and d.span.col >= 1
            if text is not None:
                lines = text.split("\n")
                assert d.span.line <= len(lines), d.format()
                assert d.span.col <= len(lines[d.span.line - 1]) + 2, d.format()
            assert "Traceback" not in d.message
        return None
    # whatever parses prints back to the same AST
    assert parse_module(print_module_surface(m), path) == m
    return m


# (a) random input --------------------------------------------------------------------------------


@FUZZ
@given(st.text())
def test_random_text(text):
    check(text)


@FUZZ
@given(st.binary())
def test_random_bytes(data):
    check(data)


@FUZZ
@given(st.lists(st.sampled_from(VOCABULARY), max_size=40))
def test_random_token_soup(tokens):
    check(" ".join(tokens))


@FUZZ
@given(st.text(alphabet="()[]+-*/^<>=,;:#.0123456789xyd \n\té\x00", max_size=60))
def test_random_punctuation(text):
    check(text)
    try:
        parse_term(text)
    except LangurError as e:
        assert all(d.code.startswith("E1") for d in e.diagnostics)


# (b) grammar-generated input and its mutations ------------------------------------------------------


@st.composite
def mutated(draw, tokens):
    tokens = list(tokens)
    for _ in range(draw(st.integers(1, 3))):
        op = draw(st.sampled_from(["delete", "insert", "duplicate", "swap"]))
        if not tokens:
            op = "insert"
        i = draw(st.integers(0, max(len(tokens) - 1, 0)))
        if op == "delete":
            del tokens[i]
        elif op == "insert":
            tokens.insert(i, draw(st.sampled_from(VOCABULARY)))
        elif op == "duplicate":
            tokens.insert(i, tokens[i])
        else:
            j = draw(st.integers(0, len(tokens) - 1))
            tokens[i], tokens[j] = tokens[j], tokens[i]
    return " ".join(tokens)


@GRAMMAR_FUZZ
@given(module_texts())
def test_grammar_generated_text_parses(pair):
    m, text = pair
    assert check(text, "<string>") == m


@GRAMMAR_FUZZ
@given(module_texts().flatmap(lambda pair: mutated(tokenize(pair[1]))))
def test_mutated_grammar_text(text):
    check(text)


# (c) mutations of the examples ---------------------------------------------------------------------


@FUZZ
@given(st.sampled_from(EXAMPLE_TOKENS).flatmap(mutated))
def test_mutated_examples(text):
    check(text)


@FUZZ
@given(st.sampled_from(EXAMPLE_TEXTS), st.data())
def test_mutated_example_bytes(text, data):
    raw = bytearray(text.encode())
    i = data.draw(st.integers(0, max(len(raw) - 1, 0)))
    raw[i : i + 1] = bytes([data.draw(st.integers(0, 255))])
    check(bytes(raw))
