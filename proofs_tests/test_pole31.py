"""A condition whose sign changes where its completion does not reach: a pole, or a product's other factor (§5, §7, Fig. 8).

``[(x − a)/(y + b) ≥ 0]`` on [−1, 1]² was completed as ``x = a + u₀·(y + b)``: its delta sits on
x = a only, but the condition also changes sign across the pole y = −b, which moves with b.
``deriv --wrt b`` printed 0 in both engines (Theorem 8.1: FAILS); the front end now splits such a
condition into conditionals on its factors' signs (``langur.syntax.poles``): a.e.
``[N/D ≥ 0] = [D ≥ 0]·[N ≥ 0] + [D < 0]·[N ≤ 0]``, each completed on its own, so the pole gets its
delta.  ⟦p⟧ is unchanged (the integrands agree off the null set D = 0).

Hand values (every zero set and pole inside the box):
* ``[(x − a)/(y + b) ≥ 0]``: y > −b: x ≥ a; y < −b: x ≤ a.  ⟦p⟧ = (1 − a)(1 + b) + (1 + a)(1 − b)
  = 2 − 2ab; d/da = −2b, d/db = −2a (the brief's −0.6 is a = 0.3; at a = b = ½ it is −1).
* ``[(y − a)/(x + b) ≥ 0]``: the same with x and y swapped: 2 − 2ab; ``[(a − x)/(y + b) ≤ 0]`` is the
  same set; ``[2(x − a)/(b(y + b)) ≥ 0]`` too for b > 0, its complement 2 + 2ab for b < 0 (d/da = 2b,
  d/db = 2a: the sign of the coefficient b is a conditional on the parameters).
* ``[(x − a)/(y + b) ≤ c]``: y > −b: x ≤ a + c(y + b); y < −b: x ≥ a + c(y + b).
  ⟦p⟧ = ∫_{−b}^{1} (1 + a + c(y + b)) dy + ∫_{−1}^{−b} (1 − a − c(y + b)) dy = 2 + 2ab + c(1 + b²)
  (while a + c(y + b) stays in [−1, 1]); d/da = 2b, d/db = 2a + 2bc.
* ``int ([0, 1.2]) [1/(x − b) ≥ 1]``: 0 < x − b ≤ 1, i.e. (b, b + 1] ∩ [0, 1.2] = (b, 1.2] for
  b ∈ [0.2, 1.2]: ⟦p⟧ = 1.2 − b, d/db = −1 (the pole's end moves; the root's is outside).
* ``int ([0, 1.2]) [1/(x − b) ≥ 0]``: x > b, the same 1.2 − b (pole30 refused it: T207).
* ``[(x − a)·(y − b) ≥ 0]``: ⟦p⟧ = (1 − a)(1 − b) + (1 + a)(1 + b) = 2 + 2ab; d/da = 2b, d/db = 2a
  (solved for y, the completion missed x = a: ∂/∂a printed 0).
* ``[(x − a)·(y − 0.5) ≥ 0]``: ⟦p⟧ = ½(1 − a) + 3/2(1 + a) = 2 + a; d/da = 1 (main: 0).
Each is checked against both engines (Monte Carlo within 5 SE) and Theorem 8.1.
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

import pytest

from langur import operational
from langur.cli import main
from langur.core import (
    Add,
    Const,
    Diffeo,
    IfDiffeo,
    InverseBranch,
    Mul,
    Param,
    Pow,
    Var,
    free_vars,
    map_children,
    subterms,
)
from langur.ddenote import ddenote_program
from langur.exact import exact_deriv, exact_eval
from langur.frontend import load_text
from langur.symbolic.quadrature import UndefinedIntegral

BOX2 = "int ([-1, 1], [-1, 1])"
QUOTIENT_X = f"{BOX2} [(x - a)/(y + b) >= 0] d(x, y)"
QUOTIENT_Y = f"{BOX2} [(y - a)/(x + b) >= 0] d(x, y)"
AT_MOST_C = f"{BOX2} [(x - a)/(y + b) <= c] d(x, y)"
ONE_VAR = "int ([0, 1.2]) [1/(x - b) >= 1] d(x)"
NO_ROOT = "int ([0, 1.2]) [1/(x - b) >= 0] d(x)"
PRODUCT = f"{BOX2} [(x - a)*(y - b) >= 0] d(x, y)"
FIXED_FACTOR = f"{BOX2} [(x - a)*(y - 0.5) >= 0] d(x, y)"
FIXED_POLE = f"{BOX2} [(x - a)/(y + 0.5) >= 0] d(x, y)"
THROUGH_DEF = f"def g(u: var, v: var) = [u/v >= 0]\n{BOX2} g(x - a, y + b) d(x, y)"
NEGATED = f"{BOX2} [(a - x)/(y + b) <= 0] d(x, y)"  # the same set as QUOTIENT_X
COEFFICIENT = f"{BOX2} [2*(x - a)/(b*(y + b)) >= 0] d(x, y)"  # b < 0 flips it: the complement, 2 + 2ab


def _cases():
    out = []
    for a, b in ((0.5, 0.5), (0.3, -0.25)):
        quotient = (2 - 2 * a * b, {"a": -2 * b, "b": -2 * a})
        out += [(QUOTIENT_X, a, b, 0.0) + quotient, (QUOTIENT_Y, a, b, 0.0) + quotient,
                (THROUGH_DEF, a, b, 0.0) + quotient, (NEGATED, a, b, 0.0) + quotient,
                (COEFFICIENT, a, b, 0.0) + (quotient if b > 0 else (2 + 2 * a * b, {"a": 2 * b, "b": 2 * a})),
                (PRODUCT, a, b, 0.0, 2 + 2 * a * b, {"a": 2 * b, "b": 2 * a})]
    c = 0.25
    for a, b in ((0.5, 0.5), (0.2, -0.3)):
        out.append((AT_MOST_C, a, b, c, 2 + 2 * a * b + c * (1 + b * b), {"a": 2 * b, "b": 2 * a + 2 * b * c}))
    for b in (0.5, 0.3):
        out += [(ONE_VAR, 0.0, b, 0.0, 1.2 - b, {"b": -1.0}), (NO_ROOT, 0.0, b, 0.0, 1.2 - b, {"b": -1.0})]
    out.append((FIXED_FACTOR, 0.3, 0.0, 0.0, 2.3, {"a": 1.0}))
    out.append((FIXED_POLE, 0.3, 0.0, 0.0, 1.7, {"a": -1.0}))  # pole30's: unchanged
    return out


def _load(body: str, a: float, b: float, c: float):
    return load_text(f"param a = {a}, b = {b}, c = {c}\n{body}\n")


@pytest.mark.parametrize("body, a, b, c, value, slopes", _cases())
def test_both_engines_and_theorem_8_1_against_the_hand_values(body, a, b, c, value, slopes):
    loaded = _load(body, a, b, c)
    params = loaded.param_values()
    r = exact_eval(loaded.program, params)
    assert not r.inconsistent, r.inconsistent
    assert r.value == pytest.approx(value, rel=1e-12)
    for name, slope in slopes.items():
        d = exact_deriv(loaded.program, params, {name: 1}, check=True)
        assert not d.inconsistent, d.inconsistent
        assert d.value == pytest.approx(slope, rel=1e-12, abs=1e-12), (name, d.value)  # main: 0 for the moving ones
        assert d.theorem_8_1 is not None and d.theorem_8_1.holds, d.theorem_8_1
        mc = operational.estimate_derivative(loaded, params, {name: 1}, samples=20_000, seed=7)
        assert abs(mc.value - slope) <= 5 * mc.stderr + 1e-12, (name, mc.value, mc.stderr)
    mv = operational.estimate_value(loaded, params, samples=20_000, seed=7)
    assert abs(mv.value - value) <= 5 * mv.stderr + 1e-12


def test_the_pole_is_a_conditional_of_its_own():
    loaded = _load(QUOTIENT_X, 0.5, 0.5, 0)
    conds = [t.psi.forward[0] for t in subterms(loaded.program.body) if isinstance(t, IfDiffeo)]
    # the pole y + b and the root x − a are conditions; no condition divides by a variable any more
    assert any(free_vars(cd) == {"y"} for cd in conds) and any(free_vars(cd) == {"x"} for cd in conds)
    assert not any(isinstance(u, Pow) and u.exponent < 0 and free_vars(u.base)
                   for cd in conds for u in subterms(cd))


def test_a_pole_that_does_not_move_keeps_its_completion():
    # must stay as before: one conditional on the quotient, solved for x (pole30)
    loaded = _load(FIXED_POLE, 0.3, 0, 0)
    (psi,) = {t.psi for t in subterms(loaded.program.body)
              if isinstance(t, IfDiffeo) and free_vars(t.psi.forward[0]) == {"x", "y"}}
    assert psi.solved_for == "x"
    assert any(isinstance(u, Pow) and u.exponent < 0 for u in subterms(psi.forward[0]))


def test_a_moving_pole_inside_a_primitive_is_refused_before_any_number(tmp_path, capsys):
    # exp(1/(x − b)) ≥ 2 changes sign at x = b, inside exp: no factor split reaches it (main: 0, Theorem 8.1 FAILS, D⟦p⟧ = −1)
    path = tmp_path / "inside.lgr"
    path.write_text("param b = 0.5\nint ([0, 1.2]) [exp(1/(x - b)) >= 2] d(x)\n")
    assert main(["deriv", str(path), "--wrt", "b"]) == 1
    out = capsys.readouterr()
    assert "T207" in out.out + out.err and "pole that moves" in out.out + out.err
    assert "MC" not in out.out and "exact       :" not in out.out


def test_a_declared_diffeo_infinite_on_its_zero_set_is_refused(tmp_path, capsys):
    # solved for y, (x − c)/(y + ½) = u has y = (x − c)/u − ½: infinite on u = 0 (main: MC 0 ± 0, exact crashed)
    path = tmp_path / "declared.lgr"
    path.write_text("param a = 0.3\n"
                    "diffeo d(x, y; c) = ((x - c)/(y + 0.5), x) inverse (u, v) = (v, (v - c)/u - 0.5)\n"
                    f"{BOX2} ifge0 d(x, y; a) then 1 else 0 d(x, y)\n")
    assert main(["deriv", str(path), "--wrt", "a"]) == 1
    out = capsys.readouterr()
    assert "T216" in out.out + out.err and "infinite on the zero set" in out.out + out.err
    assert "MC" not in out.out


@pytest.mark.parametrize("declaration", [
    "diffeo e(x; ) = (exp(x)) inverse (u) = (log(u))",
    "diffeo e(x; c) = (exp(x - c)) inverse (u) = (log(u) + c)",
])
def test_an_inverse_infinite_where_the_condition_never_vanishes_is_accepted(declaration):
    # log(u) is infinite at u = 0, but exp never vanishes: the zero set is empty, no delta sits on it and
    # Ψ̂⁻¹(0) is never used (pole31 refused this with T216).  exp > 0 on [0, 1]: ⟦p⟧ = ∫₀¹ x dx = ½, and
    # nothing moves with the parameter: d/da = 0
    call = "e(x; )" if "x; )" in declaration else "e(x; a)"
    loaded = load_text(f"param a = 0.3\n{declaration}\nint ([0, 1]) ifge0 {call} then x else 0 d(x)\n")
    params = loaded.param_values()
    r = exact_eval(loaded.program, params)
    assert not r.inconsistent, r.inconsistent
    assert r.value == pytest.approx(0.5, rel=1e-12)
    d = exact_deriv(loaded.program, params, {"a": 1}, check=True)
    assert not d.inconsistent, d.inconsistent
    assert d.value == pytest.approx(0.0, abs=1e-12)
    assert d.theorem_8_1 is not None and d.theorem_8_1.holds, d.theorem_8_1
    mv = operational.estimate_value(loaded, params, samples=20_000, seed=7)
    assert abs(mv.value - 0.5) <= 5 * mv.stderr + 1e-12


def test_the_exact_delta_path_says_undefined_for_an_inverse_infinite_on_the_zero_set():
    # a core program built without the front end: Ψ̂ solved for y, y = (x − a)/u₀ − ½
    loaded = load_text(f"param a = 0.3\n{FIXED_POLE}\n")

    def solved_for_y(t):
        t = map_children(t, solved_for_y)
        if isinstance(t, IfDiffeo) and free_vars(t.psi.forward[0]) == {"x", "y"}:
            y = Add(Mul(Add(Var("u1"), Mul(Const(Fraction(-1)), Param("a"))), Pow(Var("u0"), Fraction(-1))),
                    Const(Fraction(-1, 2)))
            psi = Diffeo(("x", "y"), (t.psi.forward[0], Var("x")), ("u0", "u1"), (InverseBranch((Var("u1"), y)),),
                         solved_for="y")
            return IfDiffeo(psi, t.then, t.orelse, span=t.span)
        return t

    program = replace(loaded.program, integrand=solved_for_y(loaded.program.integrand))
    with pytest.raises(UndefinedIntegral, match="infinite on the zero set"):  # main: KeyError 'ComplexInfinity'
        ddenote_program(program, {"a": 0.3}, {"a": 1})


def test_deriv_prints_the_right_number_in_both_engines(tmp_path, capsys):
    path = tmp_path / "pole.lgr"
    path.write_text(f"param a = 0.5, b = 0.5\n{QUOTIENT_X}\n")
    assert main(["deriv", str(path), "--wrt", "b"]) == 0
    out = capsys.readouterr().out
    assert "exact       : -1 " in out, out  # main: 0
    assert "Theorem 8.1 : holds" in out
