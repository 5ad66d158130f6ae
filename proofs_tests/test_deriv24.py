"""Issue 15, branch deriv24: answers the exact engine asked for again and again, remembered by their
arguments — ``walks.free_symbols``, ``walks.size`` (beyond the walked limit), ``walks.has_any`` and
``decompose.psi_of`` — and ``numpy.roots``' steps without its checks (``roots._companion_roots``).

Each remembered answer is compared with the answer computed independently (sympy's own
``free_symbols``, ``has`` and preorder traversal; ``psi_of``'s computation without the memo, on a
fresh Diffeo), asked twice (the second answer comes from the memo), and a caller's change to a
returned set must not reach the memo."""

from __future__ import annotations

import random
from fractions import Fraction

import numpy as np
import pytest
import sympy as sp

from langur.core import Diffeo, InverseBranch, Param, Var, const, sub
from langur.core import Mul as CMul
from langur.implicit import implicit_root
from langur.symbolic import decompose, walks
from langur.symbolic.decompose import Ctx
from langur.symbolic.quadrature import roots

x, y, z = sp.symbols("x y z", real=True)
w = sp.Symbol("w")
ATOMS = [x, y, z, w, sp.Integer(2), sp.Rational(-3, 7), sp.Float("0.125", 30), sp.Float(1.5), sp.I, sp.pi]


def _random(r: random.Random, depth: int):
    if depth == 0:
        return r.choice(ATOMS)
    a, b = _random(r, depth - 1), _random(r, depth - 1)
    return r.choice([lambda: a + b, lambda: a * b, lambda: a - b, lambda: sp.Pow(a, r.choice([2, -1, 3])),
                     lambda: sp.sin(a) + b, lambda: sp.Abs(a) * b, lambda: sp.Piecewise((a, b > 0), (0, True))])()


def _cases(seed: int, n: int) -> list:
    r = random.Random(seed)
    out = []
    while len(out) < n:
        try:
            out.append(_random(r, r.randrange(1, 5)))
        except (TypeError, ValueError, ZeroDivisionError):
            continue
    return out


@pytest.mark.parametrize("seed", range(3))
def test_free_symbols_remembered_and_fresh(seed):
    for e in _cases(seed, 120):
        want = e.free_symbols
        got = walks.free_symbols(e)
        assert got == want
        got.add(sp.Symbol("intruder"))  # a caller may change the set it got: the memo must not see it
        assert walks.free_symbols(e) == want
    R = implicit_root(y ** 2 - x, y, 0, 0, 2)
    assert walks.free_symbols(R + z) == (R + z).free_symbols == {x, z}


@pytest.mark.parametrize("seed", range(3))
def test_size_beyond_the_walked_limit(seed):
    """``size`` with a large limit: the number of nodes of the tree (each occurrence counted), here
    counted by sympy's preorder traversal; asked twice (remembered), and with small limits."""
    for a in _cases(seed, 60):
        e = (a + x) * (a - y) + sp.sin(a * z) ** 2
        n = sum(1 for _ in sp.preorder_traversal(e))
        for _ in range(2):
            assert walks.size(e, 10 ** 6) == n
            assert walks.size(e, walks.WALKED_SIZE + 1) == min(n, walks.WALKED_SIZE + 1)
            assert walks.size(e, 3) == min(n, 3)


@pytest.mark.parametrize("seed", range(3))
def test_has_any_remembered(seed):
    kinds = [(sp.Float,), (sp.Piecewise,), (sp.Abs, sp.sin), (sp.Pow,), (sp.Symbol,)]
    for e in _cases(seed, 120):
        for types in kinds:
            want = e.has(*types)
            assert walks.has_any(e, types) == want
            assert walks.has_any(e, types) == want
    # equal-looking trees with a Float and with a rational are told apart (sympy's equality does)
    assert walks.has_any(x + sp.Float(0.5), (sp.Float,)) and not walks.has_any(x + sp.Rational(1, 2), (sp.Float,))


def _diffeo(k: Fraction):
    """ifge0 ⌊x − k·a ≥ 0⌋ in x: Ψ̂ = (x − k·a), inverse u₀ + k·a (a parameter)."""
    X, A, U = Var("x"), Param("a"), Var("u0")
    ka = CMul(const(k), A)
    return Diffeo(("x",), (sub(X, ka),), ("u0",), (InverseBranch((sub(U, CMul(const(-1), ka)),)),), solved_for="x")


def test_psi_of_remembered():
    """``psi_of`` for the same Diffeo and context: the Ψ̂ computed without the memo (on an equal Diffeo
    built anew), the same object when asked again; another point or a Float in it: computed anew."""
    a = sp.Symbol("a", real=True)
    ctx = Ctx(variables=("x",))
    for k in (Fraction(1, 3), Fraction(-2), Fraction(5, 7)):
        first = decompose.psi_of(_diffeo(k), ctx)
        assert first == decompose._psi_of(_diffeo(k), ctx)
        assert first.forward[0] == sp.Symbol("x", real=True) - sp.Rational(k.numerator, k.denominator) * a
        assert decompose.psi_of(_diffeo(k), ctx) is first
        at = Ctx(variables=("x",), at={a: sp.Rational(1, 2)})
        assert decompose.psi_of(_diffeo(k), at) == decompose._psi_of(_diffeo(k), at)
        floats = Ctx(variables=("x",), at={a: sp.Float(0.5)})
        before = len(decompose._PSIS)
        assert decompose.psi_of(_diffeo(k), floats) == decompose._psi_of(_diffeo(k), floats)
        assert len(decompose._PSIS) == before  # (not kept: a Float in the point)


@pytest.mark.parametrize("seed", range(3))
def test_companion_roots_is_numpys_roots(seed):
    """``roots._companion_roots``: numpy.roots' array, element for element (real and complex roots,
    bit for bit), for polynomials of degree 3 to 6 with the first and last coefficients not 0 —
    the case ``polynomial_roots`` gives it; and ``polynomial_roots`` with a trailing 0 (numpy.roots'
    own way) the same as before."""
    r = random.Random(seed)
    for _ in range(400):
        n = r.randrange(4, 8)
        cs = [r.choice([r.uniform(-3, 3), float(r.randrange(-4, 5)) or 1.0, r.uniform(-1e-8, 1e-8)]) for _ in range(n)]
        cs[0] = cs[0] or 1.0
        cs[-1] = cs[-1] or -0.5
        got, want = roots._companion_roots(cs), np.roots(np.array(cs, dtype=float))
        assert got.dtype == want.dtype and got.shape == want.shape
        assert [complex(g).__repr__() for g in got] == [complex(g).__repr__() for g in want]
        trailing = cs + [0.0]
        expected = [float(z.real) for z in np.roots(np.array(trailing)) if abs(z.imag) <= roots.REAL_SLACK * (1 + abs(z))]
        assert roots.polynomial_roots(trailing) == expected
