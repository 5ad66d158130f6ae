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
* :func:`newton_cotes`: ∫ₐᵇ of a polynomial of degree d by the closed Newton–Cotes rule with d + 1
  points (exact for degree ≤ d, rational weights).
* :func:`closed_roots`: the real roots and poles of a condition whose numerator and denominator
  are of degree ≤ 2 in the variable, by formula (the parameter-only parts of the condition held as
  opaque symbols, so nothing is expanded), and whether that is all of its sign changes.
"""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar
from fractions import Fraction
from functools import lru_cache
from typing import Iterator

import sympy as sp

from langur.memo import remember
from langur.symbolic.rational import residue

#: Conditions (plus weight) at least this large (tree nodes) take the local path (the ray-traced
#: triangle's are 500–2,000; the renderer's quad_shader, 150, keeps its closed form for all
#: parameter values, which `render --exact` evaluates over the whole image).
LARGE_OPS = 400
#: ... or mention at least this many parameters.
MANY_PARAMS = 5
#: Highest degree of a polynomial weight integrated by a lattice or Newton–Cotes rule.
MAX_DEGREE = 8


def degree(e, vs: frozenset, memo: dict | None = None, seen: dict | None = None) -> int | None:
    """Total degree of ``e`` as a polynomial in the symbols ``vs`` (coefficients any expressions
    free of them), or None when it is not one.  Linear in the size of the tree (memoized; ``seen``
    memoizes :func:`mentions`)."""
    memo = {} if memo is None else memo
    seen = {} if seen is None else seen
    if e in memo:
        return memo[e]
    if not e.args:
        out = 1 if e in vs else 0
    elif not mentions(e, vs, seen):
        out = 0
    elif isinstance(e, sp.Add):
        ds = [degree(a, vs, memo, seen) for a in e.args]
        out = None if None in ds else max(ds)
    elif isinstance(e, sp.Mul):
        ds = [degree(a, vs, memo, seen) for a in e.args]
        out = None if None in ds else sum(ds)
    elif isinstance(e, sp.Pow) and e.exp.is_Integer and e.exp >= 0:
        d = degree(e.base, vs, memo, seen)
        out = None if d is None else d * int(e.exp)
    else:
        out = None
    memo[e] = out
    return out


def mentions(e, vs, memo: dict) -> bool:
    """Whether ``e`` has one of the symbols ``vs`` free (``e.free_symbols & vs``), memoized by
    subtree in ``memo`` (asking ``free_symbols`` of every node walks each node's subtree again)."""
    hit = memo.get(e)
    if hit is None:
        if e.is_Symbol:
            hit = e in vs
        elif not e.args:
            hit = bool(e.free_symbols & vs)
        elif not _plain_free_symbols(type(e)):
            hit = bool(e.free_symbols & vs)
        else:
            hit = any(mentions(a, vs, memo) for a in e.args)
        memo[e] = hit
    return hit


#: Limits up to which :func:`size` counts node by node; beyond, it sums over distinct subtrees.
WALKED_SIZE = 4096


def size(e, limit: int) -> int:
    """Number of nodes of the tree ``e``, counted up to ``limit`` (cheaper than ``count_ops``):
    ``min(number of nodes, limit)``.  A large limit (the closed forms printed or not, 10⁵ nodes) is
    checked by summing the sizes of the distinct subtrees (:func:`tree_size`) rather than visiting
    10⁵ nodes."""
    if limit > WALKED_SIZE:
        return min(tree_size(e), limit)
    n, stack = 0, [e]
    while stack and n < limit:
        node = stack.pop()
        n += 1
        stack.extend(node.args)
    return n


def tree_size(e, sizes: dict | None = None) -> int:
    """Number of nodes of the tree ``e`` (a subtree counted each time it occurs), each distinct
    subtree object visited once (``sizes``: the sizes found so far by object id, for the caller's
    trees that are alive meanwhile; shared between calls on trees sharing subtrees)."""
    sizes = {} if sizes is None else sizes
    if id(e) in sizes:
        return sizes[id(e)]
    stack = [(e, False)]
    while stack:
        node, done = stack.pop()
        if done:
            sizes[id(node)] = 1 + sum(sizes[id(a)] for a in node.args)
        elif id(node) not in sizes:
            stack.append((node, True))
            stack.extend((a, False) for a in node.args if id(a) not in sizes)
    return sizes[id(e)]


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


def any_node(e, holds) -> bool:
    """Whether ``holds(node)`` for a node of ``e``, each distinct subtree visited once (sympy's
    ``has`` walks the tree with its repeats: seconds for a local closed form of 10⁶ nodes over 10⁴
    distinct ones, the stylization kernel's ⟦p⟧)."""
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if holds(node):
            return True
        for a in node.args:
            if id(a) not in seen:
                seen.add(id(a))
                stack.append(a)
    return False


def atoms_of(e, types) -> set:
    """``e.atoms(*types)`` for classes ``types`` (nodes of those classes, a set), each distinct
    subtree visited once: sympy's ``atoms`` walks the tree with its repeats (the integrands and
    closed forms of a stylize or ray-traced partial derivative share their subtrees: a walk of
    10⁵ nodes over 10³ distinct ones, every time one is compiled or printed)."""
    out: set = set()
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, types):
            out.add(node)
        for a in (node.args if isinstance(node, sp.Basic) else node):  # (sympy's traversal: args, or iterables)
            if id(a) not in seen and (isinstance(a, sp.Basic) or _iterable(a)):
                seen.add(id(a))
                stack.append(a)
    return out


