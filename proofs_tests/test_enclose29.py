"""One enclosure, one high-precision evaluation, one definedness decision (enclose29).

* ``langur.symbolic.definedness`` had its own float interval arithmetic over a box (``_enclose``,
  ``_widen``) beside ``langur.enclosures``' mpmath one; now both are
  :func:`langur.enclosures.enclose` (mpmath's outward-rounded interval arithmetic of the lambdified
  expression, every variable an interval).  Checked here: the enclosure contains the values at
  sampled points computed independently with 50-digit mpmath (outward rounding included: a box
  that is one double wide around a value exact in no double), and it refuses what interval
  arithmetic cannot enclose by lambdify's text (``Max``, a complex root).
* ``definedness._num`` and ``integrability._value`` (was ``lint.blowup``): one :mod:`langur.precise`.
* X307 asks the engine's definedness (``undefined_parts``) whether a primitive is outside its
  domain on a set of positive measure: its witness is the example, and its verdicts correct the
  old sampling's in both directions (each by LANGUAGE.md §1, worked out below).
"""

from __future__ import annotations

import math
import sys

import mpmath
import numpy as np
import pytest
import sympy as sp

import langur.symbolic.definedness as definedness
import langur.symbolic.integrability.zerosets as blowup
from langur import precise
from langur import transversality as tv
from langur.denote import undefined_where
from langur.enclosures import enclose
from langur.frontend import load_text
from langur.symbolic.decompose import Ctx
from langur.sympy_bridge import at_symbols

x, y, z = sp.symbols("x y z")

# (expression, box): polynomials, rationals with constants no double holds, transcendental
# functions of the primitives, poles outside the box
CASES = [
    (x ** 2 - 2 * x * y + sp.Rational(1, 3), {x: (-1.0, 2.0), y: (0.1, 0.7)}),
    (sp.Rational(1, 10) * x - sp.Rational(1, 3) * y, {x: (-3.0, 3.0), y: (-1.0, 1.0)}),
    (sp.exp(x * y) - sp.pi, {x: (-1.0, 1.0), y: (0.0, 2.0)}),
    (sp.log(x) + sp.sqrt(y), {x: (0.5, 3.0), y: (0.0, 4.0)}),
    (sp.sin(3 * x) * sp.cos(y) - sp.tanh(x + y), {x: (-2.0, 2.0), y: (-1.0, 1.0)}),
    (sp.atan(x) + sp.erf(y) - sp.asin(z), {x: (-5.0, 5.0), y: (-2.0, 2.0), z: (-0.9, 0.9)}),
    (sp.acos(x / 2) * sp.atanh(y), {x: (-1.0, 1.0), y: (-0.5, 0.5)}),
    (1 / (x ** 2 + y ** 2 + sp.Rational(1, 7)), {x: (-1.0, 1.0), y: (-1.0, 1.0)}),
    (x ** sp.Rational(2, 3) - y ** sp.Rational(-1, 2), {x: (0.0, 8.0), y: (0.25, 4.0)}),
    (sp.tan(x) + sp.E * y, {x: (-1.5, 1.5), y: (-1.0, 1.0)}),
]


def _exact(e, point):
    """``e`` at ``point`` with 50 digits (sympy's evalf: its own arithmetic, not intervals)."""
    return sp.N(e.xreplace({s: sp.Float(v, 60) for s, v in point.items()}), 50)


@pytest.mark.parametrize("e, box", CASES)
def test_the_enclosure_contains_the_values_at_sampled_points(e, box):
    bound = enclose(e, box)
    assert bound is not None
    rng = np.random.default_rng(29)
    corners = [dict(zip(box, c)) for c in np.array(np.meshgrid(*box.values())).reshape(len(box), -1).T]
    points = corners + [{s: rng.uniform(lo, hi) for s, (lo, hi) in box.items()} for _ in range(200)]
    for p in points:
        v = _exact(e, p)
        if not v.is_real:  # (outside the real domain: nothing to contain)
            continue
        assert mpmath.mpf(bound.a) <= mpmath.mpf(str(v)) <= mpmath.mpf(bound.b), (e, p, v, bound)


def test_the_enclosure_rounds_outward():
    # x - 1/3 on the box of the single double nearest 1/3: the value there is 1/3's rounding error,
    # −1.85e-17 (by hand: float(1/3) = 6004799503160661/2^54), which rounding to nearest loses
    d = 1 / 3
    exact = sp.Rational(6004799503160661, 2 ** 54) - sp.Rational(1, 3)
    assert sp.Rational(d) == sp.Rational(6004799503160661, 2 ** 54) and exact < 0
    bound = enclose(x - sp.Rational(1, 3), {x: (d, d)})
    assert mpmath.mpf(bound.a) <= mpmath.mpf(sp.N(exact, 30)) <= mpmath.mpf(bound.b)
    # and a value exactly 0 is inside an enclosure that is not one point: 0.1 * 10 - 1 at x = 10
    bound = enclose(sp.Float("0.1") * x - 1, {x: (10.0, 10.0)})
    assert bound.a < 0 < bound.b


