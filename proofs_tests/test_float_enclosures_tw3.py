"""Float enclosures that bracket mpmath's, and remembered roots (issue 15/18, turning2d's speed).

:mod:`langur.floativ` compiles an equation's interval text to an outer enclosure (containing
mpmath's) and an inner one (contained in it); :func:`langur.enclosures.certified_brackets` lets them
decide a cell's sign only where that is the sign mpmath's enclosure gives, so its brackets must be
*bitwise* those of the mpmath-only certification it replaced (copied below as it was at 35d65c7,
cells in mpmath numbers), on random boxes of turning2d's turning points (across the fold u = 0
too), on the folium at random points (lenient or not) and on random polynomials.  The enclosures
are checked against exact rational values of the polynomials, and remembered roots against roots
solved again with nothing remembered and mpmath alone certifying."""

from __future__ import annotations

import math
import random
from fractions import Fraction

import mpmath
import numpy as np
import pytest
import sympy as sp

from langur import enclosures, floativ
from langur.core import TooManyRoots
from langur.enclosures import LOOSE, _uncertified, certified_brackets, interval_function
from langur.implicit import implicit_root, lambdified


def _old_certified_brackets(g, g_iv, dg_iv, target, lo, hi, grid=16, depth=30, what="the equation",
                            lenient=False, box=False):
    """``certified_brackets`` as it was (mpmath's enclosures alone, cells in mpmath numbers)."""
    iv = mpmath.iv
    lo, hi = mpmath.mpf(lo), mpmath.mpf(hi)
    if not hi > lo:
        return []
    t = iv.mpf(target)
    stack = [(hi if i == grid - 1 else lo + (hi - lo) * (i + 1) / grid, lo + (hi - lo) * i / grid, 0)
             for i in range(grid)][::-1]
    cells = []
    while stack:
        b, a, d = stack.pop()
        X = iv.mpf([a, b])
        G = g_iv(X)
        if G is not None:
            G = G - t
            if G.a > 0 or G.b < 0:
                cells.append((a, b, 0))
                continue
        D = dg_iv(X)
        if D is not None and (D.a > 0 or D.b < 0):
            cells.append((a, b, 1 if D.a > 0 else -1))
            continue
        if d == depth:
            if lenient:
                cells.append((a, b, LOOSE))
                continue
            raise _uncertified(what, a, b)
        m = (a + b) / 2
        stack.append((b, m, d + 1))
        stack.append((m, a, d + 1))
    points = [c[0] for c in cells] + [cells[-1][1]]
    signs = []
    for i, p in enumerate(points):
        G = g_iv(mpmath.iv.mpf([p, p]))
        G = None if G is None else G - t
        s = 0 if G is None else (1 if G.a > 0 else (-1 if G.b < 0 else 0))
        ends = i in (0, len(points) - 1)
        if s == 0 and not ends:
            before, after = cells[i - 1][2], cells[i][2]
            if (before == 0 or before != after or before == LOOSE) and not lenient:
                raise _uncertified(what, cells[i - 1][0], cells[i][1])
            ends = before == 0 or before != after or before == LOOSE
        if s == 0 and ends and box:
            raise _uncertified(what, points[max(i - 1, 0)], points[min(i + 1, len(points) - 1)])
        if s == 0 and ends:
            try:
                v = g(p) - target
                s = -1 if mpmath.isnan(v) or v < 0 else 1
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                s = -1
        signs.append(s)
    known = [(p, s) for p, s in zip(points, signs) if s != 0]
    return [(float(p), float(q)) for (p, s), (q, r) in zip(known, known[1:]) if s != r]


def _both(g, enc, denc, values, target, lo, hi, **kw):
    """The old and the new certification of the same equation at ``values`` (mpmath intervals)."""
    out = []
    for new in (False, True):
        try:
            with mpmath.workprec(53):
                if new:
                    got = certified_brackets(g, enc.bind(*values), denc.bind(*values), target, lo, hi, **kw)
                else:
                    got = _old_certified_brackets(g, lambda X: enc(X, *values), lambda X: denc(X, *values), target,
                                                  lo, hi, **kw)
            out.append([(float(p), float(q)) for p, q in got])
        except TooManyRoots as err:
            out.append(str(err))
    return out


