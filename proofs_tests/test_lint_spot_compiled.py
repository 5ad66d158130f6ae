"""The linter's numeric spot checks (``lint/algebra.spot_values``, guarding every symbolic verdict
of Def. 7.2's checks) compiled once per expression with mpmath, against the ``evalf(subs=…)``
evaluation they replace, point by point: same points kept (guards, complex and non-finite values
dropped alike), same values to 1e-12 — on random expressions with square roots of negative
numbers, logarithms, poles, piecewise terms, fixed parameter values and an implicit root (§7.3,
issue 18's conditions), where the compiled path may raise and must fall back.
"""

from __future__ import annotations

import random

import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.lint import algebra

x, y, a = sp.symbols("x y a", real=True)
_t = sp.Symbol("_t", real=True)


def _by_evalf(expr, symbols, guards, seed, fixed):
    """The same spot check with compilation switched off: every point through ``evalf``."""
    saved = algebra._compiled
    algebra._compiled = lambda e, names: None
    try:
        return algebra.spot_values(expr, symbols, guards, seed, fixed=fixed)
    finally:
        algebra._compiled = saved


def _random_expr(rng: random.Random) -> sp.Expr:
    atoms = [x, y, a, sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)), sp.Float(rng.uniform(-1, 1), 15)]
    unary = [sp.sqrt, sp.log, sp.exp, sp.sin, sp.Abs, lambda e: 1 / e, lambda e: e ** 3]

    def grow(depth):
        if depth == 0 or rng.random() < 0.25:
            return rng.choice(atoms)
        k = rng.random()
        if k < 0.35:
            return rng.choice(unary)(grow(depth - 1))
        if k < 0.7:
            return grow(depth - 1) + grow(depth - 1)
        if k < 0.9:
            return grow(depth - 1) * grow(depth - 1)
        return sp.Piecewise((grow(depth - 1), grow(depth - 1) > 0), (grow(depth - 1), True))

    return grow(4)


def _same(new, old):
    assert len(new) == len(old)
    for p, q in zip(new, old):
        assert abs(p - q) <= 1e-12 * max(1.0, abs(q)), (p, q)


def test_compiled_spot_values_match_evalf_on_random_expressions():
    rng = random.Random(20261127)
    kept = 0
    for i in range(60):
        try:
            expr, guard = _random_expr(rng), _random_expr(rng)
        except TypeError:  # a piecewise condition sympy rejects (a comparison of a non-real)
            continue
        fixed = {a: sp.Rational(rng.randint(-9, 9), 7)} if i % 2 else None
        symbols = [x, y] if fixed else [x, y, a]
        new = algebra.spot_values(expr, symbols, [guard], seed=i, fixed=fixed)
        _same(new, _by_evalf(expr, symbols, [guard], i, fixed))
        kept += len(new)
    assert kept > 100  # the comparison is not vacuous: most expressions keep points


def test_cancellation_stays_below_the_tolerance():
    # identically zero after 15 digits cancel: the compiled value must still read as zero
    e = (x * 10 ** 8 + 1) ** 2 - x ** 2 * 10 ** 16 - 2 * x * 10 ** 8 - 1
    values = algebra.spot_values(e, [x], seed=1)
    assert len(values) == algebra.SPOT_POINTS
    assert all(abs(v) < algebra._TOL for v in values)
    assert algebra.vanishes(e, [x])


def test_an_implicit_root_is_compiled_and_agrees_with_evalf():
    # the root of t^3 + t = x + a on [-3, 3] (monotone), minus the closed form of Cardano's root
    root = ImplicitRootFn(sp.Lambda(_t, _t ** 3 + _t), x + a, -3, 3, -1, 0)
    s = sp.real_root(((x + a) / 2 + sp.sqrt((x + a) ** 2 / 4 + sp.Rational(1, 27))), 3)
    cardano = s - 1 / (3 * s)
    fixed = {a: sp.Rational(1, 5)}
    new = algebra.spot_values(root, [x], [1 - x ** 2], seed=4, fixed=fixed)
    _same(new, _by_evalf(root, [x], [1 - x ** 2], 4, fixed))
    diff = algebra.spot_values(root - cardano, [x], [1 - x ** 2], seed=4, fixed=fixed)
    assert len(diff) == algebra.SPOT_POINTS and all(abs(v) < 1e-12 for v in diff)


def test_a_value_that_is_not_a_number_falls_back_to_evalf():
    # a fixed value with a free symbol cannot be compiled: evalf decides, and finds no number
    values = algebra.spot_values(x + a, [x], seed=2, fixed={a: y})
    assert values == _by_evalf(x + a, [x], (), 2, {a: y}) == []
