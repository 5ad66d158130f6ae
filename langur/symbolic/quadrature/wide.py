"""Where the mass of an integrand over a wide range may hide (paper §8.2's ⟦p⟧ at a point over a
box as large as ``[-1e10, 1e10]``, or a peak as narrow as ``exp(-1e8*(x - 0.3)^2)`` on [0, 1000];
branch exact31).

Gauss–Kronrod samples an interval at 21 abscissae and stops when the two rules agree: over
[−10¹⁰, 0.5] every abscissa of ``exp(-x*x)`` is 0 (the nearest is 4·10⁷ away from the peak), so
``quad`` answers 0 with the error estimate 0, and the exact engine printed ``0 (quadrature, error ≤
1e-10)`` against the right closed form √π(erf(½) + 1)/2 = 1.3475.  No sampling rule can find a
peak it never samples; what is done here is to put breakpoints where the mass can be:

* :func:`centres` — the points of a level's variable v where the weight's polynomial parts P (the
  arguments of its functions, the bases of its powers, and their terms; polynomials in v alone once
  the parameters' values are in) vanish or turn: the real roots of P and of P′, and the real parts
  of P's complex roots (``1/(1 + x²)``'s poles ±i: its mass sits at 0), each with P's *scale*
  |leading coefficient|^(−1/degree) (the distance over which P's leading term changes by 1: the
  width of ``exp(-1e8*(x - 0.3)^2)``'s peak is 10⁻⁴); and 0 with scale 1 (every program's
  natural origin and unit);
* :func:`spread` — on a range wider than :data:`WIDE` times a centre's scale w, breakpoints at
  c ± w·10ᵏ, k from −:data:`BELOW` up to the range's decade: each piece is then at most ten times
  farther from c than it is wide, so the peak lies in pieces of its own size, which ``quad``
  resolves, and a slowly decaying tail (``1/(1 + x²)`` to 10¹²) is integrated decade by decade
  (QUADPACK over the whole range called it "probably divergent").

Breakpoints only refine the partition (the conditions are tested on each piece, as at any
breakpoint): a value that was right stays right; nothing is assumed about the integrand.  Ranges
narrower than :data:`WIDE` scales — every example's — are partitioned as before.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import sympy as sp

from langur.symbolic.walks import free_symbols

#: A range wider than this many of a centre's scales gets :func:`spread` around it (the examples'
#: ranges are at most a few of their weights' scales).
WIDE = 1e4


#: Decades below a centre's scale where its breakpoints start (a peak a few scales wide: a
#: Gaussian's mass is within 6 of them).
BELOW = 2


#: The note of an exact-engine result whose value comes from a quadrature that placed such
#: breakpoints (:func:`langur.symbolic.integrate._finish`): its error is printed as an estimate
#: (:meth:`langur.exact.ExactValue.how`), not as a bound.
ESTIMATE = ("quadrature over a range wider than 1e4 times the integrand's scale: breakpoints were placed where "
            "its mass can concentrate (0, the roots of its polynomial parts), but sampling cannot exclude a "
            "narrow peak elsewhere: the error is quadrature's estimate, not a bound")


#: Degree up to which a polynomial part's roots are found (numpy's companion matrix).
DEGREE = 8


#: Centres closer than this (relative) are one: numpy's roots of ``(x − 10⁶)²`` are 10⁶ ± 5·10⁻¹⁰.
SAME = 1e-9


#: Centres kept per level (the nearest to 0 first: the most common place for mass).
MOST = 6


#: The natural origin: 0 with scale 1.
ORIGIN = ((0.0, 1.0),)


def centres(weight, v: sp.Symbol) -> list[tuple[float, float]]:
    """``(centre, scale)`` pairs of ``v`` where the mass of ``weight`` (parameters' values
    substituted) may concentrate (module doc), :data:`ORIGIN` first."""
    found: dict[float, float] = {}
    for part in _polynomial_parts(sp.sympify(weight), v):
        try:
            coeffs = [complex(c) for c in sp.Poly(part, v).all_coeffs()]
        except (sp.PolynomialError, TypeError, ValueError):
            continue
        degree = len(coeffs) - 1
        if not 1 <= degree <= DEGREE or not all(map(_finite, coeffs)) or coeffs[0] == 0:
            continue
        scale = abs(coeffs[0]) ** (-1.0 / degree)
        if not 0.0 < scale < math.inf:
            continue
        poly = np.array(coeffs)
        for q in (poly, np.polyder(poly)):
            for r in (np.roots(q) if len(q) >= 2 else ()):
                c = float(r.real)
                if math.isfinite(c):
                    found[c] = min(scale, found.get(c, math.inf))
    out = list(ORIGIN)
    for c in sorted(found, key=abs):  # (a multiple root comes back as a cluster within rounding)
        near = [i for i, (k, _) in enumerate(out) if abs(c - k) <= SAME * max(1.0, abs(k))]
        if near:
            i = near[0]
            out[i] = (out[i][0], min(out[i][1], found[c]))
        elif len(out) < MOST:
            out.append((c, found[c]))
    return out


def _finite(z: complex) -> bool:
    return math.isfinite(z.real) and math.isfinite(z.imag)


def _polynomial_parts(e: sp.Basic, v: sp.Symbol):
    """The sub-expressions of ``e`` that are polynomials of degree ≥ 1 in ``v`` alone: the
    arguments of its functions, the bases of its powers, and the terms of those that are sums
    (each distinct subtree visited once)."""
    seen: set = set()
    stack = [e]
    while stack:
        node = stack.pop()
        if node in seen or not node.args:
            continue
        seen.add(node)
        stack.extend(node.args)
        if isinstance(node, sp.Pow):
            candidates = [node.base]
        elif isinstance(node, sp.Function):
            candidates = list(node.args)
        else:
            continue
        for c in candidates:
            for part in (c, *(c.args if isinstance(c, sp.Add) else ())):
                if free_symbols(part) == {v} and part.is_polynomial(v):
                    yield part


def spread(lo: float, hi: float, at: Sequence[tuple[float, float]] = ORIGIN) -> list[float]:
    """Breakpoints strictly inside [lo, hi] around each ``(centre, scale)`` of ``at`` (the centre
    clamped to the range) whose scale the range exceeds :data:`WIDE` times: c and c ± w·10ᵏ; none
    around the others."""
    span = hi - lo
    if not math.isfinite(span):
        return []
    out = set()
    for c, w in at:
        if not span > WIDE * w:
            continue
        c = min(max(c, lo), hi)
        out.add(c)
        for k in range(-BELOW, math.ceil(math.log10(span / w)) + 1):
            step = w * 10.0 ** k
            out.update((c - step, c + step))
    return sorted(t for t in out if lo < t < hi)
