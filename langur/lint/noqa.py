"""``# noqa`` suppression for ``langur check`` (CLI.md, Diagnostics).

A comment on the line of a finding's primary position silences it:

* ``# noqa`` (bare, or ``# noqa:`` with no codes) silences every transversality finding there;
* ``# noqa: X301`` or ``# noqa: X301,X304`` (spaces allowed, case-insensitive ``noqa``) silences
  exactly those codes; any other code on the line is still reported.

The directive is found in the line's comment (everything from the first ``#``, which starts a
comment in `.lgr`, LANGUAGE.md §6), anywhere in it: ``# explanation  # noqa: X301`` works.
Front-end errors (``E1xx``/``T2xx``) cannot be silenced: they are not findings about a program
but the absence of one.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from ..diagnostics import Diagnostic, source_lines

_NOQA = re.compile(
    r"#\s*noqa(?P<colon>\s*:\s*(?P<codes>[A-Za-z]+[0-9]+(?:\s*[,\s]\s*[A-Za-z]+[0-9]+)*)?)?", re.IGNORECASE
)


def directive(line: str) -> frozenset[str] | None:
    """The codes a line's ``# noqa`` silences: ``None`` (no directive), an empty set (all codes)
    or the set of codes."""
    hash_at = line.find("#")
    if hash_at < 0:
        return None
    m = _NOQA.search(line, hash_at)
    if m is None:
        return None
    codes = m.group("codes")
    if not codes:
        return frozenset()
    return frozenset(c.upper() for c in re.split(r"[,\s]+", codes.strip()) if c)


def suppressed(d: Diagnostic, sources: Mapping[str, str]) -> bool:
    """Is ``d`` silenced by a ``# noqa`` on the line of its primary span?"""
    if d.span is None or d.code[:1] in ("E", "T"):
        return False
    text = sources.get(d.span.path)
    if text is None:
        return False
    lines = source_lines(text)
    if not 1 <= d.span.line <= len(lines):
        return False
    codes = directive(lines[d.span.line - 1])
    if codes is None:
        return False
    return not codes or d.code.upper() in codes
