"""A proof of where a piece's integral lies: ``∫_box Π[cᵢ ≥ 0]·w`` enclosed by outward-rounded
interval arithmetic (paper §8.2's ⟦p⟧ at a point; branches exact32 and proof33, bench/RESULTS.md).

``quad`` samples an interval at 21 abscissae and estimates its error from two rules that agree:
a peak between the abscissae (``exp(-1e8*(x - 0.3)^2)`` on [0, 1], width 10⁻⁴) is never seen,
both rules say 0, and the exact engine printed ``0 (quadrature, error ≤ 1e-10)`` — an estimate
nothing backs.  What is proved here instead: the box is cut into cells, and on each cell

* a condition whose interval enclosure (:mod:`langur.enclosures`) lies above 0 holds on the whole
  cell, one below 0 on none of it; otherwise the cell is *uncertain*;
* a *certain* cell (every condition holds) contributes the product Gauss–Legendre rule of ``n``
  points per variable with its remainder: on one variable ``∫_a^b f = Q_n(f) + c_n·h^(2n+1)·f^(2n)(ξ)``,
  ``h = b − a``, ``c_n = (n!)⁴/((2n+1)·((2n)!)³)`` (Abramowitz–Stegun 25.4.30; ``n = 1`` is the
  midpoint rule's ``h³/24``); the product rule's remainder is ``vol·c_n·Σᵢ hᵢ^(2n)·∂ᵢ^(2n)w(ξᵢ)``
  (apply the rule variable by variable: each step's remainder, averaged with positive weights over
  the others, stays in the enclosure of its derivative over the cell).  The nodes and weights are
  intervals holding the exact ones (√(3/5), (18 ± √30)/36 …), each derivative is enclosed over the
  cell, and the sum is intersected with ``vol · W`` (W the weight's enclosure over the cell); where
  a derivative is not enclosed (``Abs``' derivative ``sign``) or not finite, ``vol · W`` alone.
  ``n`` is the highest of :data:`POINTS` whose derivatives stay within :data:`DERIVATIVE_OPS`;
* an *uncertain* cell where one condition ``c`` is uncertain (the others hold) and ``c``'s gradient
  is enclosed (one or two variables) contributes ``W · A``: ``A`` the measure of ``{c ≥ 0}`` in the
  cell, enclosed through the mean-value form ``c(x) ∈ c(m) + G·(x − m)`` — ``c`` is within ``e`` of the
  affine ``c₀ + g·(x − m)`` (``g`` the middle of G, ``e`` bounding the rest), so
  ``{c̃ ≥ e} ⊆ {c ≥ 0} ⊆ {c̃ ≥ −e}`` and both measures are computed exactly in interval arithmetic
  (a half-plane cut from a rectangle).  The boundary's band is ``O(h²)`` wide, not ``h``: a curved
  boundary costs ``O(h³)`` per cell instead of ``O(h²)`` (implicit2d: proved ≤ 0.77 → ≤ 10⁻⁴);
* any other uncertain cell contributes ``vol · hull(W, 0)``.

Every contribution is an interval that contains the cell's integral, so their sum contains the
integral: a proof, whatever the weight does between samples.  The widest contribution is halved
(along the cell's side longest relative to the box) until the enclosure is as narrow as asked or
:data:`CELLS` cells have been enclosed — a count, not a time, so the answer is the same on every
machine.  Nothing is assumed about the integrand: a weight, condition or box end outside
:func:`~langur.enclosures.enclose`'s arithmetic (an implicit root, a ``Piecewise``, ``erfc``…) gives
no proof (None), and neither does one whose enclosure stays infinite (a pole, an integrable
singularity: the enclosure never becomes finite).

Used by :mod:`langur.symbolic.integrate`: a quadrature's error is printed as a bound only when
such a proof backs it, and a closed form that disagrees with its quadrature is kept when the
enclosure holds it and excludes the quadrature.
"""

from __future__ import annotations

import dataclasses
import functools
import heapq
import itertools
import math
from dataclasses import dataclass
from typing import Sequence

import mpmath
import sympy as sp

from langur.enclosures import enclose, interval_function
from langur.symbolic.offbox import box_at
from langur.symbolic.walks import free_symbols

#: Cells enclosed to back a quadrature's error estimate, before the enclosure is given as it is
#: (a count, the same on every machine: about a tenth of a CPU second for a one-variable weight).
CELLS = 300

