"""Exact values and directional derivatives of large rational closed forms (issue 15): a closed
form of rationals, symbols, +, ·, integer powers and ``Abs`` evaluated at a rational point with
integer pairs (Henrici's reduced additions) instead of sympy's nodes, and differentiated along a line
by dual numbers over the rationals.  Theorem 8.1's check (:mod:`langur.theorem`) differentiates the
closed form of ⟦p⟧ that :mod:`langur.symbolic.local` builds for large problems (the stylization
kernel's triangle, §10.3.1; the ray-traced triangle, §10.2), decides the relations of its parameter
cell at the point with :func:`sign_value`, and :mod:`langur.symbolic.context` takes such a form's
value at the point with :func:`float_value`.

Such a form is walked in two ways: flattened once into a list of operations (:class:`_Tape`, for the
values at a point and the slope along a tangent) or recursively over its distinct subtrees
(:func:`_node_walk`).  Each walk is written once, over an :class:`Arithmetic`: the operations a mode
computes with and the failure it raises where it cannot go on.  The modes are three arithmetics:

* :data:`EXACT`: reduced integer pairs (the exact values: :func:`rational_value`,
  :func:`dual_derivative`);
* :data:`BALLS`: fixed-point intervals that hold the exact value, for its double or its sign with
  less work (:func:`float_value`, :func:`sign_value`, :func:`dual_derivative_float`; the exact
  pairs where a ball cannot decide);
* :func:`residues`: values modulo a prime, which tell sympy expressions apart
  (``local._near_form``'s size certificate, :func:`residue`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import lru_cache
from typing import Callable

import sympy as sp

from langur.memo import remember


def rational_value(expr, point: dict):
    """``expr`` at ``point`` (symbols → Rationals) as an exact Fraction, for forms built from
    rationals, symbols, +, ·, integer powers and ``Abs``; None otherwise (or on a division by 0).
    The values of subtrees are remembered per point (:func:`_point_memo`): a closed form, the
    relations of its cell and the closed forms of the other partial derivatives share their
    subtrees."""
    try:
        n, d = _value_at(EXACT, expr, point)
        return Fraction(n, d)
    except (_NotRational, ZeroDivisionError):
        return None


def dual_derivative(expr, point: dict, tangent: dict):
    """``d/ds expr(point + s·tangent)`` at s = 0 as an exact Fraction, by dual numbers over the
    rationals (one pass over the distinct subtrees): for closed forms built from rationals,
    symbols, +, ·, integer powers and ``Abs`` (away from 0); None otherwise (or where it is not
    differentiable: a division by 0, ``Abs`` at 0).  The form is flattened once into a list of
    operations (:class:`_Tape`) and its values at a point computed once (every partial
    derivative's Theorem 8.1 check differentiates the same closed form of ⟦p⟧ at the same
    points); a subtree whose derivative along the line is 0 costs no arithmetic."""
    try:
        n, d = _slope_at(EXACT, expr, point, tangent)
        return Fraction(n, d)
    except (_NotRational, ZeroDivisionError):
        return None


def dual_derivative_float(expr, point: dict, tangent: dict) -> float | None:
    """``float(dual_derivative(expr, point, tangent))`` (the same double; None where that is
    None), from balls when they decide it, else from the exact value."""
    return _decided(lambda: _double(_slope_at(BALLS, expr, point, tangent)),
                    lambda: dual_derivative(expr, point, tangent), float)


def float_value(expr, point: dict) -> float | None:
    """``float(rational_value(expr, point))`` (the same double; None where that is None), from
    balls when they decide it, else from the exact value."""
    return _decided(lambda: _double(_value_at(BALLS, expr, point)), lambda: rational_value(expr, point), float)


def sign_value(expr, point: dict) -> int | None:
    """The sign (−1, 0, 1) of ``rational_value(expr, point)`` (None where that is None), from
    balls when they decide it, else from the exact value."""
    return _decided(lambda: _sign(_value_at(BALLS, expr, point)), lambda: rational_value(expr, point),
                    lambda q: (q > 0) - (q < 0))


def residue(e, point: dict, memo: dict, prime: int):
    """``e``'s value at the point modulo ``prime`` (``point``: the symbols' residues; ``memo``: the
    residues of subtrees already walked, the caller's) for a form of rationals, symbols, +, · and
    integer powers; None for anything else, a symbol without a residue, or where a denominator is
    divisible by the prime.  Equal expressions have equal residues (a ring homomorphism)."""
    try:
        return residues(prime).value_of(e, memo, point)
    except (_NotRational, _NoResidue):
        return None


def _decided(by_balls, exact, of_exact):
    """``by_balls()`` when the balls decide it; None for a form that is not rational; else
    ``of_exact`` of the exact value ``exact()`` (None where that is None)."""
    try:
        return by_balls()
    except _NotRational:
        return None
    except _Uncertain:
        pass
    value = exact()
    return None if value is None else of_exact(value)


def _value_at(arith: "Arithmetic", expr, point: dict):
    """``expr`` at ``point`` in ``arith`` (the values of subtrees remembered per point)."""
    return arith.value_of(sp.sympify(expr), _point_memo(arith, point), point)


def _slope_at(arith: "Arithmetic", expr, point: dict, tangent: dict):
    """The derivative of ``expr`` along ``tangent`` at ``point`` in ``arith`` (:meth:`_Tape.slope`)."""
    tape = _Tape.of(sp.sympify(expr))
    return tape.slope(tape.values(point, arith), tangent, arith)


class _NotRational(Exception):
    """The form is not one of rationals, symbols, +, ·, integer powers and ``Abs``, or a symbol has
    no rational value at the point (or, in :data:`EXACT`, the form is undefined there)."""


class Arithmetic:
    """How one mode computes with the values of a form's subtrees: the walks (:class:`_Tape`,
    :func:`_node_walk`) are written once over these operations.

    Declared per mode: ``const(n, d)`` (the rational n/d, d > 0), ``read(z)`` (a point's value of a
    symbol), ``total(values)`` and ``product(values)`` (of a non-empty iterable), ``add(x, y)`` and
    ``mul(x, y)`` (the same of two), ``raise_(x, k)`` (xᵏ for k ≥ 1), ``inverse(x)``, ``sign(x)``
    (−1, 0 or 1), ``neg(x)``, ``scale(x, k)`` (k·x for an integer k; only the slopes use it),
    ``failure`` (the exception the operations raise where the mode cannot decide: a reciprocal or
    a sign at or near 0) and ``points`` (the values of subtrees remembered by point, for
    :func:`_point_memo`; a dict of its own unless given).  Derived here, the same for every mode:
    ``power`` (xᵏ for any integer k: undefined at 0 for k < 1), ``magnitude`` (|x|, differentiable
    only away from 0), ``zero`` and ``one``, and the mode's recursive walk ``value_of(e, memo,
    point)`` (:func:`_node_walk`)."""

    def __init__(self, name: str, *, const: Callable, read: Callable, total: Callable, product: Callable,
                 add: Callable, mul: Callable, raise_: Callable, inverse: Callable, sign: Callable, neg: Callable,
                 failure: type, scale: Callable | None = None, points: dict | None = None):
        self.name = name
        self.const, self.read, self.total, self.product = const, read, total, product
        self.add, self.mul, self.raise_, self.inverse = add, mul, raise_, inverse
        self.sign, self.neg, self.scale, self.failure = sign, neg, scale, failure
        self.points = {} if points is None else points
        self.zero, self.one = const(0, 1), const(1, 1)
        self.power = _power_of(raise_, inverse, self.one)
        self.magnitude = _magnitude_of(sign, neg, failure)
        self.value_of = _node_walk(self)

    def __repr__(self) -> str:
        return f"Arithmetic({self.name})"


def _power_of(raise_, inverse, one):
    """xᵏ for an integer k from xᵏ (k ≥ 1) and 1/x: for k < 1 the reciprocal of x⁻ᵏ (x⁰ = 1), the
    arithmetic's failure where that is (or may be) 0."""
    def power(x, k: int):
        if k >= 1:
            return raise_(x, k)
        y = inverse(raise_(x, -k) if k else x)
        return y if k else one
    return power


