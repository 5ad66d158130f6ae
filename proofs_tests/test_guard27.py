"""A bracket factor does not keep a primitive from where it is undefined (LANGUAGE.md §1, §3).

⟦t · s⟧ = ⟦t⟧ · ⟦s⟧ evaluates both factors; only ⟦ifge0 t then s else r⟧ leaves the branch not
taken unevaluated.  So ``[x >= 0] * log(x)`` on [−1, 1] is 0 · undefined = undefined at every
x < 0, and its integral does not exist (X311), as the Monte Carlo engine's NaN says; the exact
engine used to read the bracket as a guard (the Def. 6.2 piece ``0 · log(x)``, which sympy makes 0)
and gave −1.  ``if x >= 0 then log(x) else 0`` is defined: ∫₀¹ log x dx = [x log x − x]₀¹ = −1.
"""

from __future__ import annotations

import json
import math

import pytest

from langur.cli import main

A = 0.5


def _run(capsys, tmp_path, command: str, body: str, box: str = "[-1, 1]", *extra: str) -> tuple[int, dict]:
    f = tmp_path / "p.lgr"
    f.write_text(f"param a = {A}\nint ({box}) {body} d(x)\n")
    status = main([command, str(f), "--json", *extra])
    return status, json.loads(capsys.readouterr().out)


def _codes(j: dict) -> list[tuple[str, str]]:
    return [(d["code"], d["severity"]) for d in j["diagnostics"]]


@pytest.mark.parametrize("body", ["[x >= 0] * log(x)", "[x >= a] * log(x)"])
def test_a_bracket_times_log_is_undefined_in_eval_deriv_and_check(capsys, tmp_path, body):
    status, j = _run(capsys, tmp_path, "eval", body)
    assert status == 1 and j["exact"] is None
    assert "X311" in j["undefined"] and "`log(x)`" in j["undefined"]
    assert math.isnan(float(j["mc"]["value"]))  # the Monte Carlo engine agrees: undefined
    status, j = _run(capsys, tmp_path, "deriv", body)
    assert status == 1 and j["exact"] is None and "X311" in j["undefined"]
    status, j = _run(capsys, tmp_path, "check", body)
    assert status == 1 and ("X311", "error") in _codes(j)


def test_the_conditional_leaves_log_unevaluated(capsys, tmp_path):
    status, j = _run(capsys, tmp_path, "eval", "if x >= 0 then log(x) else 0")
    assert status == 0 and j["undefined"] is None
    assert abs(j["exact"]["value"] - (-1.0)) <= 1e-12  # ∫₀¹ log x dx = −1 (by hand)
    status, j = _run(capsys, tmp_path, "check", "if x >= 0 then log(x) else 0")
    assert status == 0 and not [c for c, _ in _codes(j) if c in ("X311", "X312", "X307")]


# (body, box, value by hand, or None: undefined)
PROGRAMS = [
    # log(0) at the null set {0} only: ∫₀¹ log x dx = −1
    ("[x >= 0] * log(x)", "[0, 1]", -1.0),
    # sqrt of x < 0 on [−1, 0): undefined
    ("[x >= a] * sqrt(x)", "[-1, 1]", None),
    # ∫_{1/2}^1 √x dx = (2/3)(1 − (1/2)^{3/2})
    ("if x >= a then sqrt(x) else 0", "[-1, 1]", 2 / 3 * (1 - 0.5 ** 1.5)),
    # the bracket holds where sqrt(1 − x) is defined anyway: ∫_{−1}^{1/2} √(1 − x) dx = (2/3)(2^{3/2} − (1/2)^{3/2})
    ("[x <= a] * sqrt(1 - x)", "[-1, 1]", 2 / 3 * (2 ** 1.5 - 0.5 ** 1.5)),
    # a bracket inside the conditional's branch: sqrt(x − a) still evaluated on [0, 1/2)
    ("if x >= 0 then [x >= a] * sqrt(x - a) else 0", "[-1, 1]", None),
    # the same under a conditional on x − a: ∫_{1/2}^1 √(x − 1/2) dx = (2/3)(1/2)^{3/2}
    ("if x >= a then [x >= 0] * sqrt(x - a) else 0", "[-1, 1]", 2 / 3 * 0.5 ** 1.5),
    # asin(x + 1/2) outside [−1, 1] at x > 1/2, exactly where the bracket is 0: undefined
    ("[x <= a] * asin(x + a)", "[-1, 1]", None),
    # the same under the conditional: ∫_{−1}^{1/2} asin(x + 1/2) dx = ∫_{−1/2}^{1} asin u du
    # = [u asin u + √(1 − u²)]_{−1/2}^{1} = π/2 − (π/12 + √3/2)
    ("if a - x >= 0 then asin(x + a) else 0", "[-1, 1]", math.pi / 2 - math.pi / 12 - math.sqrt(3) / 2),
    # division by zero at the null set {0} only (the bracket is 0 around it): ∫_{1/2}^1 dx / x = log 2
    ("[x >= a] * (1 / x)", "[-1, 1]", math.log(2)),
    # a fractional power of x − 1 < 0 on [0, 1), exactly where the bracket is 0: undefined
    ("[x >= 1] * (x - 1)^(3/2)", "[0, 2]", None),
]


@pytest.mark.parametrize("body, box, value", PROGRAMS)
def test_the_engines_agree_on_a_bracket_times_a_primitive(capsys, tmp_path, body, box, value):
    status, j = _run(capsys, tmp_path, "eval", body, box)
    mc = float(j["mc"]["value"])  # (JSON writes a NaN as "nan")
    if value is None:  # exact undefined ⇔ Monte Carlo NaN
        assert status == 1 and j["exact"] is None and "X311" in j["undefined"]
        assert math.isnan(mc)
    else:
        assert status == 0 and j["undefined"] is None
        assert abs(j["exact"]["value"] - value) <= 1e-9
        assert math.isfinite(mc) and abs(mc - value) <= 5 * j["mc"]["stderr"] + 1e-12