#: Cells enclosed where a quadrature is in doubt (outside its enclosure, or disagreeing with a
#: closed form): a few CPU seconds at most.
CELLS_REFUTED = 3000

#: CPU seconds a proof of ``cells`` cells may take: ``max(1, cells/750)`` (a cell takes about a
#: millisecond — 3,000 cells of ``exp(-1e4*sin(x - 37.3)^2)`` on [0, 100] 2.2 s —, and a proof is
#: never worth much more: past it there is no proof, and the error is printed as an estimate.  mpmath's
#: interval ``exp`` of ``−e^(10⁶)`` took 30 s until :mod:`langur.enclosures` stopped computing it).
def seconds(cells: int) -> float:
    return max(1.0, cells / 750)


#: The relative width below which an enclosure of :data:`CELLS` cells is not narrowed further.
CONFIRMS = 1e-2



@dataclass(frozen=True)
class Enclosed:
    """``lo ≤ ∫ ≤ hi``, proved; ``cells``: how many cells were enclosed."""

    lo: float
    hi: float
    cells: int
    #: the width of the first enclosure, over the whole box at once: the integral's scale
    scale: float = math.inf
    #: the number of variables integrated
    dimensions: int = 1

    def holds(self, value: float, slack: float = 0.0) -> bool:
        """Whether ``value`` is within ``slack`` of the enclosure."""
        return self.lo - slack <= value <= self.hi + slack

    def confirms(self, value: float, slack: float = 0.0) -> bool:
        """Whether ``value`` is within ``slack`` of the enclosure and the enclosure is narrower than
        :data:`CONFIRMS` of its :attr:`scale` (else a narrower one may be worth its cells: ``[0, 8.6]``
        of a scale of 100 holds a quadrature's 0 that missed 31 peaks of
        ``exp(-1e4*sin(x - 37.3)^2)`` on [0, 100])."""
        return self.holds(value, slack) and self.hi - self.lo <= max(slack, CONFIRMS * self.scale)

    def distance(self, value: float) -> float:
        """The largest |value − t| over t in the enclosure: a proved bound on ``value``'s error."""
        return max(value - self.lo, self.hi - value)


def enclose_integral(conditions: Sequence[sp.Expr], weight, variables: Sequence[sp.Symbol], box, at: dict, *,
                     target: float = 0.0, cells: int = CELLS) -> Enclosed | None:
    """An enclosure of ``∫_box Π[c ≥ 0]·weight`` (``c`` in ``conditions``; strict or not makes no
    difference to the integral) at the parameter values ``at`` (symbol → sympy number), narrowed
    until its width is at most ``target`` or ``cells`` cells were enclosed; None when there is no
    proof (module docstring)."""
    variables = tuple(variables)
    try:
        w, conds = sp.sympify(weight), [sp.sympify(c) for c in conditions]
        ends = box_at(dict(zip(variables, box)), at)
        params = tuple(sorted(set().union(*map(free_symbols, [w, *conds])) - set(variables), key=str))
        values = [_constant(sp.sympify(at[p])) if p in at else None for p in params]
    except (sp.SympifyError, TypeError, AttributeError):
        return None
    if not variables or ends is None or not all(_finite(z) for z in values):
        return None  # (a symbol without a value, an end that moves)
    outer = []
    for v, (lo, hi) in ends.items():
        a, b = _constant(lo), _constant(hi)
        if a is None or b is None or not (mpmath.isfinite(a.a) and mpmath.isfinite(b.b)):
            return None
        if a.b != a.a:
            conds.append(v - lo)  # an end known to an interval: the sliver is uncertain
        if b.b != b.a:
            conds.append(hi - v)
        if not a.a < b.b:
            return Enclosed(0.0, 0.0, 0, 0.0, len(variables))
        outer.append((_down(a.a), _up(b.b)))
    f = _compiled(tuple(conds), w, variables, params)
    if f is None:
        return None  # (an implicit root, a Piecewise: never enclosed)
    return _refine(dataclasses.replace(f, values=tuple(values)), outer, target, cells)


_NONE = sp.Dummy("none")


def _constant(e: sp.Expr):
    """An interval holding the number ``e`` (:func:`~langur.enclosures.enclose` over a box of one
    unused variable: it wants one), or None."""
    return enclose(e, {_NONE: (0.0, 0.0)})


#: Gauss–Legendre points per variable at most, by the number of variables (more: the midpoint rule):
#: ``n^d`` weight evaluations per cell.
POINTS = {1: 4, 2: 3, 3: 2}

