"""precise31: readable closed forms cut where they stop being real, Abs and sign enclosed, one evaluation.

* ``readable`` decided each interval between two breakpoints at one inner point, and its breakpoints were
  only the switching points of Min/Max/Piecewise/Heaviside: ``Max(log(t), 0)`` was resolved at t = 0
  (log 0 is not real) and all of t < 1 excluded, although it is 0 on (0, 1); ``Min(sqrt(t), 1)`` was
  resolved at t = 0 (√0 = 0 < 1) and claimed √t for every t ≤ 1, t < 0 included.  Now the ends of the
  real domain (roots of a root's or a pole's base, of a partial primitive's argument minus its domain's
  ends, ``langur.primitives``) are breakpoints too, and a piece not real at its inner point is excluded.
  Each case is checked here against the closed form evaluated by Python's ``math`` (lambdify), point by
  point on a grid: independent of readable's own evaluation.
* ``enclosures.interval_function`` and ``enclose`` refused ``Abs``, which interval arithmetic encloses
  exactly (``|x − 1/3|`` on [0, 1] is [0, 2/3]; ``|x − y|`` on [−1, 1] × [0, 2] is [0, 3], by hand).
  ``sign`` stays refused: bounded but not continuous (``langur.syntax.continuity`` reads continuity off a
  finite enclosure).
* The linter's X313 for a delta term in two variables printed the blow-up's point in the zero set's
  variables under all the program's names, ``(x, y) = (1)``; it is now the point of the box.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

import mpmath
import pytest
import sympy as sp

from langur import enclosures, precise
from langur.symbolic.readable import readable

ROOT = Path(__file__).resolve().parent.parent
t = sp.Symbol("t", real=True)
GRID = [sp.Rational(k, 8) for k in range(-40, 41)]


def _python(expr):
    """The closed form at a double by Python's math (None where it raises or is not finite: not real)."""
    f = sp.lambdify(t, expr, "math")

    def at(v):
        try:
            out = f(float(v))
        except (ValueError, ZeroDivisionError, OverflowError):
            return None
        return out if isinstance(out, (int, float)) and math.isfinite(out) else None
    return at


def _check(expr, extra=()):
    """Every grid point (and ``extra``) is in exactly one case or one excluded set; in a case the case's
    expression equals the closed form there (Python's value), in an excluded set the closed form is not real."""
    r = readable(expr)
    assert r is not None and r.complete
    ref = _python(expr)
    for v in [*GRID, *map(sp.nsimplify, extra)]:
        inside = [c for c in r.cases if c.interval.contains(v) == sp.true]
        out = [iv for iv in r.excluded if iv.contains(v) == sp.true]
        assert len(inside) + len(out) == 1, (expr, v, r.text())
        want = ref(v)
        if out:
            assert want is None, (expr, v, r.text())
        else:
            got = complex(inside[0].expr.subs(t, v).evalf(30))
            assert want is not None and abs(got.imag) < 1e-12 and got.real == pytest.approx(want, abs=1e-12), \
                (expr, v, inside[0].expr, r.text())
    return r


def test_max_of_log_is_zero_between_its_domain_end_and_its_switch():
    r = _check(sp.Max(sp.log(t), 0))
    assert [(c.interval, c.expr) for c in r.cases] == [(sp.Interval.Lopen(0, 1), 0), (sp.Interval.open(1, sp.oo), sp.log(t))]
    assert r.excluded == (sp.Interval(-sp.oo, 0),)
    assert r.text().splitlines() == ["0 < t <= 1 : 0", "t > 1      : log(t)",
                                     "(t <= 0: the closed form is not real there, it does not apply)"]


def test_min_of_a_root_does_not_claim_the_root_below_zero():
    r = _check(sp.Min(sp.sqrt(t), 1))
    assert [(c.interval, c.expr) for c in r.cases] == [(sp.Interval(0, 1), sp.sqrt(t)), (sp.Interval.open(1, sp.oo), 1)]
    assert r.excluded == (sp.Interval.open(-sp.oo, 0),)


