"""Quadrature rules with rational points and weights, exact for polynomials of a given degree (paper
§6.3, Def. 6.2: the closed forms decided at the evaluation point, :mod:`langur.symbolic.local`;
issue 15).

* :func:`newton_cotes`: ∫ₐᵇ of a polynomial of degree d by the closed Newton–Cotes rule with d + 1
  points (exact for degree ≤ d, rational weights).
* :func:`triangle_rule`: a rule on the reference triangle exact for degree d (Grundmann–Möller's,
  :func:`grundmann_moeller`, or the lattice rule, :func:`lattice_rule`, whichever has fewer
  points), for the fan of triangles of :func:`langur.symbolic.local.polygon_integral`.

The closed form is exact and the weight is never expanded: it is substituted at each point.
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

import sympy as sp

from langur.symbolic.walks import rational_form, shared_xreplace

#: Highest degree of a polynomial weight integrated by a lattice or Newton–Cotes rule.
MAX_DEGREE = 8


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