def _iterable(a) -> bool:
    """Whether sympy's preorder traversal descends into ``a`` (a non-Basic argument)."""
    return isinstance(a, (tuple, list, set, frozenset))


def has_any(e, types: tuple) -> bool:
    """``e.has(*types)`` for classes ``types``, each distinct subtree visited once (:func:`any_node`)."""
    return any_node(e, lambda node: isinstance(node, types))


@lru_cache(maxsize=None)
def _plain_free_symbols(cls) -> bool:
    """Whether ``cls``'s free symbols are the union of its arguments' (sympy's ``Basic`` rule)."""
    owner = next(k for k in cls.__mro__ if "free_symbols" in k.__dict__)
    return owner is sp.Basic


def free_symbols(e) -> set:
    """``e.free_symbols`` for a tree of symbols and numbers under ordinary functions and operators,
    each distinct subtree visited once (sympy recomputes it for every occurrence: seconds for the
    ~10³-node integrands of a stylize partial derivative).  A node with bound symbols (a Lambda,
    an implicit root, an Integral) is asked for its own ``free_symbols``."""
    out: set = set()
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if node.is_Symbol:
            out.add(node)
            continue
        if not node.args:
            out |= node.free_symbols
            continue
        if not _plain_free_symbols(type(node)):  # its own rule (bound symbols, ImplicitRootFn)
            out |= node.free_symbols
            continue
        for a in node.args:
            if id(a) not in seen:
                seen.add(id(a))
                stack.append(a)
    return out


def is_large(exprs, params) -> bool:
    """Whether ``exprs`` (conditions and weight) are large enough for the local path: together
    at least :data:`LARGE_OPS` nodes, or mentioning :data:`MANY_PARAMS` parameters."""
    exprs = [sp.sympify(e) for e in exprs]
    if sum(size(e, LARGE_OPS) for e in exprs) >= LARGE_OPS:
        return True
    return len(set().union(*[free_symbols(e) for e in exprs]) & set(params)) >= MANY_PARAMS


# ------------------------------------------------------------------------------------------
# Exact values at the evaluation point.


