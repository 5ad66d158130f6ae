"""Roots of a condition in one variable: the breakpoints where the quadrature splits its range
(paper §8.2: ⟦p⟧'s integrand is smooth between the points where a condition changes sign).

Polynomials by their coefficients (compiled once, roots in closed form or by ``numpy.roots``);
anything else by a sign-change grid refined by ``brentq``, plus the pairs of roots closer than the
grid's step (:func:`_hidden_pairs`, issue 18).
"""

from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np
import sympy as sp
from scipy import optimize as so

from langur.memo import remember
from langur.symbolic import walks
from langur.symbolic.quadrature.compiling import COMPILED, printable
from langur.symbolic.text import shared_lambdify
from langur.symbolic.walks import free_symbols

GRID = 40


def _state(v: float) -> int:
    if math.isnan(v):
        return 0
    return 1 if v >= 0 else -1


#: Most cells :func:`_roots` searches besides its grid's (each one a piece its bisection set aside
#: with different states at its ends: a second transition there).
MORE_CELLS = 4 * GRID


def _roots(g: Callable[[float], float], lo: float, hi: float) -> list[float]:
    """Points in (lo, hi) where ``g`` changes sign or definedness (grid + brentq/bisection, and
    :func:`_hidden_pairs` where a pair of roots closer than the grid's step hides between nodes).
    A bisection keeps one half; a half it sets aside whose ends differ in state (defined or not,
    sign) holds another transition and is searched too: ``3/20 − √(0.96 − u²)`` has its edge of
    definedness (u = −0.9798) and its root (u = −0.9682) between two nodes, and the bisection, drawn
    to the edge, lost the root — a whole arc of a circle's delta piece (bench/history/2026-11-29.md#wide32."""
    xs = np.linspace(lo, hi, GRID + 1).tolist()  # Python floats: math functions, no numpy warnings
    vals = [g(x) for x in xs]
    out = _hidden_pairs(g, xs, vals)
    edges: list[tuple[float, float, int]] = []  # (last defined point, its value, side of the defined part)
    cells = [(xs[i], xs[i + 1], vals[i], vals[i + 1], i) for i in range(GRID - 1, -1, -1)]
    more = MORE_CELLS
    while cells:  # (the grid's cells in order, each followed by those its bisection set aside)
        a, b, fa, fb, i = cells.pop()
        if fa == 0.0 and i > 0:
            out.append(a)
        sa, sb = _state(fa), _state(fb)
        if sa == sb:
            continue
        if sa != 0 and sb != 0 and fa != 0.0 and fb != 0.0:
            try:
                out.append(so.brentq(g, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps))
                continue
            except (ValueError, RuntimeError):
                pass
        for _ in range(80):  # bisection on the state (definedness / sign)
            m = 0.5 * (a + b)
            if (m == a or m == b) and m != 0.0:
                # a and b are neighbouring doubles: every step left would evaluate ``g`` at this same m
                # (a non-zero double equal to a or b is that double) and keep a and b as they are — a's
                # state is sa, b's is not (each was given its end by its state, or is a node of the grid
                # with its state) — so the answer below is the same; issue 15: ~620 of turning2d's 4,500
                # grid evaluations, each an implicit root's condition.  (At 0, ±0 could differ.)
                break
            gm = g(m)
            if _state(gm) == sa:
                a, fa = m, gm
            else:
                if _state(gm) != _state(fb) and more > 0:  # [m, b] set aside holds a transition too
                    more -= 1
                    cells.append((m, b, gm, fb, 0))
                b, fb = m, gm
        out.append(0.5 * (a + b))
        if sa == 0 or _state(fb) == 0:  # an edge of definedness: a pair of roots beside it is not seen above
            edges.append((b, fb, 1) if sa == 0 else (a, fa, -1))
    for end, value, side in edges:
        out += _pairs_beside(g, xs, vals, end, value, side, out)
    return out


def _pairs_beside(g: Callable[[float], float], xs: list, vals: list, end: float, value: float, side: int,
                  known: list[float]) -> list[float]:
    """The pairs of roots of ``g`` next to an edge of definedness that neither the grid's bisection
    nor :func:`_hidden_pairs` sees: ``end`` is the last defined point the bisection reached
    (``value`` = g there), the defined side lies towards ``side`` (+1: to the right).  The grid's
    node next to a NaN is skipped by :func:`_hidden_pairs` (its neighbour has no sign), and a turn
    of ``g`` between the edge and that node or the next one hides a pair: ``0.0001·√(x − 0.26) +
    (x − 0.285)² − 3·10⁻⁵`` on [0, 1] (grid step 0.025) is negative on (0.28106, 0.28862), and the
    grid search saw only the edge 0.26 (bench/history/2026-11-29.md#diverge33.  Here the edge's point
    stands in for the NaN neighbour: :func:`_hidden_pairs` on ``end`` and the next two defined
    nodes, the farther one not searched (the grid's own search covers it, with both its
    neighbours); a root already ``known`` (within 10⁻¹² relative) is not repeated."""
    nodes = [k for k in (range(len(xs)) if side > 0 else range(len(xs) - 1, -1, -1)) if side * (xs[k] - end) > 0][:2]
    pts, vs = [end], [value]
    for k in nodes:
        if not math.isfinite(vals[k]):
            break
        pts.append(xs[k])
        vs.append(vals[k])
    if side < 0:
        pts, vs = pts[::-1], vs[::-1]
    near = range(len(pts)) if len(pts) < 3 else range(2) if side > 0 else range(1, 3)
    found = _hidden_pairs(g, pts, vs, searched=near) if len(pts) > 1 else []
    return [r for r in found if not any(abs(r - q) <= 1e-12 * max(1.0, abs(r)) for q in known)]