Y, U, A = sp.symbols("y u a", real=True)
TURNING = 3 * Y**2 - U  # turning2d's ∂/∂y: its sign changes are the turning points ±sqrt(u/3)
FOLIUM = Y**3 - Y * U + U**3 - A


def test_box_certifications_are_bitwise_mpmaths_across_the_fold():
    enc, denc = interval_function(Y, TURNING, (U,)), interval_function(Y, sp.diff(TURNING, Y), (U,))
    assert enc.fast is not None and denc.fast is not None
    rng = random.Random(1518)
    refused = certified = 0
    for _ in range(150):
        level = rng.randint(-15, 1)
        w = 2.0**level
        c = math.floor(rng.choice([rng.uniform(-1, 1), rng.uniform(-4 * w, 4 * w)]) / w)  # near 0: the fold
        box = [mpmath.iv.mpf([c * w, (c + 1) * w])]
        old, new = _both(None, enc, denc, box, 0.0, -1.0, 1.0, depth=8, box=True)
        assert old == new, (c, level, old, new)
        refused += isinstance(old, str)
        certified += not isinstance(old, str)
    assert refused > 20 and certified > 20  # both outcomes compared


def test_point_certifications_are_bitwise_mpmaths_on_the_folium():
    rng = random.Random(18)
    for expr in (FOLIUM, TURNING):
        free = (U, A)
        g = sp.lambdify([Y, *free], expr, modules="mpmath")
        enc, denc = interval_function(Y, expr, free), interval_function(Y, sp.diff(expr, Y), free)
        for _ in range(60):
            u = rng.choice([rng.uniform(-1, 1), rng.uniform(-1e-6, 1e-6), 0.0, 1e-30])
            a = rng.uniform(-0.5, 1.5)
            t = rng.choice([0.0, rng.uniform(-0.3, 0.3)])
            lo, hi = sorted(rng.uniform(-1.2, 1.2) for _ in range(2))
            vals = [mpmath.iv.mpf(u), mpmath.iv.mpf(a)]
            for lenient in (False, True):
                old, new = _both(lambda z, g=g, u=u, a=a: g(z, u, a), enc, denc, vals, t, lo, hi, lenient=lenient)
                assert old == new, (expr, u, a, t, lo, hi, lenient, old, new)


def _random_poly(rng):
    """A random polynomial in y and u: integer, rational (no double) and float coefficients."""
    terms = []
    for _ in range(rng.randint(1, 5)):
        c = rng.choice([sp.Integer(rng.randint(-5, 5)), sp.Rational(rng.randint(-9, 9), rng.choice([3, 7, 10])),
                        sp.Float(rng.uniform(-2, 2))])
        terms.append(c * Y ** rng.randint(0, 6) * U ** rng.randint(0, 2))
    e = sum(terms) + Y ** rng.randint(1, 5)
    return e if e.has(Y) else e + Y


def _terms(expr) -> list:
    """``expr``'s terms as (coefficient, power of y, power of u), the coefficients exact (a float
    constant its binary value)."""
    out = []
    for term in sp.Add.make_args(sp.expand(expr)):
        c, rest = term.as_coeff_Mul()
        v = Fraction(float(c)) if isinstance(c, sp.Float) else Fraction(*sp.Rational(c).as_numer_denom())
        out.append((v, sp.degree(rest, Y) if rest.has(Y) else 0, sp.degree(rest, U) if rest.has(U) else 0))
    return out


def _exact(terms, y: Fraction, u: Fraction) -> Fraction:
    """The polynomial of :func:`_terms` at rational points, exactly."""
    return sum((c * y**py * u**pu for c, py, pu in terms), Fraction(0))