#: The weight's operation count beyond which no derivative is taken (their enclosures would cost
#: more than the cells they save); the cells then use ``vol · W`` alone.
RULE_OPS = 200

#: A ``2n``-th derivative's operation count (after ``factor_terms``) beyond which ``n`` points are not
#: used (a rule of fewer points is): ``exp(-cosh x)``'s 8th derivative has 149.
DERIVATIVE_OPS = 400

#: Where a cell's rule was not worth its nodes (its remainder wider than ``vol · W``), its halves do not
#: try it until their remainder is predicted narrower, except at every RETRY-th halving (the
#: prediction is from an enclosure wider than theirs): ``exp(-1e4*sin(x - 37.3)^2)`` on [0, 100].
RETRY = 5

_IV = mpmath.iv


def _gauss_legendre(n: int):
    """The ``n``-point Gauss–Legendre rule on [−1, 1]: (node, weight) pairs as intervals holding the
    exact numbers, and the remainder's constant ``c_n`` (module docstring) as an interval."""
    iv = _IV
    if n == 1:
        rule = [(iv.mpf(0), iv.mpf(2))]
    elif n == 2:
        t = 1 / iv.sqrt(3)
        rule = [(-t, iv.mpf(1)), (t, iv.mpf(1))]
    elif n == 3:
        t = iv.sqrt(iv.mpf(3) / 5)
        rule = [(-t, iv.mpf(5) / 9), (iv.mpf(0), iv.mpf(8) / 9), (t, iv.mpf(5) / 9)]
    else:
        r, s = 2 * iv.sqrt(iv.mpf(6) / 5) / 7, iv.sqrt(iv.mpf(30)) / 36
        inner, outer = iv.sqrt(iv.mpf(3) / 7 - r), iv.sqrt(iv.mpf(3) / 7 + r)
        rule = [(-outer, iv.mpf(1) / 2 - s), (-inner, iv.mpf(1) / 2 + s),
                (inner, iv.mpf(1) / 2 + s), (outer, iv.mpf(1) / 2 - s)]
    c = iv.mpf(math.factorial(n) ** 4) / (iv.mpf(2 * n + 1) * iv.mpf(math.factorial(2 * n)) ** 3)
    return rule, c


@dataclass(frozen=True)
class _Integrand:
    """The piece compiled to interval functions of the variables then the parameters
    (:func:`interval_function`), and the parameters' values (intervals)."""

    conds: tuple
    #: per condition, its gradient's functions (None: not enclosed)
    grads: tuple
    w: object
    #: Gauss–Legendre points per variable (0: no rule, ``vol · W`` alone)
    points: int = 0
    #: per variable, ``∂ᵥ^(2n) w``'s function
    derivs: tuple = ()
    values: tuple = ()


@functools.lru_cache(maxsize=64)  # (a proof per point of `render --exact`: one derivation for all)
def _compiled(conds: tuple, w: sp.Expr, variables: tuple, params: tuple) -> _Integrand | None:
    """The piece compiled, its parameters symbols (so the same for every point), or None where the
    weight or a condition is not enclosed at all (an implicit root, a ``Piecewise``)."""
    def fn(e):
        return interval_function(variables[0], e, variables[1:] + params)

    pieces = [fn(c) for c in conds] + [fn(w)]
    if any(p.refused for p in pieces):
        return None
    grads = []
    for c in conds:
        g = [fn(sp.diff(c, v)) for v in variables] if len(variables) <= 2 else []
        grads.append(None if not g or any(z.refused for z in g) else tuple(g))
    points, derivs = 0, ()
    if sp.count_ops(w) <= RULE_OPS:
        # the derivatives of order 2, 4, …: the most points whose derivative stays small (the next
        # one is not taken past a fifth of the limit: each is 3–6 times larger, and costs its size)
        d, found, ops = [w] * len(variables), [], 0
        for _ in range(POINTS.get(len(variables), 1)):
            if 5 * ops > DERIVATIVE_OPS:
                break
            d = [sp.diff(e, v, 2) for e, v in zip(d, variables)]
            ops = max(sp.count_ops(e) for e in d)
            fns = tuple(fn(e) for e in d)
            if ops > DERIVATIVE_OPS or any(z.refused for z in fns):
                break
            found.append(fns)
        if found:
            points, derivs = len(found), found[-1]
    return _Integrand(tuple(pieces[:-1]), tuple(grads), pieces[-1], points, derivs)


