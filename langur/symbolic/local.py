"""Closed forms decided at the evaluation point, for large parametric regions (paper §6.3,
Def. 6.2; issue 15: exact ``deriv`` of every example in a second).

:mod:`langur.symbolic.regions` builds closed forms valid for all parameter values where it can
(``Max``/``Min`` nests of the bounds).  When the conditions' coefficients are large expressions in
many parameters (the stylization kernel's triangle, §10.3.1; the ray-traced triangle, §10.2),
building those nests (sympy compares every pair of symbolic arguments) and expanding the weight
take minutes.  This module builds instead the closed form valid in the parameter cell of the
evaluation point, from the combinatorial structure decided there:

* :func:`polygon_integral`: ∫∫ over the box of Π [affine condition ≥ 0] · polynomial — the region
  is a convex polygon; which lines bound it and in which order is decided at the point by clipping
  the box with exact rationals (Sutherland–Hodgman).  Each vertex is the intersection of two of the
  lines (Cramer's rule, symbolically); the integral is a sum over the fan of triangles of the
  polygon of a lattice quadrature rule exact for the weight's degree (rational weights: the closed
  form is exact, the weight is never expanded).  It is valid wherever every vertex stays strictly
  inside every other half-plane: those relations are the cell (a line can only enter or leave the
  polygon by cutting one of its vertices).
* :func:`is_large` and :func:`cell_forms`: when the local path is taken (large conditions and
  weight, or a caller that wants a closed form near the point only).

Beside it, for the same large problems: the quadrature rules with rational weights (the triangle's,
and Newton–Cotes for one variable) in :mod:`langur.symbolic.exact_rules`; the walks of large
expressions, each distinct subtree once, in :mod:`langur.symbolic.walks`; a condition's roots at
the point by formula in :mod:`langur.symbolic.root_formulas`.
"""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator

import sympy as sp

from langur.memo import remember
from langur.symbolic.exact_rules import MAX_DEGREE, _q, triangle_rule
from langur.symbolic.rational import residue
from langur.symbolic.walks import degree, exact_at, free_symbols, has_any, mentions, size, tree_size

#: Conditions (plus weight) at least this large (tree nodes) take the local path (the ray-traced
#: triangle's are 500–2,000; the renderer's quad_shader, 150, keeps its closed form for all
#: parameter values, which `render --exact` evaluates over the whole image).
LARGE_OPS = 400
#: ... or mention at least this many parameters.
MANY_PARAMS = 5


#: Whether a closed form valid in the parameter cell of the point is enough (:func:`cell_forms`).
_CELL_FORMS: ContextVar[bool] = ContextVar("cell_forms", default=False)


@contextmanager
def cell_forms() -> Iterator[None]:
    """Within the block a 2-D region of affine conditions with a polynomial weight is integrated as
    the polygon decided at the point (:func:`polygon_integral`) whatever its size: the caller wants
    a closed form near the point only (Theorem 8.1's check localizes ⟦p⟧ at the point anyway), not
    one for all parameter values, whose ``Max``/``Min`` nests cost seconds (triangle.lgr)."""
    token = _CELL_FORMS.set(True)
    try:
        yield
    finally:
        _CELL_FORMS.reset(token)


def wants_cell_forms() -> bool:
    """Whether the caller asked for closed forms valid in the point's cell (:func:`cell_forms`)."""
    return _CELL_FORMS.get()


def is_large(exprs, params) -> bool:
    """Whether ``exprs`` (conditions and weight) are large enough for the local path: together
    at least :data:`LARGE_OPS` nodes, or mentioning :data:`MANY_PARAMS` parameters."""
    exprs = [sp.sympify(e) for e in exprs]
    if sum(size(e, LARGE_OPS) for e in exprs) >= LARGE_OPS:
        return True
    return len(set().union(*[free_symbols(e) for e in exprs]) & set(params)) >= MANY_PARAMS


# ------------------------------------------------------------------------------------------
# Convex polygons cut from the box by affine conditions.


class _Tie(Exception):
    """The evaluation point is on a switching set of the polygon's structure (or a line is
    degenerate there): no local closed form by this method."""


