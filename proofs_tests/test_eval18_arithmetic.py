"""One walk per traversal over an arithmetic (issue 15's renovation, "each concept declared once",
eval18).

:mod:`langur.symbolic.rational` evaluates closed forms of rationals, symbols, +, ·, integer powers
and ``Abs`` at a rational point in three modes — exact integer pairs (:data:`exactpairs.EXACT`),
fixed-point balls (:data:`balls.BALLS`) and residues modulo a prime (:func:`residues.residues`,
``local._near_form``'s certificate) — each declared as an :class:`arithmetic.Arithmetic` over which
the tape (:class:`tape.Tape`: values and slopes) and the recursive walk are written once.

The references here are independent of those walks: sympy's own evaluation of the substituted form
(``xreplace``: exact rationals, ``zoo``/``nan`` where it is undefined), sympy's ``diff`` along the
line, Python's ``Fraction`` for the balls' ends and Python's ``pow`` for residues.  A fourth
arithmetic declared here (plain ``Fraction`` objects) plugs into the same walks and must agree.
"""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
import sympy as sp

from langur.symbolic import balls, exactpairs, local, rational
from langur.symbolic.arithmetic import Arithmetic
from langur.symbolic.balls import BALL_BITS, BALLS
from langur.symbolic.exactpairs import EXACT
from langur.symbolic.rational import residue
from langur.symbolic.residues import NoResidue, residues
from langur.symbolic.tape import TAPES, NotRational, Tape

X, Y, Z = sp.symbols("x y z", real=True)
S = sp.Symbol("s", real=True)
SYMBOLS = (X, Y, Z)
PRIME = (1 << 61) - 1
UNIT = Fraction(1, 2 ** BALL_BITS)


def _clear():
    for memo in (TAPES, exactpairs.VALUES, balls.BALL_VALUES):
        memo.clear()


def _form(rng: random.Random, depth: int):
    """A random form: rationals (zeros among them), symbols, sums, products, powers 2, 3, −1, −2 and
    Abs, some of them unevaluated (sympy keeps their order and their zeros)."""
    if depth == 0 or rng.random() < 0.2:
        c = rng.random()
        if c < 0.5:
            return rng.choice(SYMBOLS)
        if c < 0.6:
            return sp.Integer(0)
        return sp.Rational(rng.randint(-9, 9), rng.randint(1, 6))
    c = rng.random()
    evaluate = rng.random() < 0.7
    if c < 0.3:
        return sp.Add(*[_form(rng, depth - 1) for _ in range(rng.randint(2, 3))], evaluate=evaluate)
    if c < 0.6:
        return sp.Mul(*[_form(rng, depth - 1) for _ in range(rng.randint(2, 3))], evaluate=evaluate)
    if c < 0.88:
        return sp.Pow(_form(rng, depth - 1), rng.choice([2, 3, -1, -2]), evaluate=evaluate)
    return sp.Abs(_form(rng, depth - 1), evaluate=evaluate)


def _in_the_language(e) -> bool:
    """Rationals, symbols, +, ·, integer powers and Abs only (sympy may build a √ of an Abs's square)."""
    return all(isinstance(t, (sp.Rational, sp.Symbol, sp.Add, sp.Mul, sp.Abs))
               or (isinstance(t, sp.Pow) and t.exp.is_Integer) for t in sp.preorder_traversal(e))


def _point(rng: random.Random) -> dict:
    """Values for x, y, z: zeros, small rationals, floats' exact (dyadic) values."""
    out = {}
    for s in SYMBOLS:
        r = rng.random()
        out[s] = (sp.Integer(0) if r < 0.2 else sp.Rational(rng.randint(-5, 5), rng.randint(1, 4)) if r < 0.55
                  else sp.Rational(rng.uniform(-3, 3)))
    return out


