"""The exact engine called as a library says undefined where the integral does not exist
(LANGUAGE.md §1, §3; langur.symbolic.definedness).

⟦t · s⟧ = ⟦t⟧ · ⟦s⟧ evaluates both factors; a primitive outside its domain is undefined, so
``[x >= 0] * log(x)`` on [−1, 1] is 0 · undefined at every x < 0 and ⟦p⟧ does not exist, nor does
⦇p⦈.  The commands said so already (X311, ``langur.lint.singular``, test_guard27); the engine alone
(``exact_eval``, ``denote_program``, ``ddenote_program``, ``show_denotation``) gave the guarded
reading's number, −1, because its Def. 6.2 pieces have no piece where the bracket is 0.

Which tests are about the fix (they fail on main, a0eeb1e): every ``undefined`` case below
(``test_bracket_factor_*``, ``test_the_library_agrees_with_the_commands`` on the programs
test_guard27 finds undefined, ``test_undefined_*``, ``test_show_*``).  The others pin
the values that must not change (a guard, a bracket that is 0 only on a null set, a primitive
defined on the bracket's zero piece); they pass on main too.
"""

from __future__ import annotations

import json
import math

import pytest
from test_guard27 import PROGRAMS

from langur import exact
from langur.cli import main
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.frontend import load
from langur.symbolic.quadrature import UndefinedIntegral

A = 0.5


def _program(tmp_path, body: str, box: str = "[-1, 1]", xs: str = "x"):
    f = tmp_path / "p.lgr"
    f.write_text(f"param a = {A}\nint ({box}) {body} d({xs})\n")
    return load(str(f)).program, f


def _value(program):
    """(⟦p⟧ by exact_eval, by denote_program, ⦇p⦈ in a by ddenote_program); None: undefined (each
    library call raises its typed undefined result)."""
    out = []
    for call, undefined in ((lambda: exact.exact_eval(program, {"a": A}).value, exact.ExactUndefined),
                            (lambda: denote_program(program, {"a": A}).value, UndefinedIntegral),
                            (lambda: ddenote_program(program, {"a": A}, {"a": 1}).value, UndefinedIntegral)):
        try:
            out.append(call())
        except undefined:
            out.append(None)
    return out


# ----------------------------------------------------------------------------------------------
# A bracket is a factor, not a guard (fail on main: −1 and a derivative 0)


@pytest.mark.parametrize("body", ["[x >= 0] * log(x)", "[x >= a] * log(x)", "log(x) * [x >= 0]",
                                  "[x >= 0] * log(x) + x"])
def test_bracket_factor_times_log_is_undefined(tmp_path, body):
    program, _ = _program(tmp_path, body)
    assert _value(program) == [None, None, None]
    with pytest.raises(exact.ExactUndefined) as e:
        exact.exact_eval(program, {"a": A})
    assert "`log(x)`" in e.value.reason and "outside its domain" in e.value.reason
    with pytest.raises(exact.ExactUndefined):
        exact.exact_deriv(program, {"a": A}, {"a": 1})


def test_the_guard_is_defined(tmp_path):
    # ∫₀¹ log x dx = [x log x − x]₀¹ = −1; no parameter: ⦇p⦈ = 0 (passes on main)
    program, _ = _program(tmp_path, "if x >= 0 then log(x) else 0")
    value, denoted, derivative = _value(program)
    assert value == pytest.approx(-1.0, abs=1e-12) and denoted == pytest.approx(-1.0, abs=1e-12)
    assert derivative == 0


def test_the_guard_with_the_parameter_in_the_condition(tmp_path):
    # ∫_a^1 log x dx = (1·0 − 1) − (a log a − a) = −1 − a log a + a; d/da = −log a (passes on main)
    program, _ = _program(tmp_path, "if x >= a then log(x) else 0")
    value, _, derivative = _value(program)
    assert value == pytest.approx(-1 - A * math.log(A) + A, abs=1e-12)
    assert derivative == pytest.approx(-math.log(A), abs=1e-12)