def _affine(e, x, y, memo):
    """``(a, b, c)`` with ``e = a·x + b·y + c`` (each free of x, y), or None; remembered
    (:data:`_LINES`) for ``e`` without Floats."""
    key = (e, x, y)
    hit = _LINES.get(key, _LINES)
    if hit is not _LINES:
        return hit
    if degree(e, frozenset((x, y)), memo) not in (0, 1):
        out = None
    else:
        a, b = sp.diff(e, x), sp.diff(e, y)
        out = None if (a.free_symbols | b.free_symbols) & {x, y} else \
            (a, b, e.xreplace({x: sp.Integer(0), y: sp.Integer(0)}))
    if not has_any(e, (sp.Float,)):
        remember(_LINES, key, out, GEOMETRY)
    return out


#: The polygon's pieces of sympy arithmetic that depend on its lines only (:func:`polygon_integral`):
#: each condition's line ``(a, b, c)`` by (condition, x, y); each vertex by its two lines (in the
#: order they are met); each relation of the cell by (line, vertex).  ⟦p⟧ and every partial
#: derivative's regular part integrate over the same polygon (the stylization kernel's triangle in
#: its pixel: the same conditions, another weight), and the same computation of the same sympy
#: expressions gives the same expressions.  Not kept for Floats (sympy's equality does not see
#: their precision); at most :data:`GEOMETRY` entries each.
_LINES: dict = {}
_VERTICES: dict = {}
_RELATIONS: dict = {}
GEOMETRY = 4096


def _vertex(li: tuple, lj: tuple, keep: bool) -> tuple:
    """The meeting point of the lines ``li`` and ``lj`` (Cramer's rule), remembered when ``keep``."""
    hit = _VERTICES.get((li, lj))
    if hit is None:
        (ai, bi, ci), (aj, bj, cj) = li, lj
        det = ai * bj - aj * bi
        hit = ((bi * cj - bj * ci) / det, (aj * ci - ai * cj) / det)
        if keep:
            remember(_VERTICES, (li, lj), hit, GEOMETRY)
    return hit


def _relation(line: tuple, X, Y, keep: bool):
    """``a·X + b·Y + c > 0`` (unevaluated), or None when it is a number; remembered when ``keep``."""
    key = (line, X, Y)
    hit = _RELATIONS.get(key, _RELATIONS)
    if hit is _RELATIONS:
        a, b, c = line
        rel = a * X + b * Y + c
        # (unevaluated: sympy cannot decide the sign of such a form, and spends a tenth of a
        # second per relation trying)
        hit = None if rel.is_number else sp.StrictGreaterThan(rel, 0, evaluate=False)
        if keep:
            remember(_RELATIONS, key, hit, GEOMETRY)
    return hit


def polygon_integral(conds, weight, x, y, box: dict, ctx, near: bool = False):
    """∫∫_box Π [c ≥ 0] · weight d(x, y) for affine conditions and a polynomial weight, valid in
    the parameter cell of ``ctx.at`` (recorded in ``ctx.cell``); None when this method does not
    apply (not affine, not polynomial, not rational at the point, or a tie there).  ``near``: the
    form is for Theorem 8.1's check only (:func:`_near_form`)."""
    memo: dict = {}
    d = degree(sp.sympify(weight), frozenset((x, y)), memo)
    if d is None or d > MAX_DEGREE:
        return None
    (xl, xh), (yl, yh) = box[x], box[y]
    lines = [(sp.Integer(1), sp.Integer(0), -xl), (sp.Integer(-1), sp.Integer(0), xh),
             (sp.Integer(0), sp.Integer(1), -yl), (sp.Integer(0), sp.Integer(-1), yh)]
    for c in conds:
        abc = _affine(sp.sympify(c.expr), x, y, memo)
        if abc is None:
            return None
        if abc not in lines:  # the box's own conditions come back as conditions
            lines.append(abc)
    num = []
    for abc in lines:
        vals = [exact_at(k, ctx.at) for k in abc]
        if None in vals:
            return None
        num.append(vals)
    try:
        poly = _clip(num)
    except _Tie:
        return None
    cell = []
    if len(poly) < 3:  # empty at the point: only a tie-free emptiness is decided here
        return None
    keep = not any(has_any(k, (sp.Float,)) for abc in lines for k in abc)
    verts = {}
    for key in {k for _, k in poly}:
        i, j = sorted(key)
        verts[key] = _vertex(lines[i], lines[j], keep)
    for _, key in poly:
        X, Y = verts[key]
        for k, line in enumerate(lines):
            if k not in key:
                rel = _relation(line, X, Y, keep)
                if rel is not None:
                    cell.append(rel)
    rule = triangle_rule(d)
    coeffs = monomials(sp.sympify(weight), x, y)  # w = Σ c_ab xᵃ yᵇ, the c_ab never expanded
    (x0, y0) = verts[poly[0][1]]
    triangles = [_triangle_points(x0, y0, *verts[k1], *verts[k2], rule) for (_, k1), (_, k2) in zip(poly[1:], poly[2:])]
    form = _near_form(coeffs, triangles, ctx.at) if near else None
    if form is None:
        # Σ_points w·(Σ_ab c_ab·Xᵃ·Yᵇ) as one sum of the terms w·c_ab·Xᵃ·Yᵇ (:func:`_point_terms`)
        form = sp.Add(*[half * sp.Add(*[t for w, X, Y, powers in points for t in _point_terms(coeffs, X, Y, powers, w)])
                        for half, points in triangles])
    for rel in cell:
        if rel not in ctx.cell:
            ctx.cell.append(rel)
    return form


