"""deriv22 (issue 15): the grid search of :func:`langur.symbolic.quadrature.roots._roots` stops its
bisection on a condition's state (definedness or sign) once the bracket's ends are neighbouring
doubles (its midpoint is one of them): every further step evaluated the condition at that same
point and kept the bracket.  The roots found are those of the unchanged search, written out here
as it was (80 halvings, every one evaluated), on conditions with definedness boundaries (square
roots of affine and quadratic functions: NaN on part of the range), sign changes the grid sees,
and ends at or across 0."""

from __future__ import annotations

import math
import random

import numpy as np
import pytest
from scipy import optimize as so

from langur.symbolic.quadrature import roots


def _unchanged(g, lo: float, hi: float) -> list[float]:
    """``_roots`` as it was before deriv22 (the bisection always takes its 80 steps)."""
    xs = np.linspace(lo, hi, roots.GRID + 1).tolist()
    vals = [g(x) for x in xs]
    out = roots._hidden_pairs(g, xs, vals)
    for i in range(roots.GRID):
        a, b, fa, fb = xs[i], xs[i + 1], vals[i], vals[i + 1]
        if fa == 0.0 and i > 0:
            out.append(a)
        sa, sb = roots._state(fa), roots._state(fb)
        if sa == sb:
            continue
        if sa != 0 and sb != 0 and fa != 0.0 and fb != 0.0:
            try:
                out.append(so.brentq(g, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps))
                continue
            except (ValueError, RuntimeError):
                pass
        for _ in range(80):
            m = 0.5 * (a + b)
            if roots._state(g(m)) == sa:
                a = m
            else:
                b = m
        out.append(0.5 * (a + b))
    return out


class _Counted:
    """``f`` with a count of its evaluations."""

    def __init__(self, f):
        self.f, self.calls = f, 0

    def __call__(self, x):
        self.calls += 1
        return self.f(x)


def _sqrt_or_nan(v: float) -> float:
    return math.sqrt(v) if v >= 0 else math.nan


def _reciprocal(v: float) -> float:
    return math.inf if v == 0 else 1.0 / v


def _conditions(rng: random.Random):
    """Conditions with definedness boundaries (NaN beyond them) and sign changes."""
    r, s = rng.uniform(-1, 1), rng.uniform(-1, 1)
    k = rng.uniform(0.1, 3)
    c = rng.uniform(-0.5, 0.5)
    return [
        lambda x: _sqrt_or_nan(x - r) - c,                     # defined from r on, a sign change maybe
        lambda x: _sqrt_or_nan(k * (x - r) * (s - x)) - 0.1,    # defined between r and s
        lambda x: _sqrt_or_nan(r - x) * k - c,                  # defined up to r
        lambda x: _reciprocal(_sqrt_or_nan(x - r)) - k,         # defined from r on (a pole at r)
        lambda x: _sqrt_or_nan(x * x - r * r) - abs(c),         # two boundaries, at ±r
    ]


@pytest.mark.parametrize("seed", range(8))
def test_the_same_roots_as_the_unchanged_search(seed):
    rng = random.Random(seed)
    for lo, hi in [(-1.0, 1.0), (-2.0, 0.5), (0.0, 1.0), (-1.0, 0.0), (1e-3, 2e-3)]:
        for g in _conditions(rng):
            got = roots._roots(g, lo, hi)
            want = _unchanged(g, lo, hi)
            _with_lost_transitions(got, want, g)


def _with_lost_transitions(got: list[float], want: list[float], g) -> None:
    """``got`` is ``want`` (the same doubles, in order) with, in between, transitions the unchanged
    search lost: wide32 (bench/history/2026-11-29.md#wide32 searches the halves its bisection set aside with
    different states at their ends (``√(x − r) − c``: its edge r and its root r + c² in one cell);
    each one added is a change of state within a few units in the last place."""
    rest = iter(got)
    extra = []
    for w in want:
        for t in rest:
            if t.hex() == w.hex():
                break
            extra.append(t)
        else:
            raise AssertionError(f"{w} of the unchanged search is missing from {got}")
    extra += list(rest)
    for t in extra:
        left, right = t, t
        for _ in range(4):
            left, right = math.nextafter(left, -math.inf), math.nextafter(right, math.inf)
        assert roots._state(g(left)) != roots._state(g(right)), (t, got, want)
        assert all(abs(t - w) > 1e-12 for w in want), (t, want)


def test_a_boundary_at_a_node_and_at_zero():
    # definedness from 0 on (an end of the bracket at 0: the bisection runs to the signed zeros)
    for g in (lambda x: _sqrt_or_nan(x), lambda x: _sqrt_or_nan(-x), lambda x: _sqrt_or_nan(x) - 0.25):
        for lo, hi in [(-1.0, 1.0), (-0.7, 0.3), (-1e-300, 1e-300)]:
            assert [t.hex() for t in roots._roots(g, lo, hi)] == [t.hex() for t in _unchanged(g, lo, hi)]


def test_the_bisection_stops_at_neighbouring_doubles():
    # √(x − 0.3): defined from 0.3 on; the grid on [-1, 1] has its nodes 0.05 apart, and a bracket
    # 0.05 wide reaches neighbouring doubles near 0.3 after ~52 halvings, not 80
    r = 0.3
    old, new = _Counted(lambda x: _sqrt_or_nan(x - r)), _Counted(lambda x: _sqrt_or_nan(x - r))
    want = _unchanged(old, -1.0, 1.0)
    got = roots._roots(new, -1.0, 1.0)
    assert got == want
    (t,) = got
    assert abs(t - r) <= 2 * math.ulp(r)  # the boundary, to the last place or so
    assert new.calls < old.calls - 20  # (80 halvings before, about 52 now)


