"""Undefined is an answer, and nothing crashes (issue 9, part B).

An integral that does not exist must be reported as undefined, never as a finite number with a
small error bound; an integrable singularity keeps its value.  Expected values are by hand.
"""

import json
import math
import subprocess
import sys
import warnings

import pytest
import sympy as sp

from langur.symbolic import quadrature
from langur.symbolic.pieces import Piece
from langur.symbolic.quadrature import UndefinedIntegral

x, y = sp.symbols("x y", real=True)


def quad(weight, box, variables=(x,)):
    return quadrature.quad_pieces([Piece((), weight)], list(variables), box, {})


# ----------------------------------------------------------------------------------------------
# Quadrature's own diagnostics (never silenced, never leaked)


@pytest.mark.parametrize(
    "weight, box",
    [
        (1 / x**2, [(0, 1)]),  # ∫₀¹ x⁻² = ∞ (scipy used to answer −1)
        (1 / x, [(0, 1)]),  # no convergence, and the integrand grows like x⁻¹ at 0
        (1 / x, [(-1, 1)]),  # a pole inside: quad sampled NaN at 0 and crashed the process
        (1 / x**2, [(-1, 1)]),
        (1 / x, [(-1, sp.Rational(1, 2))]),  # the principal value −log 2 is not the integral
        (1 / (x**2 + y**2), [(0, 1), (0, 1)]),  # ∫∫ r⁻² r dr dθ diverges at the corner
        (1 / (x - y), [(0, 1), (0, 1)]),  # a pole on the diagonal
    ],
)
def test_divergent_integrals_are_undefined(weight, box):
    variables = (x, y)[: len(box)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing leaks: scipy's warnings are read, not printed
        with pytest.raises(UndefinedIntegral):
            quad(weight, box, variables)


@pytest.mark.parametrize(
    "weight, box, value",
    [
        # ∫₋₁¹ log(x²) = 2·2·∫₀¹ log x = −4; quad samples x = 0 (the midpoint) where it is −∞
        (sp.log(x**2), [(-1, 1)], -4.0),
        (1 / sp.sqrt(x), [(0, 1)], 2.0),  # ∫₀¹ x^(−1/2) = 2
        (sp.log(x), [(0, 1)], -1.0),  # ∫₀¹ log x = −1
        # ∫∫_[0,1]² r⁻¹ = 2·∫₀^{π/4} ∫₀^{1/cos θ} dr dθ = 2·log(1 + √2)
        (1 / sp.sqrt(x**2 + y**2), [(0, 1), (0, 1)], 2 * math.log(1 + math.sqrt(2))),
    ],
)
def test_integrable_singularities_keep_their_value(weight, box, value):
    variables = (x, y)[: len(box)]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v, err = quad(weight, box, variables)
    assert abs(v - value) <= 1e-7 + err


# ----------------------------------------------------------------------------------------------
# The command line: never a signal, the other engine's answer still printed


def langur(tmp_path, text, *argv):
    f = tmp_path / "p.lgr"
    f.write_text(text)
    return subprocess.run([sys.executable, "-m", "langur", *argv, str(f)], capture_output=True, text=True,
                          timeout=120)


@pytest.mark.parametrize("body", ["1 / x", "1 / x^2", "a / x"])
@pytest.mark.parametrize("command", ["eval", "deriv"])
def test_pole_inside_does_not_kill_the_process(tmp_path, body, command):
    r = langur(tmp_path, f"param a = 1\nint ([-1, 1]) {body} d(x)\n", command, "--samples", "500", "--json")
    assert r.returncode in (0, 1), r.stderr  # exit 135 (bus error) before
    assert "Traceback" not in r.stderr
    out = json.loads(r.stdout)
    assert out["mc"]["samples"] == 500  # the Monte Carlo answer is still there
    if command == "eval" or body == "a / x":  # ⦇p⦈ of 1/x in a is 0: see the structural analysis
        assert r.returncode == 1
        assert out["exact"] is None and out["undefined"]


def test_ball_derivative_by_quadrature_or_closed_form(tmp_path):
    # d/dr of the volume of the ball's positive octant, πr³/6, is πr²/2 (0 < r < 1)
    r = langur(tmp_path, "param r = 0.5\nint ([0,1],[0,1],[0,1]) [x^2+y^2+z^2 <= r^2] d(x,y,z)\n",
               "deriv", "--engine", "exact", "--no-theorem", "--json")
    assert r.returncode == 0, r.stderr
    ex = json.loads(r.stdout)["exact"]
    assert abs(ex["value"] - math.pi * 0.25 / 2) <= 1e-7 + ex.get("error", 0.0)


def test_slowly_convergent_is_not_called_divergent():
    # ∫₀^½ dx / (x log²x) = [−1/log x]₀^½ = 1/log 2: quad does not converge (its error bound is
    # optimistic: it says so in a note), but the integrand's growth x⁻¹·log⁻²x is integrable
    notes = []
    v, _ = quadrature.quad_pieces([Piece((), 1 / (x * sp.log(x) ** 2))], [x], [(0, sp.Rational(1, 2))], {},
                                  notes)
    assert abs(v - 1 / math.log(2)) < 1e-2
    assert any("did not reach its tolerance" in n for n in notes)


def test_ball_show_derivative(capsys):
    # `langur show --wrt r` used to die with "internal error: ValueError" (a NaN at the fold of
    # the inverse branch z = sqrt(r² − x² − y²)); the value is πr²/2 = π/8 at r = 1/2
    import io
    import re
    import sys as _sys

    from langur.cli import main

    old = _sys.stdin
    _sys.stdin = io.TextIOWrapper(io.BytesIO(b"param r = 0.5\nint ([0,1],[0,1],[0,1]) [x^2+y^2+z^2 <= r^2] d(x,y,z)\n"))
    try:
        status = main(["show", "-", "--wrt", "r"])
    finally:
        _sys.stdin = old
    out = capsys.readouterr().out
    assert status == 0
    (value,) = re.findall(r"value at r = 1/2: ([0-9.]+)", out.split("derivative")[1])
    assert abs(float(value) - math.pi / 8) < 1e-8


@pytest.mark.parametrize("name", ["pole2_end", "pole1_end", "pole1_inside", "principal_value", "tan_pole",
                                  "inverse_log", "expanded_square", "r2_corner", "sum_squared_corner",
                                  "diagonal", "moving_circle", "tan_line", "basel_squared"])
def test_exact_engine_alone_never_answers_a_divergent_integral(name):
    # without the structural analysis of the command layer: quadrature's diagnostics suffice
    from singular_corpus import CORPUS

    from langur import exact as api
    from langur import frontend

    (text,) = [t for n, t, *_ in CORPUS if n == name]
    loaded = frontend.load_text(text, f"{name}.lgr")
    with pytest.raises(api.ExactUndefined):
        api.exact_eval(loaded.program, loaded.param_values())


def test_unconverged_quadrature_is_no_error_bound():
    from langur import exact as api
    from langur import frontend

    # ∫₀^½ dx/(x log x) = [log|log x|]₀^½ diverges (like log log): sympy has no closed form and
    # quad does not converge, so there is no value whose error bound could be trusted
    slow = frontend.load_text("int ([0, 0.5]) 1 / (x * log(x)) d(x)\n", "a.lgr")
    with pytest.raises(api.ExactUnavailable, match="did not converge"):
        api.exact_eval(slow.program, {})
    # ∫₀^½ dx/(x log²x) = 1/log 2: the closed form stands, cross-checked only roughly (quad says
    # 1.4389 ± 1.6e-5, an optimistic bound), and says so
    ok = frontend.load_text("int ([0, 0.5]) 1 / (x * log(x)^2) d(x)\n", "b.lgr")
    r = api.exact_eval(ok.program, {})
    assert r.method == "closed_form" and abs(r.value - 1 / math.log(2)) < 1e-12
    assert any("cross-checked only" in n for n in r.notes)