def _magnitude_of(sign, neg, failure):
    """|x| where it is differentiable (away from 0; the arithmetic's failure at 0)."""
    def magnitude(x):
        s = sign(x)
        if s == 0:
            raise failure()  # (not differentiable there)
        return x if s > 0 else neg(x)
    return magnitude


_RAT, _SYM, _ADD, _MUL, _POW, _ABS = range(6)
#: Flattened closed forms (:class:`_Tape`) by form, or the exception met flattening it.
_TAPES: dict = {}


class _Tape:
    """A form of rationals, symbols, +, ·, integer powers and ``Abs`` as a list of operations over
    its distinct subtrees, children before parents (the form itself last): ``(kind, operand
    indices, payload)`` with the payload a rational's integer pair, a symbol, or a power's
    exponent; and its values by arithmetic and point."""

    def __init__(self, expr):
        index: dict = {}
        self.ops: list = []
        self.nodes: list = []  # (the subtree of each operation)
        stack = [(expr, False)]
        while stack:
            node, done = stack.pop()
            if node in index:
                continue
            if done:
                index[node] = len(self.ops)
                self.ops.append(self._op(node, index))
                self.nodes.append(node)
                continue
            stack.append((node, True))
            stack.extend((a, False) for a in _operands(node) if a not in index)
        self._values: dict = {}  # arithmetic -> point key -> values

    @staticmethod
    def _op(node, index):
        if isinstance(node, sp.Rational):
            return _RAT, (), (int(node.p), int(node.q))
        if isinstance(node, sp.Symbol):
            return _SYM, (), node
        if isinstance(node, sp.Add):
            return _ADD, tuple(index[a] for a in node.args), None
        if isinstance(node, sp.Mul):
            return _MUL, tuple(index[a] for a in node.args), None
        if isinstance(node, sp.Pow):
            return _POW, (index[node.base],), int(node.exp)
        return _ABS, (index[node.args[0]],), None

    @classmethod
    def of(cls, expr) -> "_Tape":
        tape = _TAPES.get(expr)
        if tape is None:
            try:
                tape = cls(expr)
            except _NotRational as exc:
                tape = exc
            remember(_TAPES, expr, tape, 64)
        if isinstance(tape, Exception):
            raise tape
        return tape

    def values(self, point: dict, arith: "Arithmetic") -> list:
        """The value of every operation at ``point`` in ``arith`` (remembered for the last few
        points), sharing the values of subtrees at the point with the recursive walk
        (:func:`_point_memo`): the Theorem 8.1 check differentiates ⟦p⟧'s closed form and
        evaluates ⦇p⦈'s and its cell's relations at the same points, and they share their
        subtrees (a polygon's vertices and their powers, the weights' coefficients)."""
        memo = self._values.get(arith)
        if memo is None:
            memo = self._values[arith] = {}
        key = _point_key(point)
        vals = memo.get(key)
        if vals is None:
            const, read, total, product = arith.const, arith.read, arith.total, arith.product
            power, magnitude = arith.power, arith.magnitude
            vals = []
            at = vals.__getitem__
            known = _point_memo(arith, point)
            for node, (kind, args, k) in zip(self.nodes, self.ops):
                v = known.get(node)
                if v is None:
                    if kind == _RAT:
                        v = const(*k)
                    elif kind == _SYM:
                        if k not in point:
                            raise _NotRational()
                        v = read(point[k])
                    elif kind == _ADD:
                        v = total(map(at, args))
                    elif kind == _MUL:
                        v = product(map(at, args))
                    elif kind == _POW:
                        v = power(vals[args[0]], k)
                    else:
                        v = magnitude(vals[args[0]])
                    known[node] = v
                vals.append(v)
            remember(memo, key, vals, VALUE_POINTS)
        return vals

    def slope(self, vals: list, tangent: dict, arith: "Arithmetic"):
        """The derivative along ``tangent`` in ``arith`` (forward mode over the values ``vals``,
        ``None`` standing for an exact 0)."""
        read, add, mul, power, sign, neg, scale = (arith.read, arith.add, arith.mul, arith.power, arith.sign,
                                                   arith.neg, arith.scale)
        zero, one = arith.zero, arith.one
        d: list = []
        for kind, args, k in self.ops:
            if kind == _RAT:
                out = None
            elif kind == _SYM:
                out = read(tangent.get(k, 0))
            elif kind == _ADD:
                out = None
                for j in args:
                    dj = d[j]
                    if dj is not None:
                        out = dj if out is None else add(out, dj)
            elif kind == _MUL:
                out = None
                last = -1
                for i, j in enumerate(args):
                    if d[j] is not None:
                        last = i
                # Σᵢ dᵢ·Πⱼ≠ᵢ vⱼ as d ← d·vᵢ + v·dᵢ, v ← v·vᵢ (v: the product so far, None for 1;
                # needed up to the last dᵢ ≠ 0)
                v = None
                for i in range(last + 1):
                    j = args[i]
                    if out is not None:
                        out = mul(out, vals[j])
                    dj = d[j]
                    if dj is not None:
                        term = dj if v is None else mul(v, dj)
                        out = term if out is None else add(out, term)
                    if i < last:
                        v = vals[j] if v is None else mul(v, vals[j])
                if out is not None:
                    for i in range(last + 1, len(args)):
                        out = mul(out, vals[args[i]])
            elif kind == _POW:
                db = d[args[0]]
                # (k·xᵏ⁻¹·dx; x¹'s slope is dx, also at x = 0)
                out = None if db is None else mul(scale(one if k == 1 else power(vals[args[0]], k - 1), k), db)
            else:
                da = d[args[0]]
                out = da if da is None or sign(vals[args[0]]) > 0 else neg(da)
            if out is not None and out == zero:
                out = None
            d.append(out)
        return d[-1] or zero


