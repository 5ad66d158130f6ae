"""Constructs drawn with ``programs(deep=True)`` (``langur fuzz --deep``; fuzz33): the split
conditions of :mod:`.poles` where fuzz32's campaigns did not reach (bench/history/2026-11-29.md#fuzz32,
"Not done"), each well-typed (LANGUAGE.md §2, §6) and its zero sets registered
(:meth:`~.conditions.Scope.register`) so the program stays generic at its defaults.

* products of moving factors over *two* variables (``[(x + 2*y - P)·(x - y - Q) CMP 0]``, one of them
  cubed, or over a moving pole of both variables ``[(x - P)·(y - Q) / (x + y - R) CMP 0]``):
  each factor's zero set is a moving line of the plane, not an axis-parallel one, so the front
  end's split (``langur/syntax/poles.py``) meets factors that cross inside the box;
* conditionals nested three deep whose conditions are :mod:`.poles` brackets (a moving pole or a
  product), the innermost a bracket times a smooth factor: a split under a split under a split;
* (in :func:`~.programs.programs`) such a factor moved into a ``def`` and called at a second site
  with other parameter terms (:func:`~.variants.call_elsewhere`): the split of one body at two
  sets of parameter values.
"""

from __future__ import annotations

from fractions import Fraction as F

from hypothesis import strategies as st

from ..syntax import surface as S
from . import conditions as C
from . import poles as P
from . import terms as T
from .terms import mul, num, power, sub

#: Coefficient pairs of a moving line ``c·v + d·w - (P + k)`` (never axis-parallel).
LINES = ((F(1), F(1)), (F(1), F(-1)), (F(1), F(2)), (F(2), F(-1)), (F(-1), F(1, 2)))


def line(scope: C.Scope, v: str, w: str) -> S.STerm:
    """A moving line over the two variables ``v``, ``w``: ``c·v + d·w - (P + k)``."""
    c, d = scope.pick(LINES)
    return sub(T.linear({v: c, w: d}), C.shifted_param(scope))


def plane_product(scope: C.Scope) -> S.Iverson:
    """``[L1 · L2 CMP 0]``, ``[L1^3 · L2 CMP 0]``, ``[L1 · L2 / L3 CMP 0]`` or ``[(v - P)·(w - Q) / L CMP 0]``
    with ``Li``, ``L`` moving lines over two variables (:func:`line`); each factor's (and the pole's)
    zero set registered.  Three factors come with a pole: a product of three moving factors and no
    pole is refused in a def or on a box whose intervals all move (T207, findings33 F1), though the
    same condition inline on a fixed box is split.  A program in one variable gets
    :func:`.poles.ratio` instead."""
    if len(scope.variables) < 2:
        return P.ratio(scope)
    v, w = scope.two_vars()
    form = scope.index(4)
    if form == 3:  # a moving pole over both variables, its numerator a product of moving factors
        f, g, h = P.moving(scope, False), P.moving(scope, False), line(scope, v, w)
    else:
        f, g = line(scope, v, w), line(scope, v, w)
        h = line(scope, v, w) if form == 2 else None
    for u in (f, g, h):
        if u is not None:
            scope.register(u, key=("factor", u))
    term = mul(power(f, 3) if form == 1 else f, g)
    return S.Iverson((term if h is None else T.div(term, h), num(0)), (scope.pick(C.CMPS),))


#: The brackets :func:`nested3` branches on (each split by the front end; the first is what
#: shrinking aims at).  Not :func:`.poles.product`'s three factors (F1, above).
SPLIT = (P.ratio, plane_product, P.reciprocal)


def _split(scope: C.Scope) -> S.Iverson:
    return SPLIT[scope.index(len(SPLIT))](scope)


def nested3(scope: C.Scope, depth: int = 3) -> S.STerm:
    """``if B1 then (if B2 then (if B3 then [B4]·s else …) else …) else …``: ``depth`` conditionals,
    each on a split bracket (:data:`SPLIT`), the innermost branch a split bracket times a smooth
    factor; each ``else`` a literal or a smooth factor."""
    if depth == 0:
        return mul(_split(scope), C.smooth(scope))
    cond = _split(scope)
    lhs, rhs = cond.terms
    then = nested3(scope, depth - 1)
    orelse = num(F(1, 2)) if scope.draw(st.booleans()) else C.smooth(scope)
    return S.IfCmp(lhs, cond.ops[0], rhs, then, orelse)


#: The factors of ``deep`` (the first is what shrinking aims at).
FACTORS = (plane_product, lambda scope: nested3(scope, 2 + scope.index(2)))


def factor(scope: C.Scope) -> S.STerm:
    """One factor of :data:`FACTORS`; the factor is remembered (:attr:`~.conditions.Scope.split`) so
    that a def made of it can be called at other parameter terms."""
    made = FACTORS[scope.index(len(FACTORS))](scope)
    scope.split.append(made)
    return made
