"""The smooth primitives ``f(t)`` of LANGUAGE.md §1, declared once.

One :class:`Primitive` per function holds everything an interpreter needs, next to each other
(the rule-table style of Autodidax, micrograd's op beside its derivative):

* ``name`` as written, and whether users may write it (``surface``; every primitive is, today) or
  only the front end introduces it inside inverse branches of completed diffeomorphisms;
* ``sympy``: the name of the sympy function (the exact engine's ⟦f⟧, looked up by
  ``langur.sympy_bridge``; this module never imports sympy);
* ``value``: f on numpy arrays, NaN outside the domain (the Monte Carlo engine, the linter);
  ``scalar``: f on floats, NaN outside the domain (the naive evaluator, interval enclosures);
* ``derivative``: f'(a) given a and v = f(a), on numpy arrays, NaN outside the domain (the chain
  rule of §1's extension, forward mode in the Monte Carlo engine);
* ``domain``: the interval where f is defined, as data (the linter's domain check);
* ``image``: how f maps an interval (monotone increasing, decreasing, or into a fixed range);
  ``exact``: exact values at rational points, for constant folding;
* ``inverse``: the inverse f⁻¹ with the guard ``g(u) ≥ 0`` saying where it exists, or the
  inverse branches of a periodic f, used by diffeomorphism completion (§5.2).

``REGISTRY`` maps each name to its entry; ``PRIMITIVES`` are the surface names (in the order
error messages list them).  Adding a primitive is adding one entry here: the test
``proofs_tests/test_primitives.py`` checks that every interpreter covers every entry.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from enum import Enum
from fractions import Fraction

import numpy as np

from .records import frozen

NAN = float("nan")


class Image(Enum):
    """How f maps an interval [lo, hi] (interval enclosures of the Monte Carlo engine)."""

    INCREASING = "increasing"  # [f(lo), f(hi)]
    DECREASING = "decreasing"  # [f(hi), f(lo)]
    BOUNDED = "bounded"  # into ``Primitive.range``, whatever the interval
    UNBOUNDED = "unbounded"  # anywhere


@frozen
class Domain:
    """The interval where f is defined; ``closed``: its finite ends belong to it.  ``poles``: f is
    also undefined at isolated periodic points (tan at π/2 + kπ).  ``why``: how the linter says a
    value lies outside."""

    lo: float = -math.inf
    hi: float = math.inf
    closed: bool = False
    poles: bool = False
    why: str = ""

    @property
    def everywhere(self) -> bool:
        return self.lo == -math.inf and self.hi == math.inf and not self.poles

    def outside_closure(self, v: np.ndarray) -> np.ndarray:
        """Where ``v`` lies outside the closed interval [lo, hi] (the ends are a null set)."""
        return (v < self.lo) | (v > self.hi)

    def contains(self, a: float) -> bool:
        """``a`` in the domain (an infinite end is reached by an infinite ``a``)."""
        above = a > self.lo or a == self.lo and (self.closed or a == -math.inf)
        below = a < self.hi or a == self.hi and (self.closed or a == math.inf)
        return above and below


@frozen
class Inverse:
    """x = f⁻¹(u) where ``guard(u, π) ≥ 0`` (``guard`` None: everywhere); ``guard`` is written
    with arithmetic only, so it works on sympy expressions (π exact) and numbers alike."""

    name: str
    guard: Callable | None = None


@frozen
class PeriodicBranch:
    """One family of inverse branches of a periodic f: x = sign·f⁻¹(u) + (offset + j·period)·π,
    whose image is [lo·π, hi·π] + j·period·π (all in units of π)."""

    inverse: str
    sign: int
    offset: Fraction
    lo: Fraction
    hi: Fraction


@frozen
class Periodic:
    period: int  # in units of π
    branches: tuple[PeriodicBranch, ...]
    guard: Callable | None = None  # (u, π) ↦ g(u), like Inverse.guard


@frozen
class Primitive:
    name: str
    surface: bool
    sympy: str
    value: Callable[[np.ndarray], np.ndarray]
    scalar: Callable[[float], float]
    derivative: Callable[[np.ndarray, np.ndarray], np.ndarray]
    domain: Domain = Domain()
    image: Image = Image.UNBOUNDED
    range: tuple[float, float] = (-math.inf, math.inf)
    exact: tuple[tuple[Fraction, Fraction], ...] = ()
    inverse: Inverse | Periodic | None = None

    def interval(self, lo, hi):
        """An interval containing f([lo, hi]) (unbounded where f is undefined on part of it); ``lo``,
        ``hi`` numbers or arrays of interval ends (then arrays, elementwise: the Monte Carlo
        engine's enclosures, :mod:`langur.operational.interval`)."""
        lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
        if self.image in (Image.INCREASING, Image.DECREASING):
            with np.errstate(all="ignore"):
                a, b = self.value(lo), self.value(hi)
            bad = np.isnan(a) | np.isnan(b)
            if self.image is Image.DECREASING:
                a, b = b, a
            # rounded outward by two units in the last place: libraries' f differ by an ulp or so
            a = np.nextafter(np.nextafter(a, -math.inf), -math.inf)
            b = np.nextafter(np.nextafter(b, math.inf), math.inf)
            return np.where(bad, -math.inf, a), np.where(bad, math.inf, b)
        if self.image is Image.BOUNDED:
            return np.broadcast_to(np.float64(self.range[0]), lo.shape), np.broadcast_to(np.float64(self.range[1]), lo.shape)
        return np.broadcast_to(-math.inf, lo.shape), np.broadcast_to(math.inf, lo.shape)

    def at(self, a: Fraction) -> Fraction | None:
        """f(a) when it is a known rational (constant folding), else None."""
        return dict(self.exact).get(a)


def _scalar(f: Callable[[float], float], domain: Domain) -> Callable[[float], float]:
    """f on a float: NaN outside the domain, ±inf on overflow."""

    def g(a: float) -> float:
        if math.isnan(a) or not domain.contains(a):
            return NAN
        try:
            return f(a)
        except (ValueError, ZeroDivisionError):
            return NAN
        except OverflowError:
            return math.inf

    return g


def _log(a):  # NaN where a ≤ 0, computed on safe arguments only (no warnings)
    return np.where(a > 0, np.log(np.where(a > 0, a, 1.0)), NAN)


def _atanh(a):
    return np.where(np.abs(a) < 1, np.arctanh(a), NAN)


_ERF = np.frompyfunc(math.erf, 1, 1)


def _erf(a):  # the C library's erf, element by element (numpy has none)
    out = np.asarray(_ERF(a), dtype=float)
    return out[()] if out.ndim == 0 else out  # a scalar stays a scalar, as numpy's ufuncs do


_HALF = Fraction(1, 2)
_TWO_OVER_SQRT_PI = 2 / math.sqrt(math.pi)
_ZERO, _ONE = Fraction(0), Fraction(1)
_UNIT_CLOSED = Domain(-1.0, 1.0, closed=True, why="its argument lies outside [-1, 1]")
_UNIT_OPEN = Domain(-1.0, 1.0, why="its argument lies outside (-1, 1)")
_NONNEG = Domain(0.0, math.inf, closed=True, why="its argument is negative")
_POSITIVE = Domain(0.0, math.inf, why="its argument is negative")


def _entries() -> tuple[Primitive, ...]:
    def prim(name, surface, value, scalar, derivative, domain=Domain(), sympy=None, **facts):  # noqa: B008 (a frozen record)
        return Primitive(name, surface, sympy or name, value, _scalar(scalar, domain), derivative, domain, **facts)

    return (
        prim("exp", True, np.exp, math.exp, lambda a, v: v, image=Image.INCREASING,
             exact=((_ZERO, _ONE),), inverse=Inverse("log", lambda u, pi: u)),
        prim("log", True, _log, math.log,
             lambda a, v: np.where(a > 0, 1.0 / np.asarray(a, dtype=float), NAN),  # no exception at 0
             _POSITIVE, image=Image.INCREASING, exact=((_ONE, _ZERO),), inverse=Inverse("exp")),
        prim("sin", True, np.sin, math.sin, lambda a, v: np.cos(a), image=Image.BOUNDED, range=(-1.0, 1.0),
             exact=((_ZERO, _ZERO),),
             inverse=Periodic(2, (PeriodicBranch("asin", 1, _ZERO, -_HALF, _HALF),
                                  PeriodicBranch("asin", -1, _ONE, _HALF, 3 * _HALF)), lambda u, pi: 1 - u ** 2)),
        prim("cos", True, np.cos, math.cos, lambda a, v: -np.sin(a), image=Image.BOUNDED, range=(-1.0, 1.0),
             exact=((_ZERO, _ONE),),
             inverse=Periodic(2, (PeriodicBranch("acos", 1, _ZERO, _ZERO, _ONE),
                                  PeriodicBranch("acos", -1, _ZERO, -_ONE, _ZERO)), lambda u, pi: 1 - u ** 2)),
        prim("tan", True, np.tan, math.tan, lambda a, v: 1.0 + v * v,
             Domain(poles=True, why="its argument crosses a pole (cos changes sign)"), exact=((_ZERO, _ZERO),),
             inverse=Periodic(1, (PeriodicBranch("atan", 1, _ZERO, -_HALF, _HALF),))),
        prim("sqrt", True, np.sqrt, math.sqrt, lambda a, v: np.where(a > 0, 0.5 / v, NAN), _NONNEG,
             image=Image.INCREASING, exact=((_ZERO, _ZERO), (_ONE, _ONE))),
        prim("tanh", True, np.tanh, math.tanh, lambda a, v: 1.0 - v * v, image=Image.INCREASING,
             exact=((_ZERO, _ZERO),), inverse=Inverse("atanh", lambda u, pi: 1 - u ** 2)),
        prim("atan", True, np.arctan, math.atan, lambda a, v: 1.0 / (1.0 + a * a), image=Image.INCREASING,
             exact=((_ZERO, _ZERO),), inverse=Inverse("tan", lambda u, pi: pi ** 2 / 4 - u ** 2)),
        prim("erf", True, _erf, math.erf, lambda a, v: _TWO_OVER_SQRT_PI * np.exp(-a * a), image=Image.INCREASING,
             exact=((_ZERO, _ZERO),)),
        prim("asin", True, np.arcsin, math.asin,
             lambda a, v: np.where(np.abs(a) < 1, 1.0 / np.sqrt(1.0 - a * a), NAN), _UNIT_CLOSED,
             image=Image.INCREASING, inverse=Inverse("sin", lambda u, pi: pi ** 2 / 4 - u ** 2)),
        prim("acos", True, np.arccos, math.acos,
             lambda a, v: np.where(np.abs(a) < 1, -1.0 / np.sqrt(1.0 - a * a), NAN), _UNIT_CLOSED,
             image=Image.DECREASING, inverse=Inverse("cos", lambda u, pi: u * (pi - u))),
        prim("atanh", True, _atanh, math.atanh,
             lambda a, v: np.where(np.abs(a) < 1, 1.0 / np.asarray(1.0 - a * a, dtype=float), NAN), _UNIT_OPEN,
             image=Image.INCREASING, inverse=Inverse("tanh")),
    )



REGISTRY: dict[str, Primitive] = {p.name: p for p in _entries()}
#: The primitives users may write (LANGUAGE.md §1), in the order messages list them.
PRIMITIVES: tuple[str, ...] = tuple(p.name for p in REGISTRY.values() if p.surface)
#: Every primitive a core term may hold.
ALL_PRIMITIVES: tuple[str, ...] = tuple(REGISTRY)