@pytest.mark.parametrize("body, box, value, derivative", [
    # log(0) at the null set {0} only: ∫_a^2 log x dx = (2 log 2 − 2) − (a log a − a), d/da = −log a
    ("[x >= a] * log(x)", "[0, 2]", 2 * math.log(2) - 2 - (A * math.log(A) - A), -math.log(A)),
    # √x on [0, 1] everywhere: ∫_a^1 √x dx = (2/3)(1 − a^{3/2}), d/da = −√a
    ("[x >= a] * sqrt(x)", "[0, 1]", 2 / 3 * (1 - A ** 1.5), -math.sqrt(A)),
    # the bracket's zero piece x > a lies where √(1 − x) is defined (x ≤ 1):
    # ∫_{−1}^a √(1 − x) dx = (2/3)(2^{3/2} − (1 − a)^{3/2}), d/da = √(1 − a)
    ("[x <= a] * sqrt(1 - x)", "[-1, 1]", 2 / 3 * (2 ** 1.5 - (1 - A) ** 1.5), math.sqrt(1 - A)),
    # 1/x is undefined at the null set {0} only: ∫_a^1 dx/x = −log a, d/da = −1/a
    ("[x >= a] * (1 / x)", "[-1, 1]", -math.log(A), -1 / A),
    # tan's poles ±π/2 lie outside [−1, 1]: ∫_a^1 tan x dx = log cos a − log cos 1, d/da = −tan a
    ("[x >= a] * tan(x)", "[-1, 1]", math.log(math.cos(A)) - math.log(math.cos(1)), -math.tan(A)),
    # atanh is undefined at the ends ±1 only (a null set): ∫_a^1 atanh x dx
    # = [x atanh x + ½ log(1 − x²)]_a^1 = log 2 − a atanh a − ½ log(1 − a²), d/da = −atanh a
    ("[x >= a] * atanh(x)", "[-1, 1]", math.log(2) - A * math.atanh(A) - 0.5 * math.log(1 - A * A),
     -math.atanh(A)),
])
def test_a_bracket_that_hides_no_undefined_value_stays_a_number(tmp_path, body, box, value, derivative):
    # (pass on main: the fix must not make them undefined)
    program, _ = _program(tmp_path, body, box)
    got, denoted, d = _value(program)
    assert got == pytest.approx(value, abs=1e-9) and denoted == pytest.approx(value, abs=1e-9)
    assert d == pytest.approx(derivative, abs=1e-9)


@pytest.mark.parametrize("body", ["[x >= a] * log(x)", "[x >= a] * sqrt(x)", "[x <= a] * acos(x + a)"])
def test_bracket_factor_with_the_parameter_derivative_is_undefined(tmp_path, body):
    # on [−1, 1] the primitive is evaluated outside its domain where the bracket is 0 (x < 0 for
    # log and sqrt; x + 1/2 > 1 for acos): ⟦p⟧ and ⦇p⦈ do not exist (on main: numbers)
    program, _ = _program(tmp_path, body)
    with pytest.raises(UndefinedIntegral):
        ddenote_program(program, {"a": A}, {"a": 1})
    with pytest.raises(exact.ExactUndefined):
        exact.exact_deriv(program, {"a": A}, {"a": 1}, check=False)


# ----------------------------------------------------------------------------------------------
# The library agrees with the commands (test_guard27's programs; the undefined ones fail on main)


@pytest.mark.parametrize("body, box, value", PROGRAMS)
def test_the_library_agrees_with_the_commands(capsys, tmp_path, body, box, value):
    program, f = _program(tmp_path, body, box)
    got, denoted, derivative = _value(program)
    status = main(["eval", str(f), "--json"])
    command = json.loads(capsys.readouterr().out)
    if value is None:
        assert got is None and denoted is None and derivative is None
        assert status == 1 and command["exact"] is None
    else:
        assert got == pytest.approx(value, abs=1e-9) and denoted == pytest.approx(value, abs=1e-9)
        assert derivative is not None and math.isfinite(derivative)
        assert status == 0 and command["exact"]["value"] == pytest.approx(got, abs=1e-12)


# ----------------------------------------------------------------------------------------------
# Other ways a value 0 hides an undefined one (fail on main), and their guards


