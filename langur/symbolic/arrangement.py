"""Cells of an arrangement of hyperplanes in the parameters: where a closed form of several
parameters is one expression (issue 14, readable forms; used by :mod:`langur.symbolic.readable`).

The switching functions of a closed form (the differences of the arguments of its ``Min``/``Max``,
the sides of its ``Piecewise`` relations) are, in the paper's programs, affine in the parameters:
box bounds ``a + 10``, window ends ``b - a``.  Their zero sets cut the parameter space into open
convex cells; on each cell no switching function changes sign, so the closed form is one
expression there.  :func:`cells` finds every cell that is not empty with an exact rational point
inside it (a linear program gives the point, exact arithmetic checks it), :func:`merged` joins
neighbouring cells on which the closed form is the same expression, and :func:`essential` keeps
only the bounding relations that matter.  Everything is exact except the search for a point, which
is checked exactly afterwards: a cell whose point fails the check makes :func:`cells` give up.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from math import gcd

import numpy as np
import sympy as sp

from langur import lazy

# scipy.optimize (for its linprog), imported at the first case split (``langur.lazy``): ~0.3 s of
# import that the analyses importing this module through ``symbolic.pieces`` seldom need.
so = lazy.module("scipy.optimize")

#: More cells or planes than this: no case split (the engine's form is shown instead).
MAX_CELLS = 48
MAX_PLANES = 24


@dataclass(frozen=True)
class Plane:
    """``coeffs · p + const`` (integers, primitive, first nonzero coefficient positive)."""

    coeffs: tuple[int, ...]
    const: int

    def value(self, point) -> Fraction:
        return sum((Fraction(c) * v for c, v in zip(self.coeffs, point)), Fraction(self.const))

    def expr(self, params) -> sp.Expr:
        return sum((c * p for c, p in zip(self.coeffs, params)), sp.Integer(self.const))


@dataclass(frozen=True)
class Cell:
    """Where each of ``signs``' planes has the given sign (+1 or −1); ``point`` is exact and inside."""

    signs: tuple[tuple[Plane, int], ...]
    point: tuple[Fraction, ...]


def plane(s: sp.Expr, params) -> Plane | None:
    """``s`` as a normalized plane, or None when it is not affine with rational coefficients (or
    constant)."""
    try:
        poly = sp.Poly(sp.expand(s), *params)
    except sp.PolynomialError:
        return None
    if poly.total_degree() != 1:
        return None
    coeffs = [poly.coeff_monomial(p) for p in params]
    const = poly.coeff_monomial(1)
    if not all(c.is_Rational for c in [*coeffs, const]):
        return None
    den = 1
    for c in [*coeffs, const]:
        den = den * sp.Rational(c).q // gcd(den, sp.Rational(c).q)
    ints = [int(c * den) for c in [*coeffs, const]]
    g = 0
    for v in ints:
        g = gcd(g, abs(v))
    ints = [v // g for v in ints]
    if next(v for v in ints[:-1] if v != 0) < 0:
        ints = [-v for v in ints]
    return Plane(tuple(ints[:-1]), ints[-1])


def _point(signs, n: int) -> tuple[Fraction, ...] | None:
    """An exact point strictly inside ``signs`` (None when the cell is empty or too thin to find)."""
    if not signs:
        return tuple(Fraction(0) for _ in range(n))
    # maximize t subject to sign·(c·p + d) ≥ t, t ≤ 1: t > 0 at the optimum iff the cell is open
    a_ub = np.array([[-s * c for c in pl.coeffs] + [1.0] for pl, s in signs])
    b_ub = np.array([s * pl.const for pl, s in signs], dtype=float)
    res = so.linprog(np.r_[np.zeros(n), -1.0], A_ub=a_ub, b_ub=b_ub,
                  bounds=[(None, None)] * n + [(None, 1.0)], method="highs")
    if res.status != 0 or res.x[-1] <= 1e-9:
        return None
    for limit in (10**3, 10**6, None):
        pt = tuple(Fraction(float(v)) if limit is None else Fraction(float(v)).limit_denominator(limit)
                   for v in res.x[:-1])
        if all(s * pl.value(pt) > 0 for pl, s in signs):
            return pt
    raise ArithmeticError("the linear program's point is not inside its cell")


def cells(planes: list[Plane], n: int) -> list[Cell] | None:
    """Every nonempty open cell of the arrangement (None past :data:`MAX_CELLS` or
    :data:`MAX_PLANES`)."""
    found = [Cell((), tuple(Fraction(0) for _ in range(n)))]
    if len(set(planes)) > MAX_PLANES:
        return None
    for pl in dict.fromkeys(planes):
        nxt = []
        for c in found:
            for s in (1, -1):
                signs = (*c.signs, (pl, s))
                side = pl.value(c.point)
                pt = c.point if s * side > 0 else _point(signs, n)
                if pt is not None:
                    nxt.append(Cell(signs, pt))
        if len(nxt) > MAX_CELLS:
            return None
        found = nxt
    return found


def merged(groups: list[tuple[object, Cell]], same) -> list[tuple[object, Cell]]:
    """Join two cells whose sign conditions differ in one plane only and whose values are ``same``
    (the union is then the cell without that plane), until no two can be joined."""
    out = list(groups)
    changed = True
    while changed:
        changed = False
        for i in range(len(out)):
            for j in range(i + 1, len(out)):
                (vi, ci), (vj, cj) = out[i], out[j]
                if {p for p, _ in ci.signs} != {p for p, _ in cj.signs}:
                    continue
                diff = set(ci.signs) ^ set(cj.signs)
                if len(diff) == 2 and same(vi, vj):
                    (gone,) = {p for p, _ in diff}
                    out[i] = (vi, Cell(tuple(ps for ps in ci.signs if ps[0] != gone), ci.point))
                    del out[j]
                    changed = True
                    break
            if changed:
                break
    return out


def essential(cell: Cell, n: int, given=()) -> tuple[tuple[Plane, int], ...]:
    """The cell's bounding relations without ``given`` ones (known to hold) and without those the
    others and ``given`` imply (up to its boundary)."""
    keep = [ps for ps in cell.signs if ps not in given]
    for ps in list(keep):
        others = [q for q in keep if q != ps]
        if _point([*given, *others, (ps[0], -ps[1])], n) is None:
            keep = others
    return tuple(keep)