def _by_sympy(e, point):
    """sympy's own value of ``e`` at ``point``: substituted, every node rebuilt with evaluation (an
    unevaluated node that nothing was substituted into stays as built otherwise)."""
    def rebuilt(t):
        return t.func(*[rebuilt(a) for a in t.args]) if t.args else t
    return rebuilt(e.xreplace(point))


def _undefined_by_sympy(e, point) -> bool:
    """Where sympy's own substitution is not a finite number (a power of 0 below 1: zoo, nan), or an
    Abs is at 0 (defined, but not differentiable there: the walks' forms are for derivatives)."""
    for sub in sp.preorder_traversal(e):
        if isinstance(sub, (sp.Pow, sp.Abs)):
            v = _by_sympy(sub, point)
            if not v.is_finite or (isinstance(sub, sp.Abs) and v == 0):
                return True
    return False


def _exact(e, point) -> Fraction:
    v = _by_sympy(e, point)
    assert isinstance(v, sp.Rational), v
    return Fraction(int(v.p), int(v.q))


def _inside(ball, q: Fraction) -> bool:
    m, r = ball
    return (m - r) * UNIT <= q <= (m + r) * UNIT


def _mod(q: Fraction, p: int = PRIME) -> int:
    return q.numerator * pow(q.denominator, -1, p) % p


def _fractions() -> Arithmetic:
    """A fourth arithmetic, declared here: Python's Fraction objects (failure: ZeroDivisionError)."""
    def sign(q):
        return (q > 0) - (q < 0)

    def inverse(q):
        return 1 / q  # (ZeroDivisionError at 0)

    def total(xs):
        return sum(xs, Fraction(0))

    def product(xs):
        out = Fraction(1)
        for q in xs:
            out *= q
        return out

    return Arithmetic(
        "fractions", const=Fraction, read=lambda z: Fraction(str(sp.Rational(z))), total=total, product=product,
        add=lambda a, b: a + b, mul=lambda a, b: a * b, raise_=lambda q, k: q ** k, inverse=inverse, sign=sign,
        neg=lambda q: -q, scale=lambda q, k: k * q, failure=ZeroDivisionError, points={})


def test_every_arithmetic_agrees_with_sympy_on_random_forms():
    rng = random.Random(18)
    fractions = _fractions()
    counts = {"defined": 0, "undefined": 0, "ball decided": 0, "residue": 0, "slope": 0}
    for _ in range(300):
        e = _form(rng, rng.randint(1, 5))
        if not _in_the_language(e):
            assert rational.rational_value(e, _point(rng)) is None
            continue
        for _ in range(2):
            point = _point(rng)
            tangent = {s: sp.Rational(rng.randint(-3, 3), rng.randint(1, 3)) for s in SYMBOLS}
            _clear()
            got = rational.rational_value(e, point)
            residues_at = {s: _mod(_exact(v, {})) for s, v in point.items()}
            if _undefined_by_sympy(e, point):
                counts["undefined"] += 1
                assert got is None, (e, point)
                assert rational.dual_derivative(e, point, tangent) is None
                assert rational.float_value(e, point) is None and rational.sign_value(e, point) is None
                with pytest.raises((NotRational, balls.Uncertain)):
                    BALLS.value_of(e, {}, point)
                with pytest.raises((ZeroDivisionError, NotRational)):
                    fractions.value_of(e, {}, point)
                continue
            counts["defined"] += 1
            want = _exact(e, point)
            assert got == want, (e, point)
            # the fourth arithmetic, through both traversals
            assert fractions.value_of(e, {}, point) == want
            tape = Tape(e)
            assert tape.values(point, fractions)[-1] == want
            # balls hold the exact value (or cannot decide: a ball holding 0 under Abs or a reciprocal)
            try:
                ball = BALLS.value_of(e, {}, point)
            except balls.Uncertain:
                ball = None
            if ball is not None:
                counts["ball decided"] += 1
                assert _inside(ball, want), (e, point, ball)
            assert rational.float_value(e, point) == float(want)
            assert rational.sign_value(e, point) == (want > 0) - (want < 0)
            # residues: the exact value modulo the prime (no residue of |·|)
            r = residue(e, residues_at, {}, PRIME)
            if e.has(sp.Abs):
                assert r is None
            else:
                counts["residue"] += 1
                assert r == _mod(want), (e, point)
                assert local._residue(e, residues_at, {}) == r
                assert tape.values(residues_at, residues(PRIME))[-1] == r  # (the tape walks residues too)
            # the slope along the tangent: sympy's derivative on the line, in every arithmetic
            line = e.xreplace({s: v + S * tangent[s] for s, v in point.items()})
            slope = rational.dual_derivative(e, point, tangent)
            want_slope = _by_sympy(sp.diff(line, S), {S: 0})
            if want_slope.is_Rational:
                counts["slope"] += 1
                assert slope == Fraction(int(want_slope.p), int(want_slope.q)), (e, point, tangent)
            assert tape.slope(tape.values(point, fractions), tangent, fractions) == slope
            assert rational.dual_derivative_float(e, point, tangent) == float(slope)
            try:
                bslope = tape.slope(tape.values(point, BALLS), tangent, BALLS)
            except balls.Uncertain:
                continue
            assert _inside(bslope, slope), (e, point, tangent, bslope)
    assert min(counts.values()) >= 50, counts