def _hidden_pairs(g: Callable[[float], float], xs: list, vals: list, flat: bool = True,
                  searched: range | None = None) -> list[float]:
    """The roots of ``g`` a sign-change search on the grid ``xs`` cannot see: two roots between
    neighbouring nodes where ``g`` turns (``[x ≥ sin(z) + a]`` in z near z = π/2, x just below
    a + 1: the set in z has a gap narrower than the step, and ∫∫ lost ~10⁻⁵ with an error bound of
    10⁻⁹).  Wherever the nodes' values have a local maximum below 0 or a local minimum above 0
    (each extremum of ``g`` between nodes shows as one, at a node next to it), the extremum is
    found by bounded Brent's method between the neighbouring nodes, and if ``g`` changes sign
    there, the two roots on its sides by brentq.  Nothing is added where the grid sees the turn.
    ``flat=False``: a node equal to all its neighbours is not searched (a value constant along the
    grid — the fold grid's many series that do not depend on the outer variable — would cost one
    Brent search per node).  ``searched``: the nodes searched (default all)."""
    out: list[float] = []
    n = len(xs)
    for j in range(n) if searched is None else searched:
        v = vals[j]
        if not (math.isfinite(v) and v != 0.0):
            continue
        left = vals[j - 1] if j > 0 else None
        right = vals[j + 1] if j + 1 < n else None
        if any(w is not None and not (math.isfinite(w) and (w > 0) == (v > 0)) for w in (left, right)):
            continue  # a sign change or a NaN next to it: the grid search handles it
        sign = 1.0 if v > 0 else -1.0  # a minimum of sign·g above 0 may dip below it
        if not flat and all(w is None or w == v for w in (left, right)):
            continue
        if (left is None or sign * left >= sign * v) and (right is None or sign * right >= sign * v):
            a, b = xs[max(j - 1, 0)], xs[min(j + 1, n - 1)]
            try:
                # (float(t): scipy passes numpy scalars, on which a compiled ``math`` function's powers of
                # negatives are numpy's NaN with a RuntimeWarning, not Python's complex number)
                opt = so.minimize_scalar(lambda t, sign=sign: sign * g(float(t)), bounds=(a, b), method="bounded",
                                         options={"xatol": 1e-13 * max(1.0, abs(a), abs(b))})
            except (ValueError, ArithmeticError):
                continue
            t, w = float(opt.x), g(float(opt.x))
            if not (math.isfinite(w) and sign * w < 0 and a < t < b):
                continue
            for u, z in ((a, t), (t, b)):
                try:
                    out.append(so.brentq(g, u, z, xtol=1e-15, rtol=4 * np.finfo(float).eps))
                except (ValueError, RuntimeError):
                    pass
    return out


_COEFFICIENTS: dict = {}


def _coefficients(expr, syms: tuple, level: int, params: tuple = ()):
    """The coefficients of ``expr`` as a polynomial in ``syms[level]`` (of degree ≤ 8), highest
    first, compiled as one function of ``syms[:level]`` and then ``params`` returning them all
    (``math``; ``numpy`` for what ``math`` lacks), cached like :data:`_COMPILED`; or None."""
    key = (expr, syms[: level + 1], params)
    if key in _COEFFICIENTS:
        return _COEFFICIENTS[key]
    v = syms[level]
    fn = None
    try:
        coeffs = _expanded_coefficients(expr, v)
        if coeffs is None:
            poly = sp.Poly(expr, v)
            coeffs = poly.all_coeffs() if poly.degree() <= 8 else None
        if coeffs is not None and not any(v in free_symbols(c) for c in coeffs):
            args, body = list(syms[:level]) + list(params), [printable(c) for c in coeffs]
            fn = shared_lambdify(args, body, "math")  # (sympy's lambdify of the list, shared subtrees printed once)
            try:
                fn(*[0.5] * len(args))  # probe: NameError for functions math lacks
            except NameError:
                fn = shared_lambdify(args, body, "numpy")
            except Exception:  # noqa: BLE001 - a domain error at the probe point is fine
                pass
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        pass
    remember(_COEFFICIENTS, key, fn, COMPILED)
    return fn


