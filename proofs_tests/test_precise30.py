"""precise30: one high-precision evaluation, one public interval function that refuses what it would
enclose wrongly, no private attributes reached across modules.

* :mod:`langur.precise` is the one 50-digit evaluation: the linter's X311–X313 (``lint/singular``),
  the readable closed forms (``symbolic/readable``) and the quadrature's bounds (``symbolic/quadrature``)
  each had their own (30 digits; a complex value read as its real part, raised, or NaN).  A bound that
  is not a real number is now refused, not read as its real part.
* :func:`langur.enclosures.interval_function` (was the private ``_interval_fn``, imported by
  continuity, monotone and the implicit roots) refuses an equation holding ``Max``/``Min``/``Piecewise``/
  ``Heaviside``/…: lambdify prints them as Python comparisons of intervals, which pick one side of an
  interval holding both; on main, :func:`~langur.enclosures.certified_brackets` returned no sign
  change for an equation with two (below).
* ``lint/geometry`` kept its memo in ``Occurrence._moving``; now the public ``Occurrence.moves``,
  left unset when the decision is interrupted (main kept ``False``).
"""

from __future__ import annotations

import ast
import math
import pathlib
import random
from fractions import Fraction

import mpmath
import pytest
import sympy as sp

from langur import enclosures, precise
from langur.core import TooManyRoots
from langur.enclosures import certified_brackets, interval_function
from langur.lint import geometry
from langur.lint.collect import Occurrence
from langur.symbolic.quadrature import brackets, compiling
from langur.symbolic.readable import readable

ROOT = pathlib.Path(__file__).resolve().parents[1]
x, a = sp.symbols("x a", real=True)


# -- one high-precision evaluation ---------------------------------------------------------------

def test_a_point_is_read_as_the_doubles_the_compiled_integrand_sees():
    third = 1 / 3  # the double nearest 1/3, not 1/3
    want = float(1 - 3 * Fraction(third))  # by hand, exactly: 2⁻⁵⁴ = 5.55e-17
    assert want == 2.0 ** -54
    assert precise.real_number_at(1 - 3 * a, {a: third}) == want
    assert precise.real_number_at(1 - 3 * a, {a: sp.Rational(1, 3)}) == want  # read as the same double
    assert precise.real_value(1 - 3 * sp.Rational(1, 3)) == 0.0  # (exact: 0)


def test_a_number_that_is_not_real_is_refused_not_read_as_its_real_part():
    assert math.isnan(precise.real_value(sp.sqrt(-2)))
    with pytest.raises(precise.NotReal):
        precise.real_number(sp.sqrt(-2))
    with pytest.raises(TypeError):  # (NotReal is one: callers that caught float()'s TypeError still do)
        precise.real_number(sp.zoo)
    with pytest.raises(precise.NotReal):
        precise.real_number_at(sp.sqrt(a - 2), {a: 1.0})
    assert precise.real_number(sp.Rational(1, 3)) == 1 / 3
    # an unbounded end is ±inf, as before (the first version refused it: Theorem 8.1's F6 fell back to quadrature)
    assert precise.real_number(sp.oo) == math.inf and precise.real_number_at(-sp.oo, {a: 1.0}) == -math.inf


def test_an_implicit_roots_bracket_end_that_is_not_real_is_no_bound():
    """main read ``sqrt(a − 2)`` at a = 1 as the real part of i, 0.0: a bracket [0, 0]."""
    with pytest.raises(TypeError):
        brackets._bracket_range(sp.sqrt(a - 2), {a: 1.0})
    assert brackets._bracket_range(sp.sqrt(a + 2), {a: 2.0}) == (2.0, 2.0)  # √4, by hand


def test_readable_cases_unchanged():
    """max(0, 1 − t): 1 − t up to t = 1, 0 beyond (by hand)."""
    t = sp.Symbol("t", real=True)
    r = readable(sp.Max(0, 1 - t))
    assert [(c.interval, c.expr) for c in r.cases] == [(sp.Interval(-sp.oo, 1), 1 - t), (sp.Interval.open(1, sp.oo), 0)]