def shared_xreplace(e, rule: dict, rational: bool | None = None):
    """``e.xreplace(rule)``, the same expression, each distinct subtree rebuilt once (sympy's
    ``xreplace`` rebuilds a subtree every time it occurs: a weight substituted at every point of a
    lattice rule is a tree of thousands of nodes over a few hundred distinct ones).

    When ``e`` and the replacements are real rational forms (:func:`rational_form`; ``rational``:
    that answer when the caller knows it), a rebuilt integer power of a sum is made without sympy's
    evaluation, which gives that same node: for a sum with a symbol in it and an integer exponent
    other than 0 and 1, ``Pow`` evaluates only through ``Add._eval_power``, which rewrites nothing
    without the imaginary unit in the sum — and a real rational form has none, nor can one appear
    by substituting such forms — but first asks whether either term of a two-term sum is
    infinite: a query of sympy's assumptions through the whole new subtree (two thirds of the time
    of the stylization kernel's delta pieces' Newton–Cotes sums, :func:`newton_cotes`)."""
    e = sp.sympify(e)
    if rational is None:
        rational = rational_form(e) and all(rational_form(sp.sympify(r)) for r in rule.values())
    memo: dict = {}

    def go(node):
        if not node.args:  # (atoms are not memoized: equal Floats of other precisions stay as they are)
            return rule.get(node, node)
        hit = memo.get(node)
        if hit is not None:
            return hit
        if node in rule:
            out = rule[node]
        else:
            args = tuple(go(a) if isinstance(a, sp.Basic) else a for a in node.args)
            if all(a is b for a, b in zip(args, node.args)):
                out = node
            elif rational and isinstance(node, sp.Pow) and isinstance(args[0], sp.Add):
                out = sp.Pow(*args, evaluate=False)  # (an Integer exponent, not 0 or 1: unchanged)
            else:
                out = node.func(*args)
        memo[node] = out
        return out

    return go(e)


def rational_form(e) -> bool:
    """Whether ``e`` is built from real symbols and rationals by +, ·, integer powers other than 0
    and 1, and ``Abs`` (no imaginary unit can come out of sympy's evaluation of such a form with
    other such forms substituted), each distinct subtree looked at once."""
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if isinstance(node, sp.Symbol):
            if node.is_real is not True:
                return False
        elif isinstance(node, sp.Pow):
            if not (node.exp.is_Integer and node.exp not in (0, 1)):
                return False
            if id(node.base) not in seen:
                seen.add(id(node.base))
                stack.append(node.base)
        elif isinstance(node, (sp.Add, sp.Mul, sp.Abs)):
            for a in node.args:
                if id(a) not in seen:
                    seen.add(id(a))
                    stack.append(a)
        elif not isinstance(node, sp.Rational):
            return False
    return True


def exact_at(e, at: dict):
    """``e`` at the point as a Fraction when it is rational there, else None."""
    z = sp.sympify(e).xreplace(at)
    if isinstance(z, sp.Rational):
        return Fraction(int(z.p), int(z.q))
    return None


# ------------------------------------------------------------------------------------------
# Quadrature rules with rational weights, exact for polynomials of a given degree.


def _solve(rows: list[list[Fraction]], rhs: list[Fraction]) -> list[Fraction]:
    n = len(rhs)
    m = [row[:] + [b] for row, b in zip(rows, rhs)]
    for c in range(n):
        p = next(r for r in range(c, n) if m[r][c] != 0)
        m[c], m[p] = m[p], m[c]
        for r in range(n):
            if r != c and m[r][c] != 0:
                f = m[r][c] / m[c][c]
                m[r] = [a - f * b for a, b in zip(m[r], m[c])]
    return [m[i][n] / m[i][i] for i in range(n)]


@lru_cache(maxsize=None)
def line_rule(d: int) -> tuple[tuple[Fraction, Fraction], ...]:
    """Closed Newton–Cotes on [0, 1]: points k/d, weights summing to 1; exact for degree ≤ d."""
    d = max(d, 1)
    pts = [Fraction(k, d) for k in range(d + 1)]
    ws = _solve([[p ** j for p in pts] for j in range(d + 1)], [Fraction(1, j + 1) for j in range(d + 1)])
    return tuple(zip(pts, ws))


def _moments_exact(rule, d: int) -> bool:
    """Whether ``rule`` ((s, t, w), weights summing to 1) integrates every monomial sᵃtᵇ of degree
    ≤ d over the reference triangle exactly (∫ sᵃ tᵇ = a! b! / (a + b + 2)!, divided by the area ½)."""
    fact = [1]
    for k in range(1, 2 * d + 3):
        fact.append(fact[-1] * k)
    return all(sum(w * s ** a * t ** b for s, t, w in rule) == Fraction(2 * fact[a] * fact[b], fact[a + b + 2])
               for a in range(d + 1) for b in range(d + 1 - a))