@pytest.mark.parametrize("body, box, xs, what", [
    # sympy's log(x) − log(x) is 0; at x < 0 it is undefined − undefined (main: 0)
    ("log(x) - log(x)", "[-1, 1]", "x", "log(x)"),
    # log(0) wherever max(x, 0) is 0, i.e. at x < 0, where the bracket is 0 (main: −1)
    ("[x >= 0] * log(max(x, 0))", "[-1, 1]", "x", "log(0)"),
    # a division by max(x, 0) = 0 at x < 0 (main: ∫₀¹ 1 = 1)
    ("[x >= 0] * (x / max(x, 0))", "[-1, 1]", "x", "1/0"),
    # two variables: √(1 − x² − y²) outside the unit disk, where the bracket is 0 (main: 2π/3)
    ("[x^2 + y^2 <= 1] * sqrt(1 - x^2 - y^2)", "[-1, 1], [-1, 1]", "x, y", "sqrt("),
    # a fractional power of a negative base, x < a (main: 2√(1 − a) = √2)
    ("[x >= a] * (x - a)^(-1/2)", "[0, 1]", "x", "^(-1/2)"),
])
def test_undefined_under_a_zero_factor(tmp_path, body, box, xs, what):
    program, _ = _program(tmp_path, body, box, xs)
    with pytest.raises(exact.ExactUndefined) as e:
        exact.exact_eval(program, {"a": A})
    assert what in e.value.reason
    with pytest.raises(UndefinedIntegral):
        denote_program(program, {"a": A})


def test_the_disk_guarded_is_the_hemisphere(tmp_path):
    # ∫∫_{x²+y² ≤ 1} √(1 − x² − y²) = the volume of the half unit ball, 2π/3 (passes on main)
    program, _ = _program(tmp_path, "if x^2 + y^2 <= 1 then sqrt(1 - x^2 - y^2) else 0", "[-1, 1], [-1, 1]", "x, y")
    assert exact.exact_eval(program, {"a": A}).value == pytest.approx(2 * math.pi / 3, abs=1e-9)


def test_undefined_witness_is_exact(tmp_path):
    # the reason names a point of the set where log's argument is negative, at exact coordinates
    program, _ = _program(tmp_path, "[x >= a] * log(x)")
    with pytest.raises(exact.ExactUndefined) as e:
        exact.exact_eval(program, {"a": A})
    assert "(e.g. at x = -1/2)" in e.value.reason


# ----------------------------------------------------------------------------------------------
# langur show's text, from the library (fail on main: "⟦p⟧ = -1" and "value at a = 1/2: -1")


def test_show_denotation_says_undefined(tmp_path):
    program, _ = _program(tmp_path, "[x >= 0] * log(x)")
    undefined: list[str] = []
    text = exact.show_denotation(program, params={"a": A}, undefined=undefined)
    assert "value at a = 0.5: undefined: `log(x)` is evaluated outside its domain" in text
    assert "⟦p⟧ = -1" not in text and len(undefined) == 1
    text = exact.show_derivative(program, {"a": 1}, params={"a": A}, undefined=undefined)
    assert "value at a = 0.5: undefined" in text and len(undefined) == 2


def test_show_says_where_the_integrand_text_hides_an_undefined_value(tmp_path):
    # sympy's text of log(x) − log(x) is 0; the line under it says where ⟦t⟧ is undefined (main: none)
    program, _ = _program(tmp_path, "log(x) - log(x)")
    text = exact.show_denotation(program, params={"a": A}, known_undefined="(given)")
    lines = text.splitlines()
    assert lines[0].endswith(" 0 d(x)")
    assert lines[1] == ("  ⟦t⟧ is undefined on a set of positive measure: `log(x)` is evaluated outside its domain "
                        "(its argument is negative), e.g. at x = -1/2")
    assert lines[2] == "  value at a = 0.5: undefined: (given)"
    assert "[[t]] is undefined" in exact.show_denotation(program, latex=True, params={"a": A})
    text = exact.show_derivative(program, {"a": 1}, params={"a": A})
    assert "⟦t⟧ is undefined on a set of positive measure (so is ⦇t⦈" in text
    # a defined program has no such line
    program, _ = _program(tmp_path, "if x >= 0 then log(x) else 0")
    assert "undefined" not in exact.show_denotation(program, params={"a": A})