def _operands(node) -> tuple:
    """The operands :class:`_Tape` flattens (:class:`_NotRational` for any other node)."""
    if isinstance(node, (sp.Rational, sp.Symbol)):
        return ()
    if isinstance(node, (sp.Add, sp.Mul, sp.Abs)):
        return node.args
    if isinstance(node, sp.Pow) and node.exp.is_Integer:
        return (node.base,)
    raise _NotRational()


def _node_walk(arith: Arithmetic):
    """``value_at(e, memo, point)``: ``e`` at ``point`` in ``arith``, recursively over its
    distinct subtrees (their values remembered in ``memo``); :class:`_NotRational` when ``e`` is
    not a form of rationals, symbols, +, ·, integer powers and ``Abs`` or a symbol has no value,
    the arithmetic's failure where it cannot decide.  (The arithmetic's operations are bound once,
    here, and the memo and the point once per call: a sum's or a product's operands are walked as
    the arithmetic folds them.)"""
    const, read, total, product = arith.const, arith.read, arith.total, arith.product
    power, magnitude = arith.power, arith.magnitude

    def value_at(e, memo: dict, point: dict):
        known = memo.get

        def value_of(e):
            hit = known(e)
            if hit is not None:
                return hit
            if isinstance(e, sp.Rational):
                out = const(int(e.p), int(e.q))
            elif isinstance(e, sp.Symbol):
                if e not in point:
                    raise _NotRational()
                out = read(point[e])
            elif isinstance(e, sp.Add):
                out = total(map(value_of, e.args))
            elif isinstance(e, sp.Mul):
                out = product(map(value_of, e.args))
            elif isinstance(e, sp.Pow) and e.exp.is_Integer:
                out = power(value_of(e.base), int(e.exp))
            elif isinstance(e, sp.Abs):
                out = magnitude(value_of(e.args[0]))
            else:
                raise _NotRational()
            memo[e] = out
            return out
        return value_of(e)
    return value_at


