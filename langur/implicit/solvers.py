"""One root of a function monotone on a bracket, where it changes sign: the implicit root ``x*``
of :mod:`langur.implicit.function` found numerically (paper §7.2: a point of an inverse branch
Ψ̂⁻¹ with no closed form; issue 18).

* :func:`bracketed_root`: to any precision (false position with the Illinois rule, on numbers of
  the caller's: floats or mpmath's), for ``evalf``;
* :func:`double_root`: in doubles, by Brent's method (scipy's C routine, imported on first use),
  for lambdified code.

No sympy here: only the function's values are asked.
"""

from __future__ import annotations

import math

import numpy as np

from langur import lazy

#: What ``f`` may raise at a bracket's end (outside its domain, a pole, too large): no root there.
_FAILS = (ValueError, ZeroDivisionError, OverflowError, TypeError)


def _by_the_ends(a, b, fa, fb, nan_refused: bool):
    """The root when the bracket's ends decide it, from ``fa``, ``fb`` = f − target at ``a``, ``b``:
    an end where that is 0; NaN where it has the same sign at both ends (no root), or with
    ``nan_refused`` is NaN at one; None when a root lies strictly inside (the solvers' search).
    Without it (:func:`bracketed_root`, as before the two shared this) a NaN end counts as
    non-negative (``NaN < 0`` is false); :func:`double_root` refuses it (Brent's method needs signs)."""
    if fa == 0:
        return a
    if fb == 0:
        return b
    if (nan_refused and (math.isnan(fa) or math.isnan(fb))) or not (fa < 0) ^ (fb < 0):
        return math.nan
    return None


def bracketed_root(f, target, lo, hi, bits: int = 53):
    """The ``x`` in ``[lo, hi]`` with ``f(x) = target`` for ``f`` monotone there, to within
    ``|hi − lo|·2^−(bits + 8)`` (so the result has full precision in that many bits): false
    position with the Illinois rule, the bracket halved whenever two steps did not halve it;
    NaN when ``target`` is not between ``f(lo)`` and ``f(hi)`` (no root there)."""
    try:
        a, b = lo, hi  # (the caller's numbers: mpmath's keep their precision)
        fa, fb = f(a) - target, f(b) - target
    except _FAILS:
        return math.nan
    decided = _by_the_ends(a, b, fa, fb, nan_refused=False)
    if decided is not None:
        return decided
    tol = abs(hi - lo) / 2 ** (bits + 8)
    side = 0  # the end kept by the last step (Illinois: its value is halved when kept twice)
    width = b - a
    for i in range(3 * (bits + 8) + 64):
        if not b - a > tol:
            break
        # false position (Illinois), or a halving when the last two steps did not halve the bracket
        m = (a + b) / 2 if i % 2 == 0 and b - a > width / 2 else a - fa * (b - a) / (fb - fa)
        if i % 2 == 0:
            width = b - a
        if not a < m < b:
            m = (a + b) / 2
            if m == a or m == b:
                break
        fm = f(m) - target
        if fm == 0:
            return m
        if (fm < 0) == (fa < 0):
            a, fa = m, fm
            if side == -1:
                fb /= 2
            side = -1
        else:
            b, fb = m, fm
            if side == 1:
                fa /= 2
            side = 1
    return (a + b) / 2


def double_root(f, target, lo, hi, args: tuple = ()):
    """:func:`bracketed_root` in double precision, by Brent's method (scipy's ``brentq``: ~10
    evaluations of ``f`` instead of ~60 halvings; the same root to within a few units in the
    last place); bisection where ``f`` fails inside the bracket.  ``f`` is called as
    ``f(x, *args)`` (no closure per root: a quadrature asks for tens of thousands)."""
    try:
        a, b = float(lo), float(hi)
        fa, fb = float(f(a, *args)) - target, float(f(b, *args)) - target
    except _FAILS:
        return math.nan
    decided = _by_the_ends(a, b, fa, fb, nan_refused=True)
    if decided is not None:
        return decided
    try:
        # scipy's C routine itself, as ``so.brentq`` calls it with these tolerances (its wrapper
        # only checks them and raises on NaN, which ``_root_value`` already does): the same root
        return _BRENTQ(_root_value, a, b, 1e-300, _RTOL, _MAXITER, (f, target, args), False, True)
    except (ValueError, ZeroDivisionError, OverflowError, TypeError, RuntimeError):
        return bracketed_root(lambda z: f(z, *args), target, lo, hi)


def _root_value(z, f, target, args):
    """``f(z, *args) − target`` for Brent's method, raising where it is NaN."""
    v = float(f(z, *args)) - target
    if v != v:
        raise ValueError
    return v


#: Brent's method as ``so.brentq`` runs it (its relative tolerance and iteration limit).
_RTOL = 4 * np.finfo(float).eps
_MAXITER = 100

# scipy.optimize, imported when a root is first solved (``langur.lazy``): its import (linprog,
# linalg, …) costs ~0.3 s, and the commands that import this module through ``sympy_bridge`` for
# an analysis that solves no implicit root (``deriv --engine mc`` of an affine program) never need it.
so = lazy.module("scipy.optimize")
_zeros = lazy.module("scipy.optimize._zeros")


def _BRENTQ(g, a, b, xtol, rtol, maxiter, args, full_output, disp):
    """scipy's C routine of Brent's method (resolved at the first call, then called directly);
    its public wrapper, the same root, for a scipy without it."""
    global _BRENTQ
    try:
        _BRENTQ = _zeros._brentq
    except (ImportError, AttributeError):
        def _BRENTQ(g, a, b, xtol, rtol, maxiter, args, full_output, disp):
            return so.brentq(g, a, b, args=args, xtol=xtol, rtol=rtol, maxiter=maxiter)
    return _BRENTQ(g, a, b, xtol, rtol, maxiter, args, full_output, disp)
