"""Independent adaptive quadrature of pieces at the evaluation point (cross-check and fallback).

Nothing here uses the closed-form machinery of :mod:`langur.symbolic.regions`: every integrand is
evaluated numerically (``lambdify`` at the parameter values) and integrated with nested
``scipy.integrate.quad``.  At each level the range of the current variable is split at the
breakpoints of the conditions that depend only on it and on outer variables:

* the roots given by a condition's Psi when it is solved for that variable (inverse branches at
  ``u0 = 0``, guards checked), and
* numerically found roots: sign changes of the condition on a grid refined with ``brentq``, and
  boundaries of the set where the condition is defined (NaN, e.g. ``sqrt`` of a negative number)
  refined by bisection.

On each sub-interval the conditions are constant (tested at the midpoint), so ``quad`` only ever
sees smooth integrands.  Delta pieces (LANGUAGE.md §4) are integrated over ``u'`` after the change
of variables; the Jacobian used here is ``1/|det DΨ̂(x)|`` at ``x = Ψ̂_b⁻¹(0, u')`` (the forward
map's derivative), independent of the inverse-map Jacobian used by the closed form.
"""

from __future__ import annotations

import itertools
import math
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Callable, Iterator, Sequence

import numpy as np
import sympy as sp
from scipy import integrate as si
from scipy import optimize as so

from langur.implicit import ImplicitRootFn
from langur.symbolic.local import atoms_of, free_symbols
from langur.symbolic.pieces import DeltaPiece, Piece, Psi
from langur.symbolic.text import lambdify, shared_lambdify
from langur.timebox import run_with_timeout

GRID = 40
EPSABS = 1e-11  # innermost level; each outer level is 10x looser
#: Rounds of splitting an interval at the abscissae where the integrand was found not finite.
SPLIT_ROUNDS = 3
#: A sub-interval narrower than this (relative to the variable's range) on which the integrand
#: cannot be evaluated is left out, with a note: there the rounding error of a guard exceeds its
#: value (at a fold of an inverse branch, z = sqrt(r² − x² − y²) near the rim of a disk), not a
#: property of the integral.
NARROW = 1e-8
#: A condition whose value is at most this at a point where a ``folds`` problem's weight is not
#: finite puts that point outside the region or on its boundary within rounding (an implicit root
#: at its piece's turning point, where it cannot be bracketed and 1/|f'| is 1/0): a fold met, not a
#: pole inside the region (there the conditions hold).
BOUNDARY = 1e-9
#: CPU seconds sympy may spend on the critical points of one condition (:func:`_critical_points`):
#: CPU, not wall clock, so that the breakpoints found (and the error bounds) do not change with the
#: machine's load.
CRITICAL_SECONDS = 1.0
#: More abscissae than this where the integrand is not finite, in one pass of ``quad``: not a few
#: isolated singular points but a set quadrature keeps hitting (undefined on a set of positive
#: measure, or an inner integral that diverges as the outer variable tends to a point).
MAX_BAD = 3
#: The warnings of scipy's QUADPACK wrapper that mean "no convergence" (ier = 1: the subdivision
#: limit, ier = 3: bad integrand behaviour): the error estimate is not to be trusted.  ier = 2 and
#: ier = 4 (roundoff kept the tolerance from being reached) are harmless at the tight tolerances
#: used here, and ier = 5 ("probably divergent") means the integral does not exist.
NOT_CONVERGED = ("maximum number of subdivisions", "bad integrand behavior")
DIVERGENT = "probably divergent"

#: The factor by which the outermost level's tolerance is loosened (:func:`outer_tolerance`).
_OUTER = [1.0]


@contextmanager
def outer_tolerance(factor: float) -> Iterator[None]:
    """Within it, the outermost level of every nested quadrature asks ``quad`` for ``factor``
    times its usual tolerance (absolute and relative); the inner levels keep theirs.  What a
    quadrature reports as its error is the outermost level's error estimate (plus the allowance
    for the inner levels' unpropagated errors, which is still valid because their tolerances are
    unchanged), so the looser tolerance shows in the error bound: a caller that needs a value
    only to an accuracy it can state (Theorem 8.1's finite differences, :mod:`langur.theorem`)
    spends less, and checks the bound it got.  Results computed inside are remembered apart
    (:data:`_DONE`, and :func:`looseness` for the callers' caches)."""
    before = _OUTER[0]
    _OUTER[0] = float(factor)
    try:
        yield
    finally:
        _OUTER[0] = before


def looseness() -> float:
    """The current factor of :func:`outer_tolerance` (1.0 outside it)."""
    return _OUTER[0]


def _num(expr, at: dict) -> float:
    return complex(sp.sympify(expr).xreplace(_floats(at)).evalf(30)).real


def _floats(at: dict) -> dict:
    return {k: sp.Float(float(v), 30) for k, v in at.items()}


def printable(e: sp.Expr) -> sp.Expr:
    """``e`` with rationals of thousands of digits as 30-digit floats: ``lambdify`` prints numbers
    as text, and Python refuses to print an integer of more than 4300 digits (a product of 10,000
    exact constants has such a value)."""
    big = {r: sp.Float(r, 30) for r in atoms_of(e, sp.Rational) if max(abs(r.p), r.q).bit_length() > 4000}
    return e.xreplace(big) if big else e


#: Compiled integrands by (arguments, expression): the same conditions and weights come back at
#: other parameter values (the value, each partial derivative, Theorem 8.1's shifted and nearby
#: points), and ``lambdify`` costs milliseconds per call; at most this many kept.
COMPILED = 4096
_COMPILED: dict = {}


def _compile(args: tuple, e) -> tuple[Callable | None, Callable | None]:
    """``(math function, None)`` or, for a function ``math`` lacks, ``(None, mpmath function)``."""
    key = (args, e)
    hit = _COMPILED.get(key)
    if hit is not None:
        return hit
    try:
        f = shared_lambdify(list(args), e, "math")  # (sympy's lambdify, shared subtrees printed once)
        f(*[0.5] * len(args))  # probe: fails with NameError for functions math lacks
        out = (f, None)
    except NameError:
        out = (None, shared_lambdify(list(args), e, "mpmath"))
    except Exception:  # noqa: BLE001 - a domain error at the probe point is fine
        out = (shared_lambdify(list(args), e, "math"), None)
    if len(_COMPILED) >= COMPILED:
        _COMPILED.pop(next(iter(_COMPILED)))
    _COMPILED[key] = out
    return out


def _lambdify(symbols: Sequence[sp.Symbol], expr, at: dict) -> Callable[..., float]:
    """A fast scalar function of ``symbols`` (``math``); NaN where the expression is undefined or
    complex.  The parameters ``at`` are passed as trailing arguments of a compiled function cached
    by expression (:data:`COMPILED`), so other parameter values reuse it; an expression ``math``
    cannot evaluate with symbolic parameters is compiled with their values substituted."""
    e = printable(sp.sympify(expr))
    free = free_symbols(e)  # (not cached by sympy: a walk of the distinct subtrees, once)
    params = tuple(k for k in at if k in free)
    f, g = _compile(tuple(symbols) + params, e)
    extra = tuple(float(at[k]) for k in params)
    if f is None and params:  # e.g. Heaviside of a parameter: decided once its value is known
        f, g = _compile(tuple(symbols), printable(e.xreplace(_floats(at))))
        extra = ()
    if f is not None:
        def call(*vals):
            try:
                return float(f(*vals, *extra))
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                return math.nan
        return call

    def slow(*vals):
        try:
            v = complex(g(*vals, *extra))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError):
            return math.nan
        return v.real if abs(v.imag) <= 1e-12 * max(1.0, abs(v.real)) else math.nan

    return slow


_VECTORIZED: dict = {}


def _vectorize(symbols: Sequence[sp.Symbol], expr, at: dict) -> Callable | None:
    """``expr`` as a numpy function of ``symbols`` (the last one an array), the parameters ``at``
    passed like :func:`_lambdify`'s; None when numpy cannot evaluate it (then the scalar path
    alone integrates it)."""
    e = printable(sp.sympify(expr))
    free = free_symbols(e)  # (once, not once per parameter)
    params = tuple(k for k in at if k in free)
    key = (tuple(symbols) + params, e)
    f = _VECTORIZED.get(key, 0)
    if f == 0:
        try:
            f = shared_lambdify(list(key[0]), e, "numpy")  # (sympy's code, shared subtrees printed once)
            with np.errstate(all="ignore"):
                f(*[0.5] * (len(key[0]) - 1), np.linspace(0.1, 0.9, 3))  # probe: numpy has every function
        except NameError:
            f = None
        except Exception:  # noqa: BLE001 - a domain error at the probe point is fine
            pass
        if len(_VECTORIZED) >= COMPILED:
            _VECTORIZED.pop(next(iter(_VECTORIZED)))
        _VECTORIZED[key] = f
    if f is None:
        return None
    extra = tuple(float(at[k]) for k in params)
    return lambda *vals: f(*vals, *extra)


