"""Certifying that a condition is strictly monotone in one variable on the box (issue 18).

A condition ``f(x⃗; θ)`` in several variables is completed by a variable ``v`` with no closed-form
inverse (:func:`langur.syntax.turning.complete_by_monotone`) only when ``∂f/∂v`` has one strict
sign on the whole box and ``f`` is defined there.  Both are *proved*, not sampled: sympy's interval
arithmetic (``AccumBounds``, exact rational ends, transcendental ends kept exact: ``e``, ``sin(3)``)
encloses ``f`` and ``∂f/∂v`` over the box, split by bisection of its widest side into at most
:data:`MAX_BOXES` sub-boxes where one enclosure is not enough (the dependency problem: ``3x² − 2x
+ 1`` over ``[-1, 1]``).  An enclosure of ``∂f/∂v`` with one sign on every sub-box proves the sign
and that it is defined and bounded there (``log``, ``sqrt`` of a box that reaches below 0, ``1/x``
across 0: not certified), so ``f(v, u) = f(lo, u) + ∫ ∂f/∂v`` is continuous and strictly monotone
in ``v`` wherever it is defined: the implicit root's bisection is sound.

A sign change seen at two sub-box centres proves the opposite (``∂f/∂v`` vanishes inside: not
monotone, reported as such).  Parameters are not bounded by the front end, so a derivative that
mentions one is not certified.
"""

from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass
from fractions import Fraction
from functools import lru_cache

import mpmath
import sympy as sp

from ..enclosures import interval_function

#: Most sub-boxes the enclosure of ∂f/∂v is split into before giving up.
MAX_BOXES = 256
#: CPU seconds the certification may take (CPU, not wall clock: what a condition completes to must not change
#: with the machine's load, as for every other limit of the completion).
CERTIFY_LIMIT = 2.0


@dataclass(frozen=True)
class Monotone:
    """``∂f/∂v`` has the strict sign ``sign`` (+1 or −1) on the whole box (proved)."""

    sign: int


def rational(f: float | sp.Rational) -> sp.Rational:
    """The box end as a rational: the short one that prints as ``f`` (``0.1`` is 1/10), else exact
    (a sympy rational: itself)."""
    if isinstance(f, sp.Rational):
        return f
    short = Fraction(f).limit_denominator(10**12)
    return sp.Rational(short if float(short) == f else Fraction(f))


def certify(f: sp.Expr, v: sp.Symbol, box: dict[sp.Symbol, tuple[float, float]]) -> Monotone | str:
    """Prove that ``f`` is strictly monotone in ``v`` over ``box`` (every free symbol of ``f`` is a
    variable with an interval there, ``v``'s bounded): its sign, or the reason it is not proved."""
    return certify_derivative(sp.diff(f, v), v, box)


def certify_derivative(d: sp.Expr, v: sp.Symbol, box: dict) -> Monotone | str:
    """:func:`certify` given ``d`` = ∂f/∂v (the ends of ``box`` floats or sympy rationals)."""
    free = d.free_symbols
    unbounded = sorted(s.name for s in free if s not in box)
    if unbounded:
        return f"∂/∂{v} = {d} depends on the parameters {', '.join(unbounded)}, whose range Langur does not know"
    if d.is_zero:
        return "the condition does not depend on it"
    start = {s: (rational(lo) if math.isfinite(lo) else -sp.oo, rational(hi) if math.isfinite(hi) else sp.oo)
             for s, (lo, hi) in box.items() if s in free}
    if _both_signs_on_grid(d, start):
        return f"it is not monotone in {v}: ∂/∂{v} = {d} takes both signs on the box"
    boxes, signs, seen = [start], set(), {}
    deadline = time.process_time() + CERTIFY_LIMIT
    count = 1
    while boxes:
        if time.process_time() > deadline:
            return f"Langur could not prove within {CERTIFY_LIMIT:g} CPU s that ∂/∂{v} = {d} keeps one sign on the box"
        b = boxes.pop()
        sign = _sign(d, b)
        if sign is not None:
            signs.add(sign)
            if len(signs) > 1:
                break
            continue
        centre = _centre_sign(d, b)
        if centre:
            seen.setdefault(centre, b)
        if len(seen) > 1:
            break
        split = _split(b)
        if split is None or count + 1 > MAX_BOXES:
            return (f"Langur could not prove that ∂/∂{v} = {d} keeps one strict sign on the box (interval "
                    f"enclosures over {MAX_BOXES} sub-boxes; a zero on the box's boundary is not excluded)")
        boxes.extend(split)
        count += 1
    if len(seen) > 1 or len(signs) > 1:
        return f"it is not monotone in {v}: ∂/∂{v} = {d} takes both signs on the box"
    return Monotone(signs.pop())


#: Points per side of the grid on which ∂f/∂v is first sampled (a sign change there refutes).
GRID = 9