@lru_cache(maxsize=None)
def grundmann_moeller(k: int) -> tuple[tuple[Fraction, Fraction, Fraction], ...]:
    """The Grundmann–Möller rule of degree 2k + 1 on the reference triangle (SIAM J. Numer. Anal.
    15(2), 1978): rational points and weights (some negative), (k + 1)(k + 2)(k + 3)/6 points —
    fewer than the lattice rule of the same degree.  Points in barycentric coordinates
    ((2β₀ + 1)/m, (2β₁ + 1)/m, (2β₂ + 1)/m) with |β| = k − i and m = 2k + 3 − 2i, weight ∝
    (−1)ⁱ m^(2k+1) / (i! (2k + 3 − i)!); normalized to sum 1 and verified exact (by
    :func:`_moments_exact`, in rationals) before use."""
    d = 2 * k + 1
    fact = [1]
    for j in range(1, d + 4):
        fact.append(fact[-1] * j)
    out = []
    for i in range(k + 1):
        m = d + 2 - 2 * i
        c = Fraction((-1) ** i * m ** d, fact[i] * fact[d + 2 - i])
        for b1 in range(k - i + 1):
            for b2 in range(k - i + 1 - b1):
                out.append((Fraction(2 * b1 + 1, m), Fraction(2 * b2 + 1, m), c))
    total = sum(w for _, _, w in out)
    rule = tuple((s, t, w / total) for s, t, w in out)
    if not _moments_exact(rule, d):  # pragma: no cover - the construction above is exact
        raise AssertionError(f"Grundmann–Möller rule of degree {d} is not exact")
    return rule


@lru_cache(maxsize=None)
def triangle_rule(d: int) -> tuple[tuple[Fraction, Fraction, Fraction], ...]:
    """A rule on the reference triangle {s, t ≥ 0, s + t ≤ 1} with rational points and weights
    summing to 1 (times the area), exact for degree ≤ d: the Grundmann–Möller rule of the
    smallest odd degree ≥ d when it has fewer points than the lattice rule (the closed form is a
    copy of the weight per point), else the lattice rule."""
    d = max(d, 1)
    k = d // 2  # degree 2k + 1 ≥ d
    if (k + 1) * (k + 2) * (k + 3) // 6 < (d + 1) * (d + 2) // 2:
        return grundmann_moeller(k)
    return lattice_rule(d)


@lru_cache(maxsize=None)
def lattice_rule(d: int) -> tuple[tuple[Fraction, Fraction, Fraction], ...]:
    """The lattice rule on the reference triangle {s, t ≥ 0, s + t ≤ 1}: points (i/d, j/d),
    weights summing to 1 (times the area); exact for degree ≤ d (the lattice is unisolvent)."""
    d = max(d, 1)
    pts = [(Fraction(i, d), Fraction(j, d)) for i in range(d + 1) for j in range(d + 1 - i)]
    monos = [(a, b) for a in range(d + 1) for b in range(d + 1 - a)]
    fact = [1]
    for k in range(1, 2 * d + 3):
        fact.append(fact[-1] * k)
    # ∫ s^a t^b over the triangle = a! b! / (a + b + 2)!; divided by its area 1/2
    rhs = [Fraction(2 * fact[a] * fact[b], fact[a + b + 2]) for a, b in monos]
    ws = _solve([[s ** a * t ** b for s, t in pts] for a, b in monos], rhs)
    return tuple((s, t, w) for (s, t), w in zip(pts, ws) if w != 0)


def _q(f: Fraction) -> sp.Rational:
    return sp.Rational(f.numerator, f.denominator)


def newton_cotes(w, v, a, b, d: int):
    """∫ₐᵇ w dv for ``w`` a polynomial of degree ≤ ``d`` in ``v`` (exact, unexpanded)."""
    rational = rational_form(w) and rational_form(a) and rational_form(b)
    return (b - a) * sp.Add(*[_q(c) * shared_xreplace(w, {v: a + _q(p) * (b - a)}, rational)
                              for p, c in line_rule(d)])


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


# ------------------------------------------------------------------------------------------
# Roots of a condition in one variable by formula.


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
