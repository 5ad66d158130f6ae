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
for the k-th sign change, the cell of a grid where it is seen), and ``lambdify`` calls the same
solver on the compiled ``f``.  The Monte Carlo engine has its own vectorized solver (no sympy
there: ``langur.operational.compile``).
"""

from __future__ import annotations

import math
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

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


#: Cells of the grid on which an indexed root's sign changes are found (each then bisected).
GRID = 512


def sign_changes(f, target, lo, hi, bits: int = 53, grid: int = GRID) -> list:
    """The points of ``[lo, hi]`` where ``f − target`` changes sign, increasing: found on a grid of
    ``grid`` cells (a sign change certifies a point in its cell; two in one cell are not seen) and
    each bisected to ``bits`` bits."""
    cells = _cells(f, target, lo, hi, grid)
    return [bracketed_root(f, target, lo + (hi - lo) * i / grid, lo + (hi - lo) * (i + 1) / grid, bits) for i in cells]


def indexed_root(f, target, lo, hi, index: int, of: int, bits: int = 53):
    """The ``index``-th sign change of ``f − target`` on ``[lo, hi]`` (``hi`` when there are
    fewer); :class:`~langur.core.TooManyRoots` when there are more than ``of``."""
    found = sign_changes(f, target, lo, hi, bits)
    if len(found) > of:
        raise TooManyRoots(f"{len(found)} turning points on [{float(lo):g}, {float(hi):g}] at these parameter values, "
                           f"more than the {of} the condition was split for: Langur cannot differentiate it here")
    return found[index] if index < len(found) else hi


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
        of a condition in several variables, the parameters); arrays (the numpy module) are solved
        element by element."""
        if any(np.ndim(v) for v in (target, lo, hi, *free)):
            t, a, b, *rest = np.broadcast_arrays(target, lo, hi, *free)
            return np.array([_solve(lambda x, r=r: fn(x, *r), ti, ai, bi, index, of)
                             for ti, ai, bi, *r in zip(t.flat, a.flat, b.flat, *(c.flat for c in rest))],
                            dtype=float).reshape(t.shape)
        return _solve(lambda x: fn(x, *free), target, lo, hi, index, of)

    def _code(self, printer):
        """``lambdify``'s text: the equation as a Python ``lambda`` of the root's variable and the
        equation's other symbols, whose values follow the bracket."""
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        free = sorted(f.free_symbols - {x}, key=str)
        params = ", ".join(printer._print(s) for s in (x, *free))
        args = ", ".join(printer._print(a) for a in (target, lo, hi))
        values = "".join(f", {printer._print(s)}" for s in free)
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


def _solve(fn, target, lo, hi, index, of, bits: int = 53):
    if index < 0:
        return bracketed_root(fn, target, lo, hi, bits)
    return indexed_root(fn, target, lo, hi, int(index), int(of), bits)


@lru_cache(maxsize=4096)
def _evalf(args, prec):
    lam, target, lo, hi, index, of = args
    (x,), f = lam.variables, lam.expr
    dps = mpmath.libmp.prec_to_dps(prec) + 5
    with mpmath.workdps(dps):
        fn = sp.lambdify(x, f, modules="mpmath")
        t, a, b = (mpmath.mpf(sp.Float(v.evalf(dps), dps)) for v in (target, lo, hi))
        if index >= 0:  # the cell of the index-th sign change, on a grid in doubles; then bisected
            cells = _cells(sp.lambdify(x, f, modules="math"), float(t), float(a), float(b))
            if len(cells) > of:
                raise TooManyRoots(f"{len(cells)} turning points on [{float(a):g}, {float(b):g}] at these parameter "
                                   f"values, more than the {int(of)} the condition was split for: Langur cannot "
                                   "differentiate it here")
            if index >= len(cells):
                return sp.Float(b, dps)
            c = cells[int(index)]
            a, b = a + (b - a) * c / GRID, a + (b - a) * (c + 1) / GRID
        r = bracketed_root(fn, t, a, b, bits=prec + 10)
        if isinstance(r, float) and math.isnan(r):
            return sp.nan
        return sp.Float(r, dps)


def _cells(f, target: float, lo: float, hi: float, grid: int = GRID) -> list[int]:
    """The cells of a ``grid``-cell grid of ``[lo, hi]`` where ``f − target`` changes sign."""
    signs = []
    for i in range(grid + 1):
        try:
            signs.append(f(lo + (hi - lo) * i / grid) - target >= 0)
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            signs.append(None)
    return [i for i in range(grid) if None not in (signs[i], signs[i + 1]) and signs[i] != signs[i + 1]]


def implicit_root(equation: sp.Expr, variable: sp.Symbol, target: sp.Expr, lo: sp.Expr, hi: sp.Expr,
                  index: int | None = None, of: int = 0) -> sp.Expr:
    """``ImplicitRootFn`` of ``equation`` in ``variable`` (bound: replaced by a dummy)."""
    x = sp.Dummy(variable.name, real=True)
    return ImplicitRootFn(sp.Lambda(x, equation.xreplace({variable: x})), target, lo, hi,
                          sp.Integer(-1 if index is None else index), sp.Integer(of))