def _both_signs_on_grid(d: sp.Expr, b: dict) -> bool:
    """``d`` is seen > 0 and < 0 at points of a grid over the bounded sides of ``b`` (each sign
    confirmed at 30 digits): a proof that it is not monotone, found before any enclosure."""
    syms = [s for s, (lo, hi) in b.items() if lo.is_finite and hi.is_finite]
    if len(syms) != len(b) or len(syms) > 3:
        return False
    try:
        fn = sp.lambdify(syms, d, modules="math")
    except (TypeError, ValueError, SyntaxError):
        return False
    axes = [[float(lo + (hi - lo) * sp.Rational(i, GRID - 1)) for i in range(GRID)] for lo, hi in (b[s] for s in syms)]
    found: dict[int, tuple] = {}
    for point in itertools.product(*axes):
        try:
            value = fn(*point)
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            continue
        if isinstance(value, float) and math.isfinite(value) and value != 0:
            found.setdefault(1 if value > 0 else -1, point)
            if len(found) > 1:
                break
    if len(found) < 2:
        return False
    at = [d.subs(dict(zip(syms, map(sp.Rational, p)))).evalf(30) for p in found.values()]
    return all(x.is_real for x in at) and (at[0] > 0) != (at[1] > 0) and all(x != 0 for x in at)


def _bounds(b: dict) -> dict:
    return {s: (sp.AccumBounds(lo, hi) if lo != hi else lo) for s, (lo, hi) in b.items()}


def _enclose(e: sp.Expr, b: dict):
    """An enclosure ``(lo, hi)`` of ``e`` over the box ``b`` (None: none found): sympy's
    ``AccumBounds``; where it leaves a function unevaluated (it knows neither ``erf``, ``tanh``,
    ``atan``, ``asin``, ``acos``, ``atanh`` nor a fractional power), mpmath's interval arithmetic
    (:mod:`langur.enclosures`, rounded outward), its ends as exact binary floats."""
    try:
        r = e.subs(_bounds(b), simultaneous=True)
    except (TypeError, ValueError, ZeroDivisionError, AttributeError, NotImplementedError):
        return None
    if isinstance(r, sp.AccumBounds):
        return r.min, r.max
    if r.is_number and r.is_extended_real and r.is_finite:
        return r, r
    if r.is_number or not r.has(sp.AccumBounds):
        return None
    return _enclose_mpmath(e, b)


def _enclose_mpmath(e: sp.Expr, b: dict):
    """``e`` over ``b`` by mpmath's interval arithmetic (every symbol of ``e`` has an interval in ``b``)."""
    syms, fn = _mpmath_fn(e)
    if not syms or any(s not in b for s in syms):
        return None
    r = fn(*(_iv(*b[s]) for s in syms))
    if r is None or not (mpmath.isfinite(r.a) and mpmath.isfinite(r.b)):
        return None
    return sp.Float(r.a), sp.Float(r.b)


@lru_cache(maxsize=256)
def _mpmath_fn(e: sp.Expr):
    """``e``'s symbols (sorted) and its enclosure on mpmath intervals of them, built once per ``e``."""
    syms = tuple(sorted(e.free_symbols, key=lambda s: s.name))
    return syms, (interval_function(syms[0], e, syms[1:]) if syms else None)


def _iv(lo, hi):
    """The interval ``[lo, hi]`` (sympy rationals or infinities) in mpmath, rounded outward."""
    def end(x, side):
        if x.is_infinite:
            return mpmath.inf if x > 0 else -mpmath.inf
        return getattr(mpmath.iv.mpf(int(x.p)) / int(x.q), side)
    return mpmath.iv.mpf([end(lo, "a"), end(hi, "b")])


def _sign(d: sp.Expr, b: dict) -> int | None:
    """+1 (−1) when the enclosure of ``d`` on ``b`` is finite and above (below) 0; else None."""
    r = _enclose(d, b)
    if r is None or not all(x.is_finite for x in r):
        return None
    lo, hi = r
    if lo.is_extended_positive:
        return 1
    if hi.is_extended_negative:
        return -1
    return None


def _centre_sign(d: sp.Expr, b: dict) -> int:
    """The sign of ``d`` at the centre of ``b`` (0: unknown, zero, or an unbounded side)."""
    if any(not (lo.is_finite and hi.is_finite) for lo, hi in b.values()):
        return 0
    try:
        value = d.subs({s: (lo + hi) / 2 for s, (lo, hi) in b.items()}).evalf(30)
    except (TypeError, ValueError, ZeroDivisionError):
        return 0
    if not (value.is_number and value.is_real) or value == 0:
        return 0
    return 1 if value > 0 else -1


def _split(b: dict) -> list[dict] | None:
    """``b`` halved across its widest bounded side (None: no bounded side wider than a point)."""
    sides = [(hi - lo, s) for s, (lo, hi) in b.items() if lo.is_finite and hi.is_finite and hi != lo]
    if not sides:
        return None
    _, s = max(sides, key=lambda w: (float(w[0]), w[1].name))
    lo, hi = b[s]
    mid = (lo + hi) / 2
    return [{**b, s: (lo, mid)}, {**b, s: (mid, hi)}]