@pytest.mark.parametrize("expr", [
    sp.Min(sp.log(t), 1),                  # log below e, 1 above; nothing for t <= 0
    sp.Max(0, 1 / t),                      # a pole: 0 for t < 0, 1/t for t > 0, nothing at 0
    sp.Abs(sp.log(t)),                     # -log t on (0, 1]
    sp.sqrt(t) + sp.Max(0, t),             # was: sqrt(t) claimed for t <= 0
    sp.log(sp.Min(1, t)),                  # was: log(t) claimed for t < 0
    sp.Max(0, sp.asin(t)),                 # asin's domain [-1, 1]
    sp.Piecewise((sp.sqrt(1 - t ** 2), t < 2), (0, True)),
    sp.Max(0, t + sp.log(t)),              # 0 on (0, W(1)): was excluded
    sp.Max(1 - t, 0),                      # real everywhere: as before
])
def test_every_case_is_the_closed_form_and_every_exclusion_is_not_real(expr):
    _check(expr, extra=[sp.LambertW(1).evalf(30)] if expr.has(sp.log) else ())


def test_a_pole_is_a_breakpoint():
    r = _check(sp.Max(0, 1 / t))
    assert [(c.interval, c.expr) for c in r.cases] == [(sp.Interval.open(-sp.oo, 0), 0), (sp.Interval.open(0, sp.oo), 1 / t)]
    assert r.excluded == (sp.FiniteSet(0),)


def test_the_case_of_the_evaluation_point_states_where_it_is_real():
    a, b = sp.symbols("a b", real=True)
    r = readable(sp.Max(sp.sqrt(a) - b, 0), {a: sp.Integer(4), b: sp.Integer(1)})
    assert not r.complete and sp.Gt(a, 0) in r.cases[0].condition.args


# -- Abs and sign enclosed ---------------------------------------------------------------------------

def test_abs_is_enclosed_exactly():
    x = sp.Symbol("x", real=True)
    f = enclosures.interval_function(x, sp.Abs(x - sp.Rational(1, 3)))
    assert not f.refused
    iv = mpmath.iv
    whole = f(iv.mpf([0, 1]))
    assert whole.a == 0 and 2 / 3 <= whole.b <= 2 / 3 + 1e-15  # |x − 1/3| on [0, 1] is [0, 2/3]
    right = f(iv.mpf([0.5, 1]))
    assert 1 / 6 - 1e-15 <= right.a <= 1 / 6 and 2 / 3 <= right.b <= 2 / 3 + 1e-15
    # |x − 1/3| − 1/4 on [0, 1]: no zero on the cells the enclosure keeps off 0 (by hand, zeros at 1/12, 7/12)
    g = enclosures.interval_function(x, sp.Abs(x - sp.Rational(1, 3)) - sp.Rational(1, 4))
    assert g(iv.mpf([0.25, 0.375])).b < 0 and g(iv.mpf([0.625, 1])).a > 0 and g(iv.mpf([0, 0.125])).a <= 0


def test_sign_stays_refused():
    # sign is bounded but jumps: a finite enclosure would "prove" it continuous (syntax/continuity)
    x = sp.Symbol("x", real=True)
    assert enclosures.interval_function(x, sp.sign(x - 1)).refused
    assert enclosures.interval_function(x, sp.diff(sp.Abs(x - 1), x)).refused  # Abs' derivative: its roots are refused


def test_abs_in_a_box_enclosure():
    x, y = sp.symbols("x y", real=True)
    e = enclosures.enclose(sp.Abs(x - y), {x: (-1, 1), y: (0, 2)})
    assert e.a == 0 and e.b == 3  # |x − y| on [−1, 1] × [0, 2]: 0 at x = y, 3 at (−1, 2)


# -- the linter's point of a delta blow-up in two variables --------------------------------------------