def test_float_enclosures_bracket_mpmaths_and_hold_the_exact_values():
    rng = random.Random(15)
    checked = 0
    for _ in range(60):
        expr = _random_poly(rng)
        for e in (expr, sp.diff(expr, Y)):
            enc, terms = interval_function(Y, e, (U,)), _terms(e)
            assert enc.fast is not None, e
            outer, inner = enc.fast
            for _ in range(8):
                ylo = rng.choice([rng.uniform(-1.5, 1.5), 0.0, -2.0**-rng.randint(1, 40)])
                yhi = ylo + rng.choice([0.0, 2.0**-rng.randint(0, 30), rng.uniform(0, 1)])
                ulo = rng.choice([rng.uniform(-1, 1), 0.0])
                uhi = ulo + rng.choice([0.0, rng.uniform(0, 0.5)])
                t = rng.choice([0.0, rng.uniform(-1, 1)])
                with mpmath.workprec(53):
                    M = enc(mpmath.iv.mpf([ylo, yhi]), mpmath.iv.mpf([ulo, uhi]))
                    M = M - mpmath.iv.mpf(t)
                o = outer(ylo, yhi, ulo, uhi, t, t)
                i = inner(ylo, yhi, ulo, uhi, t, t)
                assert o is not None
                assert o[0] <= M.a and M.b <= o[1], (e, ylo, yhi, ulo, uhi, o, M)  # outer ⊇ mpmath
                if i is not None:
                    assert M.a <= i[0] and i[1] <= M.b, (e, ylo, yhi, ulo, uhi, i, M)  # inner ⊆ mpmath
                for yy in (ylo, yhi, (ylo + yhi) / 2):  # and the enclosure holds the exact values
                    for uu in (ulo, uhi):
                        v = _exact(terms, Fraction(yy), Fraction(uu)) - Fraction(t)
                        assert Fraction(o[0]) <= v <= Fraction(o[1]), (e, yy, uu)
                checked += 1
    assert checked == 60 * 2 * 8


def test_signs_from_float_enclosures_are_mpmaths_even_at_exact_zeros():
    # ends that are 0 exactly (6y on [−c, 0], 3y² − u at u = 0): mpmath says "holds 0", so must the signer
    rng = random.Random(7)
    for expr in (TURNING, sp.diff(TURNING, Y), FOLIUM, Y**4 - U**2, Y * U):
        enc = interval_function(Y, expr, (U, A))
        for _ in range(200):
            k = rng.randint(0, 20)
            ylo = rng.choice([-(2.0**-k), 0.0, rng.uniform(-1, 1)])
            yhi = rng.choice([0.0, ylo + 2.0**-k]) if ylo < 0 else ylo + 2.0**-k
            u = rng.choice([[0.0, 0.0], [0.0, 2.0**-k], [-(2.0**-k), 0.0], sorted(rng.uniform(-1, 1) for _ in range(2))])
            vals = (mpmath.iv.mpf(u), mpmath.iv.mpf(0.1))
            fast = enclosures._signer(enc.bind(*vals), 0.0)
            slow = enclosures._signer(lambda X, enc=enc, vals=vals: enc(X, *vals), 0.0)
            with mpmath.workprec(53):
                assert fast(ylo, yhi) == slow(ylo, yhi), (expr, ylo, yhi, u)


def test_signs_within_rounding_of_zero_are_left_to_mpmath():
    # 3y² − u at a point y with u a few ulps from 3y²: mpmath's tight enclosure excludes 0 where the
    # float one, an ulp wider per operation, does not; then mpmath must decide (the same sign)
    enc = interval_function(Y, TURNING, (U,))
    rng = random.Random(3)
    decided = 0
    for _ in range(400):
        y = rng.uniform(-1, 1)
        u = 3 * y * y
        for _ in range(rng.randint(0, 3)):
            u = math.nextafter(u, rng.choice([-math.inf, math.inf]))
        vals = (mpmath.iv.mpf(u),)
        fast = enclosures._signer(enc.bind(*vals), 0.0)
        slow = enclosures._signer(lambda X, vals=vals: enc(X, *vals), 0.0)
        with mpmath.workprec(53):
            assert fast(y, y) == slow(y, y), (y, u)
            decided += slow(y, y) != 0
    assert decided > 50  # mpmath decides many that the float enclosure alone could not


def test_an_equation_float_enclosures_cannot_compile_is_left_to_mpmath():
    enc = interval_function(Y, sp.sin(Y) - U * sp.sqrt(Y + 2), (U,))
    assert enc.fast is None
    assert floativ.compile_enclosure(lambda y: y ** 0.5, 1) is None  # a fractional power
    with mpmath.workprec(53):
        got = certified_brackets(sp.lambdify([Y], sp.sin(3 * Y), "mpmath"), interval_function(Y, sp.sin(3 * Y)),
                                 interval_function(Y, 3 * sp.cos(3 * Y)), 0, -2, 2)
    assert [p < r < q for (p, q), r in zip(got, (-math.pi / 3, 0.0, math.pi / 3))] == [True] * 3 and len(got) == 3