def test_each_arithmetic_fails_its_own_way_where_a_power_below_1_or_abs_meets_0():
    modulo = residues(PRIME)
    for arith, zero, fails in ((EXACT, (0, 1), NotRational), (BALLS, (0, 0), balls.Uncertain),
                               (BALLS, (0, 5), balls.Uncertain), (modulo, 0, NoResidue)):
        assert arith.failure is fails
        for k in (-2, -1, 0):
            with pytest.raises(fails):
                arith.power(zero, k)
        with pytest.raises(fails):
            arith.magnitude(zero)
    # away from 0: xᵏ for every k, and |x| (no order modulo a prime: no residue of |·|)
    three = Fraction(-3, 4)
    assert EXACT.power((-3, 4), -3) == (-64, 27) and EXACT.power((-3, 4), 0) == (1, 1)
    assert EXACT.magnitude((-3, 4)) == (3, 4)
    ball = BALLS.const(-3, 4)
    for k in (-3, -1, 0, 1, 2):
        assert _inside(BALLS.power(ball, k), three ** k)
    assert _inside(BALLS.magnitude(ball), -three)
    assert modulo.power(modulo.const(-3, 4), -3) == _mod(three ** -3)
    with pytest.raises(NoResidue):
        modulo.magnitude(modulo.const(3, 4))


def test_the_public_readers_at_the_edges():
    half = sp.Rational(1, 2)
    at = {X: half, Y: sp.Rational(-2, 3)}
    unevaluated_zero = sp.Add(X, -half, evaluate=False)
    # Abs at 0, a division by 0, 0⁰: undefined (None) in every reader
    for e in (sp.Abs(unevaluated_zero), sp.Pow(unevaluated_zero, -1, evaluate=False),
              sp.Pow(unevaluated_zero, 0, evaluate=False), sp.sqrt(X), sp.Float(0.5) * X, Z * X):
        assert rational.rational_value(e, at) is None
        assert rational.float_value(e, at) is None and rational.sign_value(e, at) is None
        assert rational.dual_derivative(e, at, {X: 1}) is None
        assert rational.dual_derivative_float(e, at, {X: 1}) is None
    # an exact 0 the balls cannot decide is the exact path's
    assert rational.float_value(unevaluated_zero, at) == 0.0 and rational.sign_value(unevaluated_zero, at) == 0
    assert rational.dual_derivative_float(sp.Mul(unevaluated_zero, Y, evaluate=False), at, {Y: 1}) == 0.0
    # x¹ left unevaluated, at x = 0: its slope is the tangent's (exactly, and by balls that decide it)
    first = sp.Mul(sp.Pow(unevaluated_zero, 1, evaluate=False), Y, evaluate=False)
    _clear()
    assert rational.dual_derivative(first, at, {X: 3}) == Fraction(-2)
    tape = Tape(first)
    assert _inside(tape.slope(tape.values(at, BALLS), {X: 3}, BALLS), Fraction(-2))
    assert rational.dual_derivative_float(first, at, {X: 3}) == -2.0
    # the order of the operands decides which failure comes first (the balls' _Uncertain falls back
    # to the exact values, a non-rational form is None)
    uncertain = sp.Abs(unevaluated_zero)
    with pytest.raises(balls.Uncertain):
        BALLS.value_of(sp.Add(uncertain, sp.sqrt(Y), evaluate=False), {}, at)
    with pytest.raises(NotRational):
        BALLS.value_of(sp.Add(sp.sqrt(Y), uncertain, evaluate=False), {}, at)


