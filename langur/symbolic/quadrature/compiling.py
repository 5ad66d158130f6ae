"""Sympy expressions compiled to fast numeric functions for the quadrature (paper §8.2: the
integrand of ⟦p⟧ evaluated at the parameters' values; issue 13's caches).

``_lambdify`` gives scalar ``math`` functions (``mpmath`` for what ``math`` lacks), ``_vectorize``
numpy functions of the innermost variable; both are cached by expression with the parameters as
trailing arguments, so other parameter values reuse them.
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import mpmath
import numpy as np
import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.memo import remember
from langur.symbolic.text import shared_lambdify
from langur.symbolic.walks import atoms_of, free_symbols, has_any
from langur.sympy_bridge import magnitude

#: The point's values as 30-digit Floats, by point (:func:`_floats`): every condition of every piece
#: has them substituted (:func:`~.pieceproblems.piece_problem`), 46 times for a stylize partial
#: derivative with its ~40 parameters; a Float is a pure function of the value (equal values, of
#: any precision, have the same ``float``).  The dict is shared: callers only read it.
_FLOATS: dict = {}


def _floats(at: dict) -> dict:
    try:
        key = tuple(at.items())
        out = _FLOATS.get(key)
    except TypeError:  # (an unhashable value: built each time)
        key, out = None, None
    if out is None:
        out = {k: sp.Float(float(v), 30) for k, v in at.items()}
        if key is not None:
            remember(_FLOATS, key, out, 64)
    return out


#: :func:`substituted`'s expressions by (expression, point); at most :data:`SUBSTITUTED` kept.
_SUBSTITUTED: dict = {}
SUBSTITUTED = 4096


def substituted(expr: sp.Expr, at: dict) -> sp.Expr:
    """``expr.xreplace(_floats(at))`` (the point's 30-digit Floats substituted), remembered by the
    expression and the point: each problem of a program (⟦p⟧ near the point, its quadrature
    cross-check, each partial derivative's regular and delta pieces) substitutes the same
    conditions at the same point, and sympy's ``xreplace`` rebuilds them each time; it is a pure
    function of the two (the same rule gives an equal tree).  Not for an expression holding Floats
    (sympy's equality does not see their precision)."""
    if has_any(expr, (sp.Float,)):
        return expr.xreplace(_floats(at))
    try:
        key = (expr, tuple(at.items()))
        out = _SUBSTITUTED.get(key)
    except TypeError:  # (an unhashable value: substituted each time)
        return expr.xreplace(_floats(at))
    if out is None:
        out = remember(_SUBSTITUTED, key, expr.xreplace(_floats(at)), SUBSTITUTED)
    return out


def printable(e: sp.Expr) -> sp.Expr:
    """``e`` with rationals of thousands of digits as 30-digit floats: ``lambdify`` prints numbers
    as text, and Python refuses to print an integer of more than 4300 digits (a product of 10,000
    exact constants has such a value)."""
    big = {r: sp.Float(r, 30) for r in atoms_of(e, sp.Rational) if max(abs(r.p), r.q).bit_length() > 4000}
    return e.xreplace(big) if big else e


#: Compiled integrands by (arguments, expression): the same conditions and weights come back at
#: other parameter values (the value, each partial derivative, Theorem 8.1's shifted and nearby
#: points), and ``lambdify`` costs milliseconds per call; at most this many kept.
COMPILED = 4096


_COMPILED: dict = {}


def _compile(args: tuple, e) -> tuple[Callable | None, Callable | None]:
    """``(math function, None)`` or, for a function ``math`` lacks, ``(None, mpmath function)``."""
    key = (args, e)
    hit = _COMPILED.get(key)
    if hit is not None:
        return hit
    try:
        f = shared_lambdify(list(args), e, "math")  # (sympy's lambdify, shared subtrees printed once)
        f(*[0.5] * len(args))  # probe: fails with NameError for functions math lacks
        out = (f, None)
    except NameError:
        out = (None, shared_lambdify(list(args), e, "mpmath"))
    except Exception:  # noqa: BLE001 - a domain error at the probe point is fine
        out = (shared_lambdify(list(args), e, "math"), None)
    remember(_COMPILED, key, out, COMPILED)
    return out


def _lambdify(symbols: Sequence[sp.Symbol], expr, at: dict) -> Callable[..., float]:
    """A fast scalar function of ``symbols`` (``math``); NaN where the expression is undefined or
    complex.  The parameters ``at`` are passed as trailing arguments of a compiled function cached
    by expression (:data:`COMPILED`), so other parameter values reuse it; an expression ``math``
    cannot evaluate with symbolic parameters is compiled with their values substituted."""
    e = printable(sp.sympify(expr))
    free = free_symbols(e)  # (not cached by sympy: a walk of the distinct subtrees, once)
    params = tuple(k for k in at if k in free)
    compiled = (tuple(symbols) + params, e)
    f, g = _compile(*compiled)
    extra = tuple(float(at[k]) for k in params)
    if f is None and params:  # e.g. Heaviside of a parameter: decided once its value is known
        compiled = (tuple(symbols), printable(e.xreplace(_floats(at))))
        f, g = _compile(*compiled)
        extra = ()
    if f is not None:
        rescue = OnFirstCall(lambda: _mpmath_of(*compiled))

        def call(*vals):
            try:
                v = float(f(*vals, *extra))
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                v = math.nan
            if v - v == 0.0:  # finite (the common case: one subtraction, no call)
                return v
            if _off_the_reals(compiled, vals + extra):
                return v  # mpmath's value is not real either (:func:`_off_the_reals`): _in_mpmath's answer
            return _in_mpmath(rescue, vals + extra, v)  # overflowed on the way? mpmath's exponents do not
        return call

    def slow(*vals):
        try:
            v = complex(g(*vals, *extra))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            return math.nan
        return v.real if abs(v.imag) <= 1e-12 * max(1.0, abs(v.real)) else math.nan

    return slow


def _mpmath_of(args: tuple, e) -> Callable:
    """``e`` compiled for ``mpmath`` (cached like :func:`_compile`'s functions)."""
    key = ("mpmath", args, e)
    hit = _COMPILED.get(key)
    if hit is None:
        hit = shared_lambdify(list(args), e, "mpmath")
        remember(_COMPILED, key, hit, COMPILED)
    return hit


#: :func:`_complex_term`'s answers by (arguments, expression).
_COMPLEX_TERMS: dict = {}
#: The least |imaginary part| :func:`_off_the_reals` accepts as certainly not 0 once mpmath's value
#: is converted to a Python complex (far above the smallest normal double, 2.2e-308).
_VISIBLE = 1e-250


def _off_the_reals(compiled: tuple, vals: tuple) -> bool:
    """Whether :func:`_in_mpmath` is certain to return ``math``'s non-finite value at ``vals`` without
    computing anything: the expression is ``A + c·s**q`` (:func:`_complex_term`) and ``s < 0``
    here.  mpmath then evaluates ``A`` (sums, products and integer powers of real numbers and of
    the arguments: a finite real mpf, or a ZeroDivisionError) and ``s**q`` as a complex number
    ``|s|^q·e^{iqπ}``, whose imaginary part is not 0 (q is not an integer: |sin qπ| ≥ 2/d for
    q = p/d); the sum's imaginary part is exactly ``c·Im(s**q)`` (adding a real number leaves it
    as it is), at least ``|c|·|s|^q·2/d``; when that is above :data:`_VISIBLE` it is still not 0
    as a Python complex, so ``_in_mpmath`` returns ``v`` (or mpmath raised first: ``v`` too).  Below
    it (a tiny ``|s|``: the imaginary part may round to 0 in a double), and for any other
    expression, :func:`_in_mpmath` decides as before.  The cubic conditions' turning values
    ``x³ − a ± (2√3/9)·x^{3/2}`` of the kinks (issue 18) are of this shape: 1,000 mpmath
    evaluations per partial derivative of turning2d, all of them NaN again (issue 15).

    ``s`` may also be a polynomial ``B`` of the arguments (:class:`_Base`: ``√(r² − u₁²) ± 1``,
    the disk's delta piece, 2,820 mpmath evaluations per partial derivative): then mpmath's value
    of ``B`` is not the double one, and ``s < 0`` is taken only where the double value is below
    0 by more than twice the bound of both evaluations' rounding (:meth:`_Base.size`), and ``|s|``
    as the least size mpmath's value can have (deriv22).

    The expression may also be ``A + c·R`` with ``R`` an implicit root of a polynomial equation
    (:class:`_RootTerm`: ``root(y: y³ − x·y − a + x³ = 0 in [−1, sign_change₀(…)]) ± 1``, turning2d's
    substituted box conditions, 1,194 mpmath evaluations per partial derivative, every one NaN
    again): when the equation has certainly the same sign at both ends of the root's bracket, in
    doubles and in mpmath alike, mpmath finds no root either, and ``A + c·NaN`` is NaN (deriv23)."""
    shape = _COMPLEX_TERMS.get(compiled, 0)
    if shape == 0:
        shape = remember(_COMPLEX_TERMS, compiled, _complex_term(*compiled), COMPILED)
    if shape is None:
        return False
    if type(shape) is _RootTerm:
        return shape.no_root(vals)
    i, c, q, d = shape
    if type(i) is int:
        s = vals[i]
        if not (s < 0.0 and math.isfinite(s)):
            return False
        size = -s
    else:
        size = i.size(vals, q)
        if size is None:
            return False
    try:
        size = c * size ** q * (2.0 / d)
    except OverflowError:  # |s|^q beyond a double: so is the imaginary part (±inf: not 0)
        return True
    return size >= _VISIBLE


class _Base:
    """A base ``B`` of :func:`_complex_term` that is not an argument: a polynomial of the arguments
    with rational coefficients (sums, products, powers with exponents ≥ 0; no Float, whose printed
    forms for ``math`` and for mpmath could differ), compiled for ``math`` with its magnitude
    ``M`` (:func:`~langur.sympy_bridge.magnitude`: the same tree over the absolute values, every
    sum a sum of sizes).

    Evaluated in doubles and by mpmath at 53 bits, every operation of the tree rounds (by at most
    one unit in the last place: ``math``'s powers; half a unit elsewhere; a rational constant up to
    three times in mpmath: its numerator, its denominator, their quotient), so each value is within
    γ·M of the exact ``B`` — γ = n·ε/(1 − n·ε) for n roundings, here n = 4·(nodes) + 4, ε = 2⁻⁵² —
    and the two within 2γ·M of each other (Higham, *Accuracy and Stability of Numerical
    Algorithms*, §3.1, applied node by node; M's own double is within γ·M of M, so 2γ·M/(1 − γ)
    bounds it from the double).  Where the double ``B`` is below −2 times that bound, mpmath's
    ``B`` is negative and its size within half of the double's either way.  Only where the double
    M is a normal number well above underflow (:data:`_NORMAL`) and both values are finite."""

    def __init__(self, args: tuple, base):
        self.b = shared_lambdify(list(args), base, "math")
        self.m = shared_lambdify(list(args), magnitude(base), "math")
        n = 4 * sum(1 for _ in sp.preorder_traversal(base)) + 4
        gamma = n * EPS / (1.0 - n * EPS)
        self.slack = 2.0 * gamma / (1.0 - gamma)

    def size(self, vals: tuple, q: float) -> float | None:
        """The least (q > 0) or greatest (q < 0) size of mpmath's ``B`` at ``vals`` when it is certainly
        below 0 there, else None."""
        try:
            b, m = float(self.b(*vals)), float(self.m(*vals))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            return None
        err = self.slack * m
        if not (math.isfinite(b) and math.isfinite(err) and m >= _NORMAL and b < -2.0 * err):
            return None
        return -b - err if q > 0 else -b + err

    def sign(self, vals: tuple) -> int:
        """The sign (±1) that the exact ``B``, its double and mpmath's ``B`` at 53 bits (and that value
        rounded to a double) all have at ``vals``, when the double is farther from 0 than twice the
        bound of both evaluations' rounding (as :meth:`size`); 0 when that is not certain."""
        try:
            b, m = float(self.b(*vals)), float(self.m(*vals))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            return 0
        err = self.slack * m
        if not (math.isfinite(b) and math.isfinite(err) and m >= _NORMAL and abs(b) > 2.0 * err):
            return 0
        return 1 if b > 0 else -1


#: The least magnitude :class:`_Base` certifies a sign at (far from underflow: relative rounding).
_NORMAL = 1e-280
EPS = 2.0 ** -52


class _RootTerm:
    """The implicit root ``R`` of a term ``c·R`` of :func:`_complex_term`'s ``A + c·R``:
    ``root(x: f(x; v) = t in [lo, hi])`` (index −1: Brent's method in its bracket,
    :func:`langur.implicit.solvers.double_root`), ``f`` a polynomial of ``x`` and of arguments ``v`` of the
    compiled function with rational coefficients (:func:`_polynomial`), ``t`` an integer, each end an
    integer, an argument, or an indexed root (a sign change, :func:`langur.implicit.lambdified._indexed_at`)
    whose target and ends are integers or arguments and whose other symbols are arguments.

    **Why mpmath's ``R`` is NaN where :meth:`no_root` says so.**  Compiled for mpmath, ``R`` is the
    same :meth:`~langur.implicit.ImplicitRootFn._imp_` call with mpf arguments: its ``t``, ends and
    values are converted by ``float`` to the doubles ``math`` has (an indexed root is found from those
    doubles: the same double), and ``double_root`` evaluates ``f`` — now with mpmath's arithmetic —
    at both ends, returning NaN when the two values minus ``t`` have the same sign and neither is 0
    (or when an evaluation raises).  :meth:`_Base.sign` certifies that sign for ``f − t`` at each end:
    the exact value's, so mpmath's (rounded to a double: not 0, the same sign) too.  Then mpmath's
    ``A + c·R`` is NaN (``A`` is a real mpf, ±inf or NaN from real arguments, or it raised
    ZeroDivisionError), and :func:`_in_mpmath` returns ``math``'s value."""

    def __init__(self, args: tuple, root):
        lam, target, lo, hi, index, _ = root.args
        (x,), f = lam.variables, lam.expr
        free = sorted(f.free_symbols - {x}, key=str)  # (the values ``_imp_`` is called with)
        index_of = {a: k for k, a in enumerate(args)}
        if not (index < 0 and target.is_Integer and all(s in index_of for s in free)
                and _polynomial(f - target, {x: 0, **{s: 0 for s in free}})):
            raise ValueError("not a root of a polynomial equation in the arguments")
        self.values = tuple(index_of[s] for s in free)
        self.ends = tuple(_end(args, index_of, e) for e in (lo, hi))
        self.equation = _Base((x, *free), f - target)

    def no_root(self, vals: tuple) -> bool:
        """Whether mpmath's ``R`` at ``vals`` is certainly NaN (class doc)."""
        try:
            a, b = (float(end(vals)) for end in self.ends)
        except (ValueError, ZeroDivisionError, OverflowError, TypeError, ArithmeticError):
            return False
        if not (math.isfinite(a) and math.isfinite(b)):
            return False
        rest = tuple(vals[k] for k in self.values)
        sa = self.equation.sign((a, *rest))
        return sa != 0 and sa == self.equation.sign((b, *rest))


def _end(args: tuple, index_of: dict, e) -> Callable[[tuple], float]:
    """An end of a :class:`_RootTerm`'s bracket as a function of the compiled function's
    arguments, giving the double ``_imp_`` gets for it under ``math`` and under mpmath alike."""
    if e.is_Integer:
        value = float(e)
        return lambda vals: value
    if e in index_of:
        k = index_of[e]
        return lambda vals: vals[k]
    if isinstance(e, ImplicitRootFn):
        _, target, lo, hi, index, _ = e.args
        if index >= 0 and all(a.is_Integer or a in index_of for a in (target, lo, hi)) \
                and all(s in index_of for s in e.free_symbols):
            fn = shared_lambdify(list(args), e, "math")  # (the same ``_imp_`` call, with the doubles)
            return lambda vals: fn(*vals)
    raise ValueError("an end that is not an integer, an argument or an indexed root of them")


def _complex_term(args: tuple, e) -> tuple | _RootTerm | None:
    """``(i, |c|, q, d)`` when ``e`` is ``A + c·s**q``: ``s`` the ``i``-th of ``args`` (a symbol),
    ``q = p/d`` a rational that is not an integer, ``c`` a non-zero real number, ``A`` built from
    ``args``, rationals, floats and real constants (positive rationals to rational powers) by
    sums, products and integer powers only (:func:`_real_parts`); a :class:`_RootTerm` when ``e`` is
    ``A + c·R``, ``c`` a real constant and ``R`` an implicit root of its kind; None otherwise."""
    index = {a: k for k, a in enumerate(args)}
    found = None
    for t in (e.args if isinstance(e, sp.Add) else (e,)):
        if _real_parts(t, index):
            continue
        if found is not None:
            return None  # (two such terms could cancel each other's imaginary parts)
        factors = t.args if isinstance(t, sp.Mul) else (t,)
        roots = [f for f in factors if isinstance(f, ImplicitRootFn)]
        if roots:  # ``c·R``: mpmath's value is NaN where R's is (whatever A's)
            if len(roots) != 1 or not all(_real_parts(f, {}) for f in factors if f is not roots[0]):
                return None
            try:
                found = _RootTerm(args, roots[0])
            except Exception:  # noqa: BLE001 - not of the kind (or not compilable): _in_mpmath decides
                return None
            continue
        powers = [f for f in factors if isinstance(f, sp.Pow) and (f.base in index or (not f.base.is_number and _polynomial(f.base, index)))
                  and f.exp.is_Rational and not f.exp.is_Integer]
        if len(powers) != 1:
            return None
        rest = [f for f in factors if f is not powers[0]]
        if not all(_real_parts(f, {}) for f in rest):
            return None
        c = abs(float(sp.Mul(*rest)))
        if not (c > 0.0 and math.isfinite(c)):
            return None
        pw = powers[0]
        base = index[pw.base] if pw.base in index else _Base(args, pw.base)
        found = (base, c, float(pw.exp), int(pw.exp.q))
    return found


def _polynomial(e, index: dict) -> bool:
    """Whether ``e`` is a polynomial of the symbols of ``index`` (at least one of them) with rational
    coefficients: rationals, symbols, sums, products and powers with exponents ≥ 0 (:class:`_Base`)."""
    if isinstance(e, sp.Rational):
        return True
    if isinstance(e, sp.Symbol):
        return e in index
    if isinstance(e, (sp.Add, sp.Mul)):
        return all(_polynomial(a, index) for a in e.args) and not e.is_number
    if isinstance(e, sp.Pow):
        return e.exp.is_Integer and e.exp >= 0 and _polynomial(e.base, index) and not e.is_number
    return False


def _real_parts(e, index: dict) -> bool:
    """Whether ``e`` is built from the symbols of ``index``, rationals, floats and positive
    rationals to rational powers by sums, products and integer powers: real wherever mpmath
    evaluates it at real arguments (or a ZeroDivisionError)."""
    if isinstance(e, (sp.Rational, sp.Float)):
        return True
    if isinstance(e, sp.Symbol):
        return e in index
    if isinstance(e, (sp.Add, sp.Mul)):
        return all(_real_parts(a, index) for a in e.args)
    if isinstance(e, sp.Pow):
        if e.exp.is_Integer:
            return _real_parts(e.base, index)
        return isinstance(e.base, sp.Rational) and e.base > 0 and isinstance(e.exp, sp.Rational)
    return False


def _in_mpmath(g: Callable, vals: tuple, v: float) -> float:
    """The value ``math`` could not give at ``vals`` (``v``: ±inf or NaN), computed again by ``g``,
    the same expression compiled for mpmath.

    ``math`` gives up where an intermediate value leaves the floating-point range although the
    integrand's value does not: ``exp(800 x) · exp(−800 x + a)`` is ``inf · 0`` in floating point and
    ``e^a`` in fact.  mpmath's numbers have unbounded exponents (and the same 53-bit precision), so
    where mpmath finds a real value, that is the value.  Case by case, mpmath's value ``m``:

    * mpmath raises (a pole, a primitive outside its domain): ``v`` (``math`` was right);
    * ``m`` is not real (a root or logarithm of a negative number): ``v`` (likewise);
    * ``m`` is a finite double: ``m`` (what ``math`` lost on the way);
    * ``m`` is finite but beyond a double's range: ±inf with its sign (so a sample that is ±inf
      means *too large for a double*, not a pole: :class:`~.adaptive._Finite` tells the two apart);
    * ``m`` is mpmath's own ±inf or NaN: ``v``."""
    try:
        m = g(*[mpmath.mpf(u) for u in vals])  # (mpf arguments: a float's ** overflows like math's)
        w = complex(m)  # (a finite mpf too large for a double becomes ±inf here)
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        return v
    if w.imag != 0.0:
        return v
    if math.isfinite(w.real):
        return w.real
    if math.isinf(w.real) and mpmath.isfinite(m):
        return w.real
    return v


class OnFirstCall:
    """A function compiled when it is first called (``make()`` gives it): the scalar weight of a
    piece whose vectorized weight integrates every innermost interval (:func:`~.nested._first_panel`)
    is never called — the stylization kernel's regular pieces, whose weights are printed and
    compiled for ``math`` only to be dropped.  The same function as ``make()`` made at once, as long
    as ``make`` is a pure function of what it captured and cannot fail (the caller's to ensure)."""

    __slots__ = ("_make", "_f")

    def __init__(self, make: Callable[[], Callable]):
        self._make = make
        self._f: Callable | None = None

    def __call__(self, *vals):
        f = self._f
        if f is None:
            f = self._f = self._make()
            self._make = None
        return f(*vals)


_VECTORIZED: dict = {}


def _vectorize(symbols: Sequence[sp.Symbol], expr, at: dict) -> Callable | None:
    """``expr`` as a numpy function of ``symbols`` (the last one an array), the parameters ``at``
    passed like :func:`_lambdify`'s; None when numpy cannot evaluate it (then the scalar path
    alone integrates it)."""
    e = printable(sp.sympify(expr))
    free = free_symbols(e)  # (once, not once per parameter)
    params = tuple(k for k in at if k in free)
    key = (tuple(symbols) + params, e)
    f = _VECTORIZED.get(key, 0)
    if f == 0:
        try:
            f = shared_lambdify(list(key[0]), e, "numpy")  # (sympy's code, shared subtrees printed once)
            with np.errstate(all="ignore"):
                f(*[0.5] * (len(key[0]) - 1), np.linspace(0.1, 0.9, 3))  # probe: numpy has every function
        except NameError:
            f = None
        except Exception:  # noqa: BLE001 - a domain error at the probe point is fine
            pass
        remember(_VECTORIZED, key, f, COMPILED)
    if f is None:
        return None
    extra = tuple(float(at[k]) for k in params)
    return lambda *vals: f(*vals, *extra)

