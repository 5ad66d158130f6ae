"""exact6 (issue 15): the exact engine's deterministic tidy and the code printers' shared texts.

* ``integrate._tidy`` folds (``sympy.piecewise_fold``) a closed form whose Piecewise conditions are
  not polynomial (``sqrt(a) <= 1``) instead of running sympy's simplify on it under a CPU cap: the
  printed form no longer depends on whether simplify finished before the cap (the machine's load).
  Checked: the form is the same with no time for simplify at all, and it is the hand-derived
  derivative (∫₀¹ [x² ≥ a] dx = 1 − √a, ∫₋₁¹ [x² ≥ a] dx = 2 − 2√a) at many parameter values.
* ``text.shared_lambdify`` keeps subtrees' code across printers: the generated code is still
  sympy's own (``sympy.lambdify``), character for character, whatever was printed before, and
  equal trees of different Float precisions do not share text.
"""

from __future__ import annotations

import inspect
import math
import random
from pathlib import Path

import sympy as sp

from langur.exact import exact_deriv
from langur.frontend import load
from langur.symbolic import integrate, text
from langur.symbolic.integrate import _nonpolynomial_conditions
from langur.symbolic.text import shared_lambdify

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
a, x, y, z = sp.symbols("a x y z")


def test_nonpolynomial_conditions_are_recognised():
    s = sp.sqrt(a)
    assert _nonpolynomial_conditions(sp.Piecewise((1 / s, (s >= 0) & (s <= 1)), (0, True)))
    assert _nonpolynomial_conditions(2 * sp.Piecewise((a, sp.log(a + 1) <= 1), (0, True)))
    # polynomial conditions (risk.lgr, window.lgr) keep sympy's simplify; no Piecewise: nothing to fold
    assert not _nonpolynomial_conditions(sp.Piecewise((sp.exp(a), (a >= -10) & (a <= y)), (0, True)))
    assert not _nonpolynomial_conditions(sp.Piecewise((1, a ** 2 - 2 * a * y <= 3), (0, True)))
    assert not _nonpolynomial_conditions(sp.sqrt(a) + sp.log(a))


def _derivative_form(path: Path):
    loaded = load(str(path))
    at = loaded.param_values()
    return exact_deriv(loaded.program, at, {"a": 1})


def test_tidy_is_the_same_without_time_for_simplify(monkeypatch):
    """The printed closed form of quadratic_one_root.lgr's derivative does not depend on the cap
    (before: sympy's simplify took ~0.9-1.2 CPU s against a 1 s cap, and either form was printed)."""
    path = EXAMPLES / "adapters" / "programs" / "quadratic_one_root.lgr"
    integrate._TIDIED.clear()
    normal = _derivative_form(path)
    integrate._TIDIED.clear()
    monkeypatch.setattr(integrate, "TIDY_SECONDS", 1e-6)  # simplify could not finish anything
    starved = _derivative_form(path)
    assert normal.expr == starved.expr
    assert normal.value == starved.value == -1.0


def test_folded_forms_are_the_hand_derived_derivatives():
    """d/da (1 − √a) = −1/(2√a) on [0, 1] (quadratic_one_root.lgr); d/da (2 − 2√a) = −1/√a
    (quadratic.lgr): the closed forms, as printed, at parameter values across their cell a > 0."""
    for name, want in (("quadratic_one_root.lgr", lambda v: -1 / (2 * math.sqrt(v))),
                       ("quadratic.lgr", lambda v: -1 / math.sqrt(v))):
        res = _derivative_form(EXAMPLES / "adapters" / "programs" / name)
        form = sp.sympify(res.expr)
        assert form.free_symbols == {sp.Symbol("a")}
        for v in (0.01, 0.1, 0.25, 0.5, 0.9, 0.99):
            got = float(form.subs(sp.Symbol("a"), sp.Rational(str(v))))
            assert math.isclose(got, want(v), rel_tol=1e-12), (name, v, got)
        if name == "quadratic.lgr":  # folded: 2·Piecewise((−1/(2|√a|), …)) → Piecewise((−1/|√a|, …))
            assert isinstance(form, sp.Piecewise)


def _random_tree(rng: random.Random, leaves: list, depth: int):
    if depth == 0 or rng.random() < 0.2:
        return rng.choice(leaves)
    op = rng.choice(["add", "mul", "pow", "fn", "div"])
    u, v = _random_tree(rng, leaves, depth - 1), _random_tree(rng, leaves, depth - 1)
    if op == "add":
        return u + v
    if op == "mul":
        return u * v
    if op == "pow":
        return u ** rng.choice([2, 3, -1, sp.Rational(1, 2)])
    if op == "fn":
        return rng.choice([sp.sin, sp.exp, sp.Abs, sp.cos])(u)
    return u / (v ** 2 + 1)


def _code(f) -> str:
    return inspect.getsource(f)


def test_shared_code_is_sympys_code_whatever_was_printed_before():
    """Trees sharing subtrees (a pool of them reused across expressions), compiled one after the
    other for math, mpmath and numpy: every generated function's source is sympy's lambdify's,
    and its values are the same."""
    rng = random.Random(6)
    pool = [x, y, z, sp.pi, sp.Rational(3, 7), sp.Float("0.1", 15), x * y + 1, sp.sqrt(z ** 2 + 1)]
    for _ in range(12):
        pool.append(_random_tree(rng, pool, 3))
    args = [x, y, z]
    for module in ("math", "mpmath", "numpy"):
        for k in range(10):
            e = _random_tree(rng, pool, 3) + pool[-1 - k % 5]
            ours, theirs = shared_lambdify(args, e, module), sp.lambdify(args, e, modules=[module])
            assert _code(ours) == _code(theirs), (module, e)
            pt = (0.3, -0.7, 1.1)
            try:
                want = complex(theirs(*pt))
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                continue
            got = complex(ours(*pt))
            assert got == want or (math.isnan(got.real) and math.isnan(want.real))


def test_floats_of_other_precisions_do_not_share_code():
    """0.1 at 15 and at 30 digits are different trees (sympy's equality sees the precision), printed
    with their own digits even when the other was printed first."""
    low, high = x + sp.Float(0.1, 15), x + sp.Float(0.1, 30)
    f_low = shared_lambdify([x], sp.sin(low), "math")
    f_high = shared_lambdify([x], sp.sin(high), "math")
    assert _code(f_low) == _code(sp.lambdify([x], sp.sin(low), modules=["math"]))
    assert _code(f_high) == _code(sp.lambdify([x], sp.sin(high), modules=["math"]))
    assert _code(f_low) != _code(f_high)


def test_constants_printed_before_still_resolve_in_a_new_function():
    """A subtree naming module constants (π, e), printed first in one function, then taken from the
    shared texts in another: the new function still evaluates (the names are imported)."""
    text._CODE_TEXTS.clear()
    first = shared_lambdify([x], sp.pi * x + sp.E, "numpy")
    second = shared_lambdify([x, y], sp.cos(sp.pi * x + sp.E) * y, "numpy")
    assert math.isclose(float(first(1.0)), math.pi + math.e)
    assert math.isclose(float(second(0.5, 2.0)), 2 * math.cos(math.pi / 2 + math.e))
    assert _code(second) == _code(sp.lambdify([x, y], sp.cos(sp.pi * x + sp.E) * y, modules=["numpy"]))
