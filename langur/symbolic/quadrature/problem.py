"""The numeric problem one piece's integral becomes (paper §8.2, Def. 6.2's pieces): conditions
``f(x₁, …, x_k) ≥ 0`` per level of the nested integral, the weight, the box, and what is found once
per level (each condition's root finder, which roots move with the outer variables); and
:class:`UndefinedIntegral`, the answer when the integral does not exist.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable, Sequence

import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.memo import make_room
from langur.symbolic.quadrature.roots import _poly_roots, _roots
from langur.symbolic.walks import free_symbols


@dataclass
class NumCond:
    """``f(*vals) >= 0`` where ``vals`` are the values of the first ``level + 1`` variables."""

    f: Callable[..., float]
    level: int
    hints: Callable[..., list[float]] | None = None
    expr: sp.Expr | None = None  # with the parameters' values substituted (for polynomial roots)
    roots: Callable[..., list[float]] | None = None
    #: ``expr`` with the parameters left as symbols (their values are the problem's ``at``): the
    #: polynomial roots and kinks computed from it hold at every parameter point, so Theorem 8.1's
    #: shifted points and nearby points reuse them (:func:`_kink_functions`); None when ``expr``
    #: is not polynomial in its symbols (:func:`_parametric`)
    sym: sp.Expr | None = None
    #: whether :attr:`hints` depend on the outer variables (False: the same roots at every outer
    #: abscissa, found once per problem, :meth:`NumProblem.fixed`)
    hints_vary: bool = True


def _parametric(expr: sp.Expr) -> sp.Expr | None:
    """``expr`` as :attr:`NumCond.sym` when it is a polynomial in all its symbols, else None (the
    values substituted, as before): with a parameter in a denominator (the ray tracer's conditions
    are rational in ``t``) sympy's ``Poly`` over a field of rational functions cost ~0.1–0.5 s per
    condition and doubled the ray tracer's ∂/∂t, more than the reuse at shifted points saves."""
    return expr if expr.is_polynomial(*free_symbols(expr)) else None


class UndefinedIntegral(ValueError):
    """The integral does not exist: quadrature's own diagnostics say so (scipy's "probably
    divergent", no convergence next to a point where the integrand is not finite), or the
    integrand is undefined (NaN) on a set that sampling keeps hitting (a set of positive measure).
    The message names the variable and the interval."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class BeyondRange(OverflowError):
    """The integrand's values are too large for a float (beyond ±1.8·10³⁰⁸, by mpmath:
    :func:`~.compiling._in_mpmath`) on a set that sampling keeps hitting: floating-point quadrature can
    give neither a value nor an error bound.  Not a verdict on the integral, which may well exist
    (``∫₀¹ exp(1000 x) dx``); the exact engine reports no value rather than *undefined*."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class TooManyLevels(ValueError):
    """Nested quadrature over more variables than it can finish (:data:`MOST_LEVELS`): not a verdict
    on the integral; the exact engine reports no value, at once instead of after its time limit."""


#: Most variables nested quadrature is tried over: each level evaluates what is inside it at least
#: 21 times (the 21-point Gauss–Kronrod rule of its first panel), so d levels cost at least 21^d
#: evaluations of the integrand — 8.6·10⁷ at d = 6, 1.8·10⁹ at d = 7, hours at microseconds each; a
#: program in 41 variables ran until its 600 s limit (bench/history/2026-11-29.md#hostile32.
MOST_LEVELS = 6