def test_the_private_evaluators_are_gone():
    for rel in ("langur/lint/singular.py", "langur/symbolic/readable.py", "langur/symbolic/quadrature/compiling.py"):
        tree = ast.parse((ROOT / rel).read_text())
        assert "_num" not in {n.name for n in ast.walk(tree) if isinstance(n, ast.FunctionDef)}, rel


# -- the public interval function refuses what it would enclose wrongly ----------------------------

def test_two_sign_changes_in_one_cell_of_a_piecewise_are_refused_not_missed():
    """(x + 1/25)(x + 1/50) for x < 0, else 1, on [−1, 2]: sign changes at −0.04 and −0.02 (by hand),
    both in the grid's cell [−0.0625, 0.125]; lambdify's ``x < 0`` on that cell's interval takes the
    ``else`` branch, [1, 1], "no zero": main returned no sign change at all."""
    f = sp.Piecewise(((x + sp.Rational(1, 25)) * (x + sp.Rational(1, 50)), x < 0), (1, True))
    g = sp.lambdify(x, f, "mpmath")
    assert g(-0.03) < 0 < g(-0.05) and g(-0.01) > 0  # the two sign changes
    enc, denc = interval_function(x, f), interval_function(x, sp.diff(f, x))
    with pytest.raises(TooManyRoots):  # (main: [])
        certified_brackets(g, enc, denc, 0, -1, 2)
    assert enc.refused and enc(mpmath.iv.mpf([-0.0625, 0.125])) is None
    with pytest.raises(TooManyRoots):  # lenient too (and at once: no cell is halved)
        certified_brackets(g, enc.bind(), denc.bind(), 0, -1, 2, lenient=True)


@pytest.mark.parametrize("e", [sp.Max(x, 0), sp.Min(x, a), sp.Piecewise((x, x < 0), (x + 5, True)),
                               sp.Heaviside(x), sp.sign(x), x * sp.Symbol("b"),  # (Abs: enclosed since precise31)
                               sp.Function("h")(x), sp.besselj(0, x), sp.oo * x])
def test_refused(e):
    enc = interval_function(x, e, (a,))
    assert enc.refused and enc(mpmath.iv.mpf([-1, 2]), 1) is None


def test_main_enclosed_max_wrongly():
    """What the refusal is for: ``max(0, X)`` of lambdify's text on X = [−1, 2] is 0 (Python's max
    compares the intervals), but max(0, 2) = 2."""
    fn = enclosures._on_intervals([x], sp.Max(0, x))
    assert mpmath.iv.mpf(fn(mpmath.iv.mpf([-1, 2]))).b < 2


def test_what_it_encloses_it_encloses_soundly():
    """Every primitive, a rational power, π and a parameter: the 50-digit value at random points of
    random intervals lies in the enclosure."""
    e = sp.exp(x) * sp.sin(3 * x) - a * x ** 3 + sp.log(x + 3) + sp.atan(x) * sp.erf(x) + sp.sqrt(x + 2) \
        - sp.pi * sp.tanh(x) + sp.cos(x) ** 2 + sp.Rational(1, 3) * x
    enc = interval_function(x, e, (a,))
    assert not enc.refused
    rng = random.Random(30)
    for _ in range(40):
        lo = rng.uniform(-1.5, 1.5)
        hi = lo + rng.uniform(0, 0.5)
        av = rng.uniform(-2, 2)
        box = enc(mpmath.iv.mpf([lo, hi]), av)
        for _ in range(5):
            p = rng.uniform(lo, hi)
            v = precise.value_at(e, (x, a), (p, av))
            assert box.a <= v <= box.b


