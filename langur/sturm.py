"""Real roots of an exact polynomial isolated exactly by its Sturm sequence (issue 15/18).

``sturm_brackets(p, lo, hi)``: ``p`` a polynomial with rational coefficients (``Fraction``,
highest first); the brackets, with rational ends, each holding exactly one sign change of ``p``
on ``[lo, hi]``.  The Sturm sequence of the square-free part of ``p`` counts its distinct real
roots between any two rationals exactly (the difference of its sign variations there); an
interval holding more than one is halved until each holds one, and a root is a sign change when
``p``'s signs on its two sides differ.  Every sign is computed in integers (:func:`_sign`), so
nothing is rounded and no interval enclosure is involved: the brackets are certified however
close two roots are.

Used by :mod:`langur.implicit` for an indexed root whose equation is a polynomial in the root's
variable (``_exact_brackets``, ``_brackets_at``): there it replaces the interval certification of
:func:`langur.enclosures.certified_brackets`, which decides where this returns None.
"""

from __future__ import annotations

import math


def _strip(p: list) -> list:
    i = 0
    while i < len(p) - 1 and p[i] == 0:
        i += 1
    return p[i:]


def _horner(p: list, x):
    v = 0
    for c in p:
        v = v * x + c
    return v


def _rem(p: list, q: list) -> list:
    """The remainder of ``p`` divided by ``q`` (highest first, ``q[0] != 0``)."""
    p = list(p)
    while len(p) >= len(q) and any(p):
        c = p[0] / q[0]
        for i in range(len(q)):
            p[i] -= c * q[i]
        p.pop(0)
    return _strip(p) if p else [0]


def _gcd(p: list, q: list) -> list:
    while any(q):
        p, q = q, _rem(p, q)
    return [c / p[0] for c in p]


def _quotient(p: list, q: list) -> list:
    p, out = list(p), []
    while len(p) >= len(q):
        c = p[0] / q[0]
        out.append(c)
        for i in range(len(q)):
            p[i] -= c * q[i]
        p.pop(0)
    return out


def _integral(p: list) -> list[int]:
    """The rational coefficients ``p`` times the (positive) least common multiple of their
    denominators: integers, a polynomial with the same sign as ``p`` everywhere."""
    den = 1
    for c in p:
        den = den * c.denominator // math.gcd(den, c.denominator)
    return [c.numerator * (den // c.denominator) for c in p]


def _sign(q: list[int], x) -> int:
    """The sign (−1, 0, 1) of the polynomial ``q`` (integer coefficients, highest first) at the
    rational ``x = n/d`` (d > 0), exactly: that of q(x)·dᵈᵉᵍ = Σ qᵢ·n^(deg−i)·dⁱ, in integers (no
    fraction reduced at each step, as :func:`_horner` on fractions does: several times faster;
    issue 15, exact13t)."""
    n, d = x.numerator, x.denominator
    v, dp = 0, 1
    for c in q:
        v = v * n + c * dp
        dp *= d
    return (v > 0) - (v < 0)


def sturm_brackets(p: list, lo, hi, depth: int = 200, squarefree: bool = False) -> list | None:
    """The brackets, increasing, each holding one sign change of the polynomial ``p`` (exact
    rational coefficients, highest first) on ``[lo, hi]``, all of them; None when ``p`` is
    identically zero or vanishes at ``lo`` or ``hi`` (there :func:`langur.enclosures.certified_brackets`'s convention
    decides), when isolating its roots takes more than ``depth`` halvings, or (``squarefree``)
    when it has a multiple root (a degenerate turning point, anywhere)."""
    p = _strip(p)
    if not any(p):
        return None
    ip = _integral(p)  # (the signs of p, in integers: see _sign)
    if _sign(ip, lo) == 0 or _sign(ip, hi) == 0:
        return None
    if len(p) == 1:
        return []
    dp = [c * (len(p) - 1 - i) for i, c in enumerate(p[:-1])]
    g = _gcd(p, dp)
    if squarefree and len(g) > 1:
        return None
    p0 = _quotient(p, g) if len(g) > 1 else p
    chain = [p0, [c * (len(p0) - 1 - i) for i, c in enumerate(p0[:-1])] or [0]]
    while len(chain[-1]) > 1 or chain[-1][0] != 0:
        r = _rem(chain[-2], chain[-1])
        if not any(r):
            break
        chain.append([-c for c in r])
        if len(chain[-1]) == 1:
            break

    ichain = [_integral(q) for q in chain]
    ip0 = ichain[0]
    known: dict = {}

    def variations(x) -> int:
        out = known.get(x)
        if out is None:
            signs = [v for v in (_sign(q, x) for q in ichain) if v != 0]
            out = known[x] = sum((u < 0) != (w < 0) for u, w in zip(signs, signs[1:]))
        return out

    def split(a, b):
        for k in range(1, 8):  # the midpoint, or a dyadic point next to it that is not a root
            for m in (a + (b - a) / 2 + (b - a) / 2 ** (k + 1) * (k > 1), a + (b - a) / 2 - (b - a) / 2 ** (k + 1)):
                if _sign(ip0, m) != 0:
                    return m
        return None

    points = [lo, hi]
    stack = [(lo, hi, variations(lo) - variations(hi), 0)]
    while stack:
        a, b, n, d = stack.pop()
        if n <= 1:
            continue
        if d >= depth:
            return None
        m = split(a, b)
        if m is None:
            return None
        points.append(m)
        vm = variations(m)
        stack.append((a, m, variations(a) - vm, d + 1))
        stack.append((m, b, vm - variations(b), d + 1))
    points = sorted(set(points))
    signs = [-1 if _sign(ip, x) < 0 else 1 for x in points]  # never 0: the ends and split points are no roots
    return [(x, y) for x, y, s, r in zip(points, points[1:], signs, signs[1:]) if s != r]
