"""R̄: the closed region of one simply decomposable piece ``Π [c ≥ 0] · w`` (Def. 6.2) — the box cut by
its conditions at given parameter values — and a grid on it (its faces and corners included), on which
:mod:`.zerosets` samples a pole base.  Compiled numpy functions of its conditions are shared by regions."""

from __future__ import annotations

import functools
import itertools
from collections.abc import Sequence

import numpy as np
import sympy as sp

from ...precise import real_value as _num

#: Grid points per dimension (the grid has at most a few thousand points).
GRID = {1: 401, 2: 41, 3: 15}


class Undecidable(Exception):
    """The analysis cannot be carried out (no numeric value, time, shape)."""

class Region:
    """R̄: the box (numbers) cut by conditions ``c ≥ 0`` (sympy, parameters substituted)."""

    def __init__(self, xs: Sequence[sp.Symbol], box: Sequence[tuple[sp.Expr, sp.Expr]], conds: Sequence[sp.Expr]):
        self.xs = tuple(xs)
        self.box = [(sp.nsimplify(lo), sp.nsimplify(hi)) for lo, hi in box]
        self.lo = np.array([float(lo) for lo, _ in self.box])
        self.hi = np.array([float(hi) for _, hi in self.box])
        if not (np.all(np.isfinite(self.lo)) and np.all(np.isfinite(self.hi)) and np.all(self.hi > self.lo)):
            raise Undecidable("the box is empty or unbounded")
        self.scale = float(np.max(self.hi - self.lo))
        self.conds = [c for c in conds if c.free_symbols & set(self.xs)]
        # a condition constant on the box (a guard of an inverse branch that does not apply at
        # these parameters) that is negative empties the region: nothing there can blow up
        self.empty = any(_num(c) < 0 for c in conds if not c.free_symbols & set(self.xs))
        self._cfs = [compiled(c, self.xs) for c in self.conds]

    def grid(self) -> np.ndarray:
        n = len(self.xs)
        k = GRID.get(n, 7)
        axes = [np.linspace(lo, hi, k) for lo, hi in zip(self.lo, self.hi)]
        return np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, n), k

    def inside(self, pts: np.ndarray, tol: float = 1e-12) -> np.ndarray:
        ok = np.all((pts >= self.lo - tol * self.scale) & (pts <= self.hi + tol * self.scale), axis=1)
        for f in self._cfs:
            with np.errstate(all="ignore"):
                v = f(pts)
            ok &= np.nan_to_num(v, nan=-1.0) >= -tol * self.scale
        return ok

    def inside_exact(self, p: Sequence[sp.Expr]) -> bool:
        for (lo, hi), v in zip(self.box, p):
            if not (_num(v - lo) >= -1e-40 and _num(hi - v) >= -1e-40):
                return False
        sub = dict(zip(self.xs, p))
        return all(_num(c.xreplace(sub)) >= -1e-40 for c in self.conds)


@functools.lru_cache(maxsize=4096)  # one condition bounds many regions
def _lambdified(e: sp.Expr, xs: tuple):
    """``e`` compiled for numpy over ``xs``, or False where sympy cannot print it (zoo, nan…)."""
    try:
        return sp.lambdify(list(xs), e, modules="numpy")
    except Exception:  # noqa: BLE001 - sympy cannot print zoo, nan… for numpy: nowhere a number
        return False


def compiled(e: sp.Expr, xs) -> callable:
    """``e`` as a function of an (N, n) array of points: real values, NaN where not a real number."""
    f = _lambdified(e, tuple(xs))
    if f is False:
        return lambda pts: np.full(pts.shape[0], np.nan)

    def call(pts: np.ndarray) -> np.ndarray:
        with np.errstate(all="ignore"):
            try:
                v = np.asarray(f(*[pts[:, i] for i in range(pts.shape[1])]), dtype=complex)
            except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                return np.full(pts.shape[0], np.nan)
        v = np.broadcast_to(v, (pts.shape[0],))
        return np.where(np.abs(v.imag) <= 1e-12 * np.maximum(1.0, np.abs(v.real)), v.real, np.nan)

    return call

