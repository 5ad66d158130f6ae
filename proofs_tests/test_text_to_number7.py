"""Loading with fewer Python steps, ninth pass (issue 15, branch front7): a loop's index leaf and
its powers built in integer arithmetic (``core.index_const``, ``core.index_power_small``), the
solution of an affine completion built from the shapes of the first one of its shape
(``affine._ordered`` with the shape's table), and the LALR driver's table resolved once
(``syntax/lalr.py``; its trees, spans and errors are compared with lark's by ``test_lalr.py``).

Each fast builder is compared with the constructors it replaces (equal, every attribute the same),
and conditions of one shape completed with the shape's table kept give what completing each one
alone gives.
"""

from __future__ import annotations

import random
from fractions import Fraction

import pytest

from langur import core
from langur.frontend import core_term_from_text
from langur.syntax import affine
from langur.syntax.parser import parse_term

_INTS = [0, 1, -1, 2, -3, 10, 99, -1000, 2 ** 255, 2 ** 256 + 1, -(2 ** 300), 2 ** 999 - 1, 2 ** 999,
         2 ** 1000, -(2 ** 1200), 3 ** 700]
_EXPONENTS = [-65, -64, -5, -3, -2, -1, 0, 1, 2, 3, 5, 63, 64, 65]


def test_index_const_is_the_constructors_const():
    r = random.Random(0)
    for v in _INTS + [r.randint(-10 ** 6, 10 ** 6) for _ in range(200)]:
        span = object()
        made, built = core.Const(Fraction(v), span=span), core.index_const(v, span)
        assert made == built and built.span is span
        assert core.kept_attributes(made) == core.kept_attributes(built), v


def test_index_power_small_is_small_power():
    # small_power(small value of Const(v), k): the rational v^k when it is small (numerator and
    # denominator in range), False when not (a 1000-bit power, a 300-bit denominator, 0^-1, 0^0)
    r = random.Random(1)
    for v in _INTS + [r.randint(-999, 999) for _ in range(100)]:
        x = core.small_value(core.Const(Fraction(v)))
        for n in _EXPONENTS:
            expected = core.small_power(x, Fraction(n))
            got = core.index_power_small(v, n)
            assert got == expected and type(got) is type(expected), (v, n, got, expected)
    assert core.index_power_small(7, -2) == Fraction(1, 49)
    assert core.index_power_small(-2, -3) == Fraction(-1, 8)
    assert core.index_power_small(0, -1) is False and core.index_power_small(0, 0) is False
    assert core.index_power_small(2, 64) == 2 ** 64 and core.index_power_small(2, 65) is False


_CONDITIONS = ["x + 1/i + a - 1", "2*x - y + 3*a - 1/i", "x/3 - a + i/7", "-x + 2*y - 1/i", "x - 1/i"]


@pytest.mark.parametrize("text", _CONDITIONS)
def test_conditions_of_one_shape_completed_alike(text):
    # every copy's condition completed while the shape's table (its sums' shapes, its branches by
    # constant) is kept, against each condition completed with the memos emptied first: equal Ψ̂,
    # equal inverse branches with every attribute of every node the same
    variables = ("x", "y")
    kept = []
    for i in list(range(1, 40)) + [-7, 10 ** 40 + 1]:
        cond = _core(text.replace("i", f"({i})"))
        kept.append((cond, affine.complete(cond, variables)))
    for cond, psi in kept:
        affine._solve.cache_clear()
        affine._atoms.cache_clear()
        alone = affine.complete(cond, variables)
        assert psi == alone
        for b, c in zip(psi.branches, alone.branches):
            for s, t in zip(b.components, c.components):
                _same_everywhere(s, t)


def _core(text: str) -> core.Term:
    """The core term of a surface term over x, y and the parameter a."""
    return core_term_from_text(text, variables=("x", "y"), params=("a",))




def _same_everywhere(s: core.Term, t: core.Term) -> None:
    stack = [(s, t)]
    while stack:
        a, b = stack.pop()
        assert a == b
        assert core.kept_attributes(a) == core.kept_attributes(b), (a, b)
        stack.extend(zip(core.children(a), core.children(b)))


def test_the_parser_still_parses_a_term():
    # (the driver's resolved table: a term whose last reductions are a run of unit rules)
    assert parse_term("x").name == "x"
    assert parse_term("((1))").value == 1