def test_residues_at_their_edges():
    p = 7
    modulo = residues(p)
    assert residues(p) is modulo  # (one arithmetic per prime)
    at = {X: 3, Y: 0}
    assert residue(X * Y + 2, at, {}, p) == 2
    assert residue(X ** -1, at, {}, p) == 5  # 3·5 = 15 ≡ 1
    assert residue(sp.Rational(1, 14) + X, at, {}, p) is None  # 7 divides a denominator
    assert residue(sp.Rational(3, 8) * X, at, {}, p) == 3 * pow(8, -1, p) * 3 % p
    assert residue(Y ** -2, at, {}, p) is None and residue(sp.Pow(Y, 0, evaluate=False), at, {}, p) is None
    assert residue(sp.Abs(X), at, {}, p) is None and residue(Z * X, at, {}, p) is None
    assert residue(sp.sqrt(X), at, {}, p) is None and residue(sp.Float(0.5) * X, at, {}, p) is None
    # a value 0 modulo the prime that is not 0: its reciprocal has no residue, its square is 0
    assert residue((X + 4) ** 2, at, {}, p) == 0 and residue((X + 4) ** -1, at, {}, p) is None
    # the memo is the caller's: a residue walked once is read back
    memo: dict = {}
    assert residue((X + 1) * (X + 2), at, memo, p) == 20 % p and memo[X + 1] == 4


def test_an_arithmetic_counts_the_operations_of_the_one_walk():
    # the walks call only the arithmetic's operations: a counting wrapper around EXACT sees each
    # distinct subtree once (the recursive walk) and each operation of the tape once
    calls: dict = {}

    def counted(name, f):
        def g(*a):
            calls[name] = calls.get(name, 0) + 1
            return f(*a)
        return g

    names = ("const", "read", "total", "product", "add", "mul", "inverse", "sign", "neg", "scale")
    ops = {n: counted(n, getattr(EXACT, n)) for n in names}
    counting = Arithmetic("counting", raise_=counted("raise_", lambda x, k: (x[0] ** k, x[1] ** k)),
                          failure=NotRational, points={}, **ops)
    shared = X + Y
    e = sp.Mul(shared ** 2, sp.Abs(shared - 3), shared ** -1, evaluate=False)
    at = {X: sp.Rational(1, 3), Y: sp.Rational(5, 7)}
    calls.clear()
    assert counting.value_of(e, {}, at) == EXACT.value_of(e, {}, at)
    assert calls["read"] == 2 and calls["total"] == 2 and calls["product"] == 1
    assert calls["raise_"] == 2 and calls["inverse"] == 1 and calls["sign"] == 1
    tape = Tape(e)
    calls.clear()
    assert tape.values(at, counting)[-1] == EXACT.value_of(e, {}, at)
    assert calls["read"] == 2 and calls["total"] == 2 and calls["product"] == 1
    assert tape.slope(tape.values(at, counting), {X: 1}, counting) == tape.slope(tape.values(at, EXACT), {X: 1}, EXACT)