#: The size (tree nodes) from which Theorem 8.1's check treats a closed form as large
#: (``langur.theorem.SYMBOLIC_OPS``): a polygon's closed form for that check is built as sums of
#: moments (:func:`_near_form`) only when both it and the canonical form are at least this large.
NEAR_LARGE = 3000
#: A prime: values at the point modulo it tell sympy expressions apart (:func:`_residue`).
_PRIME = (1 << 61) - 1


def _near_form(coeffs: dict, triangles: list, at: dict):
    """The polygon's closed form for Theorem 8.1's check (``near``, :func:`cell_forms`) as
    Σ_ab c_ab·M_ab with the moments M_ab = Σ_triangles half·Σ_points w·Xᵃ·Yᵇ, every sum and product
    unevaluated (sympy neither flattens nor sorts them): the same function as the canonical form
    of :func:`polygon_integral` (the same rule, points and coefficients, regrouped by
    distributivity), and only that check differentiates it (exactly, by dual numbers over the
    rationals: the same numbers).  What the check does with a form depends on its size
    (:data:`NEAR_LARGE`; ``integrate._tidy`` and ``Context.exact_value`` below that), so this form is
    returned only when it is large and the canonical one is certainly large too; else None (the
    canonical form is built).

    The canonical form is certainly large when the terms w·c·Xᵃ·Yᵇ that :func:`_point_terms` makes
    in one product (c a sum, X and Y sums, a or b > 0; then the term's number is w and its other
    factors c, Xᵃ, Yᵇ) have sizes adding up to :data:`NEAR_LARGE` and each is kept by sympy's sum:
    a sum merges two terms only when their non-numeric parts are equal, so equal values there.
    Values at the point modulo a prime (:func:`_residue`) tell them apart: of the terms whose parts
    share a residue (a rule's repeated point, or a coincidence) at least one is kept when their
    numbers do not add up to 0 (equal parts are merged, adding their numbers), so each such group
    counts with its smallest term, provided no other term of the triangle has that residue; each
    triangle's half·Σ (not a number, so not distributed) must have a residue of its own among the
    triangles.  A denominator the prime divides, a Float or anything else: None."""
    point: dict = {}
    for k, v in at.items():
        if isinstance(v, sp.Rational):
            r = _residue(v, {}, {})
            if r is None:
                return None
            point[k] = r
    memo: dict = {}
    cres = {ab: _residue(c, point, memo) for ab, c in coeffs.items()}
    if None in cres.values():
        return None
    # the constant term w·c_00 of every point, c_00 a sum: sympy distributes the number w over its terms,
    # whose parts without their numbers are those of c_00's terms (the same residues at every point)
    zero, zero_rests = coeffs.get((0, 0)), None
    if zero is not None and zero.is_Add:
        zero_rests = {_residue(t.as_coeff_Mul()[1], point, memo) for t in zero.args if not t.is_Number}
        if None in zero_rests:
            return None
    total = 0
    sizes: dict = {}  # (tree sizes by subtree: the coefficients and powers are alive throughout)
    parts = []  # per triangle: the residue of half·Σ without its number
    for half, points in triangles:
        h = _residue(half, point, memo)
        k = half.as_coeff_Mul()[0]
        if half.is_Number or h is None or _residue(k, {}, {}) in (None, 0):
            return None
        main: dict = {}  # residue of c·Xᵃ·Yᵇ -> its term's size
        other: set = set()
        s = 0  # Σ's residue
        for w, X, Y, powers in points:
            rx, ry = _residue(X, point, memo), _residue(Y, point, memo)
            if rx is None or ry is None:
                return None
            rw = _residue(w, {}, {})  # (w a rational: its numerator and denominator, not sympy's comparisons)
            one = X.is_Add and Y.is_Add and (rx != ry or X != Y) and w.p != 0
            for (a, b), c in coeffs.items():
                rc = cres[(a, b)]
                r = rc * pow(rx, a, _PRIME) * pow(ry, b, _PRIME) % _PRIME
                s = (s + rw * r) % _PRIME
                # (equal expressions have equal residues: sympy's comparison only where they are equal)
                shape = one and c.is_Add and (a or b) and (rc != rx or c != X) and (rc != ry or c != Y)
                factors = [f for f, e in ((_power(X, a, "x", powers), a), (_power(Y, b, "y", powers), b)) if e] \
                    if shape else []
                if shape and all(f.is_Pow or f.is_Add for f in factors):
                    # (sympy's product w·c·Xᵃ·Yᵇ: the number w, then c, Xᵃ, Yᵇ as they are: distinct bases)
                    n = 1 + (w.p != w.q) + tree_size(c, sizes) + sum(tree_size(f, sizes) for f in factors)
                    known = main.get(r)
                    main[r] = (w, n) if known is None else (known[0] + w, min(known[1], n))
                    continue
                if (a, b) == (0, 0) and zero_rests is not None:
                    other |= zero_rests
                    continue
                for rest in _rests(c * _power(X, a, "x", powers) * _power(Y, b, "y", powers) * w):
                    q = _residue(rest, point, memo)
                    if q is None:
                        return None
                    other.add(q)
        kept = [n for w, n in main.values() if w.p != 0]
        if len(kept) < 2 or other & main.keys():
            return None
        total += sum(kept)
        parts.append(h * s * pow(_residue(k, {}, {}), -1, _PRIME) % _PRIME)
    if total < NEAR_LARGE or len(set(parts)) != len(parts):
        return None
    moments = {ab: [] for ab in coeffs}
    for half, points in triangles:
        for a, b in moments:
            inner = [sp.Mul(w, *([_power(X, a, "x", powers)] if a else []), *([_power(Y, b, "y", powers)] if b else []),
                            evaluate=False) for w, X, Y, powers in points]
            moments[(a, b)].append(sp.Mul(half, sp.Add(*inner, evaluate=False), evaluate=False))
    form = sp.Add(*[sp.Mul(c, sp.Add(*moments[ab], evaluate=False), evaluate=False) for ab, c in sorted(coeffs.items())],
                  evaluate=False)
    return form if size(form, NEAR_LARGE) >= NEAR_LARGE else None


