"""Output formats of ``langur check`` (CLI.md, Diagnostics).

* ``text``: ``PATH:LINE:COL: SEVERITY CODE message``, one per line (compilers' and linters' form);
* ``json``: ``{"diagnostics": [{"path", "line", "col", "end_line", "end_col", "severity", "code",
  "message", "related": [...], "prove"?}]}``;
* ``sarif``: a SARIF 2.1.0 log (OASIS standard) with one run, the rules reported, results with
  their primary and related locations;
* ``github``: GitHub Actions workflow commands ``::error file=…,line=…,col=…,endLine=…,
  endColumn=…,title=CODE::message`` (``::warning`` for warnings).

Each entry is a :class:`Report`: a diagnostic plus, with ``--prove``, the Theorem 8.1 check.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, replace
from pathlib import Path
from urllib.parse import quote

from ..codes import CODES
from ..diagnostics import Diagnostic, Span, span_json

#: The transversality codes (docs/CODES.md has the long form).


def known_codes() -> frozenset[str]:
    """Every diagnostic code there is (``langur.codes``; docs/CODES.md): E1xx, T2xx and X3xx."""
    return frozenset(CODES)


@dataclass
class Report:
    diagnostic: Diagnostic
    prove: dict | None = None

    @property
    def message(self) -> str:
        msg = self.diagnostic.message
        if self.prove and self.prove.get("summary"):
            msg += f" [--prove: {self.prove['summary']}]"
        return msg


def _place(s: Span | None):
    """A span as a place in a file: its path resolved (``a.lgr`` and ``./a.lgr`` are one file)."""
    if s is None:
        return None
    path = os.path.realpath(s.path) if os.path.isfile(s.path) else s.path
    return (path, s.line, s.col, s.end_line, s.end_col)


def _finding(d: Diagnostic) -> tuple:
    """What makes two diagnostics one finding: the same code and message at the same places."""
    return (_place(d.span), d.severity, d.code, d.message, tuple(_place(s) for s in d.related))


def distinct(reports: list[Report]) -> list[Report]:
    """Each finding of one run once (CLI.md, Diagnostics), in the order first reported.  A finding
    inside an imported module is reported at the module's place by the check of every FILE that
    imports it, and by the module's own check when it is a FILE too (``langur check examples``:
    shader.lgr's X306 twice).  With ``--prove``, the Theorem 8.1 checks of one finding made in
    different programs (each at its own parameter values) are all kept, and a copy without one
    (the module checked as a library) is dropped when another copy has one."""
    groups: dict[tuple, list[Report]] = {}
    for r in reports:
        groups.setdefault(_finding(r.diagnostic), []).append(r)
    out: list[Report] = []
    for copies in groups.values():
        proved: dict[str, Report] = {}
        for r in copies:
            if r.prove is not None:
                proved.setdefault(json.dumps(r.prove, sort_keys=True, default=str), r)
        out.extend(proved.values() if proved else copies[:1])
    return out


def _shown(r: Report) -> Diagnostic:
    """The diagnostic as reported: its message with the ``--prove`` summary, if any."""
    return replace(r.diagnostic, message=r.message)


def text_lines(reports: list[Report]) -> list[str]:
    return [_shown(r).format() for r in reports]


def json_document(reports: list[Report]) -> dict:
    items = []
    for r in reports:
        item = {**_shown(r).to_json(), "related": [span_json(s) for s in r.diagnostic.related]}
        if r.prove is not None:
            item["prove"] = r.prove
        items.append(item)
    return {"diagnostics": items}


def _uri(path: str) -> str:
    p = Path(path)
    if p.is_absolute():
        return p.as_uri()
    return quote(p.as_posix())


def _region(s: Span) -> dict:
    region = {"startLine": max(1, s.line), "startColumn": max(1, s.col)}
    if s.end_line >= s.line:
        region["endLine"] = max(1, s.end_line)
        end_col = s.end_col if (s.end_line > s.line or s.end_col > s.col) else s.col + 1
        region["endColumn"] = max(1, end_col)
    return region


def _location(s: Span) -> dict:
    return {"physicalLocation": {"artifactLocation": {"uri": _uri(s.path)}, "region": _region(s)}}


def sarif_document(reports: list[Report], version: str = "0") -> dict:
    codes = sorted({r.diagnostic.code for r in reports})
    rules = []
    index = {}
    for code in codes:
        index[code] = len(rules)
        entry = CODES.get(code)
        rule = {"id": code}
        if entry is not None and entry.name:
            rule["name"] = entry.name
        rule["shortDescription"] = {"text": entry.summary if entry is not None else code}
        rule["defaultConfiguration"] = {"level": entry.severity if entry is not None else "error"}
        rules.append(rule)
    results = []
    for r in reports:
        d = r.diagnostic
        res = {
            "ruleId": d.code,
            "ruleIndex": index[d.code],
            "level": "error" if d.severity == "error" else "warning",
            "message": {"text": r.message},
        }
        if d.span is not None:
            res["locations"] = [_location(d.span)]
        related = [s for s in d.related if s is not None]
        if related:
            res["relatedLocations"] = [
                {**_location(s), "id": k, "message": {"text": "the other condition"}}
                for k, s in enumerate(related)
            ]
        if r.prove is not None:
            res["properties"] = {"prove": r.prove}
        results.append(res)
    return {
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [
            {
                "tool": {
                    "driver": {
                        "name": "langur",
                        "version": version,
                        "semanticVersion": version,
                        "rules": rules,
                    }
                },
                "columnKind": "unicodeCodePoints",
                "results": results,
            }
        ],
    }


def _escape_data(s: str) -> str:
    return s.replace("%", "%25").replace("\r", "%0D").replace("\n", "%0A")


def _escape_property(s: str) -> str:
    return _escape_data(s).replace(":", "%3A").replace(",", "%2C")


def github_lines(reports: list[Report]) -> list[str]:
    out = []
    for r in reports:
        d = r.diagnostic
        kind = "error" if d.severity == "error" else "warning"
        props = []
        if d.span is not None:
            s = d.span
            props += [
                f"file={_escape_property(s.path)}",
                f"line={s.line}",
                f"col={s.col}",
                f"endLine={s.end_line}",
                f"endColumn={s.end_col}",
            ]
        props.append(f"title={_escape_property(d.code)}")
        out.append(f"::{kind} {','.join(props)}::{_escape_data(d.code + ' ' + r.message)}")
    return out


def render(reports: list[Report], fmt: str, version: str = "0") -> str:
    """The whole output of ``langur check`` in format ``fmt`` (text, json, sarif, github)."""
    if fmt == "json":
        return json.dumps(json_document(reports), ensure_ascii=False)
    if fmt == "sarif":
        return json.dumps(sarif_document(reports, version), ensure_ascii=False, indent=2)
    if fmt == "github":
        return "\n".join(github_lines(reports))
    return "\n".join(text_lines(reports))