def test_x_squared_minus_two_brackets_by_hand():
    brs = certified_brackets(sp.lambdify(x, x ** 2 - 2, "mpmath"), interval_function(x, x ** 2 - 2),
                             interval_function(x, 2 * x), 0, -2, 2)
    assert len(brs) == 2 and all(lo <= r <= hi for (lo, hi), r in zip(brs, (-math.sqrt(2), math.sqrt(2))))


def _imported_private(rel: str, module: str) -> set[str]:
    tree = ast.parse((ROOT / rel).read_text())
    return {n.name for node in ast.walk(tree) if isinstance(node, ast.ImportFrom) and (node.module or "").endswith(module)
            for n in node.names if n.name.startswith("_")}


@pytest.mark.parametrize("rel", ["langur/syntax/continuity.py", "langur/syntax/monotone.py",
                                 "langur/implicit/evalf.py", "langur/implicit/lambdified.py"])
def test_no_private_name_of_enclosures_imported(rel):
    assert _imported_private(rel, "enclosures") == set()


@pytest.mark.parametrize("rel", ["langur/symbolic/quadrature/brackets.py", "langur/symbolic/quadrature/deltaproblems.py",
                                 "langur/symbolic/quadrature/pieceproblems.py"])
def test_no_private_evaluator_of_compiling_imported(rel):
    assert "_num" not in _imported_private(rel, "compiling")


def test_interval_function_is_documented():
    assert "Refuses" in interval_function.__doc__ and "Max" in interval_function.__doc__


# -- lint/geometry: no private attribute of another module's class ----------------------------------

def _occurrence(f) -> Occurrence:
    return Occurrence(index=0, psi=None, span=None, f=f, branches=(({x: a}, ()),), uprime=(), nonzero=())


def test_moving_is_decided_once_on_a_public_field():
    """x − a = 0 is x = a: it moves with a (D_a = −1 ≠ 0); x − 1 = 0 does not (by hand)."""
    occ = _occurrence(x - a)
    assert occ.moves is None
    assert geometry.moving(occ, ["x"]) is True and occ.moves is True
    still = _occurrence(x - 1)
    assert geometry.moving(still, ["x"]) is False and still.moves is False
    assert "_moving" not in Occurrence.__dataclass_fields__


def test_an_interrupted_decision_is_not_kept(monkeypatch):
    """main set the memo to False before deciding: a time budget running out in the middle left
    "does not move" for every later question."""
    occ = _occurrence(x - a)

    def interrupted(*args, **kwargs):
        raise TimeoutError

    monkeypatch.setattr(geometry, "vanishes", interrupted)
    with pytest.raises(TimeoutError):
        geometry.moving(occ, ["x"])
    assert occ.moves is None
    monkeypatch.undo()
    assert geometry.moving(occ, ["x"]) is True


def test_geometry_reaches_no_private_attribute():
    tree = ast.parse((ROOT / "langur/lint/geometry.py").read_text())
    reached = {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute) and n.attr.startswith("_")
               and not n.attr.startswith("__")}
    assert reached == set()


# -- compiling's mpmath recomputation (renamed from _again, behaviour unchanged) -------------------

def test_mpmath_recomputes_what_overflowed_in_doubles():
    """exp(800x)·exp(−800x + a) at x = 1, a = 1/2 is e^½ (inf·0 in doubles); exp(800x) at x = 1 is
    beyond a double (+inf: too large, mpmath's value is finite); log of −1 stays NaN."""
    f = compiling._lambdify([x], sp.exp(800 * x) * sp.exp(-800 * x + a), {a: 0.5})
    assert f(1.0) == pytest.approx(math.exp(0.5), rel=1e-15)
    assert compiling._lambdify([x], sp.exp(800 * x), {})(1.0) == math.inf
    assert compiling._lambdify([x], -sp.exp(800 * x), {})(1.0) == -math.inf
    assert math.isnan(compiling._lambdify([x], sp.log(x), {})(-1.0))
