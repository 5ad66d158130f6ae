"""The parser's LALR tables, shipped with the package as JSON data (never a pickle).

lark's ``cache=True`` keeps its tables as a pickle at a predictable name in the system temp folder
and unpickles it at every start: anyone who can write there runs code as the next user of Langur
(SECURITY.md).  Instead the tables are generated from ``grammar.lark`` once, when the grammar
changes, and shipped as ``grammar.tables.json`` beside it.  JSON holds only data: loading it can
build a parser or fail, never run code.  The file records the SHA-256 of the grammar it was made
from; a file that does not match the grammar, or does not decode, is ignored and the parser is
built from the grammar (slower start-up, same parser).

Regenerate after editing the grammar::

    python -m langur.syntax.tables          # writes grammar.tables.json
    python -m langur.syntax.tables --check  # exit 1 if the shipped tables do not match the grammar
"""

from __future__ import annotations

import hashlib
import json
import sys
from pathlib import Path
from typing import Any

from .larkload import Lark, Rule, TerminalDef

GRAMMAR = Path(__file__).with_name("grammar.lark")
TABLES = Path(__file__).with_name("grammar.tables.json")
FORMAT = 1
MAX_TABLES_BYTES = 4_000_000  # the shipped file is ~100 kB; anything far larger is not ours

# The options every Langur parser is built with (the transformer is attached at load time).
OPTIONS: dict[str, Any] = dict(
    parser="lalr",
    lexer="basic",
    start=["start", "term"],
    keep_all_tokens=True,
    maybe_placeholders=False,
)


def grammar_text() -> str:
    return GRAMMAR.read_text(encoding="utf-8")


def digest(text: str) -> str:
    return hashlib.sha256(text.encode("utf-8")).hexdigest()


# lark's serialized form is nested dicts, lists, tuples, strings, numbers and booleans; dicts may
# have integer keys (parse states).  JSON keeps all of that if tuples and non-string-keyed dicts are
# tagged.
def _encode(x: Any) -> Any:
    if isinstance(x, dict):
        if all(isinstance(k, str) for k in x) and "__t" not in x:
            return {k: _encode(v) for k, v in x.items()}
        return {"__t": "dict", "items": [[_encode(k), _encode(v)] for k, v in x.items()]}
    if isinstance(x, tuple):
        return {"__t": "tuple", "items": [_encode(v) for v in x]}
    if isinstance(x, list):
        return [_encode(v) for v in x]
    if x is None or isinstance(x, (str, int, float, bool)):
        return x
    raise TypeError(f"not plain data: {type(x).__name__}")


def _decode(x: Any) -> Any:
    if isinstance(x, dict):
        tag = x.get("__t")
        if tag == "dict":
            return {_decode(k): _decode(v) for k, v in x["items"]}
        if tag == "tuple":
            return tuple(_decode(v) for v in x["items"])
        return {k: _decode(v) for k, v in x.items()}
    if isinstance(x, list):
        return [_decode(v) for v in x]
    return x


def _tagged(x: dict) -> Any:
    """:func:`_decode` of one JSON object whose members are decoded already (``json``'s
    ``object_hook``: the whole file decoded in C but for the objects, at start-up)."""
    tag = x.get("__t")
    if tag == "dict":
        return {k: v for k, v in x["items"]}
    if tag == "tuple":
        return tuple(x["items"])
    return x


def build(text: str | None = None, **kwargs: Any) -> Lark:
    """The parser built from the grammar, without any cache."""
    return Lark(grammar_text() if text is None else text, cache=False, **OPTIONS, **kwargs)


def generate(text: str | None = None) -> dict[str, Any]:
    text = grammar_text() if text is None else text
    data, memo = build(text).memo_serialize([TerminalDef, Rule])
    return {"format": FORMAT, "grammar_sha256": digest(text), "data": _encode(data), "memo": _encode(memo)}


def load(transformer: Any, path: Path = TABLES) -> Lark | None:
    """The parser from the shipped tables, or ``None`` when they are missing, too large, malformed
    or made from another grammar (the caller then builds it from the grammar)."""
    try:
        if path.stat().st_size > MAX_TABLES_BYTES:
            return None
        doc = json.loads(path.read_text(encoding="utf-8"), object_hook=_tagged)
        if doc.get("format") != FORMAT or doc.get("grammar_sha256") != digest(grammar_text()):
            return None
        return Lark._load_from_dict(doc["data"], doc["memo"], transformer=transformer)
    except Exception:  # noqa: BLE001 - any defect in the data file: fall back to the grammar
        return None


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--check"]:
        try:
            doc = json.loads(TABLES.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            print(f"{TABLES}: missing or unreadable; run python -m langur.syntax.tables", file=sys.stderr)
            return 1
        if doc.get("grammar_sha256") != digest(grammar_text()):
            print(f"{TABLES}: made from another grammar; run python -m langur.syntax.tables", file=sys.stderr)
            return 1
        return 0
    if argv:
        print("usage: python -m langur.syntax.tables [--check]", file=sys.stderr)
        return 2
    TABLES.write_text(json.dumps(generate(), separators=(",", ":"), sort_keys=True) + "\n", encoding="utf-8")
    print(f"wrote {TABLES}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
