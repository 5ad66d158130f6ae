"""X311 "undefined" is the exact engine's definedness check (``langur.symbolic.definedness``), declared once.

``langur check`` used to walk the term and search for a witness with its own copies (in
``langur.lint.singular`` and ``langur.lint.blowup``); now it asks ``langur.denote.undefined_where`` and
blames the application the witness was found for.  The cases below are where the two analyses
disagreed (the old linter was wrong, by LANGUAGE.md §1, §3) or where the blamed span is pinned:

* ``log(a - 1)`` at a = 1/2 is log(−1/2) at every x: undefined on the whole box, so ⟦p⟧ does not
  exist; the old linter skipped a weight constant in x and found nothing.
* ``[x >= 0] * log(max(x, 0))`` on [−1, 1] is 0 · log(0) at every x < 0: undefined (a bracket is a
  factor, not a guard); ``[x >= 0] * (x / max(x, 0))`` is 0 · (x / 0) there.  The old linter's
  grid saw sympy's weight 0 and missed both.
* ``1 / x + log(x - 1/2)`` on [−1, 1]: log is undefined on [−1, 1/2); the old linter blamed
  ``1 / x``, which is defined at its example point x = −1/4.
* ``sqrt(x) * sqrt(x - 1)`` on [−2, 0]: both roots are undefined there; the first in the text is
  blamed (the walk is pre-order, as ``core.subterms``).
"""

from __future__ import annotations

import json
import math

import pytest

from langur.cli import main


def _run(capsys, tmp_path, command: str, body: str, box: str, *extra: str) -> tuple[int, dict, str]:
    f = tmp_path / "p.lgr"
    text = f"param a = 0.5\nint ({box}) {body} d(x)\n"
    f.write_text(text)
    status = main([command, str(f), "--json", *extra])
    return status, json.loads(capsys.readouterr().out), text.splitlines()[1]


@pytest.mark.parametrize("body, box, blamed", [
    ("log(a - 1)", "[0, 1]", "log(a - 1)"),
    ("[x >= 0] * log(max(x, 0))", "[-1, 1]", "log(max(x, 0))"),
    ("[x >= 0] * (x / max(x, 0))", "[-1, 1]", "x / max(x, 0)"),
    ("1 / x + log(x - 0.5)", "[-1, 1]", "log(x - 0.5)"),
    ("sqrt(x) * sqrt(x - 1) + a", "[-2, 0]", "sqrt(x)"),
])
def test_check_blames_the_application_evaluated_outside_its_domain(capsys, tmp_path, body, box, blamed):
    status, j, line = _run(capsys, tmp_path, "check", body, box)
    x311 = [d for d in j["diagnostics"] if d["code"] == "X311"]
    assert status == 1 and len(x311) == 1 and x311[0]["severity"] == "error"
    d = x311[0]
    assert (d["line"], d["col"], d["end_col"]) == (2, line.index(blamed) + 1, line.index(blamed) + len(blamed) + 1)
    assert d["message"].startswith(f"`{blamed}` is undefined on a set of positive measure of the domain (e.g. at x = ")
    # the example point lies where the blamed argument is outside its domain (read off the message)
    x = float(d["message"].split("(e.g. at x = ", 1)[1].split(":", 1)[0])
    lo, hi = (float(v) for v in box.strip("[]").split(","))
    assert lo < x < hi
    argument = {"log(a - 1)": -0.5, "log(max(x, 0))": max(x, 0.0), "x / max(x, 0)": max(x, 0.0),
                "log(x - 0.5)": x - 0.5, "sqrt(x)": x}[blamed]
    assert argument < 0 or (argument == 0 and blamed != "sqrt(x)")  # log(0) and a division by 0: undefined


@pytest.mark.parametrize("body, box", [("log(a - 1)", "[0, 1]"), ("[x >= 0] * log(max(x, 0))", "[-1, 1]")])
def test_the_engines_and_the_linter_agree_that_the_integral_does_not_exist(capsys, tmp_path, body, box):
    status, j, _ = _run(capsys, tmp_path, "eval", body, box)
    assert status == 1 and j["exact"] is None and "X311" in j["undefined"]
    assert math.isnan(float(j["mc"]["value"]))  # the Monte Carlo engine (real arithmetic): NaN


def test_a_conditional_still_guards(capsys, tmp_path):
    # ∫₋₁¹ (if x ≥ 1/2 then log(x − 1/2) else 0) dx = ∫₀^{1/2} log u du = ½ log ½ − ½ (by hand)
    status, j, _ = _run(capsys, tmp_path, "eval", "if x >= a then log(x - a) else 0", "[-1, 1]", "--engine", "exact")
    assert status == 0 and j["undefined"] is None
    assert abs(j["exact"]["value"] - (0.5 * math.log(0.5) - 0.5)) <= 1e-12
    status, j, _ = _run(capsys, tmp_path, "check", "if x >= a then log(x - a) else 0", "[-1, 1]")
    assert not [d for d in j["diagnostics"] if d["code"] == "X311"]
