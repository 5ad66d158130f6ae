"""Issue 15, deriv20: the generated ``math`` and ``numpy`` code of ``text.shared_lambdify`` evaluates
each repeated subexpression once (``langur.symbolic.cse``) and gives what sympy's ``lambdify`` gives:
the same values bit for bit, the same exception (type and message) where it raises; lazy forms are
left as they were; the stylization kernel's vectorized weight, the case it is for, evaluates its
repeated parts once and gives sympy's values."""

from __future__ import annotations

import math
import random
import struct

import numpy as np
import pytest
import sympy as sp

from langur.symbolic import cse, text
from langur.symbolic.text import shared_lambdify

x, y, z = sp.symbols("x y z", real=True)


@pytest.fixture(autouse=True)
def _every_size(monkeypatch):
    """Short code rewritten too (the engine leaves code under ``text.SHARED_CODE`` characters as it is)."""
    monkeypatch.setattr(text, "SHARED_CODE", 0)


def _bound_names(f) -> list[str]:
    return [n for n in f.__code__.co_varnames if n.startswith(cse.PREFIX)]


def _expression(rng: random.Random, size: int) -> sp.Expr:
    """A random expression over x, y, z built from a pool of its own subexpressions (so that subtrees
    repeat, as in a weight built by substitution), with divisions, powers and math's partial
    functions (raising somewhere)."""
    pool = [x, y, z, x - y, y + 2 * z, sp.Rational(3, 7) * x]
    for _ in range(size):
        a, b = rng.choice(pool), rng.choice(pool)
        op = rng.randrange(8)
        e = (a + b if op == 0 else a * b if op == 1 else a / b if op == 2 else a - 3 * b if op == 3
             else a ** rng.choice([2, 3, -1, sp.Rational(1, 2)]) if op == 4 else sp.sqrt(a) * b if op == 5
             else sp.exp(a / 4) + b if op == 6 else sp.log(a) - b)
        pool.append(e)
    return sp.Add(*rng.sample(pool[6:], 4))


def _same_float(a: float, b: float) -> bool:
    return (math.isnan(a) and math.isnan(b)) or struct.pack("<d", a) == struct.pack("<d", b)


def _outcome(f, *args):
    try:
        v = f(*args)
    except Exception as exc:  # noqa: BLE001 - the exception is the outcome compared
        return ("raised", type(exc), str(exc))
    return ("value", v)


@pytest.mark.parametrize("seed", range(12))
def test_math_code_same_values_and_exceptions_as_sympy(seed):
    rng = random.Random(seed)
    e = _expression(rng, 14)
    # (and a sum whose terms share a part, as a weight built by substitution: that part bound once)
    e = e + (e.args[0] + z) * sp.sin(x) + (e.args[0] + z) * sp.cos(y)
    ours, theirs = shared_lambdify([x, y, z], e, "math"), sp.lambdify([x, y, z], e, modules=["math"])
    assert _bound_names(ours)
    for _ in range(60):
        pt = [rng.choice([rng.uniform(-3, 3), rng.uniform(0, 1e-3), 0.0, 1.0, -1.0, 700.0]) for _ in range(3)]
        got, want = _outcome(ours, *pt), _outcome(theirs, *pt)
        if want[0] == "raised":
            assert got == want  # the same exception at the same operation
        else:
            assert got[0] == "value"
            g, w = complex(got[1]), complex(want[1])
            assert _same_float(g.real, w.real) and _same_float(g.imag, w.imag)


@pytest.mark.parametrize("seed", range(8))
def test_numpy_code_same_values_as_sympy(seed):
    rng = random.Random(100 + seed)
    e = _expression(rng, 14)
    e = e + (e.args[0] + z) * sp.sin(x) + (e.args[0] + z) * sp.cos(y)
    ours, theirs = shared_lambdify([x, y, z], e, "numpy"), sp.lambdify([x, y, z], e, modules=["numpy"])
    assert _bound_names(ours)
    t = np.linspace(-2.0, 2.0, 21)
    for _ in range(10):
        a, b = rng.uniform(-2, 2), rng.uniform(-2, 2)
        with np.errstate(all="ignore"):
            got, want = _outcome(ours, a, b, t), _outcome(theirs, a, b, t)
        if want[0] == "raised":
            assert got == want
            continue
        g = np.broadcast_to(np.asarray(got[1], dtype=complex), t.shape)
        w = np.broadcast_to(np.asarray(want[1], dtype=complex), t.shape)
        for gv, wv in zip(g.ravel(), w.ravel()):
            assert _same_float(gv.real, wv.real) and _same_float(gv.imag, wv.imag)


