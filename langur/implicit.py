"""The implicit root ``x*`` of :class:`langur.core.ImplicitRoot` as a sympy function (issue 18).

``ImplicitRootFn(Lambda(x, f), target, lo, hi, -1, 0)`` is the one ``x`` in ``[lo, hi]`` with
``f(x) = target``, ``f`` strictly monotone on ``[lo, hi]`` (an inverse branch of a condition
between two of its turning points, :mod:`langur.syntax.turning`); with an index k ≥ 0 and a
bound n it is the k-th sign change of ``f − target`` on ``[lo, hi]`` (a turning point that moves
with the parameters).  It stays symbolic in the exact engine's closed forms; its derivative is
the implicit function theorem's,

    ∂x*/∂s = (∂target/∂s − ∂f/∂s(x*)) / ∂f/∂x(x*),

so every derivative (and the Jacobian dx*/du₀ = 1/f'(x*) of the delta's change of variables) is
exact in terms of ``x*``; ``evalf`` finds ``x*`` to the requested precision by bisection with
mpmath (on a bracket where ``f − target`` changes sign: for the unique root, the whole piece;
for the k-th sign change, a bracket certified to hold exactly one, :func:`certified_brackets`),
and ``lambdify`` calls the same solver on the compiled ``f``.  The Monte Carlo engine has its own vectorized solver (no sympy
there: ``langur.operational.compile``).
"""

from __future__ import annotations

import math
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from .core import TooManyRoots


def bracketed_root(f, target, lo, hi, bits: int = 53):
    """The ``x`` in ``[lo, hi]`` with ``f(x) = target`` for ``f`` monotone there: bisection
    (``bits`` + 8 halvings of the bracket, so the result has full precision in that many bits),
    NaN when ``target`` is not between ``f(lo)`` and ``f(hi)`` (no root there)."""
    try:
        a, b = lo, hi
        fa, fb = f(a) - target, f(b) - target
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        return math.nan
    if fa == 0:
        return a
    if fb == 0:
        return b
    if not (fa < 0) ^ (fb < 0):
        return math.nan
    rising = fa < 0
    for _ in range(bits + 8 + int(math.log2(1 + abs(float(hi - lo))))):
        m = (a + b) / 2
        if m == a or m == b:
            break
        fm = f(m) - target
        if fm == 0:
            return m
        if (fm < 0) == rising:
            a = m
        else:
            b = m
    return (a + b) / 2


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


#: lambdify's names for the interval versions (the rest from ``mpmath.iv``; ``log`` is a method of
#: its class, which lambdify would otherwise take from ``math``).
_IV = {"log": mpmath.iv.log, "mpf": mpmath.iv.mpf, "atan": _monotone_iv(mpmath.atan), "tanh": _monotone_iv(mpmath.tanh), "erf": _monotone_iv(mpmath.erf),
       "asin": _monotone_iv(mpmath.asin), "acos": _monotone_iv(mpmath.acos, increasing=False),
       "atanh": _monotone_iv(mpmath.atanh)}


class _IntervalPrinter(PythonCodePrinter):
    """lambdify's text for mpmath intervals: a rational constant as the interval quotient of its
    numerator and denominator (``1/3`` would be the double 0.333…, ``x**(1/3)`` a double power),
    a float as the interval of its decimal digits."""

    def _print_Rational(self, e):
        return f"(mpf({e.p})/mpf({e.q}))"

    def _print_Half(self, e):
        return self._print_Rational(e)

    def _print_Float(self, e):
        return f"mpf({str(sp.Float(e, e._prec)).strip()!r})"