@dataclass
class NumProblem:
    conds: list[NumCond]
    weight: Callable[..., float]
    bounds: list[tuple[float, float]]
    errors: list[float] = field(default_factory=list)
    kinks: dict = field(default_factory=dict)
    syms: list = field(default_factory=list)  # one symbol per level (for polynomial roots)
    notes: list[str] = field(default_factory=list)  # scipy's warnings that did not stop the result
    converged: bool = True  # every quad reached its tolerance (else the error bound may be optimistic)
    #: the weight vectorized over the innermost variable (``prefix..., array``), or None: the
    #: innermost integrals first try one 21-point Gauss–Kronrod panel on it (:func:`_first_panel`)
    vweight: Callable | None = None
    #: the parameters' values (symbol -> number) and the box with the parameters left as symbols,
    #: when every condition has its ``sym``: kinks are then computed once per shape of problem
    at: dict = field(default_factory=dict)
    sbounds: list | None = None
    #: a delta through an implicit root: its weight 1/|f'(x*)| is singular (like 1/√) along the fold
    #: where x* reaches a turning point of its piece; ``fold_hit``: the weight was not finite at a
    #: point outside the region or on its boundary within rounding (:data:`BOUNDARY`); ``until``: the
    #: CPU time (``time.process_time``) past which such a problem in two or more coordinates gives up
    folds: bool = False
    fold_hit: bool = False
    until: float = math.inf
    #: the fold's rounding allowances (:func:`_fold_innermost`, :func:`_fold_outer`): per innermost
    #: integral ``(outer abscissae, allowance)``, and absolute amounts left out at outer levels
    fold_allow: list = field(default_factory=list)
    fold_extra: float = 0.0
    #: the largest bound of an innermost piece left out by :func:`_narrow` (per innermost integral)
    narrow_allow: float = 0.0
    #: level -> the allowance for the breakpoints' rounding (:mod:`.rounding`) of the integral over
    #: that level last computed (:func:`_nested` integrates it over the outer variables)
    round_last: dict = field(default_factory=dict)
    #: level -> its conditions' magnitudes, compiled (:func:`~.rounding.uncertainty`)
    sizes: dict = field(default_factory=dict, repr=False)
    _here: dict = field(default_factory=dict, repr=False)  # level -> its conditions
    _finders: dict = field(default_factory=dict, repr=False)  # level -> (condition, root finder)
    _tests: dict = field(default_factory=dict, repr=False)  # level -> :meth:`tests`
    #: level -> the outer levels each of :attr:`kinks`' functions depends on (:func:`_depends`)
    kink_vary: dict = field(default_factory=dict, repr=False)
    #: level -> the positions in :attr:`kinks` of its tangency kinks (:func:`_kink_functions`)
    kink_tangent: dict = field(default_factory=dict, repr=False)
    #: level -> the breakpoints and kinks that do not depend on the outer variables (found once, by
    #: :func:`~.nested._nested` at its first abscissa), and the tangency kinks among them
    fixed: dict = field(default_factory=dict, repr=False)
    fixed_tangent: dict = field(default_factory=dict, repr=False)
    _moving: dict = field(default_factory=dict, repr=False)  # (level, vary) -> :meth:`moving`
    #: level -> breakpoints where the weight's mass may hide on a range wide for it (:func:`~.wide.spread`)
    spread: dict = field(default_factory=dict, repr=False)
    #: such breakpoints were used: the error is an estimate (:data:`~.wide.ESTIMATE`)
    wide: bool = False

    def here(self, level: int) -> list[NumCond]:
        """The conditions whose last variable is ``level``'s."""
        out = self._here.get(level)
        if out is None:
            out = self._here[level] = [c for c in self.conds if c.level == level]
        return out

    def tests(self, level: int) -> tuple[list[NumCond], bool]:
        """``level``'s conditions in the order :func:`_nested` tests them at a sub-interval's
        midpoint, and whether that order may change: a condition found false is tried first at the
        next sub-interval (move to front), so that the conditions that hold are not evaluated
        before it each time.  Whether all hold does not depend on the order (pure functions of
        the point); conditions through an implicit root (whose root solves remember brackets) keep
        their order.  Issue 13, camp8."""
        out = self._tests.get(level)
        if out is None:
            here = self.here(level)
            fixed = any(c.expr is None or c.expr.has(ImplicitRootFn) for c in here)
            out = self._tests[level] = (list(here), not fixed)
        return out

    def finders(self, level: int) -> list[tuple[NumCond, Callable | None]]:
        """``level``'s conditions, each with its polynomial root finder (None: the grid search of
        :func:`_roots`), looked up once per level instead of once per outer abscissa."""
        out = self._finders.get(level)
        if out is None:
            at = self.at if self.sbounds is not None else None
            out = self._finders[level] = [(c, _finder(c, self.syms, level, at)) for c in self.here(level)]
        return out

    def moving(self, level: int, vary: bool) -> tuple[list, list, list, list]:
        """``level``'s root functions of its conditions (each with its condition's position in
        :meth:`here`; ``prefix ↦ roots``: polynomial finder or grid search) that depend on the outer variables (``vary``) or do not, the conditions whose
        Psi hints do or do not, and the kink functions (:attr:`kinks`, already computed; ``prefix
        ↦ roots``) that do or do not, with whether each is a tangency kink (:attr:`kink_tangent`).
        A moving function that depends on some of the outer
        variables only remembers its roots by their values (:func:`_by_outer`).  Found once per
        level."""
        out = self._moving.get((level, vary))
        if out is None:
            lo, hi = self.bounds[level]
            points = []
            for i, (c, f) in enumerate(self.finders(level)):
                deps = _depends(c.expr, self.syms, level)
                if bool(deps) != vary:
                    continue
                if f is None:
                    def f(*prefix, c=c):
                        return _roots(lambda t: c.f(*prefix, t), lo, hi)
                points.append((i, _by_outer(f, deps, level)))
            hinted = [(i, c) for i, c in enumerate(self.here(level)) if c.hints is not None and c.hints_vary == vary]
            kinks, tangent = [], []
            tangents = self.kink_tangent.get(level, ())
            for k, ((kf, roots), deps) in enumerate(zip(self.kinks[level], self.kink_vary[level])):
                if bool(deps) != vary:
                    continue
                if roots is None:
                    def roots(*prefix, kf=kf):
                        return _roots(lambda t: kf(*prefix, t), lo, hi)
                kinks.append(_by_outer(roots, deps, level))
                tangent.append(k in tangents)
            out = self._moving[(level, vary)] = (points, hinted, kinks, tangent)
        return out

    def forget_moving(self) -> None:
        """Forget :meth:`moving`'s functions and the roots they remember by outer abscissae (after an
        integration: the problem may be kept, ``pieceproblems._DONE``, and they would be kept with it)."""
        self._moving.clear()