def _power(base, k: int, tag: str, powers: dict):
    """``base**k``, remembered in ``powers`` by (tag, k) (:func:`_point_terms`' powers)."""
    if (tag, k) not in powers:
        powers[(tag, k)] = base ** k
    return powers[(tag, k)]


def _rests(term) -> list:
    """The non-numeric parts of what sympy's sum makes of ``term`` (a number: none; a sum: each of
    its terms; a product: without its number)."""
    if term.is_Number:
        return []
    if term.is_Add:
        return [r for a in term.args for r in _rests(a)]
    return [term.as_coeff_Mul()[1]]


def _residue(e, point: dict, memo: dict):
    """``e``'s value at the point modulo :data:`_PRIME` (``point``: the symbols' residues), for a
    form of rationals, symbols, + , · and integer powers; None for anything else or when a
    denominator is divisible by the prime (:func:`langur.symbolic.rational.residue`: the walk of
    the exact values in the arithmetic modulo the prime).  Equal expressions have equal residues."""
    return residue(e, point, memo, _PRIME)


def monomials(w, x, y) -> dict:
    """The polynomial ``w`` in ``x``, ``y`` as ``{(a, b): c_ab}`` (``w = Σ c_ab xᵃ yᵇ``), the
    coefficients built from ``w``'s own subterms free of x and y by + and · (not expanded: one pass
    over the distinct subtrees of ``w``).  The weight at a quadrature point is then a short sum over
    these shared coefficients instead of a rebuilt copy of the whole weight.  The decompositions of
    subtrees are remembered across calls (:data:`_MONOMIALS`): each partial derivative's weight
    shares most of its subtrees with ⟦p⟧'s and the other partial derivatives' (the stylization
    kernel's colour differences, the barycentric coordinates); not for a weight holding Floats
    (sympy's equality does not see their precision)."""
    memo, seen = ({}, {}) if has_any(w, (sp.Float,)) else _monomial_memos(x, y)

    def mul(p: dict, q: dict) -> dict:
        out: dict = {}
        for (a1, b1), c1 in p.items():
            for (a2, b2), c2 in q.items():
                k = (a1 + a2, b1 + b2)
                out[k] = out[k] + c1 * c2 if k in out else c1 * c2
        return {k: c for k, c in out.items() if c != 0}

    def go(e) -> dict:
        if e in memo:
            return memo[e]
        if not mentions(e, frozenset((x, y)), seen):
            out = {(0, 0): e} if e != 0 else {}
        elif e == x:
            out = {(1, 0): sp.Integer(1)}
        elif e == y:
            out = {(0, 1): sp.Integer(1)}
        elif isinstance(e, sp.Add):
            out = {}
            for a in e.args:
                for k, c in go(a).items():
                    out[k] = out[k] + c if k in out else c
            out = {k: c for k, c in out.items() if c != 0}
        elif isinstance(e, sp.Mul):
            out = {(0, 0): sp.Integer(1)}
            for a in e.args:
                out = mul(out, go(a))
        elif isinstance(e, sp.Pow) and e.exp.is_Integer and e.exp >= 0:
            base, out = go(e.base), {(0, 0): sp.Integer(1)}
            for _ in range(int(e.exp)):
                out = mul(out, base)
        else:  # pragma: no cover - degree() accepted only these
            raise ValueError(f"not a polynomial in {x}, {y}: {e}")
        memo[e] = out
        return out

    return go(w)


