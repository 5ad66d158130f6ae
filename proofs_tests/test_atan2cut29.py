"""atan2's branch cut in the exact engine and the linter (fuzz29's F7; the coordinator's fix).

``atan2(y, x)`` is ``acos(x/√(x² + y²))`` on y ≥ 0 and its negative below (LANGUAGE.md §1).  The
chain rule gave its derivative −u'/√(1 − u²) with u = x/√(x² + y²): in doubles 1 − u² cancels to 0
for |y| ≲ 1e-8·|x|, so the exact engine's quadrature of the regular part, ending on the cut,
met NaNs there and said "undefined"; and the linter's integrability analysis met a pole base
|y − a| whose zeros (a line on the cut) it could not snap to exact numbers: X312 "cannot decide".
Now ``sympy_bridge.derivative_function`` puts such a radicand over one denominator (√(1 − u²) =
|y|/√(x² + y²)), and the analysis reads |h| as h and polishes a zero by Newton steps before
snapping it.  Expected values are computed here by hand and with mpmath.
"""

from __future__ import annotations

import math

import mpmath as mp
import numpy as np
import pytest
import sympy as sp

from langur import exact
from langur.cli import main
from langur.frontend import load_text
from langur.symbolic import integrability
from langur.sympy_bridge import derivative_function

F7 = "param a = 0.29\nint ([-1, 1], [-1, 1]) atan2(y - a, -1) * [x ^ 2 + y ^ 2 <= 0.5] d(x, y)\n"


def _f7_by_hand(a: float) -> float:
    """atan2(Y, −1) = sign(Y)·π − atan(Y) (Y = y − a ≠ 0).  On the disc x² + y² ≤ 1/2:
    ∂a ∫∫ −atan(y − a) = ∫∫ 1/(1 + (y − a)²) = ∫ 2√(1/2 − y²)/(1 + (y − a)²) dy, and
    ∂a ∫∫ sign(y − a)·π = π·∂a(|{y > a}| − |{y < a}|) = −2π·(the chord at y = a) = −4π√(1/2 − a²)."""
    r = mp.sqrt(mp.mpf(1) / 2)
    regular = mp.quad(lambda y: 2 * mp.sqrt(max(mp.mpf(1) / 2 - y * y, 0)) / (1 + (y - a) ** 2), [-r, a, r])
    return float(regular - 4 * mp.pi * mp.sqrt(mp.mpf(1) / 2 - a * a))


def test_acos_chain_rule_is_finite_beside_the_cut():
    x, y = sp.symbols("x y", real=True)
    d = derivative_function("acos")(x / sp.sqrt(x ** 2 + y ** 2)) * sp.diff(x / sp.sqrt(x ** 2 + y ** 2), y)
    f = sp.lambdify((x, y), d, "numpy")
    for t in (1e-6, 1e-9, 1e-12):  # ∂y acos(x/r) = x·sign(y)/(x² + y²): at x = −1, −sign(y)/(1 + y²)
        assert f(-1.0, t) == pytest.approx(-1 / (1 + t * t), rel=1e-12)
        assert f(-1.0, -t) == pytest.approx(1 / (1 + t * t), rel=1e-12)


def test_acos_of_a_plain_argument_is_unchanged():
    x = sp.Symbol("x", real=True)
    assert derivative_function("acos")(x / 3) == sp.diff(sp.acos(x / 3), x) * 3


def test_a_condition_line_is_a_site_not_undecided():
    x, y = sp.symbols("x y", real=True)
    a = sp.Rational(29, 100)
    region = integrability.Region((x, y), [(-1, 1), (-1, 1)], [y - a])
    found = integrability.sites(y - a, region)
    assert found and all(s.shape == "condition" and s.codim == 1 for s in found)
    assert all(s.point[1] == a for s in found)
    w = (2 * a - 2 * y) / (2 * ((y - a) ** 2 + 1) * sp.Abs(a - y))  # ∂a of atan2(y − a, −1) above the cut
    assert [b.verdict for b in integrability.blowups(w, region)] == [integrability.Verdict.INTEGRABLE] * len(found)


def test_polish_lands_on_a_line_to_rounding():
    gf = lambda q: q[:, 1] - 0.29  # noqa: E731
    x0 = np.array([-0.3, 0.29 + 3e-9])
    out = integrability.zerosets._polish(gf, x0, [(-1, 1), (-1, 1)], 2.0)
    assert abs(out[1] - 0.29) < 1e-15 and out[0] == -0.3


def test_f7_derivative_exact_against_the_hand_value():
    d = exact.exact_deriv(load_text(F7).program, {"a": 0.29}, {"a": 1}, check=False)
    assert math.isfinite(d.value)
    assert d.value == pytest.approx(_f7_by_hand(0.29), abs=1e-7)
    assert d.boundary == pytest.approx(-4 * math.pi * math.sqrt(0.5 - 0.29 ** 2), abs=1e-7)


def test_f7_check_no_longer_warns(tmp_path, capsys):
    path = tmp_path / "f7.lgr"
    path.write_text(F7)
    code = main(["check", str(path)])
    out = capsys.readouterr().out
    assert code == 0 and "X312" not in out, out