def test_a_delta_blowup_in_two_variables_is_printed_as_a_point_of_the_box(tmp_path):
    # At a = 0 the delta sits on y = x with the weight 1/(√2·x) − 1/(√2·(1 − x)) (test_integ30, by hand):
    # it blows up at x = 0 and at x = 1, the points (0, 0) and (1, 1) of the box; each is the pole of one
    # of the two divisions.  main printed `(x, y) = (1)` (the zero set's one coordinate under two names)
    # and blamed the first division whatever the point.
    path = tmp_path / "diagonal.lgr"
    path.write_text("param a = 0\nint ([0, 1], [0, 1]) if y - x - a >= 0 then "
                    "1 / sqrt(x^2 + y^2) - 1 / sqrt((1 - x)^2 + (1 - y)^2) else 0 d(x, y)\n", encoding="utf-8")
    out = subprocess.run([sys.executable, "-P", "-m", "langur", "check", str(path), "--at", "a=0"],
                         capture_output=True, text=True, timeout=600,
                         env={**os.environ, "PYTHONPATH": str(ROOT)})
    (line,) = [ln for ln in out.stdout.splitlines() if "X313" in ln]
    point = re.search(r"at the point \(x, y\) = \(([^)]*)\)", line).group(1)
    assert point in ("0, 0", "1, 1"), line
    culprit = "`1 / sqrt(x^2 + y^2)`" if point == "0, 0" else "`1 / sqrt((1 - x)^2 + (1 - y)^2)`"
    assert f"the derivative of {culprit}" in line, line


# -- one evaluation: langur.precise ---------------------------------------------------------------------

def test_the_checks_evaluate_through_precise_only():
    # theorem, lint/tangent and syntax/turning had their own evalf(20/30/40) and sp.N calls
    for name in ("theorem.py", "lint/tangent.py", "syntax/turning.py"):
        text = (ROOT / "langur" / name).read_text(encoding="utf-8")
        code = "\n".join(ln.split("#")[0] for ln in text.splitlines())
        assert not re.search(r"\.evalf\(|\bsp\.N\(", code), name


def test_sign_and_number_are_not_rounded_to_doubles():
    tiny = sp.Integer(10) ** -400
    assert precise.sign(tiny) == 1 and precise.sign(-tiny) == -1 and precise.real_value(tiny) == 0.0
    assert precise.sign(sp.sqrt(2) ** 2 - 2) == 0  # exactly 0
    root2 = precise.number(sp.sqrt(2))
    assert root2 ** 2 - 2 != 0 and abs(root2 ** 2 - 2) < sp.Float("1e-48")  # 50 digits, not 16
    assert precise.number(sp.oo) is sp.oo
    for bad in (sp.sqrt(-2), sp.zoo, sp.Symbol("q"), sp.nan):
        with pytest.raises(precise.NotReal):
            precise.number(bad)
        with pytest.raises(precise.NotReal):
            precise.sign(bad)
    with pytest.raises(precise.NotReal):
        precise.sign(sp.oo)  # a sign of a finite value only
    assert precise.complex_value(sp.sqrt(-4)) == 2j and abs(precise.complex_value(sp.sqrt(-2), 20)) == pytest.approx(2 ** 0.5)


def test_an_argument_at_its_domain_end_on_an_interval_keeps_the_case():
    # disk.lgr's ⟦p⟧ = 2r²·asin(r/|r|) in the cell 0 < r < 1: asin's argument is 1, its domain's end, for
    # every r > 0 (a zero set that is an interval: its end 0 is the breakpoint); by hand 2r²·π/2 = πr²
    r = sp.Symbol("r", real=True)
    out = readable(2 * r ** 2 * sp.asin(r / sp.Abs(r)), {r: sp.Rational(1, 2)}, cell=(1 - r > 0, r > 0, r ** 2 > 0),
                   everywhere=False, generic=True)
    assert [(c.interval, c.expr) for c in out.cases] == [(sp.Interval.open(0, 1), sp.pi * r ** 2)]