def _interval_fn(x: sp.Symbol, e: sp.Expr, free: tuple = ()):
    """``e`` (in ``x`` and the symbols ``free``) on mpmath intervals: ``X, *values ↦`` an interval
    containing ``e(X)`` at those values of ``free``; None where it cannot be enclosed.  Every
    operation is mpmath's interval arithmetic (rounded outward), constants included
    (:class:`_IntervalPrinter`)."""
    printer = _IntervalPrinter({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                                "user_functions": {k: k for k in _IV}})  # lambdify's own settings
    fn = sp.lambdify([x, *free], e, modules=[_IV, mpmath.iv], printer=printer)

    def enclose(X, *values):
        try:
            out = fn(X, *values)
            out = out if isinstance(out, mpmath.iv.mpf) else mpmath.iv.mpf(out)
        except (ValueError, ZeroDivisionError, TypeError, OverflowError, mpmath.libmp.NoConvergence):
            return None
        return None if (mpmath.isnan(out.a) or mpmath.isnan(out.b)) else out
    return enclose


def certified_brackets(g, g_iv, dg_iv, target, lo, hi, grid: int = GRID, depth: int = DEPTH,
                       what: str = "the equation", lenient: bool = False) -> list[tuple]:
    """The brackets, increasing, each holding exactly one sign change of ``g − target`` on
    ``[lo, hi]``, all of them: each cell of a ``grid``-cell grid is certified, by an interval
    enclosure of ``g − target`` that excludes 0 (no zero there) or one of ``g'`` that excludes 0
    (``g`` monotone: a zero iff a sign change between the ends); a cell certified by neither is
    halved, at most ``depth`` times, then refused (:class:`~langur.core.TooManyRoots`, naming the
    piece).  The signs at the cells' ends are those of ``g_iv`` at the point (mpmath's interval
    arithmetic rounds outward: a proof); a point where that enclosure contains 0 joins the two
    monotone cells around it when ``g`` rises (or falls) on both, else the piece is refused (an
    extremum of ``g`` that is 0 within rounding); at ``lo`` and ``hi`` such a sign is ``g``'s value's.
    ``g``: a function of a number; ``g_iv``, ``dg_iv``: of an mpmath interval (None: no
    enclosure).  ``lenient``: a cell still uncertified after ``depth`` halvings, and a point of
    unknown sign between cells that do not join, are decided by ``g``'s values instead of refused
    (turning points that move with the other *integration* variables merge on a null set of them:
    :func:`langur.operational.signchanges.certified_brackets`).  The Monte Carlo engine certifies
    the same way on its own (:mod:`langur.operational.signchanges`)."""
    iv = mpmath.iv
    lo, hi = mpmath.mpf(lo), mpmath.mpf(hi)
    if not hi > lo:  # an empty interval (a moving end past the other): no sign change
        return []
    t = iv.mpf(target)
    stack = [(hi if i == grid - 1 else lo + (hi - lo) * (i + 1) / grid, lo + (hi - lo) * i / grid, 0)
             for i in range(grid)][::-1]
    cells = []  # (a, b, direction), increasing; direction 0: no zero in the cell
    while stack:
        b, a, d = stack.pop()
        X = iv.mpf([a, b])
        G = g_iv(X)
        if G is not None:
            G = G - t
            if G.a > 0 or G.b < 0:
                cells.append((a, b, 0))  # no zero in the cell
                continue
        D = dg_iv(X)
        if D is not None and (D.a > 0 or D.b < 0):  # monotone: at most one zero
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
    return _sign_changes(g, g_iv, t, target, cells, what, lenient)


#: The direction of a cell left uncertified in lenient mode (its ends' signs decide).
LOOSE = 2


def _uncertified(what, a, b) -> TooManyRoots:
    return TooManyRoots(f"cannot certify the turning points (sign changes of {what}) near x in "
                        f"[{float(a):.12g}, {float(b):.12g}] at these parameter values: there it and its "
                        "derivative both vanish (a degenerate turning point) or their interval enclosures "
                        "stay too wide; Langur refuses rather than miss one")