def _depends(expr, syms, level: int) -> tuple[int, ...]:
    """The outer levels (< ``level``) whose variables ``expr`` contains (all of them when there is
    no expression to look at)."""
    if expr is None:
        return tuple(range(level))
    fs = free_symbols(expr)
    return tuple(i for i in range(level) if syms[i] in fs)


#: Outer abscissae whose roots :func:`_by_outer` keeps per function (cleared when full).
BY_OUTER = 4096


def _by_outer(fn: Callable[..., list[float]], deps: tuple[int, ...], level: int) -> Callable[..., list[float]]:
    """``fn`` (``prefix ↦ roots``), its answers remembered by the values of the outer variables it
    depends on (``deps``) when that is not all of them: ``x² + z² ≤ a`` at the level of z, inside
    x and y, has the same roots at every y for one x (the same function of the same arguments, so
    the same numbers)."""
    if len(deps) == level and deps:
        return fn
    memo: dict = {}

    def remembered(*prefix):
        key = tuple(prefix[i] for i in deps)
        out = memo.get(key)
        if out is None:
            make_room(memo, BY_OUTER, at_once=True)
            out = memo[key] = list(fn(*prefix))
        return out

    return remembered


def _finder(c: NumCond, syms, level: int, at: dict | None = None):
    if c.roots is None and c.expr is not None and syms:
        c.roots = (_poly_roots(c.sym, syms, level, at) if c.sym is not None and at is not None
                   else _poly_roots(c.expr, syms, level)) or False
    return c.roots or None


def _level(expr, variables: Sequence[sp.Symbol]) -> int:
    fs = free_symbols(sp.sympify(expr))  # (each distinct subtree once)
    lv = -1
    for i, v in enumerate(variables):
        if v in fs:
            lv = i
    return lv

