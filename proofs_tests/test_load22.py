"""A loop's copies add up their conditions' constant terms in integers (issue 15, branch load22).

``template.Template`` completes a copy's condition that differs from the first copy's only in
constant summands by moving the solution's constant term (``affine.summands``); the constant is
now kept as a numerator and a denominator (``copies.moved``) and the completion made by
``affine.solved_at_ratio``, which builds the ``Fraction`` only when the branch is new.  Checked
here: the integer arithmetic against ``Fraction``'s; ``solved_at_ratio`` against ``solved_at``;
and loops whose conditions shift with factors 1, −1 and others (``2*x + i``: the solution moves
by −i/2) against the copies desugared one by one and against the solution computed by hand.
"""

from __future__ import annotations

import random
from fractions import Fraction

import pytest

from langur.core import Add, Const, Mul, Param, Var, free_vars
from langur.frontend import clear_load_cache, load_text
from langur.operational import estimate_value
from langur.syntax import affine, template
from langur.syntax.copies import STATS, moved


def test_moved_is_fraction_arithmetic():
    r = random.Random(22)
    for _ in range(500):
        base = Fraction(r.randint(-50, 50), r.randint(1, 40))
        new = Fraction(r.randint(-50, 50), r.randint(1, 40))
        factor = Fraction(r.choice([1, -1, 2, -3]), r.choice([1, 1, 5]))
        sign = 1 if factor == 1 else (-1 if factor == -1 else 0)
        num, den = moved(base.numerator, base.denominator, new, factor, sign)
        assert den > 0
        assert Fraction(num, den) == base + factor * new


def test_solved_at_ratio_is_solved_at():
    x, a = Var("x"), Param("a")
    for k in (1, 2, 7):
        cond = Add(Add(Mul(Const(Fraction(k)), x), a), Const(Fraction(3, 4)))  # k·x + a + 3/4
        solved, c0 = affine.solve(cond, ("x",))
        for constant in (Fraction(-3, 4), Fraction(5, 9), Fraction(0), Fraction(11)):
            one = affine.solved_at(cond, ("x",), solved, constant)
            two = affine.solved_at_ratio(cond, ("x",), solved, constant.numerator, constant.denominator)
            assert one == two
            assert one.branches is two.branches  # the same constant: the branch built once
        # a constant not met before: its branch built from the integers
        fresh = affine.solved_at_ratio(cond, ("x",), solved, -13, 17)
        (component,) = fresh.branches[0].components
        assert free_vars(component) == {"u0"}
        assert fresh == affine.solved_at(cond, ("x",), solved, Fraction(-13, 17))


def _load(text: str, enabled: bool):
    clear_load_cache()
    old = template.ENABLED
    template.ENABLED = enabled
    try:
        return load_text(text)
    finally:
        template.ENABLED = old
        clear_load_cache()


@pytest.mark.parametrize("cond, root", [
    ("x + 1/i + a - 1 >= 0", lambda i, a: 1 - a - Fraction(1, i)),  # factor 1
    ("x - i/3 + a >= 0", lambda i, a: Fraction(i, 3) - a),           # factor −1 in the solution
    ("2*x + i - a >= 0", lambda i, a: (a - i) / 2),                   # factor −1/2
    ("3*x - 2*i + a <= 0", lambda i, a: (2 * i - a) / 3),             # factor 2/3
])
def test_copies_shifted_in_integers(cond, root):
    text = f"param a = 0.25\nint ([-30, 30]) sum i in 2..9: [{cond}] * (x + i) d(x)\n"
    before = dict(STATS)
    built = _load(text, True)
    assert STATS["shifted"] - before["shifted"] >= 7  # the copies took the integer path
    desugared = _load(text, False)
    assert built.program == desugared.program
    # the solution of each copy's condition, by hand: the branch's constant at u0 = 0 is the root
    copies = []
    stack = [built.program.integrand]
    while stack:
        u = stack.pop()
        if type(u).__name__ == "IfDiffeo":
            copies.append(u.psi)
            continue
        stack.extend(getattr(u, f) for f in ("left", "right") if hasattr(u, f))
    assert len(copies) == 8
    a = Fraction(1, 4)
    roots = sorted(_value(psi.branches[0].components[0], a) for psi in copies)
    assert roots == sorted(root(i, a) for i in range(2, 10))
    # and the numbers: the same program evaluated by the Monte Carlo engine, both ways
    one = estimate_value(built, {"a": 0.3}, samples=2000, seed=3)
    two = estimate_value(desugared, {"a": 0.3}, samples=2000, seed=3)
    assert one.value == two.value


def _value(t, a: Fraction) -> Fraction:
    """A branch's component at u0 = 0 and parameter ``a``, exactly (sums and products only)."""
    name = type(t).__name__
    if name == "Const":
        return t.value
    if name == "Var":
        return Fraction(0)
    if name == "Param":
        return a
    if name == "Add":
        return _value(t.left, a) + _value(t.right, a)
    if name == "Mul":
        return _value(t.left, a) * _value(t.right, a)
    if name == "Pow":
        return _value(t.base, a) ** t.exponent
    raise TypeError(name)