def _sign_changes(g, g_iv, t, target, cells, what, lenient=False) -> list[tuple]:
    """The brackets between consecutive points of known sign (cells' ends) where the sign differs."""
    points = [c[0] for c in cells] + [cells[-1][1]]
    signs = []
    for i, p in enumerate(points):
        G = g_iv(mpmath.iv.mpf([p, p]))
        G = None if G is None else G - t
        s = 0 if G is None else (1 if G.a > 0 else (-1 if G.b < 0 else 0))
        ends = i in (0, len(points) - 1)
        if s == 0 and not ends:  # inside: the cells around it must be monotone the same way
            before, after = cells[i - 1][2], cells[i][2]
            if (before == 0 or before != after or before == LOOSE) and not lenient:
                raise _uncertified(what, cells[i - 1][0], cells[i][1])
            ends = before == 0 or before != after or before == LOOSE  # lenient: its value's sign
        if s == 0 and ends:  # within rounding of an end of the domain (or lenient: see above)
            try:
                v = g(p) - target
                s = -1 if mpmath.isnan(v) or v < 0 else 1
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                s = -1
        signs.append(s)
    known = [(p, s) for p, s in zip(points, signs) if s != 0]
    return [(p, q) for (p, s), (q, r) in zip(known, known[1:]) if s != r]


class ImplicitRootFn(sp.Function):
    """``x*(target; θ)``: ``ImplicitRootFn(Lambda(x, f), target, lo, hi, index, of)`` is the root of
    ``f(x; θ) = target`` in ``[lo, hi]`` (``index`` = −1, ``f`` monotone there), or the ``index``-th
    sign change of ``f − target`` there (:class:`langur.core.ImplicitRoot`)."""

    nargs = 6
    is_real = True

    @property
    def is_number(self) -> bool:  # the bound variable of the Lambda is not a free symbol
        return not self.free_symbols

    @classmethod
    def eval(cls, lam, target, lo, hi, index, of):
        return None  # stays symbolic: it has no closed form (that is why it exists)

    def _eval_derivative(self, s):
        lam, target = self.args[:2]
        (x,), f = lam.variables, lam.expr
        at = {x: self}
        return (sp.diff(target, s) - sp.diff(f, s).xreplace(at)) / sp.diff(f, x).xreplace(at)

    def _eval_evalf(self, prec):
        if self.free_symbols:
            return None
        return _evalf(self.args, prec)

    @staticmethod
    def _imp_(fn, target, lo, hi, index, of, *free):
        """``lambdify``'s implementation: ``fn`` is ``f`` compiled by lambdify (module namespace),
        called as ``fn(x, *free)`` with the values of the equation's other symbols (the other inputs
        of a condition in several variables, the parameters), or for an indexed root the key of its
        equation (certified by :func:`certified_brackets`, as ``evalf``); arrays (the numpy module)
        are solved element by element."""
        if any(np.ndim(v) for v in (target, lo, hi, *free)):
            t, a, b, *rest = np.broadcast_arrays(target, lo, hi, *free)
            return np.array([_solve(fn, ti, ai, bi, index, of, *r)
                             for ti, ai, bi, *r in zip(t.flat, a.flat, b.flat, *(c.flat for c in rest))],
                            dtype=float).reshape(t.shape)
        return _solve(fn, target, lo, hi, index, of, *free)

    def _code(self, printer):
        """``lambdify``'s text: the equation as a Python ``lambda`` of the root's variable and the
        equation's other symbols, whose values follow the bracket."""
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        free = sorted(f.free_symbols - {x}, key=str)
        params = ", ".join(printer._print(s) for s in (x, *free))
        args = ", ".join(printer._print(a) for a in (target, lo, hi))
        values = "".join(f", {printer._print(s)}" for s in free)
        if index >= 0:  # certified by the exact engine's own enclosures: the equation named by a key
            return f"ImplicitRootFn({_indexed_key(lam, free)!r}, {args}, {int(index)}, {int(of)}{values})"
        return (f"ImplicitRootFn((lambda {params}: {printer._print(f)}), {args}, {int(index)}, {int(of)}"
                f"{values})")

    _pythoncode = _mpmathcode = _numpycode = _lambdacode = _code

    def _latex(self, printer, exp=None):
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        which = r"\operatorname{root}" if index < 0 else rf"\operatorname{{sign\,change}}_{{{int(index)}}}"
        out = (rf"{which}_{{{printer.doprint(x)} \in [{printer.doprint(lo)}, {printer.doprint(hi)}]}}"
               rf"\left({printer.doprint(f)} = {printer.doprint(target)}\right)")
        return out if exp is None else rf"\left({out}\right)^{{{exp}}}"

    def _sympystr(self, printer):
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        which = "root" if index < 0 else f"sign_change_{int(index)}"
        bound = "" if index < 0 else f"; at most {int(of)}"
        return (f"{which}({printer.doprint(x)}: {printer.doprint(f)} = {printer.doprint(target)} "
                f"in [{printer.doprint(lo)}, {printer.doprint(hi)}]{bound})")


