"""exact7 (issue 15): the exact engine's shortcuts give what the slow paths gave.

* ``walks.atoms_of(e, types)`` is sympy's ``e.atoms(*types)`` with each distinct subtree visited
  once (``quadrature.printable`` uses it: sympy's walk visits every repeat of a shared subtree);
  checked against sympy's own ``atoms`` on random trees with shared subtrees, on Piecewise /
  relational / Tuple trees, and on a real closed form (stylize/linear.lgr's ∂/∂ax).
* ``quadrature.printable`` still replaces exactly the rationals of more than 4,000 bits.
* ``local.monomials`` keeps its subtrees' decompositions across calls: the decomposition of each
  weight equals the one computed with nothing remembered, and Σ c_ab xᵃ yᵇ expands to the weight;
  a weight holding Floats does not use (nor fill) the memo.
* ``quadrature.delta_problems`` remembers det DΨ̂ per Ψ̂: the remembered determinant equals
  sympy's (since exact13r it is the cofactor formula, not sympy's simplified form), and a delta
  piece's quadrature is the same number with and without the memo.
"""

from __future__ import annotations

import random
from pathlib import Path

import sympy as sp

from langur.ddenote import ddenote_program
from langur.frontend import load
from langur.symbolic import local
from langur.symbolic.local import monomials
from langur.symbolic.quadrature import printable
from langur.symbolic.quadrature.deltaproblems import _FORWARD_DETS
from langur.symbolic.walks import atoms_of

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
x, y, a, b, c = sp.symbols("x y a b c")


def _random_tree(rng: random.Random, depth: int, pool: list):
    """A random expression over x, y, a, b, c and rationals, reusing earlier subtrees (``pool``)
    so that the tree shares subtrees the way the engine's closed forms do."""
    if depth == 0 or rng.random() < 0.2:
        leaf = rng.choice([x, y, a, b, c, sp.Rational(rng.randint(-9, 9), rng.randint(1, 9)), sp.Integer(2)])
        return leaf
    if pool and rng.random() < 0.4:
        return rng.choice(pool)
    kind = rng.randrange(5)
    l, r = _random_tree(rng, depth - 1, pool), _random_tree(rng, depth - 1, pool)
    if kind == 0:
        out = l + r
    elif kind == 1:
        out = l * r
    elif kind == 2:
        out = (l + 1) ** rng.randint(-2, 3)
    elif kind == 3:
        out = sp.Abs(l) + sp.sqrt(r ** 2 + 1)
    else:
        out = sp.Piecewise((l, sp.Gt(x, a)), (r, sp.Le(y, b) & sp.Ne(c, 0)), (0, True))
    pool.append(out)
    return out


def test_atoms_of_is_sympys_atoms_on_random_shared_trees():
    rng = random.Random(7)
    types_list = [(sp.Rational,), (sp.Symbol,), (sp.Pow,), (sp.Add, sp.Mul), (sp.Piecewise,),
                  (sp.core.relational.Relational,), (sp.Abs, sp.Integer)]
    for _ in range(60):
        pool: list = []
        e = sum((_random_tree(rng, 5, pool) for _ in range(3)), sp.Integer(0))
        for types in types_list:
            assert atoms_of(e, types) == e.atoms(*types), (e, types)


def test_atoms_of_descends_into_tuples_and_containers():
    e = sp.Tuple(sp.Rational(1, 3) * x, sp.Tuple(y ** 2, sp.Rational(5, 7)), sp.Eq(a, 2))
    for types in [(sp.Rational,), (sp.Symbol,), (sp.Tuple,), (sp.Eq,)]:
        assert atoms_of(e, types) == e.atoms(*types)


def test_atoms_of_on_an_examples_closed_form():
    loaded = load(str(EXAMPLES / "stylize" / "linear.lgr"))
    at = loaded.param_values()
    e = ddenote_program(loaded.program, at, {"ax": 1}).expr
    assert e is not None
    for types in [(sp.Rational,), (sp.Symbol,), (sp.Pow,)]:
        assert atoms_of(e, types) == e.atoms(*types)


def test_printable_replaces_exactly_the_huge_rationals():
    huge = sp.Rational(3 ** 3000, 7 ** 1500)  # > 4000 bits in the numerator
    small = sp.Rational(3 ** 100, 7)
    e = huge * x + small * y + huge * sp.sqrt(x + huge)
    out = printable(e)
    assert out == e.xreplace({huge: sp.Float(huge, 30)})
    assert small in out.atoms(sp.Rational) and huge not in out.atoms(sp.Rational)
    assert printable(small * x + 1) == small * x + 1


def _expanded(coeffs: dict):
    return sp.expand(sum((cf * x ** i * y ** j for (i, j), cf in coeffs.items()), sp.Integer(0)))


def test_monomials_across_calls_equal_a_fresh_decomposition(monkeypatch):
    rng = random.Random(3)
    # weights sharing subtrees, as a program's partial derivatives do
    u = (a - b) * x + (c + 1) * y - a * b
    v = (b * x - c * y + 1) / (a + 2)
    weights = [u * v, sp.diff(u * v, a), sp.diff(u * v, b) + u ** 2, (u - v) ** 3 * (a + x), v ** 2 + u * v * c]
    for _ in range(3):
        rng.shuffle(weights)
        for w in weights:
            remembered = monomials(w, x, y)
            local._MONOMIALS.clear()
            fresh = monomials(w, x, y)
            assert remembered == fresh
            assert sp.simplify(_expanded(fresh) - sp.expand(w)) == 0
    # Floats: neither read nor written
    local._MONOMIALS.clear()
    wf = sp.Float(0.5, 30) * u * x + v
    assert sp.simplify(_expanded(monomials(wf, x, y)) - sp.expand(wf)) == 0
    assert not local._MONOMIALS.get((x, y), ({}, {}))[0]


def test_forward_determinants_are_sympys_and_the_quadrature_is_unchanged():
    loaded = load(str(EXAMPLES / "fig9.lgr"))
    at = loaded.param_values()
    _FORWARD_DETS.clear()
    fresh = ddenote_program(loaded.program, at, {"theta": 1})
    assert _FORWARD_DETS
    for (forward, variables), det in _FORWARD_DETS.items():
        assert sp.cancel(det - sp.Matrix(forward).jacobian(list(variables)).det()) == 0
    remembered = ddenote_program(loaded.program, at, {"theta": 1})  # det DΨ̂ from the memo
    assert fresh.boundary.check == remembered.boundary.check  # the quadrature, bit for bit
    assert fresh.value == remembered.value == 4.0  # Fig. 9: the paper's value