def test_first_occurrence_raises_as_before():
    """A repeated part that raises (1/(x − y) at x = y) raises the same ZeroDivisionError, and math's
    domain error of a repeated log the same ValueError, at the first occurrence."""
    e = 1 / (x - y) + sp.log(z) * (1 / (x - y)) + sp.log(z) ** 2
    ours, theirs = shared_lambdify([x, y, z], e, "math"), sp.lambdify([x, y, z], e, modules=["math"])
    assert _bound_names(ours)
    for pt in [(1.0, 1.0, 2.0), (2.0, 1.0, -1.0), (1.0, 1.0, -1.0)]:
        got, want = _outcome(ours, *pt), _outcome(theirs, *pt)
        assert want[0] == "raised" and got == want
    assert _outcome(ours, 2.0, 1.0, 3.0) == _outcome(theirs, 2.0, 1.0, 3.0)


def test_lazy_forms_are_not_rewritten():
    """math's Piecewise is a conditional expression (a branch may not be evaluated): left as it was."""
    e = sp.Piecewise(((x - y) ** 2 + (x - y) ** 3, x > 0), ((x - y) ** 2, True))
    ours, theirs = shared_lambdify([x, y], e, "math"), sp.lambdify([x, y], e, modules=["math"])
    assert not _bound_names(ours)
    for pt in [(0.5, 0.25), (-0.5, 0.25)]:
        assert ours(*pt) == theirs(*pt)


def test_stylize_weight_evaluated_once_with_sympys_values():
    """The stylization kernel's regular piece of ∂ax (its weight: thousands of nodes over ~100 repeated
    parts): the vectorized weight compiled for the quadrature binds its repeated parts and gives numpy
    lambdify's values at a panel of points, bit for bit."""
    import os

    from langur.ddenote import ddenote
    from langur.frontend import load

    path = os.path.join(os.path.dirname(__file__), "..", "examples", "stylize", "quadratic.lgr")
    loaded = load(path)
    at = loaded.param_values()
    nf = ddenote(loaded.program.body, {q: int(q == "ax") for q in at}, at=at,
                 variables=tuple(loaded.program.variables))
    (piece,) = nf.regular
    w = sp.sympify(piece.weight)
    params = sorted((s for s in w.free_symbols if s.name in at), key=lambda s: s.name)
    xs = [sp.Symbol(v) for v in loaded.program.variables]
    args = [*xs, *params]
    ours = shared_lambdify(args, w, "numpy")
    theirs = sp.lambdify(args, w, modules=["numpy"])
    assert len(_bound_names(ours)) >= 50
    values = [float(at[p.name]) for p in params]
    t = np.linspace(0.25, 0.75, 21)
    for xv in (0.3, 0.5, 0.7):
        with np.errstate(all="ignore"):
            g, want = np.asarray(ours(xv, t, *values), dtype=float), np.asarray(theirs(xv, t, *values), dtype=float)
        assert g.view(np.uint64).tolist() == want.view(np.uint64).tolist()


def test_substituted_conditions_are_sympys_and_remembered():
    """A condition with the point's 30-digit Floats substituted (the quadrature's problems): sympy's
    ``xreplace`` with the same rule, the same object when asked again at the same point, a new one
    at another point; an expression holding Floats is substituted afresh each time (sympy's equality
    does not see a Float's precision)."""
    from langur.symbolic.quadrature import compiling
    from langur.symbolic.quadrature.compiling import _floats, substituted

    a, b = sp.symbols("a b", real=True)
    cond = (a - x) * (y - b) - (b + 2 * a) * (x - 3 * y)
    at = {a: sp.Rational(1, 10), b: sp.Rational(3, 20)}
    got = substituted(cond, at)
    assert got == cond.xreplace({a: sp.Float(0.1, 30), b: sp.Float(0.15, 30)}) == cond.xreplace(_floats(at))
    assert substituted(cond, dict(at)) is got
    other = substituted(cond, {a: sp.Rational(1, 10), b: sp.Rational(1, 5)})
    assert other != got and other == cond.xreplace({a: sp.Float(0.1, 30), b: sp.Float(0.2, 30)})
    floaty = cond + sp.Float("0.5", 15) * x
    first = substituted(floaty, at)
    assert first == floaty.xreplace(_floats(at))
    assert (cond, tuple(at.items())) in compiling._SUBSTITUTED
    assert not any(k[0] == floaty for k in compiling._SUBSTITUTED)
