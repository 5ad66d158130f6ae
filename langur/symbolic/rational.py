"""Exact values and directional derivatives of large rational closed forms (issue 15): a closed
form of rationals, symbols, +, ·, integer powers and ``Abs`` evaluated at a rational point with
integer pairs (Henrici's reduced additions) instead of sympy's nodes, and differentiated along a line
by dual numbers over the rationals.  Theorem 8.1's check (:mod:`langur.theorem`) differentiates the
closed form of ⟦p⟧ that :mod:`langur.symbolic.local` builds for large problems (the stylization
kernel's triangle, §10.3.1; the ray-traced triangle, §10.2), and :mod:`langur.symbolic.regions`
decides the relations of its parameter cell at the point with :func:`rational_value`.
"""

from __future__ import annotations

import math
from fractions import Fraction

import sympy as sp

from langur.memo import remember


def rational_value(expr, point: dict, memo: dict | None = None):
    """``expr`` at ``point`` (symbols → Rationals) as an exact Fraction, for forms built from
    rationals, symbols, +, ·, integer powers and ``Abs``; None otherwise (or on a division by 0).
    The values of subtrees are remembered per point (:func:`_point_values`): a closed form, the
    relations of its cell and the closed forms of the other partial derivatives share their
    subtrees.  (``memo``, a dict of the caller's for the same purpose, is not needed any more.)"""
    try:
        n, d = _value_of(sp.sympify(expr), _point_values(point), point)
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
        tape = _Tape.of(sp.sympify(expr))
        n, d = tape.slope(tape.values(point), tangent)
        return Fraction(n, d)
    except (_NotRational, ZeroDivisionError):
        return None


_RAT, _SYM, _ADD, _MUL, _POW, _ABS = range(6)
#: Flattened closed forms (:class:`_Tape`) by form, or the exception met flattening it.
_TAPES: dict = {}


