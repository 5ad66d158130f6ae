"""One key per indexed root's equation, boxes shared by the same compiled code (issue 15, turning2d's
speed, exact13t).

Each time ⟦p⟧ or ⦇p⦈ is built (the value, the derivative, Theorem 8.1's four shifted points) an
implicit root's equation gets a new bound Dummy, and :mod:`langur.implicit` named it by a new key:
turning2d compiled ``3*_y**2 - x`` under twelve keys and certified its boxes again for each.  Now an
equation that differs from an earlier one only in its bound variable's identity gets the earlier
key (:func:`langur.implicit.equations.form`), and keys whose compiled functions are the same code share their
certified boxes and roots (:func:`langur.implicit.lambdified._same_code`).  Checked here: which equations are
merged and which are not; roots through the shared keys bitwise those solved with nothing shared
and nothing remembered, and the roots themselves (closed forms, mpmath's ``polyroots`` at 50 digits);
no box certified twice for one code; and the root's free symbols and printed text, now kept per
root, equal sympy's own.
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import pytest
import sympy as sp
from sympy.printing.str import StrPrinter

from langur.core import Const, ImplicitRoot, Var
from langur.diagnostics import Span
from langur.implicit import evalf, implicit_root, lambdified

Y, U, V, A = sp.symbols("y u v a", real=True)
TURNING = 3 * Y**2 - U  # turning2d's ∂/∂y: sign changes ∓sqrt(u/3)
QUARTIC = Y**4 - 2 * Y**2 + U  # up to four sign changes on [-2, 2]
FOLIUM = Y**3 - Y * U + U**3 - A


def _indexed(eq, k, of, **kw):
    return implicit_root(eq, Y, sp.Integer(0), sp.Integer(-2), sp.Integer(2), index=k, of=of, lenient=True, **kw)


def _key(root):
    lam = root.args[0]
    (x,), f = lam.variables, lam.expr
    return lambdified.indexed_key(lam, sorted(f.free_symbols - {x}, key=str))


def _isolated(monkeypatch):
    """Nothing shared and nothing remembered from here on (restored by ``monkeypatch``; the keys
    made meanwhile stay, as keys are never reused, so the caches by key stay right)."""
    for name in ("_BY_FORM", "_SAME", "_BY_CODE", "_BOXES", "_ROOTS"):
        monkeypatch.setattr(lambdified, name, {})
    lambdified._compiled.cache_clear()
    lambdified._brackets_of.cache_clear()


def _same_bits(xs, ys) -> bool:
    return all((math.isnan(x) and math.isnan(y)) or (x == y and math.copysign(1, x) == math.copysign(1, y))
               for x, y in zip(xs, ys, strict=True))


def test_an_equation_built_again_gets_its_first_key():
    first, again = _indexed(TURNING, 0, 2), _indexed(TURNING, 1, 2)
    assert first.args[0] != again.args[0]  # two bound Dummies: two Lambdas
    assert _key(first) == _key(again) == _key(_indexed(TURNING, 0, 2))
    # what the key computes or says differs: other keys
    assert _key(_indexed(TURNING.xreplace({U: V}), 0, 2)) != _key(first)  # another symbol
    assert _key(_indexed(TURNING + 1, 0, 2)) != _key(first)
    assert _key(implicit_root(TURNING, Y, sp.Integer(0), sp.Integer(-2), sp.Integer(2), index=0, of=2)) != _key(first)
    # named when refused: the core node's place (diag32: the node is kept, its span keys the code)
    node = ImplicitRoot(Var("y"), "y", Const(0), Const(-2), Const(2), 0, 2, span=Span("a.lgr", 3, 5, 3, 9))
    assert _key(_indexed(TURNING, 0, 2, root=node)) != _key(first)
    assert _key(_indexed(TURNING, 0, 2, root=node)) == _key(_indexed(TURNING, 1, 2, root=node))
    z = sp.Dummy("y", real=True)  # a variable of another name orders its terms otherwise
    assert _key(implicit_root(TURNING.xreplace({Y: sp.Symbol("w", real=True)}), sp.Symbol("w", real=True),
                              sp.Integer(0), sp.Integer(-2), sp.Integer(2), index=0, of=2, lenient=True)) != _key(first)
    # an equation holding another Dummy (a root in it): not merged (its order against the bound
    # variable could depend on when each was made)
    inner = implicit_root(Y**2 - U, Y, sp.Integer(0), sp.Integer(0), sp.Integer(2))
    nested = [_indexed(Y**3 - inner * Y - z, 0, 2) for _ in range(2)]
    assert _key(nested[0]) != _key(nested[1])


@pytest.mark.parametrize("eq, of", [(TURNING, 2), (QUARTIC, 4)])
def test_roots_through_shared_keys_are_the_roots_solved_apart(monkeypatch, eq, of):
    rng = np.random.default_rng(1513)
    us = [float(v) for v in rng.uniform(-1.2, 1.2, 120)] + [1e-9, -1e-12, 0.0, -0.0, 2.0**-16, 1.0, 0.75]
    us += us[:30]

    def solve_all():  # each index built again (a new Dummy each time), as ⟦p⟧ and its shifts do
        out = []
        for k in range(of):
            for _ in range(2):
                f = sp.lambdify([U], _indexed(eq, k, of), modules="math")
                out.append([f(u) for u in us])
        return out

    shared = solve_all()
    for k in range(of):  # the two builds of one index: one key, the same numbers
        assert _same_bits(shared[2 * k], shared[2 * k + 1])
    _isolated(monkeypatch)
    monkeypatch.setattr(lambdified, "form", lambda lam, free: None)  # every build its own key
    monkeypatch.setattr(evalf, "form", lambda lam, free: None)
    monkeypatch.setattr(lambdified, "_same_code", lambda key: key)  # and its own boxes
    keys = len(lambdified._INDEXED)
    apart = solve_all()
    assert len(lambdified._INDEXED) == keys + 2 * of
    for p, q in zip(shared, apart, strict=True):
        assert _same_bits(p, q)
    # and they are the roots: the k-th real root of eq(·, u) on [-2, 2] (50-digit polyroots), else 2
    coeffs = [sp.lambdify([U], c) for c in sp.Poly(eq, Y).all_coeffs()]
    for j, u in enumerate(us):
        with mpmath.workdps(50):
            real = sorted(float(r.real) for r in mpmath.polyroots([mpmath.mpf(c(u)) for c in coeffs], maxsteps=200,
                                                                   extraprec=200) if abs(r.imag) < 1e-30)
        simple = [r for r in real if -2 < r < 2 and sum(abs(r - s) < 1e-6 for s in real) == 1]
        if len(simple) != len([r for r in real if -2 < r < 2]):
            continue  # a double root (u = 0, 1): a sign change or not, by the certificate's rules
        for k in range(of):
            got, want = shared[2 * k][j], simple[k] if k < len(simple) else 2.0
            # Brent's method to 4·eps relative in y: a few units in the last place, more where the
            # root is ill-conditioned (two roots close together: |eq'| small)
            slope = abs(float(sp.diff(eq, Y).subs({Y: want, U: u}))) if k < len(simple) else 1.0
            assert abs(got - want) <= 1e-15 * max(1.0, abs(want)) / min(1.0, slope), (u, k, got, want)


def test_the_same_code_under_other_names_shares_its_boxes(monkeypatch):
    _isolated(monkeypatch)
    in_u = _indexed(TURNING, 0, 2)
    in_v = _indexed(TURNING.xreplace({U: V}), 1, 2)
    other = _indexed(3 * Y**2 + U, 0, 2)
    ku, kv, ko = _key(in_u), _key(in_v), _key(other)
    assert len({ku, kv, ko}) == 3
    assert lambdified._same_code(ku) == ku and lambdified._same_code(kv) == ku
    assert lambdified._same_code(ko) == ko
    fu = sp.lambdify([U], in_u, modules="math")
    fv = sp.lambdify([V], in_v, modules="math")
    us = [0.3, 0.31, 0.7, -0.4, 1e-5, 0.05]
    first = [fu(u) for u in us]
    boxes = len(lambdified._BOXES)
    second = [fv(u) for u in us]  # the other sign change, through the boxes the first certified
    assert len(lambdified._BOXES) == boxes > 0
    assert [math.isclose(r, -math.sqrt(u / 3), rel_tol=4e-16) if u > 0 else r == 2.0 for r, u in zip(first, us)] \
        == [True] * len(us)
    assert [math.isclose(r, math.sqrt(u / 3), rel_tol=4e-16) if u > 0 else r == 2.0 for r, u in zip(second, us)] \
        == [True] * len(us)
    _isolated(monkeypatch)
    monkeypatch.setattr(lambdified, "_same_code", lambda key: key)
    alone = sp.lambdify([V], _indexed(TURNING.xreplace({U: V}), 1, 2), modules="math")
    assert _same_bits(second, [alone(u) for u in us])


def test_code_signatures_tell_constants_of_other_types_apart():
    assert lambdified._code_of(eval("lambda x: x + 1")) == lambdified._code_of(eval("lambda z: z + 1"))  # noqa: S307
    assert lambdified._code_of(eval("lambda x: x + 1")) != lambdified._code_of(eval("lambda x: x + 1.0"))  # noqa: S307
    assert lambdified._code_of(eval("lambda x: x + 0.0")) != lambdified._code_of(eval("lambda x: x + -0.0"))  # noqa: S307
    assert lambdified._code_of(eval("lambda x: sin(x)", {"sin": math.sin})) \
        != lambdified._code_of(eval("lambda x: sin(x)", {"sin": math.cos}))  # noqa: S307 - the objects named
    c = 2.0
    assert lambdified._code_of(lambda x: x + c) is lambdified._NO_CODE  # a closure: not compared


def test_free_symbols_kept_per_root_are_sympys():
    sc = _indexed(TURNING, 0, 2)
    root = implicit_root(FOLIUM, Y, sp.Integer(0), sc, sp.Integer(1))
    generic = sp.Basic.free_symbols.fget(root)
    assert root.free_symbols == generic == {U, A}
    got = root.free_symbols
    got.add(V)  # a caller's change is its own
    assert root.free_symbols == {U, A}
    number = root.xreplace({U: sp.Float(0.5), A: sp.Float(0.1)})
    assert number.is_number and not root.is_number and number.free_symbols == set()


def test_printed_roots_are_sympys_text_under_every_setting():
    class Uncached(StrPrinter):  # the same printer, not remembered (not StrPrinter itself)
        pass

    sc = _indexed(TURNING, 0, 2)
    root = implicit_root(FOLIUM, Y, sp.Float("0.1000000000000000055511151231257827", 30), sc, sp.Integer(1))
    for expr in (root, root + U, 3 * root**2 - U, sp.Float(0.25, 30) * root):
        for settings in ({}, {"full_prec": True}, {"full_prec": False}, {"order": "lex"}):
            for _ in range(2):  # asked again: remembered
                assert StrPrinter(settings).doprint(expr) == Uncached(settings).doprint(expr)
    assert str(root).startswith("root(_y: ")


def _old_sturm_brackets(p, lo, hi, depth=200, squarefree=False):
    """``sturm_brackets`` as it was before exact13t (every sign by ``_horner`` on Fractions)."""
    from langur.sturm import _gcd, _horner, _quotient, _rem, _strip

    p = _strip(p)
    if not any(p) or _horner(p, lo) == 0 or _horner(p, hi) == 0:
        return None
    if len(p) == 1:
        return []
    dp = [c * (len(p) - 1 - i) for i, c in enumerate(p[:-1])]
    g = _gcd(p, dp)
    if squarefree and len(g) > 1:
        return None
    p0 = _quotient(p, g) if len(g) > 1 else p
    chain = [p0, [c * (len(p0) - 1 - i) for i, c in enumerate(p0[:-1])] or [0]]
    while len(chain[-1]) > 1 or chain[-1][0] != 0:
        r = _rem(chain[-2], chain[-1])
        if not any(r):
            break
        chain.append([-c for c in r])
        if len(chain[-1]) == 1:
            break

    def variations(x):
        signs = [v for v in (_horner(q, x) for q in chain) if v != 0]
        return sum((u < 0) != (w < 0) for u, w in zip(signs, signs[1:]))

    def split(a, b):
        for k in range(1, 8):
            for m in (a + (b - a) / 2 + (b - a) / 2 ** (k + 1) * (k > 1), a + (b - a) / 2 - (b - a) / 2 ** (k + 1)):
                if _horner(p0, m) != 0:
                    return m
        return None

    points = [lo, hi]
    stack = [(lo, hi, variations(lo) - variations(hi), 0)]
    while stack:
        a, b, n, d = stack.pop()
        if n <= 1:
            continue
        if d >= depth:
            return None
        m = split(a, b)
        if m is None:
            return None
        points.append(m)
        vm = variations(m)
        stack.append((a, m, variations(a) - vm, d + 1))
        stack.append((m, b, vm - variations(b), d + 1))
    points = sorted(set(points))
    signs = [-1 if _horner(p, x) < 0 else 1 for x in points]
    return [(x, y) for x, y, s, r in zip(points, points[1:], signs, signs[1:]) if s != r]


def test_sturm_brackets_in_integers_are_those_in_fractions():
    from fractions import Fraction

    from langur.sturm import _integral, _sign, sturm_brackets

    rng = np.random.default_rng(1513)
    cases = []
    for _ in range(300):
        deg = int(rng.integers(1, 7))
        cs = [Fraction(float(c)) for c in rng.normal(size=deg + 1)]
        if rng.random() < 0.3:  # rational constants, double roots, roots at dyadic points and near each other
            r = Fraction(int(rng.integers(-8, 9)), int(rng.choice([1, 3, 4, 7, 1024])))
            cs = [Fraction(1), -2 * r, r * r] if rng.random() < 0.5 else [Fraction(3), Fraction(0), -r / 10**12]
        lo = Fraction(float(rng.uniform(-3, 0)))
        hi = lo + Fraction(float(rng.uniform(0, 4)))
        cases.append((cs, lo, hi))
    cases += [([Fraction(3), Fraction(0), -Fraction(1, 10**20)], Fraction(-1), Fraction(1)),
              ([Fraction(1), Fraction(0), Fraction(-1)], Fraction(-1), Fraction(1)),
              ([Fraction(3), Fraction(0), Fraction(0)], Fraction(-1), Fraction(1))]
    for cs, lo, hi in cases:
        for squarefree in (False, True):
            assert sturm_brackets(cs, lo, hi, squarefree=squarefree) == _old_sturm_brackets(cs, lo, hi, squarefree=squarefree)
        q = _integral(cs)
        for x in (lo, hi, (lo + hi) / 2, Fraction(1, 3)):
            value = sum(c * x ** (len(cs) - 1 - i) for i, c in enumerate(cs))
            assert _sign(q, x) == (value > 0) - (value < 0)


def test_evalf_through_shared_shapes_is_evalf_apart(monkeypatch):
    # roots built again (new bound Dummies) evaluated by sympy's evalf at several precisions: the
    # compiled shape and certified brackets of the first build serve the others, with the same digits
    # as each build compiled and certified on its own, and the digits are the root's (mpmath findroot)
    def builds():
        out = []
        for _ in range(2):
            sc = [_indexed(TURNING, k, 2) for k in (0, 1)]
            mid = implicit_root(FOLIUM, Y, sp.Integer(0), sc[0], sc[1])
            out.append([sc[0], sc[1], mid])
        return out

    points = [(0.5, 0.1), (0.81, -0.02), (0.3, 0.05), (1e-3, 0.0), (-0.4, 0.1)]

    def values(roots):
        return [[str(r.xreplace({U: sp.Rational(u), A: sp.Rational(a)}).evalf(n)) for r in roots
                 for n in (2, 15, 30)] for u, a in points]

    first, again = builds()
    shared = [values(first), values(again)]
    assert shared[0] == shared[1]
    _isolated(monkeypatch)
    monkeypatch.setattr(evalf, "_canonical_shape", lambda x, shape: (x, shape))
    monkeypatch.setattr(evalf, "_SHAPES", {})
    evalf.evalf_root.cache_clear()
    evalf._shape_compiled.cache_clear()
    evalf._brackets_at.cache_clear()
    alone = values(builds()[1])
    evalf.evalf_root.cache_clear()
    assert alone == shared[0]
    for (u, a), row in zip(points, shared[0]):
        with mpmath.workdps(50):
            u_, a_ = mpmath.mpf(sp.Rational(u).p) / sp.Rational(u).q, mpmath.mpf(sp.Rational(a).p) / sp.Rational(a).q
            if u_ <= 0:  # no sign change of 3y² − u: the domain's end
                assert mpmath.mpf(row[2]) == 2 and mpmath.mpf(row[5]) == 2
                continue
            s0, s1 = -mpmath.sqrt(u_ / 3), mpmath.sqrt(u_ / 3)
            assert abs(mpmath.mpf(row[2]) - s0) < mpmath.mpf(10) ** -28
            assert abs(mpmath.mpf(row[5]) - s1) < mpmath.mpf(10) ** -28
            g = lambda y, u_=u_, a_=a_: y**3 - y * u_ + u_**3 - a_  # noqa: E731
            if (g(s0) < 0) != (g(s1) < 0):
                want = mpmath.findroot(g, (s0, s1), solver="anderson")
                assert abs(mpmath.mpf(row[8]) - want) < mpmath.mpf(10) ** -28
            else:
                assert row[8] == "nan"
