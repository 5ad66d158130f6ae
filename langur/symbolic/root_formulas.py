"""Roots of a condition in one variable by formula (paper §6.3, Def. 6.2: a condition solved at the
evaluation point, :mod:`langur.symbolic.solving`; issue 15: exact ``deriv`` of every example in a
second).

* :func:`closed_roots`: the real roots and poles of a condition whose numerator and denominator
  are of degree ≤ 2 in the variable, by formula (the parameter-only parts of the condition held as
  opaque symbols, so nothing is expanded), and whether that is all of its sign changes.
"""

from __future__ import annotations

from functools import lru_cache

import sympy as sp

from langur.memo import remember
from langur.symbolic.walks import mentions


def _abstract(e, v, table: dict, memo: dict, pool: list | None = None, seen: dict | None = None):
    """``e`` with its maximal non-atomic subterms free of ``v`` replaced by dummies (``table``):
    new ones, or the next of ``pool`` (:data:`_POOL`) in the order they are first met.  (Whether a
    subtree has ``v`` free is asked by :func:`mentions`, once per distinct subtree: ``free_symbols``
    of every node walked its subtree again.)"""
    if e in memo:
        return memo[e]
    if seen is None:
        seen = {}
    if not e.args:
        out = e
    elif not mentions(e, frozenset((v,)), seen):
        out = table.get(e)
        if out is None:
            out = table[e] = sp.Dummy("k") if pool is None else _pooled(pool, len(table))
    else:
        out = e.func(*[_abstract(a, v, table, memo, pool, seen) for a in e.args])
    memo[e] = out
    return out


#: The dummies standing for the parameter-only parts in :func:`_root_formulas`, the i-th part met
#: taking the i-th: sympy orders dummies of one name by their creation, so the i-th part gets a
#: dummy that sorts after those of the parts met before it, as a new ``Dummy`` would — the formulas
#: are the same up to the renaming, and the same again for every condition of the same shape
#: (:data:`_SHAPES`; sympy's assumptions of a dummy are found once).
_POOL: list = []


def _pooled(pool: list, i: int):
    while len(pool) <= i:
        pool.append(sp.Dummy("k", finite=True))
    return pool[i]


def _poly_roots(p: sp.Poly):
    return _formula_roots(p.all_coeffs())


def _formula_roots(cs):
    """The roots of the polynomial with coefficients ``cs`` (leading first, degree 1 or 2)."""
    if len(cs) == 2:
        a, b = cs
        return [-b / a], a
    a, b, c = cs
    s = sp.sqrt(b ** 2 - 4 * a * c)
    return [(-b - s) / (2 * a), (-b + s) / (2 * a)], a


class _NotLow(Exception):
    """Not a rational function of low degree in the variable (:func:`_ratfun`)."""


#: Highest degree kept while building a rational function by :func:`_ratfun`.
_RATFUN_DEGREE = 4


def _trim(cs: list) -> list:
    while len(cs) > 1 and cs[-1] == 0:
        cs.pop()
    if len(cs) > _RATFUN_DEGREE + 1:
        raise _NotLow()
    return cs


def _padd(p: list, q: list) -> list:
    n = max(len(p), len(q))
    return _trim([(p[i] if i < len(p) else 0) + (q[i] if i < len(q) else 0) for i in range(n)])


def _pmul(p: list, q: list) -> list:
    if len(p) + len(q) - 2 > _RATFUN_DEGREE:
        raise _NotLow()
    out = [sp.Integer(0)] * (len(p) + len(q) - 1)
    for i, a in enumerate(p):
        if a == 0:
            continue
        for j, b in enumerate(q):
            out[i + j] += a * b
    return _trim(out)


def _rnorm(num: list, den: list):
    if len(den) == 1 and den[0] != 1:  # a denominator free of v: into the coefficients
        return _trim([c / den[0] for c in num]), [sp.Integer(1)]
    return num, den