class _Tape:
    """A form of rationals, symbols, +, ·, integer powers and ``Abs`` as a list of operations over
    its distinct subtrees, children before parents (the form itself last): ``(kind, operand
    indices, payload)`` with the payload a rational's integer pair, a symbol, or a power's
    exponent; and its values by point."""

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
        self._values: dict = {}
        self._balls: dict = {}

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

    def values(self, point: dict) -> list:
        """The value of every operation at ``point`` (remembered for the last few points), sharing
        the values of subtrees at the point with :func:`rational_value` (:func:`_point_values`): the
        Theorem 8.1 check differentiates ⟦p⟧'s closed form and evaluates ⦇p⦈'s and its cell's
        relations at the same points, and they share their subtrees (a polygon's vertices and their
        powers, the weights' coefficients)."""
        key = _point_key(point)
        vals = self._values.get(key)
        if vals is None:
            vals = []
            known = _point_values(point)
            for node, (kind, args, k) in zip(self.nodes, self.ops):
                v = known.get(node)
                if v is not None:
                    vals.append(v)
                    continue
                if kind == _RAT:
                    v = k
                elif kind == _SYM:
                    if k not in point:
                        raise _NotRational()
                    v = _rational(point[k])
                elif kind == _ADD:
                    v = _ZERO
                    for j in args:
                        v = _qadd(v, vals[j])
                elif kind == _MUL:
                    v = _ONE
                    for j in args:
                        v = _qmul(v, vals[j])
                elif kind == _POW:
                    b = vals[args[0]]
                    if b[0] == 0 and k < 1:
                        raise _NotRational()
                    v = _qpow(b, k)
                else:
                    a = vals[args[0]]
                    if a[0] == 0:
                        raise _NotRational()  # (not differentiable there)
                    v = (abs(a[0]), a[1])
                vals.append(v)
                known[node] = v
            remember(self._values, key, vals, VALUE_POINTS)
        return vals

    def slope(self, vals: list, tangent: dict):
        """The derivative along ``tangent`` (forward mode, ``None`` standing for 0)."""
        d: list = []
        for kind, args, k in self.ops:
            if kind == _RAT:
                out = None
            elif kind == _SYM:
                t = _rational(tangent.get(k, 0))
                out = t if t[0] else None
            elif kind == _ADD:
                out = None
                for j in args:
                    dj = d[j]
                    if dj is not None:
                        out = dj if out is None else _qadd(out, dj)
            elif kind == _MUL:
                out = None
                last = -1
                for i, j in enumerate(args):
                    if d[j] is not None:
                        last = i
                v = _ONE  # Σᵢ dᵢ·Πⱼ≠ᵢ vⱼ as d ← d·vᵢ + v·dᵢ, v ← v·vᵢ (v needed up to the last dᵢ ≠ 0)
                for i in range(last + 1):
                    j = args[i]
                    if out is not None:
                        out = _qmul(out, vals[j])
                    dj = d[j]
                    if dj is not None:
                        term = _qmul(v, dj)
                        out = term if out is None else _qadd(out, term)
                    if i < last:
                        v = _qmul(v, vals[j])
                if out is not None:
                    for i in range(last + 1, len(args)):
                        out = _qmul(out, vals[args[i]])
            elif kind == _POW:
                db = d[args[0]]
                out = None if db is None else _qmul(_qmul((k, 1), _qpow(vals[args[0]], k - 1)), db)
            else:
                da = d[args[0]]
                out = da if da is None or vals[args[0]][0] > 0 else (-da[0], da[1])
            if out is not None and out[0] == 0:
                out = None
            d.append(out)
        return d[-1] or _ZERO


    def balls(self, point: dict) -> list:
        """Every operation's value at ``point`` as a ball (:func:`_bmul`), remembered for the last
        few points and sharing the balls of subtrees at the point with :func:`float_value`
        (:func:`_point_balls`); :class:`_Uncertain` where a ball holds 0 and a sign is needed."""
        key = _point_key(point)
        vals = self._balls.get(key)
        if vals is None:
            vals = []
            known = _point_balls(point)
            for node, (kind, args, k) in zip(self.nodes, self.ops):
                v = known.get(node)
                if v is None:
                    if kind == _RAT:
                        v = _bconst(*k)
                    elif kind == _SYM:
                        if k not in point:
                            raise _NotRational()
                        v = _bconst(*_rational(point[k]))
                    elif kind == _ADD:
                        m = r = 0
                        for j in args:
                            a, s = vals[j]
                            m += a
                            r += s
                        v = (m, r)
                    elif kind == _MUL:
                        v = vals[args[0]]
                        for j in args[1:]:
                            v = _bmul(v, vals[j])
                    elif kind == _POW:
                        v = _bpow(vals[args[0]], k)
                    else:
                        a, r = vals[args[0]]
                        if abs(a) <= r:
                            raise _Uncertain()
                        v = (abs(a), r)
                    known[node] = v
                vals.append(v)
            remember(self._balls, key, vals, VALUE_POINTS)
        return vals

    def ball_slope(self, vals: list, tangent: dict):
        """:meth:`slope` in balls (``None`` standing for an exact 0)."""
        d: list = []
        for kind, args, k in self.ops:
            if kind == _RAT:
                out = None
            elif kind == _SYM:
                t = _rational(tangent.get(k, 0))
                out = _bconst(*t) if t[0] else None
            elif kind == _ADD:
                out = None
                m = r = 0
                for j in args:
                    dj = d[j]
                    if dj is not None:
                        out = True
                        m += dj[0]
                        r += dj[1]
                if out is not None:
                    out = (m, r)
            elif kind == _MUL:
                out = None
                last = -1
                for i, j in enumerate(args):
                    if d[j] is not None:
                        last = i
                v = None  # (the product of the values so far; None: 1)
                for i in range(last + 1):
                    j = args[i]
                    if out is not None:
                        out = _bmul(out, vals[j])
                    dj = d[j]
                    if dj is not None:
                        term = dj if v is None else _bmul(v, dj)
                        out = term if out is None else (out[0] + term[0], out[1] + term[1])
                    if i < last:
                        v = vals[j] if v is None else _bmul(v, vals[j])
                if out is not None:
                    for i in range(last + 1, len(args)):
                        out = _bmul(out, vals[args[i]])
            elif kind == _POW:
                db = d[args[0]]
                if db is None:
                    out = None
                else:
                    p = _bpow(vals[args[0]], k - 1)
                    out = _bmul((k * p[0], abs(k) * p[1]), db)
            else:
                da = d[args[0]]
                out = da if da is None or vals[args[0]][0] > 0 else (-da[0], da[1])
            if out is not None and out == (0, 0):
                out = None
            d.append(out)
        return d[-1] or (0, 0)


def _operands(node) -> tuple:
    """The operands :class:`_Tape` flattens (:class:`_NotRational` for any other node)."""
    if isinstance(node, (sp.Rational, sp.Symbol)):
        return ()
    if isinstance(node, (sp.Add, sp.Mul, sp.Abs)):
        return node.args
    if isinstance(node, sp.Pow) and node.exp.is_Integer:
        return (node.base,)
    raise _NotRational()


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


def _qpow(x, k: int):
    n, d = (x[0] ** k, x[1] ** k) if k >= 0 else (x[1] ** -k, x[0] ** -k)
    return (-n, -d) if d < 0 else (n, d)


_ZERO, _ONE = (0, 1), (1, 1)


def _rational(z) -> tuple[int, int]:
    z = sp.sympify(z)
    if not isinstance(z, sp.Rational):
        raise _NotRational()
    return int(z.p), int(z.q)


#: Exact values of subtrees (reduced integer pairs, :func:`_qadd`) by evaluation point, the
#: few most recent points (a point's dict is dropped with it).
_VALUES: dict = {}
#: Points whose values are kept.
VALUE_POINTS = 8
def _point_key(point: dict):
    return frozenset(point.items())


def _point_values(point: dict) -> dict:
    """The remembered values of subtrees at ``point`` (a new dict for a new point)."""
    key = _point_key(point)
    memo = _VALUES.pop(key, None)  # (moved to the end: the oldest point is dropped first)
    return remember(_VALUES, key, {} if memo is None else memo, VALUE_POINTS)


