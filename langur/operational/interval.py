"""Interval enclosures over core terms, on arrays of boxes at once (the samplers' boxes, §9).

:func:`enclose` bounds ⟦t⟧ over boxes of its variables: each box given by arrays of lower and
upper ends (any shape that broadcasts with the parameters' arrays), so a whole grid of cells for
a whole batch of parameter points is enclosed in one pass (no Python recursion per cell).
Enclosures are conservative: a NaN end (an operation outside its domain) makes the interval
unbounded, never narrower.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..core import Add, Const, IfDiffeo, IfGe0, ImplicitRoot, Let, Mul, Param, Pow, Prim, Term, Var
from ..primitives import REGISTRY
from .compile import const_value

INF = np.inf


def enclose(t: Term, box: dict, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """Arrays (lo, hi) containing ⟦t⟧ for every point of each box (``box``: variable → (lo, hi)
    arrays) at ``params`` (name → number or array, broadcast with the boxes).  A subterm shared
    in ``t`` (substituted lets, inlined calls: a DAG) is enclosed once per parameter scope."""
    return _Enclose(box).go(t, params)


class _Enclose:
    def __init__(self, box: dict):
        self.box = box
        self.memo: dict[tuple[int, int], tuple] = {}
        self.scopes: list[dict] = []  # the parameter scopes stay alive, so their ids stay theirs

    def go(self, t: Term, params: dict):
        key = (id(t), id(params))
        hit = self.memo.get(key)
        if hit is None:
            hit = self.memo[key] = self._enclose(t, params)
        return hit

    def _enclose(self, t: Term, params: dict):
        box, enclose = self.box, self.go
        match t:
            case Const():
                c = np.float64(const_value(t))
                return c, c
            case Var(name):
                return box[name]
            case Param(name):
                v = np.asarray(params[name], dtype=float)
                return v, v
            case Add(a, b):
                (al, ah), (bl, bh) = enclose(a, params), enclose(b, params)
                return al + bl, ah + bh
            case Mul(a, b):
                (al, ah), (bl, bh) = enclose(a, params), enclose(b, params)
                with np.errstate(invalid="ignore"):  # a point interval (lo is hi) multiplies once
                    p0 = al * bl
                    p1 = p0 if bl is bh else al * bh
                    p2 = p0 if al is ah else ah * bl
                    p3 = p2 if bl is bh else (p1 if al is ah else ah * bh)
                # NaN products ignored… (left to right, as a reduction over the four would)
                lo = np.fmin(np.fmin(np.fmin(p0, p1), p2), p3)
                hi = np.fmax(np.fmax(np.fmax(p0, p1), p2), p3)
                none = np.isnan(lo)  # …unless all are NaN: then anything
                if not none.any():
                    return lo, hi
                return np.where(none, -INF, lo), np.where(none, INF, hi)
            case Pow(a, k):
                return _pow(*enclose(a, params), k)
            case Prim(op, a):
                return _prim(op, *enclose(a, params))
            case IfGe0(c, a, b):
                (cl, ch), (al, ah), (bl, bh) = enclose(c, params), enclose(a, params), enclose(b, params)
                lo = np.where(cl >= 0, al, np.where(ch < 0, bl, np.minimum(al, bl)))
                hi = np.where(cl >= 0, ah, np.where(ch < 0, bh, np.maximum(ah, bh)))
                return lo, hi
            case IfDiffeo(_, a, b):
                (al, ah), (bl, bh) = enclose(a, params), enclose(b, params)
                return np.minimum(al, bl), np.maximum(ah, bh)
            case Let(name, bound, body):
                lo, hi = enclose(bound, params)
                scope = {**params, name: lo}
                self.scopes.append(scope)
                bl, bh = enclose(body, scope)
                wide = lo != hi  # a let bound to a range: its body is not enclosed per value
                return np.where(wide, -INF, bl), np.where(wide, INF, bh)
            case ImplicitRoot(_, _, _, lo, hi):  # issue 18: the root lies in its bracket
                return enclose(lo, params)[0], enclose(hi, params)[1]
        raise TypeError(f"cannot enclose {t!r}")


def _pow(lo, hi, k: Fraction):
    f = float(k)
    with np.errstate(all="ignore"):
        a, b = np.power(lo, f), np.power(hi, f)
    if k.denominator == 1 and k > 0:
        out_lo, out_hi = np.minimum(a, b), np.maximum(a, b)
        if int(k) % 2 == 0:
            straddles = (lo < 0) & (hi > 0)
            out_lo = np.where(straddles, np.minimum(out_lo, 0.0), out_lo)
        return out_lo, out_hi
    unbounded = (lo < 0) if k.denominator != 1 else np.zeros(np.shape(lo), dtype=bool)
    if k < 0:
        unbounded = unbounded | ((lo <= 0) & (hi >= 0))
    return np.where(unbounded, -INF, np.minimum(a, b)), np.where(unbounded, INF, np.maximum(a, b))


def _prim(op: str, lo, hi):
    """An interval containing f([lo, hi]): the primitive registry's own rule (one declaration)."""
    return REGISTRY[op].interval(lo, hi)