def test_the_enclosure_refuses_what_interval_arithmetic_cannot_enclose():
    assert enclose(sp.Max(x, 0), {x: (-1.0, 1.0)}) is None  # lambdify's max compares intervals
    assert enclose(sp.Piecewise((x, x > 0), (-x, True)), {x: (-1.0, 1.0)}) is None
    assert enclose(x ** sp.Rational(1, 3), {x: (-1.0, 1.0)}) is None  # a complex interval
    assert enclose(sp.log(x), {x: (-1.0, 1.0)}) is None  # log of a negative interval
    assert enclose(x + y, {x: (0.0, 1.0)}) is None  # a symbol without its side
    pole = enclose(1 / x, {x: (-1.0, 1.0)})  # a pole inside: an infinite end, still an enclosure
    assert pole.a == -mpmath.inf and pole.b == mpmath.inf


def test_definedness_proves_defined_without_sampling_and_finds_the_rest(monkeypatch):
    # log(x + 2) on [−1, 1]: −(x + 2) ≤ −1 < 0 on the box, proved by the enclosure (no witness
    # searched); log(x - 1/2): −(x − 1/2) > 0 on [−1, 1/2), found
    searched = []
    real = definedness._witness
    monkeypatch.setattr(definedness, "_witness", lambda *a: searched.append(a[0]) or real(*a))
    assert not definedness._may_be_positive(-(x + 2), (x,), [(-1, 1)])
    assert definedness._may_be_positive(-(x - sp.Rational(1, 2)), (x,), [(-1, 1)])
    assert _undefined("log(x + 2)", "[-1, 1]") is None and searched == []
    u = _undefined("log(x - 0.5)", "[-1, 1]")
    assert u is not None and searched and float(dict(u.point)["x"]) < 0.5


def _loaded(body: str, box: str, xs: str = "x"):
    return load_text(f"param a = 0.5\nint ({box}) {body} d({xs})\n", "p.lgr")


def _undefined(body: str, box: str):
    program = _loaded(body, box).program
    return undefined_where(program, Ctx(at=at_symbols({"a": 0.5}), variables=tuple(program.variables)))


def _findings(body: str, box: str, xs: str = "x", code: str | None = None):
    loaded = _loaded(body, box, xs)
    found = tv.check_loaded(loaded, sources={"p.lgr": f"param a = 0.5\nint ({box}) {body} d({xs})\n"})
    return [f for f in found if code is None or f.code == code]


def _example(message: str) -> float:
    """The example point of a one-variable X307 message."""
    return float(message.split("e.g. at x = ", 1)[1].split(";", 1)[0])


# ----------------------------------------------------------------------------------------------
# One high-precision evaluation


def test_one_high_precision_evaluation():
    assert blowup._num is precise.real_value and blowup._value is precise.value_at
    assert blowup.DIGITS == precise.DIGITS == 50
    assert precise.real_value(sp.sqrt(2) ** 2 - 2) == 0.0  # sympy's exact 0
    # exp(10^-40) - 1 = 10^-40 (1 + 5·10^-41 + …) by its series; in doubles exp(1e-40) is 1.0 and the difference 0
    assert math.exp(1e-40) - 1 == 0.0
    assert precise.real_value(sp.exp(sp.Rational(1, 10 ** 40)) - 1) == pytest.approx(1e-40, rel=1e-12)
    assert math.isnan(precise.real_value(sp.sqrt(-2)))  # complex: not a real value
    assert math.isnan(precise.real_value(sp.zoo)) and math.isnan(precise.real_value(sp.log(0)))
    assert precise.real_value(sp.Integer(10) ** 400) == sys.float_info.max  # defined, beyond doubles
    assert precise.value_at(x ** 2 - 2, (x,), (sp.sqrt(2),)) == 0.0
    assert precise.value_at(x - y, (x, y), (0.1, sp.Rational(1, 10))) == pytest.approx(5.55e-18, rel=1e-2)  # 0.1's error


# ----------------------------------------------------------------------------------------------
# X307 asks the engine's definedness