def _refine(f: _Integrand, outer, target: float, budget: int) -> Enclosed | None:
    sides = [b - a for a, b in outer]
    rule = _gauss_legendre(f.points) if f.points else None
    heap: list = []
    final: list = []  # contributions of cells that cannot be halved
    count = 0
    total_width = 0.0

    shrink = 2.0 ** (2 * f.points - 1)  # (a halved cell's remainder over its ``vol · W``, roughly)

    def push(cell, hint=0.0, depth=0):
        nonlocal count, total_width
        count += 1
        part, ratio = _cell(f, rule, cell, hint < 1 or depth % RETRY == 0)
        if part is None:
            return False
        width = _up(part.b) - _down(part.a)
        total_width += width
        heapq.heappush(heap, (-width, count, cell, part, hint if ratio is None else ratio, depth))
        return True

    if not push(tuple(outer)):
        return None
    scale = total_width
    while count < budget and heap and not total_width <= target:
        neg, _, cell, part, ratio, depth = heapq.heappop(heap)
        i = max(range(len(cell)), key=lambda k: (cell[k][1] - cell[k][0]) / sides[k])
        a, b = cell[i]
        m = a + (b - a) / 2
        if not a < m < b:  # as narrow as floats go (the sliver of an end 1/3): kept as it is
            final.append(part)
            continue
        total_width += neg
        if not math.isfinite(total_width):  # (recounted: inf − inf)
            total_width = sum(-h[0] for h in heap) + sum(_up(p.b) - _down(p.a) for p in final)
        for half in ((a, m), (m, b)):
            if not push(cell[:i] + (half,) + cell[i + 1:], ratio / shrink, depth + 1):
                return None
    total = sum((h[3] for h in heap), sum(final, _IV.mpf(0)))
    if not (mpmath.isfinite(total.a) and mpmath.isfinite(total.b)):
        return None  # (a pole, an integrable singularity: never finite)
    return Enclosed(_down(total.a), _up(total.b), count, scale, len(outer))


def _down(end) -> float:
    """A double at most the interval end ``end`` (mpmath's ends are doubles at its 53 bits, but
    for exponents beyond a double's: one step down covers the conversion's rounding)."""
    return math.nextafter(float(end), -math.inf)


def _up(end) -> float:
    """A double at least ``end`` (:func:`_down`)."""
    return math.nextafter(float(end), math.inf)


def _finite(z) -> bool:
    return z is not None and bool(mpmath.isfinite(z.a) and mpmath.isfinite(z.b))


def _cell(f: _Integrand, rule, cell, try_rule: bool = True):
    """An interval holding the cell's integral, or None (the weight not enclosed at all); and the
    width of the rule's remainder over that of ``vol · W`` where the rule was tried (``try_rule``)."""
    X = [_IV.mpf([a, b]) for a, b in cell]
    unsure = []
    for k, c in enumerate(f.conds):
        z = c(*X, *f.values)
        if z is not None and z.b < 0:
            return _IV.mpf(0), None
        if z is None or not z.a > 0:
            unsure.append(k)
    W = f.w(*X, *f.values)
    if W is None:
        return None, None
    vol = _IV.mpf(1)
    for a, b in cell:
        vol *= _IV.mpf(b) - _IV.mpf(a)
    if unsure:
        hull = vol * _IV.mpf([min(W.a, 0), max(W.b, 0)])
        if len(unsure) > 1 or f.grads[unsure[0]] is None or not _finite(W):
            return hull, None
        A = _measure(f.conds[unsure[0]], f.grads[unsure[0]], cell, X, f.values)
        return (hull if A is None else _meet(W * A, hull)), None
    whole = vol * W
    if rule is None or not _finite(W) or not try_rule:
        return whole, None
    q, ratio = _gauss(f, rule, cell, X, vol, whole)
    return _meet(q, whole), ratio


def _meet(p, q):
    """Two enclosures of the same number: their intersection (the second where they do not meet,
    which only rounding could cause)."""
    if p is None or not _finite(p):
        return q
    lo, hi = max(p.a, q.a), min(p.b, q.b)
    return _IV.mpf([lo, hi]) if lo <= hi else q


