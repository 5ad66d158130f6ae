"""Where the mass of an integrand over a wide range may hide (paper §8.2's ⟦p⟧ at a point over a
box as large as ``[-1e10, 1e10]``; branch exact31).

Gauss–Kronrod samples an interval at 21 abscissae and stops when the two rules agree: over
[−10¹⁰, 0.5] every abscissa of ``exp(-x*x)`` is 0 (the nearest is 4·10⁷ away from the peak), so
``quad`` answers 0 with the error estimate 0, and the exact engine printed ``0 (quadrature, error ≤
1e-10)`` against the right closed form √π(erf(½) + 1)/2 = 1.3475.  No sampling rule can find a
peak it never samples; what is done here is to put breakpoints where the mass can be:

* :func:`centres` — the points of a level's variable v where the weight's polynomial parts (the
  arguments of its functions, the bases of its powers, and their terms; polynomials in v alone once
  the parameters' values are in) vanish or turn: the real roots of each such polynomial P and of
  P′, and the real parts of P's complex roots (``1/(1 + x²)``'s poles ±i: its mass sits at 0), and
  0 (every program's natural origin);
* :func:`cuts` — on a range wider than :data:`WIDE`, breakpoints at c ± 10ᵏ around each centre c,
  k from the range's decade down :data:`DECADES` decades: each piece is then at most ten times
  farther from c than it is wide, so a peak of width ≳ 10⁻¹² of the range at a centre lies in
  pieces that ``quad`` resolves, and a slowly decaying tail (``1/(1 + x²)`` to 10¹²) is integrated
  decade by decade (QUADPACK over the whole range called it "probably divergent").

Breakpoints only refine the partition (the conditions are tested on each piece, as at any
breakpoint): a value that was right stays right; nothing is assumed about the integrand.
Ranges narrower than :data:`WIDE` — every example's — are partitioned as before.
"""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import sympy as sp

from langur.symbolic.walks import free_symbols

#: A range wider than this gets :func:`cuts` (the examples' boxes are at most a few units wide).
WIDE = 1e4


#: Decades below the range's own, around each centre, that get a breakpoint on each side
#: (10⁻¹² of the range: half the digits of a double).
DECADES = 12


#: Degree up to which a polynomial part's roots are found (numpy's companion matrix).
DEGREE = 8


#: The note of an exact-engine result whose value comes from a quadrature over a range wider than
#: :data:`WIDE` (:func:`langur.symbolic.integrate._finish`): its error is printed as an estimate
#: (:meth:`langur.exact.ExactValue.how`), not as a bound.
ESTIMATE = ("quadrature over a range wider than 1e4: breakpoints were placed where the integrand's mass can "
            "concentrate (0, the roots of its polynomial parts), but sampling cannot exclude a narrow peak "
            "elsewhere: the error is quadrature's estimate, not a bound")


#: Centres closer than this (relative) are one: numpy's roots of ``(x − 10⁶)²`` are 10⁶ ± 5·10⁻¹⁰.
SAME = 1e-9


#: Centres kept per level (the nearest to 0 first: the most common place for mass).
MOST = 6


def centres(weight, v: sp.Symbol) -> list[float]:
    """The points of ``v`` where the mass of ``weight`` (parameters' values substituted) may
    concentrate (module doc), 0 first."""
    found: set[float] = set()
    for part in _polynomial_parts(sp.sympify(weight), v):
        try:
            coeffs = [complex(c) for c in sp.Poly(part, v).all_coeffs()]
        except (sp.PolynomialError, TypeError, ValueError):
            continue
        if not 1 <= len(coeffs) - 1 <= DEGREE or not all(map(_finite, coeffs)):
            continue
        deriv = np.polyder(np.array(coeffs))
        for poly in (np.array(coeffs), deriv):
            if len(poly) < 2:
                continue
            found.update(float(r.real) for r in np.roots(poly) if math.isfinite(r.real))
    out = [0.0]
    for c in sorted(found, key=abs):  # (a multiple root comes back as a cluster within rounding)
        if len(out) < MOST and all(abs(c - k) > SAME * max(1.0, abs(k)) for k in out):
            out.append(c)
    return out


def _finite(z: complex) -> bool:
    return math.isfinite(z.real) and math.isfinite(z.imag)


def _polynomial_parts(e: sp.Basic, v: sp.Symbol):
    """The sub-expressions of ``e`` that are polynomials of degree ≥ 1 in ``v`` alone: the
    arguments of its functions, the bases of its powers, and the terms of those that are sums."""
    seen = set()
    for node in sp.preorder_traversal(e):
        if isinstance(node, sp.Pow):
            candidates = [node.base]
        elif isinstance(node, sp.Function):
            candidates = list(node.args)
        else:
            continue
        for c in candidates:
            for part in (c, *(c.args if isinstance(c, sp.Add) else ())):
                if part in seen or free_symbols(part) != {v} or not part.is_polynomial(v):
                    continue
                seen.add(part)
                yield part


def cuts(lo: float, hi: float, at: Sequence[float]) -> list[float]:
    """Breakpoints strictly inside [lo, hi] at c ± 10ᵏ around each centre c (clamped to the range),
    and c itself, when the range is wider than :data:`WIDE`; none otherwise."""
    span = hi - lo
    if not span > WIDE or not math.isfinite(span):
        return []
    top = math.ceil(math.log10(span))
    out = set()
    for c in at:
        c = min(max(c, lo), hi)
        out.add(c)
        for k in range(top - DECADES, top + 1):
            step = 10.0 ** k
            out.update((c - step, c + step))
    return sorted(t for t in out if lo < t < hi)
