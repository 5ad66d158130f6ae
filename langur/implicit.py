"""The implicit root ``x*`` of :class:`langur.core.ImplicitRoot` as a sympy function (issue 18).

``ImplicitRootFn(Lambda(x, f), target, lo, hi)`` is the one ``x`` in ``[lo, hi]`` with
``f(x) = target``, ``f`` strictly monotone on ``[lo, hi]`` (an inverse branch of a condition
between two of its turning points, :mod:`langur.syntax.turning`).  It stays symbolic in the
exact engine's closed forms; its derivative is the implicit function theorem's,

    ∂x*/∂s = (∂target/∂s − ∂f/∂s(x*)) / ∂f/∂x(x*),

so every derivative (and the Jacobian dx*/du₀ = 1/f'(x*) of the delta's change of variables) is
exact in terms of ``x*``; ``evalf`` finds ``x*`` to the requested precision by bisection with
mpmath (the bracket is certified: ``f − target`` changes sign on it and is monotone), and
``lambdify`` calls :func:`bracketed_root` on the compiled ``f``.  The Monte Carlo engine has its
own vectorized solver (no sympy there: ``langur.operational.compile``).
"""

from __future__ import annotations

import math

import mpmath
import numpy as np
import sympy as sp


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


class ImplicitRootFn(sp.Function):
    """``x*(target; θ)``: the root of ``f(x; θ) = target`` in ``[lo, hi]`` (module docstring)."""

    nargs = 4
    is_real = True

    @property
    def is_number(self) -> bool:  # the bound variable of the Lambda is not a free symbol
        return not self.free_symbols

    @classmethod
    def eval(cls, lam, target, lo, hi):
        return None  # stays symbolic: it has no closed form (that is why it exists)

    def _eval_derivative(self, s):
        lam, target, _, _ = self.args
        (x,), f = lam.variables, lam.expr
        at = {x: self}
        return (sp.diff(target, s) - sp.diff(f, s).xreplace(at)) / sp.diff(f, x).xreplace(at)

    def _eval_evalf(self, prec):
        lam, target, lo, hi = self.args
        (x,), f = lam.variables, lam.expr
        if (f.free_symbols - {x}) or target.free_symbols or lo.free_symbols or hi.free_symbols:
            return None
        dps = mpmath.libmp.prec_to_dps(prec) + 5
        with mpmath.workdps(dps):
            fn = sp.lambdify(x, f, modules="mpmath")
            t, a, b = (mpmath.mpf(sp.Float(v.evalf(dps), dps)) for v in (target, lo, hi))
            r = bracketed_root(fn, t, a, b, bits=prec + 10)
            if isinstance(r, float) and math.isnan(r):
                return sp.nan
            return sp.Float(r, dps)

    @staticmethod
    def _imp_(fn, target, lo, hi):
        """``lambdify``'s implementation: ``fn`` is ``f`` compiled by lambdify (module namespace);
        arrays (the numpy module) are solved element by element."""
        if any(np.ndim(v) for v in (target, lo, hi)):
            t, a, b = np.broadcast_arrays(target, lo, hi)
            return np.array([bracketed_root(fn, ti, ai, bi) for ti, ai, bi in zip(t.flat, a.flat, b.flat)],
                            dtype=float).reshape(t.shape)
        return bracketed_root(fn, target, lo, hi)

    def _code(self, printer):
        """``lambdify``'s text: the equation as a Python ``lambda`` in the printer's module."""
        lam, target, lo, hi = self.args
        (x,), f = lam.variables, lam.expr
        args = ", ".join(printer._print(a) for a in (target, lo, hi))
        return f"ImplicitRootFn((lambda {printer._print(x)}: {printer._print(f)}), {args})"

    _pythoncode = _mpmathcode = _numpycode = _lambdacode = _code

    def _sympystr(self, printer):
        lam, target, lo, hi = self.args
        (x,), f = lam.variables, lam.expr
        return (f"root({printer.doprint(x)}: {printer.doprint(f)} = {printer.doprint(target)} "
                f"in [{printer.doprint(lo)}, {printer.doprint(hi)}])")


def implicit_root(equation: sp.Expr, variable: sp.Symbol, target: sp.Expr, lo: sp.Expr, hi: sp.Expr) -> sp.Expr:
    """``ImplicitRootFn`` of ``equation`` in ``variable`` (bound: replaced by a dummy)."""
    x = sp.Dummy(variable.name, real=True)
    return ImplicitRootFn(sp.Lambda(x, equation.xreplace({variable: x})), target, lo, hi)