def _expanded_coefficients(expr, v) -> list | None:
    """``sympy.Poly(expr, v).all_coeffs()`` for a polynomial in all its symbols with rational
    coefficients, of degree 1 to 8 in ``v`` (the conditions of affine and polynomial regions), from
    sympy's ``expand`` of ``expr`` with its terms grouped by their power of ``v``: the coefficients
    are then polynomials with rational coefficients, which sympy writes in one canonical expanded
    form whichever way they are built, so they are the same expressions (and compile to the same
    code) without ``Poly``'s construction of a polynomial ring over the other symbols (two thirds
    of the time of a condition's first compilation).  None for anything else (``Poly`` then)."""
    if not walks.rational_form(expr) or walks.degree(expr, frozenset(free_symbols(expr))) is None:
        return None
    by_power: dict = {}
    for term in sp.Add.make_args(sp.expand(expr)):
        k, rest = _split_power(term, v)
        if k is None:
            return None
        by_power.setdefault(k, []).append(sp.Mul(*rest))
    top = max(by_power, default=0)
    if not 1 <= top <= 8:
        return None
    return [sp.Add(*by_power[k]) if k in by_power else sp.Integer(0) for k in range(top, -1, -1)]


def _split_power(term, v) -> tuple[int | None, list]:
    """A term of an expanded polynomial (a number times powers of symbols) as ``(k, rest)``:
    ``term = v**k · Π rest`` with ``v`` not in ``rest``; ``(None, [])`` when ``v`` appears otherwise.
    The factors of sympy's ``Mul`` directly: ``term.as_coeff_exponent(v)`` gives the same ``k`` and
    coefficient (``Mul(*rest)``: the same factors, in sympy's canonical order) but first runs
    ``collect`` on the term, which was a third of :func:`_expanded_coefficients`."""
    k, rest = 0, []
    for f in sp.Mul.make_args(term):
        if f == v:
            k += 1
        elif f.is_Pow and f.base == v and f.exp.is_Integer and f.exp > 0:
            k += int(f.exp)
        elif v in free_symbols(f):
            return None, []
        else:
            rest.append(f)
    return k, rest


#: A complex root counts as real (a double root perturbed by rounding) when its imaginary part is
#: at most this times 1 + its modulus.
REAL_SLACK = 1e-9


def polynomial_roots(cs: Sequence[float]) -> list[float]:
    """The real roots of ``cs[0]·tᵈ + … + cs[d]`` (highest first, leading exact zeros ignored):
    linear and quadratic in closed form (the quadratic formula in its cancellation-free form),
    higher degrees by ``numpy.roots``; a complex pair whose imaginary part is below
    :data:`REAL_SLACK` counts as a double real root.  Empty for a constant or non-finite
    coefficients."""
    if not all(math.isfinite(c) for c in cs):
        return []
    k = 0
    while k < len(cs) and cs[k] == 0.0:
        k += 1
    cs = cs[k:]
    if len(cs) <= 1:
        return []
    if len(cs) == 2:
        return [-cs[1] / cs[0]]
    if len(cs) == 3:
        a, b, c = cs
        disc = b * b - 4.0 * a * c
        if disc < 0.0:
            re, im = -b / (2.0 * a), math.sqrt(-disc) / (2.0 * abs(a))
            return [re, re] if im <= REAL_SLACK * (1.0 + math.hypot(re, im)) else []
        q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
        return [q / a, c / q] if q != 0.0 else [0.0, 0.0]
    out = _companion_roots(cs) if cs[-1] != 0.0 else np.roots(np.array(cs, dtype=float))
    return [float(r.real) for r in out if abs(r.imag) <= REAL_SLACK * (1 + abs(r))]


def _companion_roots(cs: Sequence[float]):
    """``numpy.roots(cs)`` for finite coefficients, the first and the last not 0 (degree ≥ 3): the same
    array — numpy's own steps for them (its companion matrix, ones below the diagonal and
    ``-p[1:] / p[0]`` in the first row, and its eigenvalues by ``numpy.linalg.eigvals``), without its
    checks and trimming of zeros (about a quarter of its time; turning2d ∂a solves ~1,000 cubics)."""
    p = np.array(cs, dtype=float)
    a = np.diag(np.ones((len(p) - 2,), p.dtype), -1)
    a[0, :] = -p[1:] / p[0]
    return np.linalg.eigvals(a)


def _poly_roots(expr, syms: Sequence[sp.Symbol], level: int, at: dict | None = None):
    """``prefix ↦ real roots in syms[level]`` when ``expr`` is a polynomial in it, else None;
    ``at``: the values of the parameters ``expr`` may contain (passed after the prefix)."""
    free = free_symbols(expr) if at else set()  # (once, not once per parameter)
    params = tuple(k for k in at if k in free) if at else ()
    fn = _coefficients(expr, tuple(syms), level, params)
    if fn is None:
        return None
    extra = tuple(float(at[k]) for k in params)

    def roots(*prefix):
        try:
            raw = fn(*prefix, *extra)
            if all(type(c) is float or type(c) is int for c in raw):  # math's: no conversion needed
                return polynomial_roots(raw)  # (it returns [] for non-finite coefficients)
            cs = [complex(c) for c in raw]
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            return []  # a coefficient undefined here (math raises where numpy gave NaN)
        if not all(math.isfinite(c.real) and math.isfinite(c.imag) for c in cs):
            return []
        return polynomial_roots([c.real for c in cs])

    return roots