def _roots(us, a):
    """Turning2d's roots at (u, a): the k-th sign changes of 3y² − u (indexed) and the folium's root on
    its middle piece between them (a unique root whose bounds are indexed roots), scalar calls."""
    sc = [implicit_root(TURNING, Y, sp.Integer(0), sp.Integer(-1), sp.Integer(1), index=k, of=2, lenient=True)
          for k in (0, 1)]
    mid = implicit_root(FOLIUM, Y, sp.Integer(0), sc[0], sc[1])
    fns = [sp.lambdify([U, A], r, modules="math") for r in (*sc, mid)]
    return [[f(u, a) for u in us] for f in fns]


def test_remembered_roots_are_the_roots_solved_again_with_mpmath_alone(monkeypatch):
    rng = np.random.default_rng(1815)
    us = [float(v) for v in rng.uniform(-1, 1, 150)] + [1e-9, -1e-12, 0.0, -0.0, 3e-300, 2.0**-16, 0.75]
    us += us[:40]  # asked again: remembered
    for a in (0.1, -0.02):
        first = _roots(us, a)
        monkeypatch.setattr(floativ, "compile_enclosure", lambda fn, n: None)  # mpmath alone
        lambdified._compiled.cache_clear()
        lambdified._brackets_of.cache_clear()
        lambdified._BOXES.clear()
        lambdified._ROOTS.clear()
        again = _roots(us, a)
        monkeypatch.undo()
        lambdified._compiled.cache_clear()
        lambdified._brackets_of.cache_clear()
        lambdified._BOXES.clear()
        for p, q in zip(first, again):
            assert all((math.isnan(x) and math.isnan(y)) or (x == y and math.copysign(1, x) == math.copysign(1, y))
                       for x, y in zip(p, q))
        # and they are the roots: ∓sqrt(u/3) (else the domain's end), the folium's zero between them
        want = [np.where(np.array(us) > 0, (-1) ** (k + 1) * np.sqrt(np.maximum(us, 0) / 3), 1.0) for k in (0, 1)]
        assert np.allclose(first[0], want[0], rtol=0, atol=1e-14) and np.allclose(first[1], want[1], rtol=0, atol=1e-14)
        mid = np.array(first[2])
        ok = ~np.isnan(mid)
        y, u = mid[ok], np.array(us)[ok]
        assert ok.sum() > 10 and np.allclose(y**3 - y * u + u**3 - a, 0, rtol=0, atol=1e-14)


@pytest.mark.parametrize("n", [2, 3, 4, 7])
def test_powers_enclose_every_power(n):
    rng = random.Random(n)
    for _ in range(300):
        lo = rng.uniform(-3, 3)
        hi = lo + rng.choice([0.0, rng.uniform(0, 2), 2.0**-30])
        (ol, oh), (il, ih) = floativ._pow_outer(lo, hi, n), floativ._pow_inner(lo, hi, n)
        exact = [Fraction(v) ** n for v in (lo, hi, (lo + hi) / 2)] + ([Fraction(0)] if lo <= 0 <= hi else [])
        assert Fraction(ol) <= min(exact) and max(exact) <= Fraction(oh)
        assert il > ih or (min(exact) <= Fraction(il) and Fraction(ih) <= max(exact))


def test_roots_of_functions_with_the_same_code_are_not_confused():
    # one lambda's code with different closures or defaults: not remembered by its code alone
    def closure(c):
        return lambda z: z**3 + z - c

    def defaults(c):
        return lambda z, c=c: z**3 + z - c

    for make in (closure, defaults):
        for c in (0.5, -0.25, 0.5, 1.5):
            root = lambdified._solve(make(c), 0, -2.0, 2.0, -1, 0)
            assert abs(root**3 + root - c) < 1e-14, (make, c, root)
    # the same code and namespace with other values: remembered apart
    f = eval("lambda z, c: z**3 + z - c")  # noqa: S307 - a constant text
    got = [lambdified._solve(f, 0, -2.0, 2.0, -1, 0, c) for c in (0.5, -0.25, 0.5)]
    assert got[0] == got[2] != got[1] and abs(got[1] ** 3 + got[1] + 0.25) < 1e-14
