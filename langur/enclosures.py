"""Certified sign changes of an equation in one variable by interval enclosures (issue 18).

The k-th sign change of ``g − target`` on ``[lo, hi]`` (an indexed root, a turning point that
moves with the parameters: :mod:`langur.syntax.turning`) is found on brackets certified to hold
exactly one: :func:`certified_brackets` certifies every cell of a grid of ``[lo, hi]`` by an
interval enclosure of ``g − target`` that excludes 0 (no zero there) or one of ``g'`` that
excludes 0 (``g`` monotone: a zero iff a sign change between the cell's ends), halving a cell
neither certifies, and refuses (:class:`~langur.core.TooManyRoots`) rather than miss one.
The enclosures are mpmath's interval arithmetic (rounded outward: a proof) of lambdify's interval
text of the equation (:func:`interval_function`, :class:`_IntervalPrinter`); for a polynomial, float
enclosures that bracket mpmath's decide first where they can (:mod:`langur.floativ`,
:func:`_signer`).  That text is interval arithmetic only for sums, products, powers and the
functions of :data:`ENCLOSED` (``Abs`` among them): ``Max``, ``Min``, ``Piecewise``, ``Heaviside`` are printed as Python
comparisons of intervals, which pick one side of an interval holding both (``max(0, [−1, 2])`` is
``0``), so an equation holding one is refused, never enclosed.

Used by :mod:`langur.implicit` (``evalf`` and lambdified code of an indexed
:class:`~langur.implicit.ImplicitRootFn`) and by :mod:`langur.syntax.continuity` and
:mod:`langur.syntax.monotone` (a condition proved continuous or monotone); the Monte Carlo
engine certifies the same way on its own, vectorized (:mod:`langur.operational.signchanges`).  The same arithmetic over a box, every
variable an interval (:func:`enclose`), proves a primitive's argument inside its domain for
:mod:`langur.symbolic.definedness`.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping

import mpmath
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from . import floativ
from .codes import turning_points_uncertified
from .core import TooManyRoots

#: Cells of the grid of ``[lo, hi]`` on which an indexed root's sign changes are certified.
GRID = 16
#: Halvings of a cell that neither enclosure certifies before the root is refused.
DEPTH = 30


def _monotone_iv(fn, increasing: bool = True):
    """An mpmath interval version of a monotone function mpmath's ``iv`` lacks (``atan``, ``tanh``,
    ``erf``, …): its values at the ends, a few bits more precise, widened outward; anything
    where it is undefined at an end."""
    def f(X):
        X = mpmath.iv.mpf(X)
        try:
            with mpmath.workprec(mpmath.iv.prec + 16):
                a, b = fn(mpmath.mpf(X.a)), fn(mpmath.mpf(X.b))
            if not (isinstance(a, mpmath.mpf) and isinstance(b, mpmath.mpf)):
                raise ValueError
        except (ValueError, ZeroDivisionError, TypeError):
            return mpmath.iv.mpf([-mpmath.inf, mpmath.inf])
        if not increasing:
            a, b = b, a
        slack = (abs(a) + abs(b)) * mpmath.mpf(2) ** (2 - mpmath.iv.prec) + mpmath.mpf(2) ** -1000
        return mpmath.iv.mpf([a - slack, b + slack])
    return f


#: The argument below which :func:`_exp` does not compute ``exp`` (a double's exponent range, far past).
_EXP_FLOOR = -(2 ** 1100)


def _exp(X):
    """mpmath's interval ``exp``, except below :data:`_EXP_FLOOR`, where it is ``[0, exp(floor)]``:
    ``exp`` is increasing and positive, so that holds it; mpmath computes ``exp(−e^(10⁶))`` to its
    53 bits, with an exponent of 434,294 digits, in seconds (``exp(-cosh x)`` on [−10⁶, 10⁶],
    bench/history/2026-11-29.md#proof33."""
    X = mpmath.iv.mpf(X)
    if X.a >= _EXP_FLOOR:
        return mpmath.iv.exp(X)
    top = _exp_floor() if X.b < _EXP_FLOOR else mpmath.iv.exp(X.b)
    return mpmath.iv.mpf([0, top.b])


@functools.lru_cache(maxsize=1)
def _exp_floor():
    return mpmath.iv.exp(mpmath.iv.mpf(_EXP_FLOOR))


#: lambdify's names for the interval versions (the rest from ``mpmath.iv``; ``log`` is a method of
#: its class, which lambdify would otherwise take from ``math``).
_IV = {"log": mpmath.iv.log, "mpf": mpmath.iv.mpf, "exp": _exp, "atan": _monotone_iv(mpmath.atan), "tanh": _monotone_iv(mpmath.tanh), "erf": _monotone_iv(mpmath.erf),
       "asin": _monotone_iv(mpmath.asin), "acos": _monotone_iv(mpmath.acos, increasing=False),
       "atanh": _monotone_iv(mpmath.atanh)}


class _IntervalPrinter(PythonCodePrinter):
    """lambdify's text for mpmath intervals: a rational constant as the interval quotient of its
    numerator and denominator (``1/3`` would be the double 0.333…, ``x**(1/3)`` a double power),
    a float as the interval of its decimal digits; ``Abs`` is Python's ``abs``, which an mpmath
    interval answers exactly (``|[−1, 2]|`` is ``[0, 2]``)."""

    def _print_Rational(self, e):
        return f"(mpf({e.p})/mpf({e.q}))"

    def _print_Half(self, e):
        return self._print_Rational(e)

    def _print_Float(self, e):
        return f"mpf({str(sp.Float(e, e._prec)).strip()!r})"


def _on_intervals(xs: list, e: sp.Expr):
    """``e`` compiled by lambdify to a function of mpmath intervals for ``xs``: every operation
    mpmath's interval arithmetic (rounded outward), constants included (:class:`_IntervalPrinter`)."""
    printer = _IntervalPrinter({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                                "user_functions": {k: k for k in _IV}})  # lambdify's own settings
    return sp.lambdify(xs, e, modules=[_IV, mpmath.iv], printer=printer)


def interval_function(x: sp.Symbol, e: sp.Expr, free: tuple = ()) -> Enclosure:
    """``e`` (in ``x`` and the symbols ``free``) as a function of mpmath intervals, an
    :class:`Enclosure`: ``enclosure(X, *values)`` is an interval containing every value of ``e`` on
    the interval ``X`` at those values of ``free`` (intervals or numbers), or None where it cannot
    be enclosed (a pole, a logarithm of an interval reaching below 0, a complex value).  Every
    operation is mpmath's interval arithmetic (rounded outward), constants included
    (:func:`_on_intervals`); a polynomial's is also compiled to float enclosures that bracket
    mpmath's (:mod:`langur.floativ`), which decide first where they can.

    **Refuses** an ``e`` that is not built of ``x``, ``free``, finite numbers, π, e, +, ·, powers
    and :data:`ENCLOSED` (``Max``, ``Min``, ``Piecewise``, ``Heaviside``, ``sign``, a relation,
    another symbol, an unknown function): the enclosure it returns is
    :attr:`~Enclosure.refused` and every call gives None, so :func:`certified_brackets` refuses its
    roots (:class:`~langur.core.TooManyRoots`) rather than trust a comparison of intervals
    (module docstring)."""
    xs = (x, *free)
    if not _enclosable(e, xs):
        return Enclosure(None, None)
    fn = _on_intervals(list(xs), e)
    return Enclosure(fn, floativ.compile_enclosure(fn, len(xs)))


#: The functions an enclosure may apply: mpmath's ``iv`` or :data:`_IV` enclose each soundly (``Abs`` by
#: mpmath's interval ``abs``).  Anything else is not enclosed: ``Max``, ``Piecewise``, a relation
#: (lambdify's text compares intervals, which is not interval arithmetic), and ``sign``, which an
#: interval function could enclose but which jumps where it is finite: every function here is
#: continuous wherever it is finite, which :mod:`langur.syntax.continuity` reads off a finite enclosure.
ENCLOSED = frozenset({sp.exp, sp.log, sp.sin, sp.cos, sp.tan, sp.tanh, sp.atan, sp.erf,
                      sp.asin, sp.acos, sp.atanh, sp.Abs})


def _enclosable(e: sp.Expr, xs: tuple) -> bool:
    """Whether :func:`enclose` and :func:`interval_function` enclose ``e`` in ``xs``: built of
    ``xs``, finite numbers, π, e, +, ·, powers and :data:`ENCLOSED`.  That interval arithmetic is
    sound for ``e``, not that ``e`` is finite (``1/x`` over [0, 1] is enclosed by [1, ∞]): a weight
    certainly finite on a box is another question, decided exactly
    (:func:`langur.symbolic.integrability.finite_on_box`)."""
    for n in sp.preorder_traversal(e):
        if n.is_Symbol:
            if n not in xs:
                return False
        elif n.is_Number:
            if n.is_finite is not True:
                return False
        elif not (n.is_Add or n.is_Mul or n.is_Pow or n is sp.pi or n is sp.E or n.func in ENCLOSED):
            return False
    return True


@functools.lru_cache(maxsize=1024)  # one condition bounds many applications
def _box_fn(e: sp.Expr, xs: tuple) -> Enclosure | None:
    return Enclosure(_on_intervals(list(xs), e), None) if _enclosable(e, xs) else None


def enclose(e: sp.Expr, box: Mapping[sp.Symbol, tuple]):
    """An interval (mpmath's) containing every real value of ``e`` on the closed box (symbol →
    its ends; ``e`` in those symbols), or None (not enclosed: anything).  The same outward-rounded
    interval arithmetic as :func:`interval_function`, every variable an interval, and the same
    refusals.  An end is a double (exact) or a sympy number (a rational exactly, as the interval quotient of its numerator and
    denominator; another, ``pi/2``, widened to the doubles around it).  An enclosure with an
    infinite end (a pole inside the box) is returned as it is; a complex one (a root of a negative
    base) is None."""
    xs = tuple(box)
    fn = _box_fn(e, xs)
    if fn is None:
        return None
    out = fn(*(mpmath.iv.mpf([_end(lo).a, _end(hi).b]) for lo, hi in box.values()))
    return out if isinstance(out, mpmath.iv.mpf) else None


def _end(v):
    """An interval holding the box end ``v`` (:func:`enclose`)."""
    if isinstance(v, sp.Rational):
        return mpmath.iv.mpf(v.p) / mpmath.iv.mpf(v.q)
    f = float(v)
    if isinstance(v, (float, int)):
        return mpmath.iv.mpf(f)
    return mpmath.iv.mpf([math.nextafter(f, -math.inf), math.nextafter(f, math.inf)])


class Enclosure:
    """:func:`interval_function`'s function: ``enclosure(X, *values)`` mpmath's interval or None;
    ``fn``: lambdify's function of intervals (None: :attr:`refused`); ``fast``: the float
    enclosures ``(outer, inner)`` of :func:`langur.floativ.compile_enclosure`, or None."""

    __slots__ = ("fn", "fast")

    def __init__(self, fn, fast):
        self.fn, self.fast = fn, fast

    @property
    def refused(self) -> bool:
        """The expression is not enclosed at all (:func:`interval_function`'s refusals)."""
        return self.fn is None

    def __call__(self, X, *values):
        if self.fn is None:
            return None
        try:
            out = self.fn(X, *values)
            out = out if isinstance(out, mpmath.iv.mpf) else mpmath.iv.mpf(out)
        except (ValueError, ZeroDivisionError, TypeError, OverflowError, mpmath.libmp.NoConvergence):
            return None
        return None if (mpmath.isnan(out.a) or mpmath.isnan(out.b)) else out

    def bind(self, *values) -> _Bound:
        """This enclosure at the values (mpmath intervals or numbers) of the other symbols."""
        return _Bound(self, values)


class _Bound:
    """An :class:`Enclosure` with its other symbols' values put in: ``bound(X)``."""

    __slots__ = ("enclosure", "values", "ends")

    def __init__(self, enclosure: Enclosure, values: tuple):
        self.enclosure, self.values = enclosure, values
        self.ends = None if enclosure.fast is None else tuple(e for v in values for e in floativ.ends(v))

    def __call__(self, X):
        return self.enclosure(X, *self.values)


def _signer(enclosure, t):
    """``(a, b) ↦`` 1 or −1 when the enclosure of ``enclosure − t`` over ``[a, b]`` (floats) is
    positive or negative, 0 when it holds 0 or there is none (``t`` None: the enclosure itself, as
    for the derivative).  mpmath's interval arithmetic decides; where ``enclosure`` is an
    :class:`Enclosure` (or :class:`_Bound`) of a polynomial, its float enclosures answer first
    when they agree with any answer mpmath could give (:mod:`langur.floativ`): the same signs,
    without mpmath in all but the cells where 0 is within rounding of an end."""
    iv = mpmath.iv
    T = None if t is None else iv.mpf(t)

    def slow(a, b):
        G = enclosure(iv.mpf([a, b]))
        if G is None:
            return 0
        if T is not None:
            G = G - T
        return 1 if G.a > 0 else (-1 if G.b < 0 else 0)

    if isinstance(enclosure, Enclosure):
        enclosure = enclosure.bind()
    fast = enclosure.enclosure.fast if isinstance(enclosure, _Bound) else None
    if fast is None or iv.prec != floativ.PREC:
        return slow
    outer, inner = fast
    args = (*enclosure.ends, *((0.0, 0.0) if T is None else floativ.ends(T)))

    def sign(a, b):
        r = outer(a, b, *args)
        if r is not None:
            if r[0] > 0:
                return 1  # mpmath's enclosure is inside this one: positive too
            if r[1] < 0:
                return -1
            q = inner(a, b, *args)
            if q is not None and q[0] <= 0 <= q[1]:
                return 0  # mpmath's enclosure holds this one: it holds 0 too
        return slow(a, b)
    return sign


def certified_brackets(g, g_iv, dg_iv, target, lo, hi, grid: int = GRID, depth: int = DEPTH,
                       what: str = "the equation", lenient: bool = False, box: bool = False,
                       most: int | None = None) -> list[tuple]:
    """The brackets, increasing, each holding exactly one sign change of ``g − target`` on
    ``[lo, hi]``, all of them: each cell of a ``grid``-cell grid is certified, by an interval
    enclosure of ``g − target`` that excludes 0 (no zero there) or one of ``g'`` that excludes 0
    (``g`` monotone: a zero iff a sign change between the ends); a cell certified by neither is
    halved, at most ``depth`` times, then refused (:class:`~langur.core.TooManyRoots`, naming the
    piece).  The signs at the cells' ends are those of ``g_iv`` at the point (mpmath's interval
    arithmetic rounds outward: a proof); a point where that enclosure contains 0 joins the two
    monotone cells around it when ``g`` rises (or falls) on both, else the piece is refused (an
    extremum of ``g`` that is 0 within rounding); at ``lo`` and ``hi`` such a sign is ``g``'s value's.
    ``g``: a function of a number (called with an mpmath number); ``g_iv``, ``dg_iv``: of an mpmath
    interval (None: no enclosure; an :func:`interval_function` or its ``bind``: float enclosures decide
    first, :func:`_signer`; a :attr:`~Enclosure.refused` one: the piece is refused at once).  The cells' ends are doubles (the grid and the halvings rounded to
    nearest, as mpmath at 53 bits).  ``lenient``: a cell still uncertified after ``depth`` halvings,
    and a point of unknown sign between cells that do not join, are decided by ``g``'s values
    instead of refused (turning points that move with the other *integration* variables merge on a
    null set of them: :func:`langur.operational.signchanges.certified_brackets`).  The Monte Carlo
    engine certifies the same way on its own (:mod:`langur.operational.signchanges`).  ``box``:
    ``g_iv`` and ``dg_iv`` enclose the equation for every value of its other symbols in a box
    (:func:`langur.implicit.lambdified._box_brackets`): nothing is decided by ``g``'s values (a point of unknown sign at an end
    of the domain is refused too), so the brackets hold for every point of the box.  ``most``: a
    caller that refuses more than ``most`` sign changes (a condition split for that many turning
    points) gets, as soon as more than ``most`` are certified, those found so far — the first ones,
    from ``lo`` on — instead of all: ``sin(100000·x)`` has 31,831 on [0, 1], 26 CPU s of
    certification to say "more than 7" (bench/history/2026-11-29.md#hostile32."""
    lo, hi = float(mpmath.mpf(lo)), float(mpmath.mpf(hi))
    if not hi > lo:  # an empty interval (a moving end past the other): no sign change
        return []
    if _refused(g_iv) or _refused(dg_iv):  # (interval_function's refusals: nothing is certified)
        raise _uncertified(what, lo, hi)
    g_sign, dg_sign = _signer(g_iv, target), _signer(dg_iv, None)
    stack = [(hi if i == grid - 1 else lo + (hi - lo) * (i + 1) / grid, lo + (hi - lo) * i / grid, 0)
             for i in range(grid)][::-1]
    cells = []  # (a, b, direction), increasing; direction 0: no zero in the cell
    monotone, ask = 0, None if most is None else most + 1  # (cells that may hold a zero; when to count)
    while stack:
        b, a, d = stack.pop()
        if g_sign(a, b):
            cells.append((a, b, 0))  # no zero in the cell
            continue
        s = dg_sign(a, b)
        if s:  # monotone: at most one zero
            cells.append((a, b, s))
            monotone += 1
            if ask is not None and monotone >= ask and stack and g_sign(b, b):
                ask = 2 * monotone  # (counted again after twice as many: linear in all)
                found = _sign_changes(g, g_sign, target, cells, what, lenient, box)
                if len(found) > most:  # (the cells so far end at b, of known sign: sign changes of all)
                    return found
            continue
        if d == depth:
            if lenient:
                cells.append((a, b, LOOSE))
                continue
            raise _uncertified(what, a, b)
        m = (a + b) / 2
        stack.append((b, m, d + 1))
        stack.append((m, a, d + 1))
    return _sign_changes(g, g_sign, target, cells, what, lenient, box)


#: The direction of a cell left uncertified in lenient mode (its ends' signs decide).
LOOSE = 2


def _refused(enclosure) -> bool:
    """An :func:`interval_function` (or its ``bind``) that refused its expression."""
    if isinstance(enclosure, _Bound):
        enclosure = enclosure.enclosure
    return isinstance(enclosure, Enclosure) and enclosure.refused


def _uncertified(what, a, b) -> TooManyRoots:
    return TooManyRoots(turning_points_uncertified(what, "x", a, b))


def _sign_changes(g, g_sign, target, cells, what, lenient=False, box=False) -> list[tuple]:
    """The brackets between consecutive points of known sign (cells' ends) where the sign differs."""
    points = [c[0] for c in cells] + [cells[-1][1]]
    signs = []
    for i, p in enumerate(points):
        s = g_sign(p, p)
        ends = i in (0, len(points) - 1)
        if s == 0 and not ends:  # inside: the cells around it must be monotone the same way
            before, after = cells[i - 1][2], cells[i][2]
            if (before == 0 or before != after or before == LOOSE) and not lenient:
                raise _uncertified(what, cells[i - 1][0], cells[i][1])
            ends = before == 0 or before != after or before == LOOSE  # lenient: its value's sign
        if s == 0 and ends and box:  # over a box, no value decides it
            raise _uncertified(what, points[max(i - 1, 0)], points[min(i + 1, len(points) - 1)])
        if s == 0 and ends:  # within rounding of an end of the domain (or lenient: see above)
            try:
                v = g(mpmath.mpf(p)) - target
                s = -1 if mpmath.isnan(v) or v < 0 else 1
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                s = -1
        signs.append(s)
    known = [(p, s) for p, s in zip(points, signs) if s != 0]
    return [(p, q) for (p, s), (q, r) in zip(known, known[1:]) if s != r]
