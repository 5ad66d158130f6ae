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
import re
from dataclasses import dataclass, replace
from pathlib import Path
from urllib.parse import quote

from ..diagnostics import Diagnostic, Span, span_json

#: The transversality codes (docs/CODES.md has the long form).
X_CODES: dict[str, tuple[str, str, str]] = {
    "X301": (
        "coincident-zero-sets",
        "error",
        "Two multiplying conditions (or one multiplied by itself through a power or primitive) have the "
        "same zero set for every parameter value: the derivative counts the jump twice (Def. 7.2).",
    ),
    "X302": (
        "tangent-zero-sets",
        "warning",
        "Two multiplying zero sets are tangent at a point (normals linearly dependent): Def. 7.2 fails "
        "on a null set; Theorem 8.1 no longer applies, the derivative is still likely right.",
    ),
    "X303": (
        "too-many-zero-sets-through-a-point",
        "warning",
        "More than n multiplying zero sets pass through one point of R^n: Def. 7.2 fails on a null set.",
    ),
    "X304": (
        "degenerate-for-some-parameters",
        "warning",
        "Multiplying zero sets coincide for some parameter values (the set is printed).",
    ),
    "X305": (
        "degenerate-at-given-parameters",
        "error",
        "At the parameter values given with --at the zero sets coincide or a condition is not a "
        "diffeomorphism: the derivative is not defined there.",
    ),
    "X306": (
        "not-a-diffeomorphism-for-some-parameters",
        "warning",
        "A parameter coefficient of a condition vanishes for some parameter values: there the condition "
        "is not a diffeomorphism.",
    ),
    "X307": (
        "primitive-outside-domain",
        "warning",
        "A primitive (log, sqrt, division, tan, ...) is applied outside its domain on the domain of "
        "integration at the parameter values in force.",
    ),
    "X308": (
        "redundant-static-coincidence",
        "warning",
        "Multiplying conditions with the same zero set that does not move with the parameters: the "
        "deltas have zero weight, the derivative is unaffected (the product is redundant).",
    ),
    "X311": (
        "not-integrable",
        "error",
        "The integrand is not integrable on the domain at the parameter values in force (a pole whose "
        "order reaches the codimension of the set it sits on): the integral does not exist.",
    ),
    "X312": (
        "integrability-undecided",
        "warning",
        "The integrand blows up on the domain and the analysis cannot decide whether it is integrable "
        "there; the engines' answers rely on their own diagnostics.",
    ),
    "X313": (
        "derivative-not-integrable",
        "error",
        "The derivative denotation in a parameter is not an integral (its regular part is not integrable, "
        "or a delta term's weight is infinite or undefined on its zero set), although the value exists.",
    ),
    "X314": (
        "empty-domain",
        "warning",
        "An interval of the domain is empty at the parameter values in force (lower end above upper end): "
        "the integrand is 0 there, so the value is 0, not minus the integral as in calculus.",
    ),
    "X399": (
        "time-limit",
        "error",
        "The check of this file did not finish within its time budget (--timeout, default 60 s): what "
        "was not reported is unchecked.",
    ),
    "X310": (
        "undecided",
        "warning",
        "The checker could not decide transversality here (a sympy computation timed out or failed).",
    ),
}


def _front_end_codes() -> dict[str, str]:
    out: dict[str, str] = {}
    try:
        from ..syntax import parser

        for m in re.finditer(r"^(E1\d\d)\s+(.+)$", parser.__doc__ or "", re.MULTILINE):
            out[m.group(1)] = m.group(2).strip()
    except ImportError:  # pragma: no cover
        pass
    try:
        from .. import typesys

        out.update(getattr(typesys, "CODES", {}))
    except ImportError:  # pragma: no cover
        pass
    return out


def known_codes() -> frozenset[str]:
    """Every diagnostic code there is (docs/CODES.md): E1xx, T2xx and X3xx."""
    return frozenset(X_CODES) | frozenset(_front_end_codes())


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
    front = _front_end_codes()
    codes = sorted({r.diagnostic.code for r in reports})
    rules = []
    index = {}
    for code in codes:
        index[code] = len(rules)
        if code in X_CODES:
            name, level, text = X_CODES[code]
            rules.append(
                {
                    "id": code,
                    "name": name,
                    "shortDescription": {"text": text},
                    "defaultConfiguration": {"level": level},
                }
            )
        else:
            rules.append(
                {
                    "id": code,
                    "shortDescription": {"text": front.get(code, code)},
                    "defaultConfiguration": {"level": "error"},
                }
            )
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