#: QUADPACK's 21-point Gauss–Kronrod rule (``dqk21``): the Kronrod abscissae on [0, 1] (the
#: 10-point Gauss rule's at odd positions, 0 last), their weights, and the Gauss weights.
XGK = (0.995657163025808080735527280689003, 0.973906528517171720077964012084452,
       0.930157491355708226001207180059508, 0.865063366688984510732096688423493,
       0.780817726586416897063717578345042, 0.679409568299024406234327365114874,
       0.562757134668604683339000099272694, 0.433395394129247190799265943165784,
       0.294392862701460198131126603103866, 0.148874338981631210884826001129720, 0.0)
WGK = (0.011694638867371874278064396062192, 0.032558162307964727478818972459390,
       0.054755896574351996031381300244580, 0.075039674810919952767043140916190,
       0.093125454583697605535065465083366, 0.109387158802297641899210590325805,
       0.123491976262065851077958109831074, 0.134709217311473325928054001771707,
       0.142775938577060080797094273138717, 0.147739104901338491374841515972068,
       0.149445554002916905664936468389821)
WG = (0.066671344308688137593568809893332, 0.149451349150580593145776339657697,
      0.219086362515982043995534934228163, 0.269266719309996355091226921569469,
      0.295524224714752870173892994651338)
#: The 21 abscissae in the order :func:`_first_panel` evaluates them (centre − half·XGK[j], then
#: centre + half·XGK[j], j < 10, then the centre): one multiply-add per panel instead of three arrays.
_X21 = np.array([-x for x in XGK[:10]] + list(XGK[:10]) + [0.0])
_WK_PAIR = np.array(WGK[:10])
_WG_PAIR = np.array([0.0, WG[0], 0.0, WG[1], 0.0, WG[2], 0.0, WG[3], 0.0, WG[4]])
_EPMACH = float(np.finfo(float).eps)
_UFLOW = float(np.finfo(float).tiny)


def _gk21_panel(y, half: float):
    """QUADPACK's ``dqk21`` ``(result, abserr, resasc)`` on the 21 values ``y`` in
    :func:`_first_panel`'s order (``y[:10]`` at centre − half·XGK[j], ``y[10:20]`` at centre +
    half·XGK[j], ``y[20]`` at the centre), with the absolute values and the deviations from the
    mean taken once over the whole panel (issue 13, camp8; bitwise the rule written out term by
    term, which proofs_tests/test_campaign_throughput8.py keeps as its reference)."""
    yc = float(y[20])
    fsum = y[:10] + y[10:20]
    resk = WGK[10] * yc + float(_WK_PAIR @ fsum)
    resg = float(_WG_PAIR @ fsum)
    ay = np.abs(y)
    resabs = WGK[10] * abs(yc) + float(_WK_PAIR @ (ay[:10] + ay[10:20]))
    reskh = 0.5 * resk
    dev = np.abs(y - reskh)
    resasc = WGK[10] * abs(yc - reskh) + float(_WK_PAIR @ (dev[:10] + dev[10:20]))
    dh = abs(half)
    result, resabs, resasc = resk * half, resabs * dh, resasc * dh
    abserr = abs((resk - resg) * half)
    if resasc != 0.0 and abserr != 0.0:
        abserr = resasc * min(1.0, (200.0 * abserr / resasc) ** 1.5)
    if resabs > _UFLOW / (50.0 * _EPMACH):
        abserr = max(_EPMACH * 50.0 * resabs, abserr)
    return result, abserr, resasc


#: :func:`_first_panel`'s answer when the vectorized weight cannot be evaluated at all.
UNVECTORIZABLE = "unvectorizable"


def _first_panel(vw: Callable, prefix: tuple, a: float, b: float, eps: float):
    """``(value, error)`` of ∫_a^b when QUADPACK's ``dqagse`` (scipy's ``quad``) would stop after
    its first 21-point panel — the panel's error estimate within ``max(eps, eps·|value|)`` and not
    saturated, every value finite — computed with the weight vectorized (one numpy call instead
    of 21 Python calls); None otherwise (then ``quad`` integrates it as before), and
    :data:`UNVECTORIZABLE` when the vectorized weight raises (its problem stops trying)."""
    centre, half = 0.5 * (a + b), 0.5 * (b - a)
    t = centre + half * _X21
    try:
        with np.errstate(all="ignore"):
            y = np.asarray(vw(*prefix, t), dtype=float)
    except (ValueError, TypeError, ZeroDivisionError, OverflowError, AttributeError):
        return UNVECTORIZABLE  # e.g. numpy's amin of an array and a number: quad from now on
    if y.ndim == 0:  # a weight constant in the innermost variable: 21 copies (np.full: cheaper
        y0 = float(y)  # than a broadcast view, the same values)
        if not math.isfinite(y0):
            return None
        y = np.full(t.shape, y0)
    else:
        if y.shape != t.shape:
            y = np.broadcast_to(y, t.shape)
        if not np.isfinite(y).all():
            return None
    result, abserr, resasc = _gk21_panel(y, half)
    if (abserr <= max(eps, eps * abs(result)) and abserr != resasc) or abserr == 0.0:
        return float(result), float(abserr)
    return None


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
    _here: dict = field(default_factory=dict, repr=False)  # level -> its conditions
    _finders: dict = field(default_factory=dict, repr=False)  # level -> (condition, root finder)
    _tests: dict = field(default_factory=dict, repr=False)  # level -> :meth:`tests`
    #: level -> the outer levels each of :attr:`kinks`' functions depends on (:func:`_depends`)
    kink_vary: dict = field(default_factory=dict, repr=False)
    #: level -> the breakpoints and kinks that do not depend on the outer variables (found once)
    _fixed: dict = field(default_factory=dict, repr=False)
    _moving: dict = field(default_factory=dict, repr=False)  # (level, vary) -> :meth:`moving`

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

    def moving(self, level: int, vary: bool) -> tuple[list, list, list]:
        """``level``'s root functions of its conditions (``prefix ↦ roots``: polynomial finder or
        grid search) that depend on the outer variables (``vary``) or do not, the conditions whose
        Psi hints do or do not, and the kink functions (:attr:`kinks`, already computed; ``prefix
        ↦ roots``) that do or do not.  A moving function that depends on some of the outer
        variables only remembers its roots by their values (:func:`_by_outer`).  Found once per
        level."""
        out = self._moving.get((level, vary))
        if out is None:
            lo, hi = self.bounds[level]
            points = []
            for c, f in self.finders(level):
                deps = _depends(c.expr, self.syms, level)
                if bool(deps) != vary:
                    continue
                if f is None:
                    def f(*prefix, c=c):
                        return _roots(lambda t: c.f(*prefix, t), lo, hi)
                points.append(_by_outer(f, deps, level))
            hinted = [c for c in self.here(level) if c.hints is not None and c.hints_vary == vary]
            kinks = []
            for (kf, roots), deps in zip(self.kinks[level], self.kink_vary[level]):
                if bool(deps) != vary:
                    continue
                if roots is None:
                    def roots(*prefix, kf=kf):
                        return _roots(lambda t: kf(*prefix, t), lo, hi)
                kinks.append(_by_outer(roots, deps, level))
            out = self._moving[(level, vary)] = (points, hinted, kinks)
        return out


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
            if len(memo) >= BY_OUTER:
                memo.clear()
            out = memo[key] = list(fn(*prefix))
        return out

    return remembered


class _Finite:
    """The integrand as ``quad`` samples it: finite everywhere.  A value that is not finite (a
    pole, NaN outside a primitive's domain) or an inner integral found undefined at this abscissa
    is recorded and replaced by 0, so ``quad`` never sees NaN (it can crash the process on one)."""

    def __init__(self, h: Callable[[float], float]):
        self.h = h
        self.bad: list[float] = []
        self.inner: str | None = None  # the first inner integral's reason for being undefined

    def __call__(self, t: float) -> float:
        try:
            v = self.h(t)
        except UndefinedIntegral as exc:
            self.inner = self.inner or exc.reason
            return self._bad(t)
        if not math.isfinite(v):
            return self._bad(t)
        return v

    def _bad(self, t: float) -> float:
        if t not in self.bad:
            self.bad.append(t)
        if len(self.bad) > MAX_BAD:
            raise _TooMany()
        return 0.0


class _TooMany(Exception):
    """Raised through ``quad`` (which propagates a callback's exception) to stop a pass early."""


def _name(p: NumProblem, level: int) -> str:
    return str(p.syms[level]) if level < len(p.syms) else f"variable {level + 1}"