def _solve(fn, target, lo, hi, index, of, *values):
    if isinstance(fn, str):  # an indexed root: certified as evalf certifies it
        return _indexed_at(fn, target, lo, hi, int(index), int(of), *values)
    return bracketed_root(lambda x: fn(x, *values), target, lo, hi)


@lru_cache(maxsize=4096)
def _evalf(args, prec):
    lam, target, lo, hi, index, of = args
    (x,), f = lam.variables, lam.expr
    dps = mpmath.libmp.prec_to_dps(prec) + 5
    with mpmath.workdps(dps):
        fn = sp.lambdify(x, f, modules="mpmath")
        t, a, b = (mpmath.mpf(sp.Float(v.evalf(dps), dps)) for v in (target, lo, hi))
        if index >= 0:  # the index-th of the certified brackets of the sign changes, then bisected
            brackets = _brackets(x, f, fn, t, a, b)
            if len(brackets) > of:
                raise TooManyRoots(f"{len(brackets)} turning points on [{float(a):g}, {float(b):g}] at these "
                                   f"parameter values, more than the {int(of)} the condition was split for: Langur "
                                   "cannot differentiate it here; split the variable's domain (a sum of integrals over "
                                   "sub-intervals, each with at most that many turning points)", _SPANS.get(x))
            if index >= len(brackets):
                return sp.Float(b, dps)
            a, b = brackets[int(index)]
        r = bracketed_root(fn, t, a, b, bits=prec + 10)
        if isinstance(r, float) and math.isnan(r):
            return sp.nan
        return sp.Float(r, dps)


def _brackets(x, f, fn, t, a, b) -> list[tuple]:
    """The certified brackets of the sign changes of ``f − t`` (``f`` in ``x`` only) on ``[a, b]``
    (``fn``: ``f`` on mpmath numbers), found once for every index and precision: in double
    precision, since the certificate does not depend on the precision the root is wanted in."""
    return [(mpmath.mpf(p), mpmath.mpf(q)) for p, q in _brackets_at(x, f, float(t), float(a), float(b))]


@lru_cache(maxsize=1024)
def _brackets_at(x, f, t: float, a: float, b: float) -> tuple:
    with mpmath.workprec(53):
        fn = sp.lambdify(x, f, modules="mpmath")
        g_iv, dg_iv = _interval_fn(x, f), _interval_fn(x, sp.diff(f, x))
        try:
            return tuple((float(p), float(q)) for p, q in certified_brackets(fn, g_iv, dg_iv, t, a, b, what=f"{f}",
                                                                              lenient=x in _LENIENT))
        except TooManyRoots as err:
            raise TooManyRoots(str(err), _SPANS.get(x)) from None


#: The equations of indexed roots lambdify printed (by a key: ``lambdify``'s code calls back with
#: it and the values of their other symbols, and the root is found as ``evalf`` finds it).
_INDEXED: dict[str, tuple] = {}
_KEYS: dict = {}


def _indexed_key(lam, free) -> str:
    key = _KEYS.get((lam, tuple(free)))
    if key is None:
        key = _KEYS[(lam, tuple(free))] = f"indexed root {len(_KEYS)}"
        _INDEXED[key] = (lam, tuple(free))
    return key