#: Points whose values of subtrees are kept, per arithmetic.
VALUE_POINTS = 8


def _point_key(point: dict):
    return frozenset(point.items())


def _point_memo(arith: Arithmetic, point: dict) -> dict:
    """The remembered values of subtrees at ``point`` in ``arith`` (a new dict for a new point; the
    few most recent points are kept, a point's dict dropped with it)."""
    key = _point_key(point)
    memo = arith.points.pop(key, None)  # (moved to the end: the oldest point is dropped first)
    return remember(arith.points, key, {} if memo is None else memo, VALUE_POINTS)


# Exact: reduced integer pairs ``(numerator, denominator > 0)``.

def _qadd(x, y):
    """``x + y`` for reduced integer pairs ``(numerator, denominator > 0)``, reduced (Henrici's
    algorithm, as CPython's ``Fraction``: the gcds are taken of the operands' denominators, not of
    the sum's far larger numerator and denominator; a gcd of two large integers was most of the
    time of evaluating a large closed form exactly)."""
    a, b = x[1], y[1]
    if a == b:
        n = x[0] + y[0]
        g = _gcd(n, a)
        return (n, a) if g == 1 else (n // g, a // g)
    g = _gcd(a, b)
    if g == 1:  # (then the sum of reduced fractions is reduced)
        return x[0] * b + y[0] * a, a * b
    s = a // g
    t = x[0] * (b // g) + y[0] * s
    g2 = _gcd(t, g)  # (a common factor of t and the denominator s·b divides g)
    return (t, s * b) if g2 == 1 else (t // g2, s * (b // g2))


def _qmul(x, y):
    """``x · y`` for reduced integer pairs, reduced (each numerator against the other denominator)."""
    n1, d1 = x
    n2, d2 = y
    g1 = _gcd(n1, d2)
    if g1 != 1:
        n1, d2 = n1 // g1, d2 // g1
    g2 = _gcd(n2, d1)
    if g2 != 1:
        n2, d1 = n2 // g2, d1 // g2
    return n1 * n2, d1 * d2


_gcd = math.gcd
_ZERO, _ONE = (0, 1), (1, 1)


def _qsum(xs):
    v = _ZERO
    for x in xs:
        v = _qadd(v, x)
    return v


def _qprod(xs):
    v = _ONE
    for x in xs:
        v = _qmul(v, x)
    return v


def _qinv(x):
    n, d = x
    if n == 0:
        raise _NotRational()
    return (-d, -n) if n < 0 else (d, n)


def _rational(z) -> tuple[int, int]:
    z = sp.sympify(z)
    if not isinstance(z, sp.Rational):
        raise _NotRational()
    return int(z.p), int(z.q)


#: Exact values of subtrees (reduced integer pairs, :func:`_qadd`) by evaluation point.
_VALUES: dict = {}

EXACT = Arithmetic(
    "exact", const=lambda n, d: (n, d), read=_rational, total=_qsum, product=_qprod, add=_qadd, mul=_qmul,
    raise_=lambda x, k: (x[0] ** k, x[1] ** k), inverse=_qinv, sign=lambda x: (x[0] > 0) - (x[0] < 0),
    neg=lambda x: (-x[0], x[1]), scale=lambda x, k: _qmul((k, 1), x), failure=_NotRational, points=_VALUES)


# Balls: the same values, bounded with less work.  Theorem 8.1's check reads of these exact
# values only their signs and their doubles, and near the parameters (floats, dyadic rationals of
# ~55 bits) their numerators and denominators carry hundreds of digits: most of the exact
# arithmetic is reducing them (gcds).  A ball ``(m, r)`` stands for the interval
# [(m − r)·2⁻ᴾ, (m + r)·2⁻ᴾ] (P = :data:`BALL_BITS`, m and r ≥ 0 integers); every operation
# below returns a ball holding every result of its operation on the points of its operands'
# balls, so the exact value is inside the final ball.  Rounding is monotone, so when both ends
# of that ball round to the same double the exact value rounds to it too: ``float`` of the exact
# Fraction, the same double.  Where a ball cannot decide (it holds 0 where a sign or a quotient is
# needed, or its ends round apart) the exact arithmetic above is computed instead.

#: Bits after the binary point of a ball's integers.
BALL_BITS = 192
_P = BALL_BITS
_MASK = (1 << _P) - 1
_SCALE = 1 << _P


class _Uncertain(Exception):
    """A ball cannot decide: the exact arithmetic is computed instead."""


def _bconst(n: int, d: int):
    """The ball of the rational n/d (d > 0): ⌊n·2ᴾ/d⌋, radius 1 unless exact."""
    m, rem = divmod(n << _P, d)
    return m, (1 if rem else 0)


def _bsum(xs):
    """A ball holding every sum of points of the balls ``xs``: the centres' and the radii's sums."""
    m = r = 0
    for a, s in xs:
        m += a
        r += s
    return m, r


def _bmul(x, y):
    """A ball holding every product of points of balls ``x`` and ``y``: the centres' product
    ab·2⁻²ᴾ is within |a|s + |b|r + rs (in 2⁻²ᴾ) of each, and shifting it down by P floors
    (< 1 in 2⁻ᴾ)."""
    a, r = x
    b, s = y
    p = a * b
    if r or s:
        return p >> _P, ((abs(a) * s + abs(b) * r + r * s) >> _P) + 2
    return p >> _P, (1 if p & _MASK else 0)


def _bprod(xs):
    it = iter(xs)
    v = next(it)
    for y in it:
        v = _bmul(v, y)
    return v


def _bpow(x, k: int):
    """A ball holding xᵏ for every point x of ball ``x`` (k ≥ 1 an integer): |(a + δ)ᵏ − aᵏ| ≤
    (|a| + |δ|)ᵏ − |a|ᵏ.  (A power below 1 is the reciprocal, :func:`_binv`, of one above:
    :class:`Arithmetic`'s ``power``.)"""
    if k == 1:
        return x
    a, r = x
    c = a ** k  # (in 2⁻ᵏᴾ)
    shift = (k - 1) * _P
    if r:
        big = abs(a)
        return c >> shift, (((big + r) ** k - big ** k) >> shift) + 2
    return c >> shift, (1 if c & ((1 << shift) - 1) else 0)


def _binv(x):
    """A ball holding 1/x for every point x of ball ``x`` (:class:`_Uncertain` when it holds 0):
    in 2⁻ᴾ, 2²ᴾ/t for t within r of a, which is within 2²ᴾ·r/(|a|(|a| − r)) of 2²ᴾ/a."""
    a, r = x
    big = abs(a)
    if big <= r:
        raise _Uncertain()
    m, rem = divmod(1 << (2 * _P), a)
    if r:
        return m, ((r << (2 * _P)) // (big * (big - r))) + 2
    return m, (1 if rem else 0)


def _double(ball) -> float:
    """The double of the exact value inside ``ball``, when both its ends round to the same one
    (:class:`_Uncertain` otherwise, or when it is beyond a double's range)."""
    m, r = ball
    try:
        lo, hi = (m - r) / _SCALE, (m + r) / _SCALE  # (int / int rounds correctly)
    except OverflowError:
        raise _Uncertain() from None
    if lo != hi or math.isinf(lo):
        raise _Uncertain()
    return lo


def _sign(ball) -> int:
    """The sign of every point of ``ball`` (:class:`_Uncertain` when they differ)."""
    m, r = ball
    if m > r:
        return 1
    if m < -r:
        return -1
    if m == r == 0:
        return 0
    raise _Uncertain()


#: Balls of subtrees by evaluation point, as :data:`_VALUES`.
_BALLS: dict = {}

BALLS = Arithmetic(
    "balls", const=_bconst, read=lambda z: _bconst(*_rational(z)), total=_bsum, product=_bprod,
    add=lambda x, y: (x[0] + y[0], x[1] + y[1]), mul=_bmul, raise_=_bpow,
    inverse=_binv, sign=_sign, neg=lambda x: (-x[0], x[1]), scale=lambda x, k: (k * x[0], abs(k) * x[1]),
    failure=_Uncertain, points=_BALLS)


# Residues: values modulo a prime.  Equal expressions have equal values, so equal residues; values
# that differ differ modulo a large prime but for a coincidence (``local._near_form`` tells sympy's
# terms apart by them, and counts a coincidence against itself).

class _NoResidue(Exception):
    """No residue: the prime divides a denominator, a power below 1 of 0, or |·|."""


@lru_cache(maxsize=None)
def residues(prime: int) -> Arithmetic:
    """The arithmetic modulo ``prime`` (a point's values given as residues)."""
    def const(n, d):
        q = d % prime
        if q == 0:
            raise _NoResidue()
        return n * pow(q, -1, prime) % prime

    def total(xs):
        out = 0
        for v in xs:
            out = (out + v) % prime
        return out

    def product(xs):
        out = 1
        for v in xs:
            out = out * v % prime
        return out

    def inverse(v):
        if v == 0:
            raise _NoResidue()
        return pow(v, -1, prime)

    def sign(v):
        raise _NoResidue()  # (no order modulo a prime: no |·|)

    return Arithmetic(
        f"residues mod {prime}", const=const, read=lambda z: z, total=total, product=product,
        add=lambda u, v: (u + v) % prime, mul=lambda u, v: u * v % prime,
        raise_=lambda v, k: pow(v, k, prime), inverse=inverse, sign=sign, neg=lambda v: -v % prime,
        failure=_NoResidue)