# --- compiling._off_the_reals with a polynomial base (``√(r² − u₁²) ± 1``, the disk's delta piece) ---

import mpmath  # noqa: E402
import sympy as sp  # noqa: E402
from test_deriv21 import _count_again, _rescued  # noqa: E402  (the unchanged path: math, then mpmath as _again takes it)

from langur.symbolic.quadrature import compiling  # noqa: E402
from langur.symbolic.text import shared_lambdify  # noqa: E402

x, y, r = sp.symbols("x y r", real=True)


def _same(got: float, want: float) -> bool:
    return (math.isnan(got) and math.isnan(want)) or got.hex() == want.hex()


def _random_base(rng: random.Random):
    """A polynomial in x, y, r with rational coefficients (degree ≤ 3), not a number."""
    syms = [x, y, r]
    while True:
        b = sum(sp.Rational(rng.randint(-9, 9), rng.randint(1, 7)) * rng.choice(syms) ** rng.randint(0, 3)
                * rng.choice(syms + [sp.Integer(1)]) for _ in range(rng.randint(1, 4)))
        if not b.is_number and b.free_symbols:
            return b


@pytest.mark.parametrize("seed", range(6))
def test_polynomial_bases_give_the_rescues_values(seed):
    rng = random.Random(100 + seed)
    for _ in range(6):
        base = _random_base(rng)
        A = sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) + rng.choice([0, x, y * r, x ** 2])
        c = rng.choice([sp.Integer(1), sp.Integer(-1), sp.Rational(3, 7), -2 * sp.sqrt(3) / 9])
        q = rng.choice([sp.Rational(1, 2), sp.Rational(3, 2), sp.Rational(1, 3), sp.Rational(-1, 2)])
        e = A + c * base ** q
        f = compiling._lambdify([x, y], e, {r: 0.75})
        for _ in range(15):
            vals = [rng.uniform(-2, 2), rng.uniform(-2, 2)]
            full = tuple(vals + [0.75])
            assert _same(f(*vals), _rescued((x, y, r), e, full)), (e, full)


@pytest.mark.parametrize("sign", [1, -1])
def test_the_disk_edge(sign, monkeypatch):
    """``1 ± √(r² − u²)`` (the disk's delta piece): NaN beyond u = r without mpmath's second
    evaluation (fails on the old code: each one re-evaluated); next to u = r, where the double and
    mpmath's value of r² − u² could differ in sign, rescued as before; every value the rescue's."""
    u = sp.Symbol("u1", real=True)
    e = 1 + sign * sp.sqrt(r ** 2 - u ** 2)
    f = compiling._lambdify([u], e, {r: 0.5})
    calls = _count_again(monkeypatch)
    far = [0.5 + k / 16 for k in range(1, 8)] + [-0.5 - k / 16 for k in range(1, 8)]
    assert all(math.isnan(f(v)) for v in far)
    assert calls == []  # (the old code: one rescue each)
    near = [math.nextafter(0.5, 1.0), math.nextafter(math.nextafter(0.5, 1.0), 1.0), 0.5 + 1e-15,
            math.nextafter(-0.5, -1.0)]
    for v in near + far + [0.0, 0.25, 0.5, -0.5]:
        assert _same(f(v), _rescued((u, r), e, (v, 0.5)))
    # next to the edge the certificate declines (mpmath's value there is not the double one's to be sure)
    base = compiling._COMPLEX_TERMS[((u, r), e)][0]
    assert base.size((math.nextafter(0.5, 1.0), 0.5), 0.5) is None
    assert base.size((0.6, 0.5), 0.5) is not None


def test_the_certificate_against_mpmath_at_the_sign_change():
    """Where :class:`compiling._Base` says mpmath's B is negative, it is (mpmath at 53 bits, as the
    rescue computes it), and its size is within the bounds given; sampled next to the zero sets of
    a few polynomials, where the double and mpmath's values differ most."""
    rng = random.Random(7)
    for base in [x ** 2 - 2, r ** 2 - x ** 2 - y ** 2, x ** 3 - x * y + y ** 3 - sp.Rational(1, 10),
                 sp.Rational(1, 3) * x - sp.Rational(2, 7) * y ** 2 + r]:
        cert = compiling._Base((x, y, r), base)
        mp = shared_lambdify([x, y, r], base, "mpmath")
        certified = 0
        for _ in range(400):
            yv, rv = rng.uniform(-1.5, 1.5), rng.uniform(0.1, 1.5)
            # x next to a root of B in x (bisected in doubles), moved by a few units in the last place
            g = shared_lambdify([x], base.subs({y: yv, r: rv}), "math")
            lo, hi = rng.choice([(0.0, 3.0), (-3.0, 0.0), (-3.0, 3.0)])
            if (g(lo) < 0) == (g(hi) < 0):
                continue
            for _ in range(80):
                mid = 0.5 * (lo + hi)
                if (g(mid) < 0) == (g(lo) < 0):
                    lo = mid
                else:
                    hi = mid
            for k in range(-6, 7):
                xv = lo + k * math.ulp(lo) * rng.choice([1, 3, 100, 10 ** 6])
                vals = (xv, yv, rv)
                for q in (0.5, -0.5):
                    size = cert.size(vals, q)
                    if size is None:
                        continue
                    certified += 1
                    with mpmath.workprec(53):
                        b = mp(*[mpmath.mpf(v) for v in vals])
                    assert b < 0
                    assert (abs(b) >= size) if q > 0 else (abs(b) <= size)
        assert certified > 100