def _indexed_at(key: str, target, lo, hi, index, of, *values) -> float:
    """The indexed root of the equation named ``key`` at these values of its other symbols, as
    ``evalf`` finds it (certified brackets, then bisection with mpmath), its equation compiled
    once for all values (a quadrature over the other inputs asks for thousands)."""
    t, a, b = float(target), float(lo), float(hi)
    if math.isnan(t) or math.isnan(a) or math.isnan(b):
        return math.nan
    vals = tuple(float(v) for v in values)
    brackets = _brackets_of(key, t, a, b, vals)
    if len(brackets) > of:
        lam, _ = _INDEXED[key]
        raise TooManyRoots(f"{len(brackets)} turning points on [{a:g}, {b:g}] at these parameter values, more than "
                           f"the {int(of)} the condition was split for: Langur cannot differentiate it here; split the variable's "
                               "domain (a sum of integrals over sub-intervals, each with at most that many turning points)",
                           _SPANS.get(lam.variables[0]))
    if index >= len(brackets):
        return b
    fn = _compiled(key)[3]
    p, q = brackets[index]
    return float(bracketed_root(lambda z: fn(z, *vals), t, p, q))  # in doubles: the result is one


@lru_cache(maxsize=256)
def _compiled(key: str) -> tuple:
    """The equation named ``key`` compiled once: on mpmath numbers, and its and its derivative's
    interval versions, each called as ``(x, *values of its other symbols)``."""
    lam, free = _INDEXED[key]
    (x,), f = lam.variables, lam.expr
    return (sp.lambdify([x, *free], f, modules="mpmath"), _interval_fn(x, f, free),
            _interval_fn(x, sp.diff(f, x), free), sp.lambdify([x, *free], f, modules="math"))


@lru_cache(maxsize=65536)
def _brackets_of(key: str, t: float, a: float, b: float, vals: tuple) -> tuple:
    """:func:`_brackets_at` for the equation named ``key`` at these values of its other symbols."""
    lam, _ = _INDEXED[key]
    x = lam.variables[0]
    fn, g_iv, dg_iv, _ = _compiled(key)
    iv_vals = [mpmath.iv.mpf(v) for v in vals]
    mp_vals = [mpmath.mpf(v) for v in vals]
    with mpmath.workprec(53):
        try:
            found = certified_brackets(lambda z: fn(z, *mp_vals), lambda X: g_iv(X, *iv_vals),
                                       lambda X: dg_iv(X, *iv_vals), t, a, b, what=f"{lam.expr}",
                                       lenient=x in _LENIENT)
        except TooManyRoots as err:
            raise TooManyRoots(str(err), _SPANS.get(x)) from None
    return tuple((float(p), float(q)) for p, q in found)


def implicit_root(equation: sp.Expr, variable: sp.Symbol, target: sp.Expr, lo: sp.Expr, hi: sp.Expr,
                  index: int | None = None, of: int = 0, span=None, lenient: bool = False) -> sp.Expr:
    """``ImplicitRootFn`` of ``equation`` in ``variable`` (bound: replaced by a dummy); ``span``:
    the condition's place in the source, named when evaluating it is refused; ``lenient``: the
    equation mentions other integration variables (see :func:`certified_brackets`)."""
    x = sp.Dummy(variable.name, real=True)
    lam = sp.Lambda(x, equation.xreplace({variable: x}))
    if span is not None:
        _SPANS[x] = span
    if lenient:
        _LENIENT.add(x)
    return ImplicitRootFn(lam, target, lo, hi, sp.Integer(-1 if index is None else index), sp.Integer(of))


#: The source place of a root's equation (sympy terms carry none), by its bound variable (a
#: Dummy of its own, kept when parameter values are put in the equation).
_SPANS: dict = {}
#: The bound variables of indexed roots whose equation mentions other integration variables (a
#: condition split along a variable at turning points that move with the others): certified
#: leniently on the null set where two of them merge (:func:`certified_brackets`).
_LENIENT: set = set()