def _value_of(e, memo: dict, point: dict):
    """``e`` at ``point`` as a reduced integer pair (:class:`_NotRational` when it is not a form
    of rationals, symbols, +, ·, integer powers and ``Abs``, or is undefined there)."""
    hit = memo.get(e)
    if hit is not None:
        return hit
    if isinstance(e, sp.Rational):
        out = (int(e.p), int(e.q))
    elif isinstance(e, sp.Symbol):
        if e not in point:
            raise _NotRational()
        out = _rational(point[e])
    elif isinstance(e, sp.Add):
        out = _ZERO
        for a in e.args:
            out = _qadd(out, _value_of(a, memo, point))
    elif isinstance(e, sp.Mul):
        out = _ONE
        for a in e.args:
            out = _qmul(out, _value_of(a, memo, point))
    elif isinstance(e, sp.Pow) and e.exp.is_Integer:
        bv = _value_of(e.base, memo, point)
        k = int(e.exp)
        if bv[0] == 0 and k < 1:
            raise _NotRational()
        out = _qpow(bv, k)
    elif isinstance(e, sp.Abs):
        av = _value_of(e.args[0], memo, point)
        if av[0] == 0:
            raise _NotRational()  # (not differentiable there)
        out = (abs(av[0]), av[1])
    else:
        raise _NotRational()
    memo[e] = out
    return out


class _NotRational(Exception):
    pass


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


def _bpow(x, k: int):
    """A ball holding xᵏ for every point x of ball ``x`` (k an integer): |(a + δ)ᵏ − aᵏ| ≤
    (|a| + |δ|)ᵏ − |a|ᵏ for k ≥ 1; a negative power is the reciprocal (:func:`_binv`) of the
    positive one; :class:`_Uncertain` for k < 1 when the ball holds 0."""
    a, r = x
    if k < 1:
        if abs(a) <= r:
            raise _Uncertain()
        return (_SCALE, 0) if k == 0 else _binv(_bpow(x, -k))
    if k == 1:
        return x
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
    m, r = ball
    if m > r:
        return 1
    if m < -r:
        return -1
    if m == r == 0:
        return 0
    raise _Uncertain()


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


def dual_derivative_float(expr, point: dict, tangent: dict) -> float | None:
    """``float(dual_derivative(expr, point, tangent))`` (the same double; None where that is
    None), from balls when they decide it, else from the exact value."""
    def by_balls():
        tape = _Tape.of(sp.sympify(expr))
        return _double(tape.ball_slope(tape.balls(point), tangent))
    return _decided(by_balls, lambda: dual_derivative(expr, point, tangent), float)


def float_value(expr, point: dict) -> float | None:
    """``float(rational_value(expr, point))`` (the same double; None where that is None), from
    balls when they decide it, else from the exact value."""
    return _decided(lambda: _double(_ball_of(sp.sympify(expr), _point_balls(point), point)),
                    lambda: rational_value(expr, point), float)


def sign_value(expr, point: dict) -> int | None:
    """The sign (−1, 0, 1) of ``rational_value(expr, point)`` (None where that is None), from
    balls when they decide it, else from the exact value."""
    return _decided(lambda: _sign(_ball_of(sp.sympify(expr), _point_balls(point), point)),
                    lambda: rational_value(expr, point), lambda q: (q > 0) - (q < 0))


#: Balls of subtrees by evaluation point, as :data:`_VALUES`.
_BALLS: dict = {}


def _point_balls(point: dict) -> dict:
    """The remembered balls of subtrees at ``point`` (a new dict for a new point)."""
    key = _point_key(point)
    memo = _BALLS.pop(key, None)  # (moved to the end: the oldest point is dropped first)
    return remember(_BALLS, key, {} if memo is None else memo, VALUE_POINTS)


def _ball_of(e, memo: dict, point: dict):
    """:func:`_value_of` in balls (:class:`_Uncertain` where a ball holds 0 and a sign is needed)."""
    hit = memo.get(e)
    if hit is not None:
        return hit
    if isinstance(e, sp.Rational):
        out = _bconst(int(e.p), int(e.q))
    elif isinstance(e, sp.Symbol):
        if e not in point:
            raise _NotRational()
        out = _bconst(*_rational(point[e]))
    elif isinstance(e, sp.Add):
        m = r = 0
        for a in e.args:
            b, s = _ball_of(a, memo, point)
            m += b
            r += s
        out = (m, r)
    elif isinstance(e, sp.Mul):
        args = e.args
        out = _ball_of(args[0], memo, point)
        for a in args[1:]:
            out = _bmul(out, _ball_of(a, memo, point))
    elif isinstance(e, sp.Pow) and e.exp.is_Integer:
        out = _bpow(_ball_of(e.base, memo, point), int(e.exp))
    elif isinstance(e, sp.Abs):
        a, r = _ball_of(e.args[0], memo, point)
        if abs(a) <= r:
            raise _Uncertain()
        out = (abs(a), r)
    else:
        raise _NotRational()
    memo[e] = out
    return out