#: Per pair of variables: the decompositions of subtrees (:func:`monomials`) and whether they
#: mention the variables; dropped whole past :data:`MONOMIAL_MEMO` entries.
_MONOMIALS: dict = {}
MONOMIAL_MEMO = 20_000


def _monomial_memos(x, y) -> tuple[dict, dict]:
    memos = _MONOMIALS.get((x, y))
    if memos is None or len(memos[0]) + len(memos[1]) > MONOMIAL_MEMO:
        memos = remember(_MONOMIALS, (x, y), ({}, {}), 8)
    return memos


#: A triangle's half Jacobian and its rule's points with their weights and the powers of their
#: coordinates computed so far (:func:`_triangle_points`), by vertices and rule.
_TRIANGLES: dict = {}
TRIANGLES = 512


def _triangle_points(x0, y0, x1, y1, x2, y2, rule) -> tuple:
    """The triangle's Jacobian over 2, and per point ``(s, t, w)`` of ``rule`` its weight ``w``, its
    coordinates ``(X, Y) = v0 + s·(v1 − v0) + t·(v2 − v0)`` and a dict for their powers
    (:func:`_at_point`).  These depend on the polygon only, and the same polygons come back for ⟦p⟧
    and every partial derivative (the weights differ): remembered, except for vertices holding Floats
    (sympy's equality does not see their precision)."""
    key = (x0, y0, x1, y1, x2, y2, rule)
    hit = _TRIANGLES.get(key)
    if hit is not None:
        return hit
    jac = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)  # twice the area: positive (counter-clockwise)
    out = (jac / 2, [(_q(w), x0 + _q(s) * (x1 - x0) + _q(t) * (x2 - x0), y0 + _q(s) * (y1 - y0) + _q(t) * (y2 - y0),
                      {}) for s, t, w in rule])
    if not any(has_any(v, (sp.Float,)) for v in key[:6]):
        remember(_TRIANGLES, key, out, TRIANGLES)
    return out