def _gauss(f: _Integrand, rule, cell, X, vol, whole):
    """The product Gauss–Legendre rule over the cell with its remainder (module docstring), or None;
    and the remainder's width over ``whole``'s."""
    nodes, c = rule
    rest = _IV.mpf(0)
    for (a, b), d in zip(cell, f.derivs):
        D = d(*X, *f.values)
        if not _finite(D):
            return None, math.inf
        rest += (_IV.mpf(b) - _IV.mpf(a)) ** (2 * f.points) * D
    rest *= vol * c
    wide, narrow = float(rest.b) - float(rest.a), float(whole.b) - float(whole.a)
    ratio = wide / narrow if narrow > 0 else math.inf
    if not ratio < 1:
        return None, ratio  # (the remainder alone is wider than ``vol · W``: the nodes are not worth evaluating)
    halves = [(_IV.mpf(b) - _IV.mpf(a)) / 2 for a, b in cell]
    per = [[(a + h * (1 + t), wt) for t, wt in nodes] for (a, _), h in zip(cell, halves)]
    q = _IV.mpf(0)
    for combo in itertools.product(*per):
        y = f.w(*(p for p, _ in combo), *f.values)
        if not _finite(y):
            return None, ratio
        for _, wt in combo:
            y *= wt
        q += y
    for h in halves:
        q *= h
    return q + rest, ratio


def _measure(c, grad, cell, X, values):
    """An interval holding the measure of ``{c ≥ 0}`` in the cell (one or two variables), from the
    mean-value form of ``c`` about the cell's middle ``m`` (module docstring), or None."""
    m = [a + (b - a) / 2 for a, b in cell]
    C = c(*(_IV.mpf(v) for v in m), *values)
    G = [g(*X, *values) for g in grad]
    if not (_finite(C) and all(_finite(z) for z in G)):
        return None
    c0, g = _mid(C), [_mid(z) for z in G]
    u = [(_IV.mpf(a) - v, _IV.mpf(b) - v) for (a, b), v in zip(cell, m)]  # x − m, exactly: intervals
    e = abs(C - c0)
    for z, gi, (lo, hi) in zip(G, g, u):
        e += abs(z - gi) * _IV.mpf([0, max(-lo.a, hi.b)])
    e = _IV.mpf(e.b)
    inner, outer = _half_space(c0, g, u, e), _half_space(c0, g, u, -e)
    if inner is None or outer is None:
        return None
    return _IV.mpf([max(inner.a, 0), outer.b])


def _mid(z) -> float:
    return float(z.a) / 2 + float(z.b) / 2  # (any number near the middle: e covers the rest)


def _clamp(z, top):
    """``min(max(z, 0), top)`` of an interval ``z``, ``top`` an interval (monotone in both: the ends)."""
    def one(v):
        return _IV.mpf([max(0, min(v, top.a)), max(0, min(v, top.b))])
    lo, hi = one(z.a), one(z.b)
    return _IV.mpf([lo.a, hi.b])


def _ramp(s, top):
    """``Φ(s) = ∫_0^s clamp(r, 0, T) dr`` of an interval ``s``, ``T`` in the interval ``top``
    (non-decreasing in both: the ends)."""
    def one(v, t):
        v, t = _IV.mpf(v), _IV.mpf(t)
        if v.b <= 0:
            return _IV.mpf(0)
        if v.b <= t.a:
            return v * v / 2
        return t * t / 2 + t * (v - t)
    return _IV.mpf([one(s.a, top.a).a, one(s.b, top.b).b])


def _half_space(c0: float, g, u, t):
    """An interval holding the measure of ``{v ∈ Π[uᵢ] : c0 + g·v ≥ t}`` (one or two variables), or
    None (``g`` = 0)."""
    k = max(range(len(g)), key=lambda i: abs(g[i]))
    if g[k] == 0:
        return None
    (lk, rk), gk = u[k], _IV.mpf(g[k])
    s = (t - c0) / gk  # the cut along k: v_k ≥ s (g_k > 0) or v_k ≤ s
    alpha = rk - s if g[k] > 0 else s - lk
    top = rk - lk
    if len(g) == 1:
        return _clamp(alpha, top)
    j = 1 - k
    (lj, rj), beta = u[j], _IV.mpf(g[j]) / gk * (1 if g[k] > 0 else -1)  # v_k's length: alpha + beta·v_j
    ends = (alpha + beta * lj, alpha + beta * rj)
    mean = (rj - lj) * _clamp(_IV.mpf([min(ends[0].a, ends[1].a), max(ends[0].b, ends[1].b)]), top)
    if beta.a > 0 or beta.b < 0:  # ∫ clamp(α + β v) dv = (Φ(α + β rj) − Φ(α + β lj)) / β
        exact = (_ramp(ends[1], top) - _ramp(ends[0], top)) / beta
        return _meet(exact, mean)
    return mean