@pytest.mark.parametrize("body, box, domain", [
    ("log(x)", "[-1, 1]", lambda v: v > 0),
    ("[x >= 0] * log(x)", "[-1, 1]", lambda v: v > 0),
    ("sqrt(x - a)", "[0, 1]", lambda v: v >= 0),
    ("asin(2 * x)", "[-1, 1]", lambda v: -1 <= v <= 1),
    ("atanh(x + a)", "[-1, 1]", lambda v: -1 < v < 1),
])
def test_x307_example_is_a_point_outside_the_domain(body, box, domain):
    (f,) = _findings(body, box, code="X307")
    assert f.severity == "warning" and "is applied outside its domain on the domain of integration" in f.message
    xv = _example(f.message)
    lo, hi = (float(v) for v in box.strip("[]").split(","))
    argument = {"log(x)": xv, "[x >= 0] * log(x)": xv, "sqrt(x - a)": xv - 0.5, "asin(2 * x)": 2 * xv,
                "atanh(x + a)": xv + 0.5}[body]
    assert lo < xv < hi and not domain(argument)


def test_x307_log_of_zero_on_a_region():
    # log(max(x, 0)) on [−1, 1] is log(0) at every x < 0 (LANGUAGE.md §1: log of a non-positive
    # number is undefined); the old sampling looked for arguments outside [0, ∞]'s closure and missed it
    (f,) = _findings("log(max(x, 0))", "[-1, 1]", code="X307")
    assert "its argument is 0 there" in f.message and _example(f.message) < 0
    assert [g.code for g in _findings("log(max(x, 0))", "[-1, 1]", code="X311")] == ["X311"]
    (f,) = _findings("log(1 - a - a)", "[0, 1]", code="X307")  # log(0) at a = 0.5, everywhere
    assert "its argument is 0 there" in f.message


def test_x307_and_x311_see_a_region_thinner_than_the_grid():
    # log(x) on [−0.001, 1]: negative on [−0.001, 0), between the box's end and the grid's first
    # point inside (step 1.001/400); found at the random points, proved, and ⟦p⟧ is undefined
    (f,) = _findings("log(x)", "[-0.001, 1]", code="X307")
    assert -0.001 < _example(f.message) < 0
    assert [g.code for g in _findings("log(x)", "[-0.001, 1]", code="X311")] == ["X311"]
    u = _undefined("log(x)", "[-0.001, 1]")
    assert -sp.Rational(1, 1000) < dict(u.point)["x"] < 0


def test_erf_in_an_argument_is_evaluated():
    # erf(x − 1/10) < 0 on [0, 1/10) (erf is odd and increasing): log of it is undefined there;
    # the witness search compiled erf to math.erf, which takes no array, and found nothing
    u = _undefined("log(erf(x - 0.1))", "[0, 1]")
    assert u is not None and 0 < dict(u.point)["x"] < sp.Rational(1, 10)
    assert _undefined("log(erf(x + 0.1))", "[0, 1]") is None  # erf(x + 1/10) > 0 on [0, 1]
    assert [f.code for f in _findings("log(erf(x - 0.1))", "[0, 1]", code="X307")] == ["X307"]


def test_x307_no_longer_reports_rounding():
    # sin(x)^2 + cos(x)^2 - 1 is 0 at every x (sqrt(0) = 0 is defined); doubles make it −1.1e-16
    # at some points, which the sampling reported as a negative argument
    assert _findings("sqrt(sin(x)^2 + cos(x)^2 - 1)", "[0, 1]", code="X307") == []


def test_x307_still_samples_poles():
    # a pole crossed is a null set, not the engine's definedness: still the samples' finding
    (f,) = _findings("1 / x", "[-1, 1]", code="X307")
    assert "the denominator changes sign, so it divides by zero inside the region" in f.message
    (f,) = _findings("tan(x)", "[0, 3]", code="X307")
    assert "its argument crosses a pole (cos changes sign)" in f.message
    assert _findings("if x > 0 then log(x) else 0", "[-1, 1]", code="X307") == []
    assert _findings("log(x + 2)", "[-1, 1]", code="X307") == []


def test_x311_reuses_x307s_search_only_for_the_same_question():
    program = _loaded("log(x - a)", "[0, 1]").program
    box = ((sp.Integer(0), sp.Integer(1)),)

    def ctx(a):
        return Ctx(at=at_symbols({"a": a}), variables=("x",))

    parts = definedness.undefined_parts(program.body, ctx(0.5), ("x",), box)
    assert len(parts) == 1 and definedness.undefined_part(program.body, ctx(0.5), ("x",), box) is parts[0]
    # another point: searched again (log(x + 1/2) is defined on [0, 1]; log(x - 1/2) is not)
    assert definedness.undefined_part(program.body, ctx(-0.5), ("x",), box) is None
    # the same value as a Float of another precision is another question (sympy's == ignores precision)
    other = Ctx(at={k: sp.Float(0.5, 30) for k in at_symbols({"a": 0.5})}, variables=("x",))
    assert definedness._key(other, ("x",), box) != definedness._key(ctx(0.5), ("x",), box)