def _at_point(coeffs: dict, X, Y, powers: dict | None = None):
    """Σ c_ab Xᵃ Yᵇ (``powers``: the powers of X and Y computed so far, by (tag, exponent))."""
    return sp.Add(*_point_terms(coeffs, X, Y, powers))


def _point_terms(coeffs: dict, X, Y, powers: dict | None = None, w=None) -> list:
    """The terms of w·Σ_ab c_ab·Xᵃ·Yᵇ (w a rational, 1 when None): their sum is the same expression
    as ``w * Add(*[c * X**a * Y**b …])`` (:func:`_at_point` times w).

    :func:`polygon_integral` adds the terms of all the points of a triangle in one sum rather than
    Σ_points w·(Σ_ab …), each point's sum sorted, then distributed and sorted again: sympy's
    product of a rational and a sum is the sum of the rational's products with the terms (``Mul``
    distributes a number over a sum, each term's number kept in front), and a sum of sums is the
    sum of all their terms (``Add`` flattens its arguments, adds the numbers of the terms with the
    same rest, drops zeros and sorts the terms canonically), so one sum of the same terms is the
    same expression.

    A coefficient that is a sum (each coefficient of the stylization kernel's weight) is multiplied
    by w, Xᵃ and Yᵇ in one product rather than three (``w·((c·Xᵃ)·Yᵇ)``) when X and Y are not numbers
    and (a, b) ≠ (0, 0): then no product is of a number with a sum (only that one distributes), so
    each is sympy's general product — the factors' powers merged by base, the number in front, the
    rest sorted canonically — and the same in one step.  Anything else is built as before."""
    powers = {} if powers is None else powers

    def pw(base, k, tag):
        if (tag, k) not in powers:
            powers[(tag, k)] = base ** k
        return powers[(tag, k)]

    one = not (X.is_Number or Y.is_Number)
    out = []
    for (a, b), c in sorted(coeffs.items()):
        if one and c.is_Add and (a or b):
            out.append(sp.Mul(c, pw(X, a, "x"), pw(Y, b, "y")) if w is None else
                       sp.Mul(w, c, pw(X, a, "x"), pw(Y, b, "y")))
        else:
            t = c * pw(X, a, "x") * pw(Y, b, "y")
            out.append(t if w is None else w * t)
    return out


def _clip(lines):
    """The box (lines 0–3) clipped by the half-planes a·x + b·y + c ≥ 0 of ``lines[4:]``, all
    exact rationals: the counter-clockwise vertices as ``(point, frozenset of its two lines)``.
    Raises :class:`_Tie` when a vertex lies on a line or a line is degenerate."""

    def meet(i, j):
        (ai, bi, ci), (aj, bj, cj) = lines[i], lines[j]
        det = ai * bj - aj * bi
        if det == 0:
            raise _Tie()
        return ((bi * cj - bj * ci) / det, (aj * ci - ai * cj) / det)

    poly = [(meet(0, 2), frozenset((0, 2))), (meet(1, 2), frozenset((1, 2))),
            (meet(1, 3), frozenset((1, 3))), (meet(0, 3), frozenset((0, 3)))]
    if not (poly[0][0][0] < poly[1][0][0] and poly[0][0][1] < poly[3][0][1]):
        raise _Tie()  # an empty or degenerate box
    for k in range(4, len(lines)):
        a, b, c = lines[k]
        if a == 0 and b == 0:
            raise _Tie()
        out = []
        n = len(poly)
        for idx in range(n):
            (p, kp), (q, kq) = poly[idx], poly[(idx + 1) % n]
            sp_ = a * p[0] + b * p[1] + c
            sq = a * q[0] + b * q[1] + c
            if sp_ == 0 or sq == 0:
                raise _Tie()
            if sp_ > 0:
                out.append((p, kp))
            if (sp_ > 0) != (sq > 0):
                edge = kp & kq
                if len(edge) != 1:
                    raise _Tie()
                (e,) = edge
                out.append((meet(e, k), frozenset((e, k))))
        poly = out
        if len(poly) < 3:
            return []
    return poly