def _quad_once(h, a: float, b: float, eps: float, inside: list[float]):
    """``quad`` over [a, b] with scipy's IntegrationWarnings recorded (never silenced, never
    leaked): ``(value, error, [warning texts])``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", si.IntegrationWarning)
        val, e = si.quad(h, a, b, epsabs=eps, epsrel=eps, limit=100, points=inside or None)
    texts = [str(w.message).strip() for w in caught if issubclass(w.category, si.IntegrationWarning)]
    return val, e, texts


#: An end-point growth exponent this close to 1 counts as 1 (``1/x`` measures 1.000).
GROWTH_SLACK = 0.02


def _end_growth(h, c: float, d: float) -> list[tuple[float, float]]:
    """Where ``quad`` did not converge on [c, d]: at each end e, the exponent α of |h| ~ |t − e|^-α
    measured at t = e ± (d − c)·10⁻⁴, 10⁻⁶, 10⁻⁸ (both differences must agree within 0.05:
    an oscillating or logarithmic integrand gives no exponent)."""
    out = []
    for end, sign in ((c, 1.0), (d, -1.0)):
        try:
            vals = [abs(h(end + sign * (d - c) * 10.0 ** -k)) for k in (4, 6, 8)]
        except (UndefinedIntegral, ArithmeticError, ValueError):
            continue
        if not all(math.isfinite(v) and v > 0 for v in vals):
            continue
        a1 = math.log10(vals[1] / vals[0]) / 2
        a2 = math.log10(vals[2] / vals[1]) / 2
        if abs(a1 - a2) <= 0.05:
            out.append((end, a2))
    return out


def _quad(h, a: float, b: float, eps: float, inside: list[float], p: NumProblem, level: int):
    """∫_a^b h by ``quad``, made safe and honest.

    The integrand is made finite where sampled (:class:`_Finite`).  Where it was not finite, the
    interval is split at those abscissae and integrated again (quad never samples an endpoint), up
    to :data:`SPLIT_ROUNDS` times: an integrable singularity (``log(x^2)`` at 0) then gets its
    value; an integrand that keeps being non-finite at new abscissae is undefined on more than a
    null set.  scipy's "probably divergent" means the integral does not exist, and so does no
    convergence on an interval that ends at a point where the integrand is not finite."""
    where = f"{_name(p, level)} in [{a:.6g}, {b:.6g}]"
    singular: list[float] = []
    for _ in range(SPLIT_ROUNDS + 1):
        g = _Finite(h)
        cuts = sorted({a, b, *singular})
        total = err = 0.0
        texts: list[tuple[float, float, str]] = []
        try:
            for c, d in zip(cuts, cuts[1:]):
                if not d > c:
                    continue
                val, e, ws = _quad_once(g, c, d, eps, [q for q in inside if c < q < d])
                total += val
                err += e
                texts += [(c, d, w) for w in ws]
        except _TooMany:
            break
        for c, d, w in texts:
            if DIVERGENT in w:
                raise UndefinedIntegral(f"quadrature over {where}: scipy says the integral is "
                                        f"probably divergent (on [{c:.6g}, {d:.6g}])")
        if not g.bad:
            for c, d, w in texts:
                if not any(k in w for k in NOT_CONVERGED):
                    continue
                touching = [s for s in singular if s in (c, d)]
                if touching:
                    raise UndefinedIntegral(
                        f"the integrand is not finite at {_name(p, level)} = {touching[0]:.6g} and "
                        f"quadrature does not converge next to it: the integral is probably divergent")
                for end, alpha in _end_growth(h, c, d):
                    if alpha >= 1 - GROWTH_SLACK:
                        raise UndefinedIntegral(
                            f"quadrature over {_name(p, level)} in [{c:.6g}, {d:.6g}] does not converge and the "
                            f"integrand grows like |{_name(p, level)} - {end:.6g}|^-{alpha:.3g} there: the "
                            "integral is probably divergent")
                p.converged = False
                p.notes.append(f"quadrature did not reach its tolerance over {_name(p, level)} "
                               f"(scipy: {w.splitlines()[0].rstrip('.')}); the error bound may be optimistic")
            return total, err
        singular += [t for t in g.bad if t not in singular]
    if g.inner:
        raise UndefinedIntegral(f"{g.inner} (for ever more values of {_name(p, level)} in [{a:.6g}, {b:.6g}])")
    raise UndefinedIntegral(f"quadrature over {where}: the integrand is undefined (NaN) or infinite at ever "
                            "more points (on a set of positive measure, or near a point where the "
                            "integral diverges)")


def _holds(v: float) -> bool:
    return not math.isnan(v) and v >= 0


def _state(v: float) -> int:
    if math.isnan(v):
        return 0
    return 1 if v >= 0 else -1


def _roots(g: Callable[[float], float], lo: float, hi: float) -> list[float]:
    """Points in (lo, hi) where ``g`` changes sign or definedness (grid + brentq/bisection, and
    :func:`_hidden_pairs` where a pair of roots closer than the grid's step hides between nodes)."""
    xs = np.linspace(lo, hi, GRID + 1).tolist()  # Python floats: math functions, no numpy warnings
    vals = [g(x) for x in xs]
    out = _hidden_pairs(g, xs, vals)
    for i in range(GRID):
        a, b, fa, fb = xs[i], xs[i + 1], vals[i], vals[i + 1]
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
            if _state(g(m)) == sa:
                a = m
            else:
                b = m
        out.append(0.5 * (a + b))
    return out


def _hidden_pairs(g: Callable[[float], float], xs: list, vals: list) -> list[float]:
    """The roots of ``g`` a sign-change search on the grid ``xs`` cannot see: two roots between
    neighbouring nodes where ``g`` turns (``[x ≥ sin(z) + a]`` in z near z = π/2, x just below
    a + 1: the set in z has a gap narrower than the step, and ∫∫ lost ~10⁻⁵ with an error bound of
    10⁻⁹).  Wherever the nodes' values have a local maximum below 0 or a local minimum above 0
    (each extremum of ``g`` between nodes shows as one, at a node next to it), the extremum is
    found by bounded Brent's method between the neighbouring nodes, and if ``g`` changes sign
    there, the two roots on its sides by brentq.  Nothing is added where the grid sees the turn."""
    out: list[float] = []
    n = len(xs)
    for j in range(n):
        v = vals[j]
        if not (math.isfinite(v) and v != 0.0):
            continue
        left = vals[j - 1] if j > 0 else None
        right = vals[j + 1] if j + 1 < n else None
        if any(w is not None and not (math.isfinite(w) and (w > 0) == (v > 0)) for w in (left, right)):
            continue  # a sign change or a NaN next to it: the grid search handles it
        sign = 1.0 if v > 0 else -1.0  # a minimum of sign·g above 0 may dip below it
        if (left is None or sign * left >= sign * v) and (right is None or sign * right >= sign * v):
            a, b = xs[max(j - 1, 0)], xs[min(j + 1, n - 1)]
            try:
                opt = so.minimize_scalar(lambda t, sign=sign: sign * g(t), bounds=(a, b), method="bounded",
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
        poly = sp.Poly(expr, v)
        coeffs = poly.all_coeffs()
        if poly.degree() <= 8 and not any(v in c.free_symbols for c in coeffs):
            args, body = list(syms[:level]) + list(params), [printable(c) for c in coeffs]
            fn = lambdify(args, body, modules=["math"])
            try:
                fn(*[0.5] * len(args))  # probe: NameError for functions math lacks
            except NameError:
                fn = lambdify(args, body, modules=["numpy"])
            except Exception:  # noqa: BLE001 - a domain error at the probe point is fine
                pass
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        pass
    if len(_COEFFICIENTS) >= COMPILED:
        _COEFFICIENTS.pop(next(iter(_COEFFICIENTS)))
    _COEFFICIENTS[key] = fn
    return fn


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
    out = np.roots(np.array(cs, dtype=float))
    return [float(r.real) for r in out if abs(r.imag) <= REAL_SLACK * (1 + abs(r))]


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


def _finder(c: NumCond, syms, level: int, at: dict | None = None):
    if c.roots is None and c.expr is not None and syms:
        c.roots = (_poly_roots(c.sym, syms, level, at) if c.sym is not None and at is not None
                   else _poly_roots(c.expr, syms, level)) or False
    return c.roots or None


#: The kink expressions of :func:`_kink_functions` by (conditions, variables, bounds, level): the
#: same problem comes back (a value, its cross-check, a derivative's regular part at the same
#: point), and the critical points and crossings are sympy work; at most :data:`COMPILED` kept.
_KINKS: dict = {}


def _kink_functions(p: NumProblem, level: int):
    """Where the inner integral's region changes shape (kinks of this level's integrand): roots of
    the deeper conditions with each deeper variable at a box end or, for a condition quadratic in
    it, at its critical point (where a region in that variable appears or vanishes), and where two
    conditions of the next level cross (:func:`_crossings`).  With the problem's parameters kept as
    symbols (``p.sbounds``), these expressions are computed once per shape of problem and hold at
    every parameter point (only :func:`_at_levels`, numeric, is redone at each).  Returns the
    ``(function, polynomial roots or None)`` pairs and, for each, the outer levels whose variables
    it depends on (:func:`_depends`; all of them for the box-corner functions of conditions
    without an expression)."""
    out, vary = [], []
    symbolic = [c for c in p.conds if c.level > level and c.expr is not None] if p.syms else []
    for c in p.conds:
        if c.level > level and c not in symbolic:
            for corner in itertools.product(*[p.bounds[j] for j in range(level + 1, c.level + 1)]):
                out.append((lambda *a, c=c, corner=corner: c.f(*a, *corner), None))
                vary.append(tuple(range(level)))
    if not symbolic:
        return out, vary
    parametric = p.sbounds is not None and all(c.sym is not None for c in symbolic)
    at = p.at if parametric else {}
    if parametric:
        key = ("sym", tuple((c.sym, c.level) for c in symbolic), tuple(p.syms), tuple(p.sbounds), level)
        bounds = p.sbounds
    else:
        key = (tuple((c.expr, c.level) for c in symbolic), tuple(p.syms), tuple(p.bounds), level)
        bounds = [(sp.Float(lo), sp.Float(hi)) for lo, hi in p.bounds]
    exprs = _KINKS.get(key)
    if exprs is None:
        exprs = []
        variables = set(p.syms)
        for c in symbolic:
            es = [c.sym if parametric else c.expr]
            for j in range(c.level, level, -1):
                v = p.syms[j]
                nxt = []
                for e in es:
                    nxt += [e.xreplace({v: b}) for b in bounds[j]]
                    nxt += [e.xreplace({v: r}) for r in _critical_points(e, v)]
                es = nxt
            exprs += [e for e in es if free_symbols(e) & variables]
        if level + 1 < len(p.syms):
            exprs += _crossings(p, level, parametric)
            if not parametric:
                exprs += _at_levels(p, level)
        if len(_KINKS) >= COMPILED:
            _KINKS.pop(next(iter(_KINKS)))
        _KINKS[key] = exprs
    if parametric and level + 1 < len(p.syms):  # numeric roots at these parameter values
        key = (tuple((c.expr, c.level) for c in symbolic), tuple(p.syms), tuple(p.bounds), level, "levels")
        levels = _KINKS.get(key)
        if levels is None:
            if len(_KINKS) >= COMPILED:
                _KINKS.pop(next(iter(_KINKS)))
            levels = _KINKS[key] = _at_levels(p, level)
        exprs = exprs + levels
    for e in exprs:
        out.append((_lambdify(p.syms[: level + 1], e, at), _poly_roots(e, p.syms, level, at)))
        vary.append(_depends(e, p.syms, level))
    return out, vary


#: CPU seconds sympy may spend on the resultant of two conditions (:func:`_crossings`) (CPU: as
#: :data:`CRITICAL_SECONDS`).
RESULTANT_SECONDS = 0.5
#: Degree (in the next variable) up to which two conditions' crossings are computed.
RESULTANT_DEGREE = 4


def _at_levels(p: NumProblem, level: int) -> list[sp.Expr]:
    """Where a condition of the next level meets a condition on the next variable alone
    (``sqrt(y + 2) <= 1.71``: y = 0.9241): the first with the next variable at the second's roots,
    as box ends are substituted in :func:`_kink_functions` (found on a grid refined by ``brentq``
    when it is not a polynomial)."""
    v, (lo, hi) = p.syms[level + 1], p.bounds[level + 1]
    if not hi > lo:
        return []
    here = [c for c in p.here(level + 1) if c.expr is not None]
    flat = [c for c in here if c.expr.free_symbols <= {v}]
    if not flat:
        return []
    roots = set()
    for c in flat:
        poly = _poly_roots(c.expr, p.syms, level + 1)
        prefix = [0.0] * (level + 1)  # unused: the condition depends on the next variable alone
        found = poly(*prefix) if poly is not None else _roots(lambda t, c=c, z=prefix: c.f(*z, t), lo, hi)
        roots |= {r for r in found if lo < r < hi}
    out = []
    for c in here:
        if c in flat:
            continue
        out += [e for r in sorted(roots) if not (e := c.expr.xreplace({v: sp.Float(r)})).is_number]
    return out


def _crossings(p: NumProblem, level: int, parametric: bool = False) -> list[sp.Expr]:
    """Where two conditions of the next level cross (kinks of this level's integrand: there the
    inner integral's region changes shape too): the resultant of the two polynomials in the next
    variable, a polynomial in this level's variables whose roots include every crossing (a
    superset: extra breakpoints only split ``quad``'s intervals).  Pairs that are not polynomials
    of degree ≤ :data:`RESULTANT_DEGREE` in it, or whose resultant takes longer than
    :data:`RESULTANT_SECONDS`, are left to ``quad``'s subdivision as before."""
    v = p.syms[level + 1]
    polys = []
    for c in p.here(level + 1):
        e = c.sym if parametric else c.expr
        if e is None:
            continue
        try:
            poly = sp.Poly(e, v)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            continue
        if 1 <= poly.degree() <= RESULTANT_DEGREE and not any(v in k.free_symbols for k in poly.all_coeffs()):
            polys.append(e)
    params = set(p.at) if parametric else set()
    out = []
    for e1, e2 in itertools.combinations(polys, 2):
        try:
            r = run_with_timeout(lambda e1=e1, e2=e2: sp.resultant(e1, e2, v), RESULTANT_SECONDS,
                                  cpu=True)
        except Exception:  # noqa: BLE001 - sympy fails in many ways (PolynomialDivisionFailed on floats, a time
            continue  # limit); the pair is then left to quad's subdivision, as before
        r = sp.sympify(r)
        if not r.is_number and p.syms[level] in r.free_symbols and r.free_symbols <= set(p.syms[: level + 1]) | params:
            out.append(r)
    return out


#: :func:`_critical_points`' answers by (expression, variable): one condition's come back at every
#: outer level of its problem, in every piece it is a factor of, and in every problem at the same
#: parameter values (the value, its cross-check, each derivative, Theorem 8.1's shifted points
#: of the pieces that do not move); a non-polynomial one costs a sympy ``solve`` (a third of a
#: second for ``tanh(z − 0.53) − 0.1``).  A time limit's empty answer is not kept (asked again,
#: as before); at most :data:`COMPILED` kept.
_CRITICAL: dict = {}


def _critical_points(e: sp.Expr, v: sp.Symbol) -> list[sp.Expr]:
    """Where ``∂e/∂v`` vanishes, as expressions in the outer variables: there a region in ``v``
    appears or vanishes as they move (the top of a circle, ``sqrt(x² + y²) < r`` at y = 0).
    A quadratic's vertex directly; otherwise sympy's solve on the derivative's numerator within
    :data:`CRITICAL_SECONDS` (none found: none used, the grid search of :func:`_roots` remains);
    remembered (:data:`_CRITICAL`)."""
    key = (e, v)
    known = _CRITICAL.get(key)
    if known is None:
        known, final = _solve_critical(e, v)
        if final:
            if len(_CRITICAL) >= COMPILED:
                _CRITICAL.pop(next(iter(_CRITICAL)))
            _CRITICAL[key] = known
    return list(known)


def _solve_critical(e: sp.Expr, v: sp.Symbol) -> tuple[list[sp.Expr], bool]:
    """:func:`_critical_points`' answer, and whether it is final (not cut short by the time limit)."""
    try:
        poly = sp.Poly(e, v)
        if poly.degree() == 2 and not any(v in k.free_symbols for k in poly.all_coeffs()):
            a2, a1, _ = poly.all_coeffs()
            return [-a1 / (2 * a2)], True
        if poly.degree() <= 1 and not any(v in k.free_symbols for k in poly.all_coeffs()):
            return [], True
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        pass
    try:
        numerator = sp.numer(sp.together(sp.diff(e, v)))
        sols = run_with_timeout(lambda: sp.solve(numerator, v), CRITICAL_SECONDS, cpu=True)
    except TimeoutError:
        return [], False
    except (NotImplementedError, ValueError, TypeError, sp.PolynomialError):
        return [], True
    return [r for r in sols if v not in r.free_symbols and not r.has(sp.I)][:8], True


def _breakpoints(p: NumProblem, level: int, prefix: tuple, vary: bool) -> tuple[set, set]:
    """``level``'s breakpoints in (lo, hi) at the outer abscissae ``prefix`` (roots of its
    conditions, from their polynomial root finders, a grid search, or their Psi's inverse) and its
    kinks (:func:`_kink_functions`): those that depend on the outer variables (``vary``), or those
    that do not — the same at every outer abscissa, so :func:`_nested` finds them once per problem
    (the same numbers: the same functions of the same arguments)."""
    lo, hi = p.bounds[level]
    pts: set = set()
    points, hinted, kink_fns = p.moving(level, vary)
    for roots in points:
        pts.update(r for r in roots(*prefix) if lo < r < hi)
    for c in hinted:
        for r in c.hints(*prefix):
            if lo < r < hi:
                pts.add(r)
    kinks: set = set()
    for roots in kink_fns:
        kinks.update(r for r in roots(*prefix) if lo < r < hi)
    return pts, kinks


def _nested(p: NumProblem, level: int, prefix: tuple) -> float:
    lo, hi = p.bounds[level]
    if not hi > lo:
        return 0.0
    here = p.here(level)
    tests, reorder = p.tests(level)
    if level not in p.kinks:
        p.kinks[level], p.kink_vary[level] = _kink_functions(p, level)
        if p.folds and level + 2 == len(p.bounds):  # where the fold curve turns, numerically (fold section)
            _add_fold_turns(p, level)
    fixed = p._fixed.get(level)
    if fixed is None:  # the first abscissa: what does not depend on the outer variables, once
        fixed = p._fixed[level] = _breakpoints(p, level, prefix, False)
    moving, kinks = _breakpoints(p, level, prefix, True)
    pts = {lo, hi}
    pts.update(fixed[0])
    pts.update(moving)
    kinks.update(fixed[1])
    pts = sorted(pts)
    last = level == len(p.bounds) - 1
    eps = EPSABS * 10 ** (len(p.bounds) - 1 - level)  # inner levels tighter than outer ones
    if level == 0:
        eps *= _OUTER[0]  # (1 but inside :func:`outer_tolerance`)
    if p.folds and len(p.bounds) >= 2:  # the fold's rounding: no tighter than its allowance (fold section)
        eps = max(eps, FOLD_EPS * 10 ** (len(p.bounds) - 1 - level))
    total = 0.0
    err = 0.0
    for a, b in zip(pts, pts[1:]):
        if b - a <= 1e-15 * max(1.0, abs(a)):
            continue
        m = 0.5 * (a + b)
        failed = None
        for c in tests:
            if not c.f(*prefix, m) >= 0:  # (NaN >= 0 is false: _holds)
                failed = c
                break
        if failed is not None:
            if reorder and tests[0] is not failed:  # tried first next time (see :meth:`NumProblem.tests`)
                tests.remove(failed)
                tests.insert(0, failed)
            continue
        inside = sorted(q for q in kinks if a < q < b)
        if last:
            quick = _first_panel(p.vweight, prefix, a, b, eps) if p.vweight is not None and not inside else None
            if quick is UNVECTORIZABLE:
                p.vweight, quick = None, None
            if quick is not None:
                total += quick[0]
                err += quick[1]
                continue

            def h(t):
                if p.folds and time.process_time() > p.until:
                    raise FoldUnresolved(_fold_message(p, f"did not reach its tolerance within {FOLD_SECONDS:g} CPU seconds"))
                v = p.weight(*prefix, t)
                if p.folds and not math.isfinite(v) and not all(c.f(*prefix, t) > BOUNDARY for c in here):
                    p.fold_hit = True  # the root at its turning point within rounding (see integrate_problem)
                return v
        else:
            def h(t):
                return _nested(p, level + 1, prefix + (t,))
            if p.folds and len(p.bounds) >= 2:  # an inner integral at the fold within rounding (fold section)
                h = _fold_outer(p, level, prefix, [a, *inside, b], hi - lo)
        try:
            if last and p.folds and len(p.bounds) >= 2:  # the fold's 1/√ at the ends substituted (fold section)
                val, e = _fold_innermost(p, level, prefix, a, b, eps, inside, hi - lo)
            else:
                val, e = _quad(h, a, b, eps, inside, p, level)
        except UndefinedIntegral:
            if b - a > NARROW * max(1.0, hi - lo):
                raise
            p.notes.append(f"left out: sub-intervals of {_name(p, level)} narrower than {NARROW:g} of its range "
                           "where the integrand cannot be evaluated in floating point (rounding at a fold); "
                           "not in the error bound")
            continue
        total += val
        err += e
    if level == 0:
        p.errors.append(err)
    return total


#: CPU seconds one delta problem through an implicit root (``folds``) may take: in two or more
#: coordinates its weight's fold singularity (1/√ along the fold curve, 1/|t − t₀| across it where
#: the fold curve is itself singular) keeps the nested quadrature from its tolerance for hours.
#: The 3-D folium on [−1, 1]³ needs 30–52 CPU s per branch problem (one implicit root, and a
#: moving turning point's certified bracket, per abscissa: ~70 % of the time), hence 90.
FOLD_SECONDS = 90.0


class FoldUnresolved(ValueError):
    """A delta through an implicit root, in two or more coordinates, whose quadrature did not finish
    within :data:`FOLD_SECONDS` or met its fold within rounding at ever more points: an engine
    limitation (the singularity along the fold is integrable), reported as no value, not undefined."""


#: The uncertainty, relative to max(1, |end|), of an innermost interval's end where a fold makes
#: the weight grow like 1/√: the end is a root of a guard computed in doubles (a few units in the
#: last place for a simple root; more next to a double root, where the fold curve turns).
FOLD_END = 2.0 ** -44
#: The innermost tolerance of a ``folds`` problem in two or more coordinates (each outer level 10×
#: looser): the weight next to the fold is computed from a root within rounding of its turning
#: point, so its values carry noise of ~10⁻¹⁰ relative that a tighter tolerance only chases.
FOLD_EPS = 1e-8
#: Where the substituted variable s is this close to 0 or 1, the point is the end within rounding
#: (the implicit root at its turning point cannot be bracketed there): the integrand counts 0 and
#: the part left out is in :data:`FOLD_END`'s allowance.
FOLD_ROUNDING = 1e-7


def _fold_innermost(p: NumProblem, level: int, prefix: tuple, a: float, b: float, eps: float,
                    inside: list[float], span: float) -> tuple[float, float]:
    """∫_a^b of a ``folds`` problem's weight over its innermost variable, in two or more
    coordinates: on each piece [c, d] between the kinks, t = c + (d − c)·(3s² − 2s³), whose
    derivative 6(d − c)·s(1 − s) vanishes like the distance to either end, so the weight's
    1/√(t − c) where the implicit root reaches its turning point (the fold) becomes bounded and
    smooth in s.  A fold end is known only within rounding (:data:`FOLD_END`), and next to it the
    root may not be found (NaN where a condition is within :data:`BOUNDARY` of 0: counted 0, and
    four times the farthest such point from the end joins δ): if the weight grows like A/√|t − c|
    there, the end's uncertainty δ changes the integral by at most 2A·√δ, kept as the fold's
    allowance (:func:`_fold_allowance`) with A measured at s = 10⁻⁴ (0 where the weight stays
    bounded)."""
    cuts = [a, *inside, b]
    here = p.here(level)
    total = err = 0.0
    for c, d in zip(cuts, cuts[1:]):
        if not d > c:
            continue
        width = d - c
        missed = [0.0, 0.0]  # how far from each end the weight was counted 0 (met the fold within rounding)

        def h(s, c=c, width=width, missed=missed):
            if time.process_time() > p.until:
                raise FoldUnresolved(_fold_message(p, f"did not reach its tolerance within {FOLD_SECONDS:g} CPU seconds"))
            ds = 6.0 * width * s * (1.0 - s)
            off = width * s * s * (3.0 - 2.0 * s)
            v = p.weight(*prefix, c + off)
            if not math.isfinite(v):
                if min(s, 1.0 - s) <= FOLD_ROUNDING or not all(q.f(*prefix, c + off) > BOUNDARY for q in here):
                    end = 0 if s < 0.5 else 1  # the root at its turning point within rounding (see FOLD_END)
                    missed[end] = max(missed[end], off if end == 0 else width - off)
                    return 0.0
                return v
            return v * ds

        if width <= NARROW * max(1.0, span):
            sliver = _fold_sliver(p, prefix, c, d)
            if sliver is not None:
                p.fold_allow.append((prefix, sliver[1]))
                total += sliver[0]
                continue
        try:
            val, e = _quad(h, 0.0, 1.0, eps, [], p, level)
        except UndefinedIntegral:
            # next to a fold (a cusp where two turning points merge, an end the guard finds only
            # roughly): reported as no value (FoldUnresolved), never as undefined
            p.fold_hit = True
            raise
        allow = 0.0
        for i, (end, s) in enumerate(((c, 1e-4), (d, 1.0 - 1e-4))):
            k = h(s)
            delta = max(FOLD_END * max(1.0, abs(end)), 4.0 * missed[i])
            if math.isfinite(k):  # A = K/(2√(3·width)), the change 2A·√δ = K·√(δ/(3·width))
                allow += abs(k) * math.sqrt(delta / (3.0 * width))
        p.fold_allow.append((prefix, allow))
        total += val
        err += e
    return total, err


def _fold_sliver(p: NumProblem, prefix: tuple, c: float, d: float) -> tuple[float, float] | None:
    """A piece [c, d] narrower than :data:`NARROW` where a fold end was found twice within rounding
    (a guard's root and the bisected edge of where the root is defined, ~10⁻¹⁴ apart): counted 0,
    its integral in the error bound.  If the weight is A/√|t − t₀| with t₀ within δ = width + the
    ends' uncertainty of every point, A ≤ |W(t)|·√δ at any finite sample, and the piece's integral is
    at most 2A·√δ ≤ 2·max|W|·δ.  None when no sample is finite (no bound: left to the caller)."""
    delta = (d - c) + FOLD_END * max(1.0, abs(c), abs(d))
    vals = [abs(p.weight(*prefix, c + (d - c) * k / 8)) for k in range(1, 8)]
    finite = [v for v in vals if math.isfinite(v)]
    if not finite:
        return None
    return 0.0, 2.0 * max(finite) * delta


#: An outer abscissa this close (relative to the variable's range) to its interval's end, where the
#: inner integral cannot be evaluated because the fold is met within rounding: left out (there the
#: fold curve turns, the end is a breakpoint, and quad's extrapolation of the inner integral's
#: logarithmic growth asks for abscissae a few units in the last place from it).
FOLD_NEAR = 1e-12


def _fold_outer(p: NumProblem, level: int, prefix: tuple, ends: list[float], span: float) -> Callable[[float], float]:
    """The integrand of an outer level of a ``folds`` problem: the inner integral, or 0 at an
    abscissa within :data:`FOLD_NEAR` of one of the ``ends`` (the interval's ends and its kinks),
    where the fold is met within rounding and the inner integral cannot be evaluated in doubles.  The part left out, η = the distance to the end, is bounded assuming the inner
    integral grows at most logarithmically there (the fold curve's turning point): ∫₀^η
    |I| ≤ η·|I₁|·(2 + ln(span/η)), |I₁| the largest inner integral evaluated on the interval."""
    near = FOLD_NEAR * max(1.0, span)
    seen = [0.0]

    def h(t):
        eta = min(abs(t - e) for e in ends)
        if eta <= near:
            eta = max(eta, 1e-300)
            p.fold_extra += eta * max(seen[0], 1.0) * (2.0 + math.log(max(span, eta) / eta))
            return 0.0
        v = _nested(p, level + 1, prefix + (t,))
        if math.isfinite(v):
            seen[0] = max(seen[0], abs(v))
        return v

    return h


#: Cells of the grid on which :func:`_add_fold_turns` looks for the fold curve's turning points
#: (two in one cell are missed; each point costs one numpy root finding).
FOLD_TURN_GRID = 512


def _fold_grid_sign_changes(groups: Callable[[float], Sequence[list]], lo: float, hi: float) -> list[float]:
    """Where the k-th value of a group of ``groups(x)`` changes sign on [lo, hi]: a grid of
    :data:`FOLD_TURN_GRID` cells, each sign change refined by brentq on that value alone (a cell
    where the group's count changes — a critical point entering or leaving the box — is not a turn
    of the fold curve).  The fold curve's turns for :func:`_add_fold_turns` and
    :func:`_add_fold_guards`."""
    xs = np.linspace(lo, hi, FOLD_TURN_GRID + 1).tolist()
    vals = [groups(x) for x in xs]
    out = []
    for a, b, fa, fb in zip(xs, xs[1:], vals, vals[1:]):
        for g, (ya, yb) in enumerate(zip(fa, fb)):
            if len(ya) != len(yb):
                continue
            n = len(ya)
            for k, (u, w) in enumerate(zip(ya, yb)):
                if not (math.isfinite(u) and math.isfinite(w)) or u == 0.0 or (u < 0) == (w < 0):
                    continue

                def one(x, g=g, k=k, n=n):
                    vs = groups(x)[g]
                    return vs[k] if len(vs) == n else math.nan

                try:
                    out.append(so.brentq(one, a, b, xtol=1e-15, rtol=4 * np.finfo(float).eps))
                except (ValueError, RuntimeError):
                    out.append(0.5 * (a + b))
    return out


def _add_fold_turns(p: NumProblem, level: int) -> None:
    """Kinks of ``level`` (the one outside the innermost) where a condition of the innermost level,
    a polynomial in its variable v, has a critical point in v on its zero set: there the fold curve
    turns (∂f/∂v = 0 on it) and the inner integral grows like log.  :func:`_kink_functions` finds
    them from sympy's ``solve`` within a wall-clock limit, so under load they could be missing and
    the outer quadrature not converge; here they are the sign changes in the outer variable of
    e(…, v_c) at each real critical point v_c in the box (numpy's roots of ∂e/∂v), on a grid of
    :data:`FOLD_TURN_GRID` cells refined by ``brentq``."""
    v = p.syms[level + 1]
    vlo, vhi = p.bounds[level + 1]
    for c in p.here(level + 1):
        if c.expr is None:
            continue
        try:
            dfn = _coefficients(sp.diff(c.expr, v), tuple(p.syms), level + 1)
        except (TypeError, ValueError):
            continue
        if dfn is None:
            continue

        def turns(*args, c=c, dfn=dfn):
            """e(…, v_c) at each real critical point v_c in the box, in increasing v_c."""
            *prefix, t = args
            try:
                cs = [float(q) for q in dfn(*prefix, t)]
            except (TypeError, ValueError, ZeroDivisionError, OverflowError):
                return []
            return [c.f(*prefix, t, r) for r in sorted(polynomial_roots(cs)) if vlo < r < vhi]

        def roots(*prefix, turns=turns):
            """Where one of them changes sign (each on its own: at x = −0.7865 in the separable
            cubic two change sign at once, and their product would not)."""
            return _fold_grid_sign_changes(lambda x: (turns(*prefix, x),), *p.bounds[level])

        def kink(*args, turns=turns):  # (the kink's value, for callers that search it themselves)
            vals = turns(*args)
            return math.prod(vals) if vals else math.nan

        p.kinks[level].append((kink, roots))
        p.kink_vary[level].append(tuple(range(level)))
    _add_fold_guards(p, level)


#: A bracket end that jumps (an indexed root appearing or vanishing: the turning points ±√(y/3) of
#: z³ − yz appear at y = 0) is looked at this far on either side, relative to max(1, |d|).
FOLD_JUMP = 1e-9
#: The step of :func:`_add_fold_guards`' central differences (relative to max(1, |v|)); critical
#: points this close to a jump (×64) are the jump's, not the factor's.
FOLD_STEP = 1e-7


def _bracket_jumps(e: sp.Expr, v: sp.Symbol, lo: float, hi: float, at: dict) -> list[float]:
    """Where a moving turning point in ``e`` (an indexed root, ``sign_change_k(3z² − y)``) appears
    or vanishes as ``v`` moves in (lo, hi): its equation g(z; v) = 0 has a double root (the resultant
    of g and ∂g/∂z in z vanishes) or a root at its bracket's end — there the bracket end, and with
    it the guard, jumps (the folium's cusp at y = 0).  Only for an equation polynomial in z whose
    other symbols are v and the parameters, with constant bracket ends; roots by numpy."""
    out: set = set()
    for r in e.atoms(ImplicitRootFn):
        lam, target, blo, bhi, index, _ = r.args
        if int(index) < 0 or not (sp.sympify(blo).is_number and sp.sympify(bhi).is_number):
            continue
        (z,), f = lam.variables, lam.expr
        g = sp.expand((f - target).xreplace(_floats(at)))
        if not free_symbols(g) <= {z, v}:
            continue
        try:
            exprs = [run_with_timeout(lambda g=g, z=z: sp.resultant(g, sp.diff(g, z), z), RESULTANT_SECONDS, cpu=True),
                     g.xreplace({z: blo}), g.xreplace({z: bhi})]
        except Exception:  # noqa: BLE001 - sympy fails in many ways; then no jump is known (as before)
            continue
        for q in exprs:
            q = sp.expand(sp.sympify(q))
            if v not in free_symbols(q):
                continue
            try:
                cs = [float(k) for k in sp.Poly(q, v).all_coeffs()]
            except (sp.PolynomialError, TypeError):
                continue
            out.update(t for t in polynomial_roots(cs) if lo < t < hi)
    return sorted(out)


def _add_fold_guards(p: NumProblem, level: int) -> None:
    """The fold curve's turns for an innermost condition that is not a polynomial (its guard
    contains a moving turning point, the 3-D folium's ``sign_change_0(3z² − y)``): on each of its
    factors φ, the special points in the innermost variable v at each outer abscissa are the
    critical points of φ (zeros of ∂φ/∂v, the implicit root differentiated by the implicit
    function theorem, found by :func:`_roots`) and the two sides of each point where a turning
    point appears (:func:`_bracket_jumps`).  Between two of them φ is monotone, so

    * the condition's roots in v are one ``brentq`` per factor and interval (its root finder,
      instead of a grid search of the product);
    * the critical points are innermost kinks: there the weight peaks like 1/√(Δ + β(v − v_c)²)
      when the fold curve nearly turns, and :func:`_fold_innermost` splits at them;
    * where φ at a special point changes sign in the outer variable, the fold curve turns or
      meets the cusp: outer kinks, on a grid of :data:`FOLD_TURN_GRID` cells refined by ``brentq``."""
    inner = level + 1
    v = p.syms[inner]
    vlo, vhi = p.bounds[inner]
    names = p.syms[: inner + 1]
    if inner not in p.kinks:
        p.kinks[inner], p.kink_vary[inner] = _kink_functions(p, inner)
    for c in p.here(inner):
        if c.expr is None or c.roots is not None or _coefficients(c.expr, tuple(p.syms), inner) is not None:
            continue
        factors = [f for f in sp.Mul.make_args(c.expr) if v in free_symbols(f)]
        if not factors or not any(f.has(ImplicitRootFn) for f in factors):
            continue
        parts = []
        for f in factors:
            jumps = _bracket_jumps(f, v, vlo, vhi, p.at)
            sides = [(d - FOLD_JUMP * max(1.0, abs(d)), d + FOLD_JUMP * max(1.0, abs(d))) for d in jumps]
            phi = _lambdify(names, f, p.at)

            def dphi(*args, phi=phi):
                """∂φ/∂v by a central difference: the implicit function theorem's derivative of
                ``sign_change_k`` is wrong where the turning point does not exist (the root is then
                its bracket's end, a constant)."""
                *outer, t = args
                h = FOLD_STEP * max(1.0, abs(t))
                return (phi(*outer, t + h) - phi(*outer, t - h)) / (2.0 * h)

            parts.append((phi, dphi, jumps, sides))
        last: dict = {}

        def crits(*args, parts=parts, last=last):
            """Each factor's critical points in v at the outer abscissae ``args`` (the last asked kept)."""
            out = last.get(args)
            if out is None:
                out = []
                for _, dphi, jumps, _ in parts:
                    found = _roots(lambda t, dphi=dphi: dphi(*args, t), vlo, vhi)
                    out.append([t for t in found if all(abs(t - d) > FOLD_STEP * 64 * max(1.0, abs(d)) for d in jumps)])
                last.clear()
                last[args] = out
            return out

        def roots(*args, parts=parts, crits=crits):
            """The condition's roots in v: each factor's, one per monotone interval."""
            out = []
            for (phi, _, jumps, sides), cs in zip(parts, crits(*args)):
                pts = sorted({vlo, vhi, *cs, *(q for ab in sides for q in ab if vlo < q < vhi)})
                vals = [phi(*args, t) for t in pts]
                if not all(math.isfinite(w) for w in vals):
                    out += _roots(lambda t, phi=phi: phi(*args, t), vlo, vhi)
                    continue
                for a, b, fa, fb in zip(pts, pts[1:], vals, vals[1:]):
                    if fa == 0.0:
                        out.append(a)
                    if fa == 0.0 or fb == 0.0 or (fa < 0) == (fb < 0):
                        continue
                    jump = next((d for d, ab in zip(jumps, sides) if ab == (a, b)), None)
                    if jump is not None:  # the guard jumps here: its sign changes at the jump
                        out.append(jump)
                        continue
                    try:
                        out.append(so.brentq(lambda t, phi=phi: phi(*args, t), a, b, xtol=1e-15,
                                             rtol=4 * np.finfo(float).eps))
                    except (ValueError, RuntimeError):
                        out.append(0.5 * (a + b))
            return out

        c.roots = roots

        def inner_kinks(*args, parts=parts, crits=crits):
            return [t for cs in crits(*args) for t in cs] + [d for _, _, jumps, _ in parts for d in jumps]

        p.kinks[inner].append((None, inner_kinks))
        p.kink_vary[inner].append(tuple(range(inner)))

        def specials(*args, parts=parts, crits=crits):
            """φ at each factor's special points: (values at critical points, values at jump sides)."""
            if time.process_time() > p.until:  # (the outer kinks' grid is part of the problem's budget)
                raise FoldUnresolved(_fold_message(p, f"did not reach its tolerance within {FOLD_SECONDS:g} CPU seconds"))
            out = []
            for (phi, _, _, sides), cs in zip(parts, crits(*args)):
                out.append(([phi(*args, t) for t in cs], [phi(*args, q) for ab in sides for q in ab]))
            return out

        def outer_roots(*prefix, specials=specials):
            return _fold_grid_sign_changes(
                lambda x: [values for part in specials(*prefix, x) for values in part], *p.bounds[level])

        p.kinks[level].append((None, outer_roots))
        p.kink_vary[level].append(tuple(range(level)))


def _fold_allowance(p: NumProblem) -> float:
    """The fold's rounding allowances integrated over the outer variables: for one outer variable
    a step rule over the abscissae where they were measured (each gap counts the larger of its two
    ends), for more the largest times the outer box's volume; plus what was left out."""
    if not p.fold_allow:
        return p.fold_extra
    dens: dict = {}
    for prefix, allow in p.fold_allow:
        dens[prefix] = dens.get(prefix, 0.0) + allow
    if len(p.bounds) == 2:
        (lo, hi) = p.bounds[0]
        xs = sorted(dens)
        out = (xs[0][0] - lo) * dens[xs[0]] + (hi - xs[-1][0]) * dens[xs[-1]]
        out += sum((q[0] - r[0]) * max(dens[q], dens[r]) for r, q in zip(xs, xs[1:]))
    else:
        out = max(dens.values()) * math.prod(hi - lo for lo, hi in p.bounds[:-1])
    return out + p.fold_extra


def _implied_by_bracket(e, variables, xs, at: dict) -> bool:
    """Whether the condition ``e ≥ 0`` is ``k·(v − c) ≥ 0`` for a variable ``v`` that the branch
    solves by an implicit root (``xs``) whose bracket lies on the condition's side of ``c`` (a bound
    of the box on the root's variable, or ``[z >= -1]`` in the program): then it holds wherever the
    root exists, and :func:`delta_problems` leaves it out — in two or more coordinates such a
    condition is not a polynomial, and finding where it changes sign (a grid search of root solves
    at every outer abscissa) was three quarters of a fold problem's time, for a condition that never
    changes sign."""
    e = sp.sympify(e)
    fs = e.free_symbols
    if len(fs) != 1:
        return False
    (v,) = fs
    if v not in variables or not isinstance(x := xs[variables.index(v)], ImplicitRootFn):
        return False
    try:
        poly = sp.Poly(e, v)
        if poly.degree() != 1:
            return False
        k, c0 = (_num(c, at) for c in poly.all_coeffs())
        a, b = _bracket_range(x.args[2], at)[0], _bracket_range(x.args[3], at)[1]
    except (sp.PolynomialError, TypeError, ValueError):
        return False
    c = -c0 / k
    return a >= c if k > 0 else b <= c


def _bracket_range(e, at: dict) -> tuple[float, float]:
    """The least and the greatest value a bracket's end ``e`` can take: itself when it is a number,
    an implicit root's own bracket's when it is one (the turning point ``sign_change_0(3z² − y)`` in
    [−1, 1], which moves with y); ValueError otherwise."""
    if isinstance(e, ImplicitRootFn):
        return _bracket_range(e.args[2], at)[0], _bracket_range(e.args[3], at)[1]
    e = sp.sympify(e)
    if not e.is_number and not (e.free_symbols <= set(at)):
        raise ValueError(e)
    v = _num(e, at)
    return v, v


def _fold_message(p: NumProblem, what: str) -> str:
    return (f"the delta's weight 1/|f'| through an implicit root is singular along the fold where f' = 0 "
            f"(over {', '.join(map(str, p.syms))}); its nested quadrature {what}, so no value has an error "
            "bound to trust (an engine limitation, not an undefined integral: use the Monte Carlo engine)")


def integrate_problem(p: NumProblem) -> tuple[float, float]:
    """Value and error estimate of ``∫_bounds Π[conds] · weight``."""
    if any(c.level < 0 and not _holds(c.f()) for c in p.conds):
        return 0.0, 0.0
    if not p.bounds:
        v = p.weight()
        if not math.isfinite(v):
            raise UndefinedIntegral(f"the integrand is undefined ({v}) at the evaluation point")
        return v, 0.0
    p.errors.clear()
    try:
        if p.folds and len(p.bounds) >= 2:  # (one coordinate: the fold is a point, quad resolves it)
            p.until = time.process_time() + FOLD_SECONDS
            p.fold_allow.clear()
            p.fold_extra = 0.0
            try:
                val = _nested(p, 0, ())
            except UndefinedIntegral as exc:
                if not p.fold_hit:
                    raise
                raise FoldUnresolved(_fold_message(p, "met the fold within rounding, where the root cannot be "
                                                      "bracketed, at ever more points")) from exc
        else:
            val = _nested(p, 0, ())
    finally:
        p._moving.clear()  # the roots remembered by outer abscissae (the problem may be kept in _DONE)
    err = sum(p.errors)
    if p.folds and len(p.bounds) >= 2:
        err += _fold_allowance(p)  # the ends' rounding at the fold (fold section)
    # Inner levels' errors are not propagated by quad; add a conservative relative allowance.
    return val, err + 1e-10 * (1.0 + abs(val)) * len(p.bounds)


def _level(expr, variables: Sequence[sp.Symbol]) -> int:
    fs = sp.sympify(expr).free_symbols
    lv = -1
    for i, v in enumerate(variables):
        if v in fs:
            lv = i
    return lv


def _psi_hints(psi: Psi | None, v: sp.Symbol, variables, level: int, at: dict):
    """Roots of the condition in ``v`` from Psi's inverse branches (completed Psi only), and
    whether they depend on the outer variables."""
    if psi is None or psi.solved_for != v or not psi.branches:
        return None, True
    others = [x for x in psi.variables if x != v]
    if any(x not in variables[:level] for x in others):
        return None, True
    sub = {psi.inputs[0]: 0}
    sub.update({u: x for u, x in zip(psi.inputs[1:], others)})
    fns = []
    outer = set(variables[:level])
    vary = False
    for b in psi.branches:
        comp = dict(b.inverse)[v].xreplace(sub)
        guards = [g.xreplace(sub) for g in b.guards]
        vary = vary or any(free_symbols(sp.sympify(e)) & outer for e in [comp, *guards])
        fns.append((_lambdify(variables[:level], comp, at), [_lambdify(variables[:level], g, at) for g in guards]))

    def hints(*prefix):
        out = []
        for f, gs in fns:
            for g in gs:
                if not g(*prefix) >= 0:  # (_holds: NaN >= 0 is false)
                    break
            else:
                r = f(*prefix)
                if r == r:  # (not NaN)
                    out.append(r)
        return out

    return hints, vary


def piece_problem(piece: Piece, variables, box, at: dict) -> NumProblem:
    variables = list(variables)
    conds = []
    for c in piece.conditions:
        lv = _level(c.expr, variables)
        hints, vary = _psi_hints(c.psi, variables[lv], variables, lv, at) if lv >= 0 else (None, True)
        expr = sp.sympify(c.expr)
        conds.append(NumCond(_lambdify(variables[: lv + 1], expr, at), lv, hints, expr.xreplace(_floats(at)),
                             sym=_parametric(expr), hints_vary=vary))
    bounds = [(_num(lo, at), _num(hi, at)) for lo, hi in box]
    return NumProblem(conds, _lambdify(variables, piece.weight, at), bounds, syms=variables,
                      vweight=_vectorize(variables, piece.weight, at) if variables else None,
                      at=dict(at), sbounds=[(sp.sympify(lo), sp.sympify(hi)) for lo, hi in box])


#: Each piece's quadrature ``(value, error, problem)`` by the piece, the variables, the box and the
#: values of the parameters the piece and the box depend on (at most :data:`DONE` kept).  Theorem
#: 8.1's finite differences evaluate ⟦p⟧ at points shifted along one parameter: the pieces that do
#: not depend on it are the same integrals there, and the same deterministic computation would
#: give the same numbers, so they are taken from here instead of being integrated again.
DONE = 256
_DONE: dict = {}


def _symbols_of(obj) -> set:
    """The free symbols of a piece (its conditions, their diffeomorphisms' forward and inverse
    maps and guards, its weight), of a box, or of any tuple of those."""
    if isinstance(obj, sp.Basic):
        return set(obj.free_symbols)
    if isinstance(obj, (tuple, list)):
        return set().union(*[_symbols_of(o) for o in obj]) if obj else set()
    if hasattr(obj, "__dataclass_fields__"):
        return set().union(*[_symbols_of(getattr(obj, f)) for f in obj.__dataclass_fields__ if f != "origin"])
    return set()


def _piece_key(piece: Piece, variables, box, at: dict):
    box = tuple((sp.sympify(lo), sp.sympify(hi)) for lo, hi in box)
    used = (_symbols_of(piece) | _symbols_of(box)) - set(variables)
    return (piece, tuple(variables), box,
            tuple(sorted(((str(k), at[k]) for k in at if k in used), key=lambda kv: kv[0])))


def quad_pieces(pieces: Sequence[Piece], variables, box, at: dict,
                notes: list[str] | None = None, problems: list[NumProblem] | None = None) -> tuple[float, float]:
    """Σ ∫_box piece at ``at``: (value, error estimate).  scipy's warnings that did not stop the
    result are appended to ``notes``, the problems integrated to ``problems`` (whether each
    converged); :class:`UndefinedIntegral` when the integral does not exist.  A piece already
    integrated with the same values of the parameters it depends on is not integrated again
    (:data:`DONE`)."""
    val = err = 0.0
    for pc in pieces:
        try:
            key = _piece_key(pc, variables, box, at)
            hit = _DONE.get(key)  # (a value at the usual tolerance serves a looser request too)
            if _OUTER[0] != 1.0:
                key = (key, _OUTER[0])  # a looser value never serves a request at the usual tolerance
                hit = hit or _DONE.get(key)
        except TypeError:  # something unhashable: integrated, not remembered
            key, hit = None, None
        if hit is None:
            prob = piece_problem(pc, variables, box, at)
            v, e = integrate_problem(prob)
            if key is not None:
                if len(_DONE) >= DONE:
                    _DONE.pop(next(iter(_DONE)))
                _DONE[key] = (v, e, prob)
        else:
            v, e, prob = hit
        val += v
        err += e
        if notes is not None:
            notes.extend(prob.notes)
        if problems is not None:
            problems.append(prob)
    return val, err


def _vanishes(expr, syms, bounds, at) -> bool:
    """Numerically zero at a few pseudo-random points of the u' box."""
    expr = sp.sympify(expr)
    if expr.is_number:
        return abs(_num(expr, at)) < 1e-300
    f = _lambdify(syms, expr, at)
    rng = np.random.default_rng(12345)
    for _ in range(5):
        v = f(*[rng.uniform(lo, hi) for lo, hi in bounds])
        if math.isnan(v) or abs(v) > 1e-12:
            return False
    return True


#: det DΨ̂ by (forward map, variables): the same Ψ̂ comes back for other partial derivatives.
_FORWARD_DETS: dict = {}


def delta_problems(piece: DeltaPiece, variables, box, at: dict, ubox) -> list[NumProblem]:
    """One problem over ``u'`` per inverse branch (forward-Jacobian form, see module doc).

    ``ubox``: the (lo, hi) bounds of ``u'`` (shared with the closed form: it is only an
    enclosure; the box conditions added here cut it to the right region)."""
    psi = piece.psi
    variables = list(variables)
    missing = [x for x in variables if x not in psi.variables]
    uprime = list(psi.inputs[1:]) + missing
    jac = _FORWARD_DETS.get((psi.forward, psi.variables))
    if jac is None:  # (sympy's det simplifies as it goes: a third of a second for the ray tracer's shader)
        jac = sp.Matrix(psi.forward).jacobian(list(psi.variables)).det()
        if len(_FORWARD_DETS) >= COMPILED:
            _FORWARD_DETS.pop(next(iter(_FORWARD_DETS)))
        _FORWARD_DETS[(psi.forward, psi.variables)] = jac
    jac_f = _lambdify(variables, jac, at)
    bounds = [(_num(lo, at), _num(hi, at)) for lo, hi in ubox]
    problems = []
    for b in psi.branches:
        sub = {psi.inputs[0]: sp.Integer(0)}
        inv = {x: e.xreplace(sub) for x, e in b.inverse}
        xs = [inv.get(x, x) for x in variables]
        x_fns = [_lambdify(uprime, e, at) for e in xs]

        def xmap(*u, x_fns=x_fns):
            return [f(*u) for f in x_fns]

        conds = []
        exprs = [c.expr for c in piece.conditions] + [g.xreplace(sub) for g in b.guards]
        guards_start = len(piece.conditions)
        for i, (lo, hi) in enumerate(box):
            exprs += [variables[i] - lo, hi - variables[i]]
        empty = False
        for k, e in enumerate(exprs):
            if len(uprime) >= 2 and k not in range(guards_start, guards_start + len(b.guards)) \
                    and _implied_by_bracket(e, variables, xs, at):  # (fold section)
                continue
            se = e if guards_start <= k < guards_start + len(b.guards) else e.xreplace(dict(zip(variables, xs)))
            if _vanishes(se, uprime, bounds, at):
                if k < guards_start and piece.conditions[k].strict:
                    empty = True  # [0 > 0] is FALSE: the piece is 0 on this branch of the zero set
                    break
                continue  # vanishes identically on the zero set: 0 >= 0 is TRUE (paper convention)
            lv = _level(se, uprime)
            conds.append(NumCond(_lambdify(uprime[: lv + 1], se, at), lv, None, se.xreplace(_floats(at)), sym=_parametric(se)))
        if empty:
            continue
        w_f = _lambdify(variables, piece.weight, at)

        def weight(*u, xmap=xmap, w_f=w_f):
            x = xmap(*u)
            d = jac_f(*x)
            return w_f(*x) / abs(d) if d != 0 else math.nan  # degenerate: Ψ̂ not invertible here

        problems.append(NumProblem(conds, weight, bounds, syms=uprime, at=dict(at),
                                   sbounds=[(sp.sympify(lo), sp.sympify(hi)) for lo, hi in ubox],
                                   folds=any(e.has(ImplicitRootFn) for e in xs)))
    return problems


def quad_delta_pieces(pieces: Sequence[DeltaPiece], variables, box, at: dict, uboxes,
                      notes: list[str] | None = None, problems: list[NumProblem] | None = None
                      ) -> tuple[float, float]:
    """Σ ∫ h δ(π₀Ψ̂) at ``at`` over the box; ``uboxes[i]`` is piece i's ``u'`` box (``notes`` and
    errors as :func:`quad_pieces`)."""
    val = err = 0.0
    for pc, ub in zip(pieces, uboxes):
        for prob in delta_problems(pc, variables, box, at, ub):
            v, e = integrate_problem(prob)
            val += v
            err += e
            if notes is not None:
                notes.extend(prob.notes)
            if problems is not None:
                problems.append(prob)
    return val, err