def _ratfun(e, v, memo: dict):
    """``e`` as ``(numerator, denominator)`` coefficient lists in ``v`` (lowest degree first; the
    coefficients are expressions free of ``v``, never expanded), or :class:`_NotLow`."""
    if e in memo:
        return memo[e]
    if v not in e.free_symbols:
        out = ([e], [sp.Integer(1)])
    elif e == v:
        out = ([sp.Integer(0), sp.Integer(1)], [sp.Integer(1)])
    elif isinstance(e, sp.Add):
        n, d = _ratfun(e.args[0], v, memo)
        for a in e.args[1:]:
            n2, d2 = _ratfun(a, v, memo)
            n, d = (_padd(n, n2), d) if d == d2 else (_padd(_pmul(n, d2), _pmul(n2, d)), _pmul(d, d2))
        out = _rnorm(n, d)
    elif isinstance(e, sp.Mul):
        n, d = [sp.Integer(1)], [sp.Integer(1)]
        for a in e.args:
            n2, d2 = _ratfun(a, v, memo)
            n, d = _rnorm(_pmul(n, n2), _pmul(d, d2))
        out = (n, d)
    elif isinstance(e, sp.Pow) and e.exp.is_Integer and e.exp != 0:
        bn, bd = _ratfun(e.base, v, memo)
        if e.exp < 0:
            bn, bd = bd, bn
        n, d = [sp.Integer(1)], [sp.Integer(1)]
        for _ in range(abs(int(e.exp))):
            n, d = _pmul(n, bn), _pmul(d, bd)
        out = _rnorm(n, d)
    else:
        raise _NotLow()
    memo[e] = out
    return out


def _direct_formulas(e, v):
    """:func:`_root_formulas` by rational arithmetic on coefficient lists (no ``together``, no
    ``Poly``: linear in the size of ``e``), or None when a part is not of degree ≤ 2 this way
    (common factors are not cancelled: then ``together`` decides)."""
    try:
        num, den = _ratfun(e, v, {})
    except _NotLow:
        return None
    out = []
    for part in (num, den):
        if len(part) > 3:
            return None
        if len(part) == 1:
            out.append(([], ()))
            continue
        cs = list(reversed(part))
        rs, _ = _formula_roots(cs)
        out.append((rs, tuple(cs)))
    return out


def closed_roots(expr, v, value) -> tuple[list, list] | None:
    """``(roots, poles)`` of ``expr`` in ``v`` when its numerator and denominator are polynomials
    of degree ≤ 2 in ``v`` whose leading coefficients do not vanish at the point (``value``: the
    point's numeric evaluation of a parameter-only expression); the candidates are to be checked at
    the point (complex or spurious ones dropped).  None otherwise."""
    parts = _root_formulas(sp.sympify(expr), v)
    if parts is None:
        return None
    out = []
    for rs, coeffs in parts:
        if coeffs and value(coeffs[0]) == 0:
            # a linear part whose slope vanishes at the point: its root is at infinity there, so
            # outside the box near the point (unless the part vanishes identically there: a tie)
            if len(coeffs) == 2 and value(coeffs[1]) != 0:
                out.append([])
                continue
            return None
        out.append(rs)
    return out[0], out[1]


@lru_cache(maxsize=2048)  # by (condition, variable): the formulas do not depend on the point
def _root_formulas(expr, v):
    """For the numerator and the denominator of ``expr``: its roots in ``v`` by formula and its
    coefficients (the leading one first), or None when either is not of degree ≤ 2."""
    table: dict = {}
    # Pooled dummies unless ``expr`` holds dummies named like them (whose order with the pool's
    # would then differ from their order with new ones): fresh ones, as before, and no memo.
    pooled = not any(isinstance(s, sp.Dummy) and s.name == "k" for s in expr.free_symbols)
    e = _abstract(expr, v, table, {}, _POOL if pooled else None)
    back = {k: s for s, k in table.items()}
    if not pooled:
        return _shape_formulas(e, v, back)
    key = (e, v)
    out = _SHAPES.get(key)
    if out is None:
        out = _shape_formulas(e, v, None)
        remember(_SHAPES, key, False if out is None else out, 2048)
    if out is None or out is False:
        return None
    return [([r.xreplace(back) for r in rs], tuple(c.xreplace(back) for c in cs)) for rs, cs in out]


#: :func:`_shape_formulas` of an abstracted condition (pooled dummies), by (form, variable): a pure
#: function of them (False for None); the dummies of the formulas are replaced by each condition's
#: parts afterwards, as they were before.
_SHAPES: dict = {}


def _shape_formulas(e, v, back: dict | None):
    """:func:`_root_formulas` of the abstracted ``e``, its dummies replaced by ``back``'s values
    (kept when ``back`` is None); None when not of degree ≤ 2."""
    def put(x):
        return x if back is None else x.xreplace(back)

    direct = _direct_formulas(e, v)
    if direct is not None:
        return [([put(r) for r in rs], tuple(put(c) for c in cs)) for rs, cs in direct]
    num, den = sp.fraction(sp.together(e))
    out = []
    for part in (num, den):
        if v not in part.free_symbols:
            out.append(([], ()))
            continue
        try:
            p = sp.Poly(part, v)
        except sp.PolynomialError:
            return None
        if p.degree() > 2 or any(v in c.free_symbols for c in p.all_coeffs()):
            return None
        rs, _ = _poly_roots(p)
        out.append(([put(r) for r in rs], tuple(put(c) for c in p.all_coeffs())))
    return out
