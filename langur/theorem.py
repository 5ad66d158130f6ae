"""The check of Theorem 8.1 (paper §8.3): ⦇int t d(x⃗)⦈(γ, γ') = D_γ⟦int t d(x⃗)⟧(γ)·γ'.

The left side is ``ddenote_program``; the right side differentiates the closed form of ⟦p⟧ when
``denote_program`` found one.  The two are compared

* symbolically, when ``simplify`` decides the difference within a time box ("how": "symbolic");
* otherwise numerically at the given parameters and a few random nearby points (re-running
  ``ddenote_program`` there; "how": "numeric");
* when ⟦p⟧ is only known by quadrature, D⟦p⟧·γ' is estimated by central finite differences of
  quadratures, with an error bound from the quadrature errors and a Richardson-style comparison
  of two step sizes ("how": "finite_difference").

Theorem 8.1 assumes the zero sets to be mutually transverse: on a coincident program (e.g.
``[x ≥ a]·[x ≥ a]``) the check fails, which is the point of reporting it.
"""

from __future__ import annotations

import math
import random
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from enum import StrEnum
from functools import lru_cache

import sympy as sp

from .ddenote import ddenote_program
from .denote import denote_program
from .implicit import ImplicitRootFn
from .onesided import closed_form_sides
from .precise import FORM_DIGITS, complex_value, evaluated
from .symbolic import quadrature
from .symbolic.context import nearly_real
from .symbolic.pieces import Method
from .symbolic.rational import dual_derivative_float, float_value, sign_value
from .symbolic.walks import atoms_of, has_any, size
from .sympy_bridge import at_symbols, exact_number, symbol
from .timebox import run_with_timeout


class How(StrEnum):
    """How D_γ⟦p⟧·γ' was compared with ⦇p⦈ (written as its value in JSON output)."""

    SYMBOLIC = "symbolic"
    NUMERIC = "numeric"
    FINITE_DIFFERENCE = "finite_difference"


@dataclass(frozen=True)
class Point:
    """Both sides of Theorem 8.1 at one parameter point."""

    params: dict[str, float]
    d_denotation: float
    derivative_denotation: float

    def to_json(self) -> dict:
        return {"params": self.params, "d_denotation": self.d_denotation,
                "derivative_denotation": self.derivative_denotation}


@dataclass(frozen=True)
class TheoremCheck:
    """The check's verdict: ``d_denotation`` is D_γ⟦p⟧·γ', ``derivative_denotation`` is ⦇p⦈, at the
    given parameters; ``points`` every point compared; ``error`` the finite differences' bound."""

    holds: bool | None  # None: inconclusive
    d_denotation: float
    derivative_denotation: float
    how: How
    points: tuple[Point, ...]
    notes: list[str] = field(default_factory=list)
    error: float | None = None

    def left_side(self, digits: int = 10, wrt: str = "") -> str:
        """D⟦p⟧·γ' as a report line shows it (``wrt``: the parameter, written as D_wrt⟦p⟧), saying
        when it is not computed from the closed form of ⟦p⟧: by finite differences of quadratures
        it is ``D⟦p⟧ ≈ value ± error``, ``error`` the estimate of :func:`_differences` (the two steps'
        difference plus the quadratures' own error estimates over the step: an estimate, not a proof)."""
        name = f"D_{wrt}⟦p⟧" if wrt else "D⟦p⟧"
        value = f"{float(self.d_denotation):.{digits}g}"
        if self.how == How.FINITE_DIFFERENCE and self.error is not None:
            return (f"{name} ≈ {value} ± {self.error:.2g} (finite differences of quadratures of ⟦p⟧, "
                    "error estimated)")
        return f"{name} = {value}"

    def compared(self) -> str:
        """How the two sides were compared, for a report line (paper §8.3; the module docstring)."""
        match self.how:
            case How.SYMBOLIC if self.holds is not None:  # (inconclusive: its note says why)
                return "compared symbolically near the parameters"
            case How.NUMERIC:
                nearby = len(self.points) - 1
                return (f"compared numerically at the parameters and {nearby} nearby point{'s' * (nearby != 1)}"
                        if nearby else "compared numerically at the parameters only")
            case How.FINITE_DIFFERENCE:
                return "compared within the finite differences' error"
        return ""

    def reason(self) -> str | None:
        """Why the check is inconclusive (its note saying so), or None."""
        return next((n for n in self.notes if n.startswith("inconclusive")), None) if self.holds is None else None

    def to_json(self) -> dict:
        out = {"holds": self.holds, "d_denotation": float(self.d_denotation),
               "derivative_denotation": float(self.derivative_denotation), "how": self.how}
        if self.error is not None:
            out["error"] = self.error
        out["points"] = [p.to_json() for p in self.points]
        out["notes"] = list(self.notes)
        return out


#: Relative and absolute tolerance of a numeric comparison of two exact values.
RTOL, ATOL = 1e-7, 1e-9
#: Symbolic time budget of each shifted ⟦p⟧ in a finite difference (values only are needed).
SHIFTED_TIMEOUT = 1.0
#: Finite-difference steps tried in turn (times the parameters' scale), and the bound a verdict
#: needs: at most TIGHT times the larger of 1 and the two sides' sizes.
FD_STEPS = (1e-3, 1e-4, 1e-5)
TIGHT = 1e-4
#: The first step's shifted values are first computed with the outermost quadrature level's
#: tolerance loosened this many times (:func:`langur.symbolic.quadrature.outer_tolerance`), and
#: that answer stands only when the quadrature's share of its bound is at most
#: :data:`QUADRATURE_SHARE` of the tight bound (see :func:`_finite_difference`).
LOOSE_OUTER = 30.0
QUADRATURE_SHARE = 0.25


def directional(expr: sp.Expr, direction: Mapping[str, object]) -> sp.Expr:
    """D_γ expr · γ' = Σ_z ∂expr/∂z · γ'(z)."""
    return sp.Add(*[sp.diff(expr, symbol(z)) * exact_number(v) for z, v in direction.items() if v != 0])


def _float(e: sp.Expr, at: Mapping[str, object]) -> float:
    """``e`` at ``at`` with :data:`~langur.precise.FORM_DIGITS` digits, as a float (nan where it is not
    real there, or not finite).  Real up to :data:`~langur.symbolic.context.IMAGINARY_NOISE` counts as
    real: a square root of a radicand that is exactly 0 (the cylinder's fold a + √0.3 put into
    3 − 10a² + 20a·y − 10y²) comes out of sympy's 20 digits as ±10⁻⁴⁸·i, not as 0.  Each implicit
    root is evaluated once, with :data:`~langur.precise.DIGITS` digits, and put in as that number:
    sympy's evalf would solve it again at every precision it tries on each subexpression holding it
    (turning.lgr: a tenth of a second per evaluation)."""
    e = e.xreplace(at_symbols(at))
    if has_any(e, (ImplicitRootFn,)):  # (each distinct subtree once: large forms share theirs)
        e = e.xreplace({r: evaluated(r) for r in atoms_of(e, (ImplicitRootFn,)) if not r.free_symbols})
    try:
        z = complex_value(e, FORM_DIGITS)
    except TypeError:  # a symbol left, or not a number
        return math.nan
    return z.real if math.isfinite(z.real) and nearly_real(z) else math.nan


class _Tie(Exception):
    """The evaluation point lies on a switching set of a Max/Min/Piecewise: no local form."""


def localize(expr: sp.Expr, at: Mapping[sp.Symbol, sp.Expr], eps: float = 1e-12) -> sp.Expr:
    """The branch of ``expr`` valid in a neighbourhood of ``at``: every Max/Min, Heaviside,
    DiracDelta and Piecewise in the parameters replaced by what it is near ``at``.  Raises
    ``_Tie`` when ``at`` is on a switching set (then no neighbourhood has one branch)."""

    def value(e: sp.Expr) -> float:
        return complex_value(e.xreplace(dict(at)), FORM_DIGITS).real

    def holds(cond) -> bool:
        if cond is sp.true or cond is sp.false:
            return bool(cond)
        if isinstance(cond, sp.And):
            return all(holds(c) for c in cond.args)
        if isinstance(cond, sp.Or):
            return any(holds(c) for c in cond.args)
        if isinstance(cond, sp.Not):
            return not holds(cond.args[0])
        if isinstance(cond, sp.core.relational.Relational):
            d = value(cond.lhs - cond.rhs)
            if abs(d) <= eps:
                raise _Tie()
            return bool(cond.func(d, 0))
        raise _Tie()

    if not _switches(expr):
        return expr  # nothing to resolve (and a large closed form is not rebuilt node by node)

    def go(e):
        if not e.args or not (e.free_symbols & set(at)):
            return e
        if isinstance(e, sp.Piecewise):
            for branch, cond in e.args:
                if holds(go_cond(cond)):
                    return go(branch)
            raise _Tie()
        args = [go(a) for a in e.args]
        if isinstance(e, (sp.Max, sp.Min)):
            vals = [value(a) for a in args]
            best = max(vals) if isinstance(e, sp.Max) else min(vals)
            winners = [a for a, v in zip(args, vals) if abs(v - best) <= eps]
            if len(set(winners)) > 1:
                raise _Tie()
            return winners[0]
        if isinstance(e, sp.Heaviside):
            v = value(args[0])
            if abs(v) <= eps:
                raise _Tie()
            return sp.Integer(1 if v > 0 else 0)
        if isinstance(e, sp.DiracDelta):
            if abs(value(args[0])) <= eps:
                raise _Tie()
            return sp.Integer(0)
        return e.func(*args)

    def go_cond(c):
        if isinstance(c, (sp.And, sp.Or, sp.Not)):
            return c.func(*[go_cond(a) for a in c.args])
        if isinstance(c, sp.core.relational.Relational):
            return c.func(go(c.lhs), go(c.rhs))
        return c

    return go(expr)


#: Operation count beyond which the symbolic difference is not attempted: expanding the difference
#: of two closed forms of ~10⁴ operations (the stylization kernel, §10.3.1) takes minutes; the
#: comparison is then numeric.
SYMBOLIC_OPS = 3000


@lru_cache(maxsize=64)
def _switches(expr: sp.Expr) -> bool:
    """Whether ``expr`` holds a Max, Min, Heaviside, DiracDelta or Piecewise (what
    :func:`localize` resolves), remembered by form: the check localizes the same closed form of
    ⟦p⟧ at the parameters and at each nearby point (a walk of its distinct subtrees each time)."""
    return has_any(expr, (sp.Max, sp.Min, sp.Heaviside, sp.DiracDelta, sp.Piecewise))


@lru_cache(maxsize=64)
def _large(expr: sp.Expr) -> bool:
    """Whether ``expr`` has :data:`SYMBOLIC_OPS` nodes or more, remembered by form (asked of the same
    closed forms of ⟦p⟧ and ⦇p⦈ at each point the check compares)."""
    return size(expr, SYMBOLIC_OPS) >= SYMBOLIC_OPS


def symbolic_difference(lhs: sp.Expr, rhs: sp.Expr, seconds: float = 5.0) -> sp.Expr | None:
    """``simplify(lhs − rhs)`` within ``seconds`` CPU (the expansion too; CPU, so that how the check
    decides does not change with the machine's load), or None when it does not finish or the two
    sides are too large to try (:data:`SYMBOLIC_OPS`)."""
    if size(lhs, SYMBOLIC_OPS) + size(rhs, SYMBOLIC_OPS) >= SYMBOLIC_OPS:
        return None
    try:
        difference = run_with_timeout(lambda: sp.expand(lhs - rhs), seconds, cpu=True)
        if difference == 0:  # the common case, without simplify's seconds
            return difference
        if difference.has(ImplicitRootFn):
            # simplify has no rule for an implicit root and evaluates it again and again: it
            # never decides such a difference, it only spends its whole budget (turning.lgr)
            return None
        return run_with_timeout(lambda: sp.simplify(difference), seconds, cpu=True)
    except (TimeoutError, RecursionError):
        return None


def _nearby(at: Mapping[str, object], n: int, seed: int, scale: float = 1e-3) -> list[dict[str, float]]:
    rng = random.Random(seed)
    return [{k: float(v) + rng.uniform(-1, 1) * scale * max(1.0, abs(float(v))) for k, v in at.items()}
            for _ in range(n)]


def _close(a: float, b: float, slack: float) -> bool:
    return abs(a - b) <= RTOL * max(abs(a), abs(b)) + ATOL + slack


def check_theorem_8_1(program, at: Mapping[str, object], direction: Mapping[str, object], *,
                      denotation=None, derivative=None, nearby: int = 3, seed: int = 0,
                      timeout: float = 20.0, simplify_seconds: float = 5.0) -> TheoremCheck:
    """Compare D_γ⟦p⟧·γ' with ⦇p⦈(γ, γ') at ``at`` (see the module docstring).  ``denotation`` /
    ``derivative``: already computed ``denote_program`` / ``ddenote_program`` results at ``at``
    (recomputed when None).  A failure whose two sides agree at ``at`` itself is inconclusive
    (``holds`` None), never a failure printed with two equal numbers."""
    th = _check(program, at, direction, denotation, derivative, nearby, seed, timeout, simplify_seconds)
    if th.holds is False and _close(th.d_denotation, th.derivative_denotation, 0.0):
        return replace(th, holds=None, notes=th.notes + [
            "inconclusive: D⟦p⟧·γ' and ⦇p⦈ agree at the parameters, but not everywhere the check "
            "looked (nearby points, or a symbolic difference it could not reduce to 0)"])
    return th


def _check(program, at: Mapping[str, object], direction: Mapping[str, object], denotation, derivative,
           nearby: int, seed: int, timeout: float, simplify_seconds: float) -> TheoremCheck:
    """The check itself, arguments as :func:`check_theorem_8_1`'s."""
    at = dict(at)
    den = denotation if denotation is not None else denote_program(program, at, timeout=timeout)
    der = derivative if derivative is not None else ddenote_program(program, at, direction, timeout=timeout)
    if den.method != Method.CLOSED_FORM or den.expr is None:
        return _finite_difference(program, at, direction, der, den, timeout,
                                  f"⟦p⟧ known by quadrature only ({den.method})")

    notes: list[str] = []
    # A closed form valid only in the parameter cell of ``at`` must not be differenced across
    # the cell's boundary, nor compared far from ``at``.
    everywhere = den.everywhere
    try:
        d_value, d_local = _closed_form_derivative(den.expr, at, direction, notes, across=everywhere)
    except _NotDifferentiable as e:  # the check has no left side here: not a failure of the theorem
        point = Point({k: float(v) for k, v in at.items()}, e.central, der.value)
        return TheoremCheck(None, e.central, der.value, How.SYMBOLIC, (point,), notes + [
            f"inconclusive: {e.sides.text()}; D⟦p⟧·γ' shown is the central difference (Theorem 8.1 "
            "holds for almost every parameter value, not at these)"])
    if d_value is not None and not math.isfinite(d_value):
        return _no_left_side(at, der, notes, f"its derivative there is {d_value}")
    if d_value is None:
        fd = _finite_difference(program, at, direction, der, den, timeout,
                                "the closed form of ⟦p⟧ holds in one parameter cell only")
        return replace(fd, notes=notes + fd.notes)
    point = Point({k: float(v) for k, v in at.items()}, d_value, der.value)
    if der.expr is not None and d_local is not None:
        try:
            rhs = localize(der.expr, at_symbols(at))
        except _Tie:
            rhs = None
        diff = symbolic_difference(d_local, rhs, simplify_seconds) if rhs is not None else None
        if diff is not None and diff.is_number:
            return TheoremCheck(bool(diff == 0), d_value, der.value, How.SYMBOLIC, (point,),
                                [f"simplify(D⟦p⟧·γ' − ⦇p⦈) = {sp.sstr(diff)} in a neighbourhood of the "
                                 "parameters (Max/Min/Piecewise replaced by their branch there)"])
    points = [point]
    holds = _close(d_value, der.value, der.error + den.error)
    closed = 0
    for q in _nearby(at, nearby, seed, 1e-3 if everywhere else 1e-6):
        try:
            dq, _ = _closed_form_derivative(den.expr, q, direction, [], across=everywhere)
        except (_NotDifferentiable, ValueError):  # (a random point on a switching set, or no real value)
            continue
        if dq is None or not math.isfinite(dq):
            continue
        rq = _large_closed_form_at(der, q)
        if rq is None:
            r = ddenote_program(program, q, direction, timeout=timeout, symbolic=False)  # a value is enough
            rq = (r.value, r.error)
        else:
            closed += 1
        points.append(Point(q, dq, rq[0]))
        holds = holds and _close(dq, rq[0], rq[1] + den.error)
    notes.append("compared numerically at the parameters and nearby points" + (
        f" (at {closed} of them ⦇p⦈ is its closed form, exactly: too large for the symbolic "
        "comparison, which this stands for)" if closed else ""))
    return TheoremCheck(holds, d_value, der.value, How.NUMERIC, tuple(points), notes)


def _no_left_side(at: Mapping[str, object], der, notes: list[str], why: str) -> TheoremCheck:
    """The check not decided: D⟦p⟧·γ' could not be computed from the closed form of ⟦p⟧ at the
    parameters (``why``) — the check's own failure, never reported as one of the theorem."""
    point = Point({k: float(v) for k, v in at.items()}, math.nan, der.value)
    return TheoremCheck(None, math.nan, der.value, How.NUMERIC, (point,), notes + [
        f"inconclusive: D⟦p⟧·γ' could not be computed from the closed form of ⟦p⟧ at the parameters "
        f"({why}); ⦇p⦈ is not compared"])


class _NotDifferentiable(Exception):
    """⟦p⟧'s closed form has a corner at the parameters in the direction asked: one-sided
    derivatives ``sides`` differ (``central`` the central difference, for the report)."""

    def __init__(self, sides, central: float):
        super().__init__(sides.text())
        self.sides, self.central = sides, central


_RELATIONS = {">": lambda v: v > 0, ">=": lambda v: v >= 0, "<": lambda v: v < 0, "<=": lambda v: v <= 0,
              "==": lambda v: v == 0, "!=": lambda v: v != 0}


def _large_closed_form_at(der, q: Mapping[str, float]) -> tuple[float, float] | None:
    """``(⦇p⦈(q), 0)`` from ``der``'s closed form, evaluated exactly at ``q``, when that form is
    too large for :func:`symbolic_difference` (the nearby comparison then stands for the symbolic
    one: the two closed forms compared at points near the parameters, not only at them, where
    both were cross-checked by quadrature), rational there, and ``q`` is inside every relation of
    its parameter cell; else None (⦇p⦈(q) is then computed by quadrature)."""
    if der.method != Method.CLOSED_FORM or der.expr is None or not _large(der.expr):
        return None
    point = at_symbols(q)  # (the relations and the form share their subtrees' values at q)
    for rel in tuple(der.regular.cell) + tuple(der.boundary.cell):
        test = _RELATIONS.get(getattr(rel, "rel_op", None))
        if test is None:
            return None
        v = sign_value(rel.lhs if rel.rhs == 0 else rel.lhs - rel.rhs, point)  # (the exact value's sign)
        if v is None or not test(v):
            return None
    value = float_value(der.expr, point)  # (the exact value's double)
    return None if value is None else (value, 0.0)


def _closed_form_derivative(expr: sp.Expr, at: Mapping[str, object], direction, notes: list[str],
                            across: bool = True):
    """D_γ expr · γ' at ``at``: differentiated symbolically in its local branch when ``at`` is not
    on a switching set (returns that local derivative too; a large form along the line only),
    else — or where that derivative is not a finite real number — by a central difference of the
    closed form evaluated with 30 digits (h = 1e-8: error O(h²) where it is differentiable) when
    the form holds on both sides (``across``); else ``(None, None)``."""
    try:
        local_form = localize(expr, at_symbols(at))
        if _large(local_form):  # large: differentiated along the line only
            local = None
            value = _line_derivative(local_form, at, direction)
        else:
            local = directional(local_form, direction)
            value = _float(local, at)
        if math.isfinite(value):
            return value, local
    except _Tie:
        notes.append("the parameters lie where the closed form of ⟦p⟧ switches branches: "
                     "D⟦p⟧ may not exist there (Theorem 8.1 holds almost everywhere)")
        if not across:
            return None, None
        sides = closed_form_sides(expr, at, direction)  # exactly, where sympy decides them
        if sides.exists:  # (a central difference's error is O(h), not O(h²), at such a point)
            notes.append(f"its one-sided derivatives there agree: D⟦p⟧·γ' = {sides.above}")
            return float(sides.above), None
        if sides.exists is False:
            raise _NotDifferentiable(sides, _central_difference(expr, at, direction)) from None
    return _central_difference(expr, at, direction), None


def _central_difference(expr: sp.Expr, at: Mapping[str, object], direction) -> float:
    """(expr(at + hγ') − expr(at − hγ'))/2h with h = 1e-8, evaluated with :data:`~langur.precise.DIGITS` digits; a ValueError
    when it is not real (beyond :data:`~langur.symbolic.context.IMAGINARY_NOISE`)."""
    h = sp.Rational(1, 10 ** 8)
    pt = at_symbols(at)
    plus = {k: v + h * exact_number(direction.get(k.name, 0)) for k, v in pt.items()}
    minus = {k: v - h * exact_number(direction.get(k.name, 0)) for k, v in pt.items()}
    z = complex_value((expr.xreplace(plus) - expr.xreplace(minus)) / (2 * h))
    if not nearly_real(z):
        raise ValueError(f"the closed form of ⟦p⟧ is not real beside the point (its central difference is {z})")
    return z.real


def _line_derivative(expr: sp.Expr, at: Mapping[str, object], direction) -> float:
    """D_γ expr · γ' at ``at``, exactly: ``d/ds expr(at + s·γ')`` at s = 0, the point's values
    substituted first (a large closed form becomes one in s alone, much smaller to differentiate
    than ``expr`` in all its parameters)."""
    point = at_symbols(at)
    tangent = {k: exact_number(direction.get(k.name, 0)) for k in point}
    exact = dual_derivative_float(expr, point, tangent)  # the exact derivative's double (dual numbers)
    if exact is not None:
        return exact
    s = sp.Dummy("s")
    line = {k: v + s * tangent[k] for k, v in point.items()}
    return _float(sp.diff(expr.xreplace(line), s).xreplace({s: sp.Integer(0)}), {})


def _finite_difference(program, at, direction, der, den, timeout, why: str) -> TheoremCheck:
    """D⟦p⟧·γ' by finite differences of quadratures, at steps h = 10⁻³, 10⁻⁴, 10⁻⁵ (times the
    parameters' scale) until one decides: a verdict is given only when its error bound is tight
    (:data:`TIGHT` relative to the values) — near a switch of ⟦p⟧ (a kink, a tangency where ⟦p⟧
    behaves like (θ − θ₀)^(3/2)) a larger step's Richardson bound is not to be trusted, and a
    smaller step stays inside the parameter cell.  What no step decides is inconclusive.

    **The accuracy the bound needs.**  At a step h the bound is ``|fd₁ − fd₂| + (e₁ + f₁)/(2h) +
    (e₂ + f₂)/(4h)``: the truncation term plus the shifted values' quadrature errors e, f divided
    by the step, and a verdict needs all of it ≤ TIGHT·size (size ≥ 1).  A shifted value needs
    only an absolute accuracy of order TIGHT·h — 10⁻⁷ at h = 10⁻³ — while the nested quadrature
    asks 10⁻⁹ (three variables) to 10⁻¹¹ (one) of its outermost level.  So at the first step the
    four shifted values are first computed with that level's tolerance loosened
    :data:`LOOSE_OUTER` times (the inner levels keep theirs, so the allowance for their
    unpropagated errors still holds; the error each value reports, the outermost level's estimate,
    is what enters the bound, exactly as before).  That answer stands only when it holds, comes
    from the central difference, its bound is tight and the quadrature's share of the bound is at
    most :data:`QUADRATURE_SHARE` of TIGHT·size (so the window within which D⟦p⟧·γ' and ⦇p⦈ are
    found to agree widens by at most that share of what a verdict accepts anyway); otherwise the
    step is computed again at the usual tolerance, as before, so every other verdict (fails,
    inconclusive, one-sided) is the usual computation's.  Both tolerances are this check's own: a
    caller that loosened the quadratures of ⟦p⟧ and ⦇p⦈ (a campaign, :mod:`langur.fuzz.compare`)
    does not loosen the shifted values."""
    scale = max([1.0] + [abs(float(v)) for v in at.values()])
    last = None
    for h in FD_STEPS:
        if last is None and LOOSE_OUTER != 1.0:
            with quadrature.outer_tolerance(LOOSE_OUTER):
                loose, share = _differences(program, at, direction, der, den, timeout, why, h * scale)
            tight = TIGHT * max(1.0, abs(loose.d_denotation), abs(loose.derivative_denotation))
            if loose.holds is True and share is not None and loose.error <= tight and share <= QUADRATURE_SHARE * tight:
                return replace(loose, notes=loose.notes + [
                    f"the shifted values' outermost quadrature at {LOOSE_OUTER:g}× its usual tolerance: "
                    f"their share of the bound is {share:.2g}"])
        with quadrature.outer_tolerance(1.0):  # the usual tolerance, whatever the caller's (a campaign's)
            last = _difference_at(program, at, direction, der, den, timeout, why, h * scale)
        size = max(1.0, abs(last.d_denotation), abs(last.derivative_denotation))
        if last.holds is not None and last.error is not None and last.error <= TIGHT * size:
            return last
    if last.holds is True:  # agreement only within a bound too wide to mean anything
        return replace(last, holds=None, notes=last.notes + [
            f"inconclusive: the finite differences agree with ⦇p⦈ only within ±{last.error:.2g} at every step "
            f"down to h = {FD_STEPS[-1] * scale:g} (⟦p⟧ is not smooth enough near the parameters for a tighter "
            "bound)"])
    return last


def _difference_at(program, at, direction, der, den, timeout, why: str, h: float) -> TheoremCheck:
    """D⟦p⟧·γ' by central differences of quadratures at steps h and 2h, error bound from both;
    one-sided differences where the central one straddles a switch."""
    return _differences(program, at, direction, der, den, timeout, why, h)[0]


def _differences(program, at, direction, der, den, timeout, why: str, h: float) -> tuple[TheoremCheck, float | None]:
    """:func:`_difference_at`'s check, and the quadrature errors' share of its bound when it is the
    central difference's (None for a one-sided answer)."""
    def shifted(s: float) -> tuple[float, float]:
        q = {k: float(v) + s * float(direction.get(k, 0)) for k, v in at.items()}
        # only values are needed here: quadrature with its error bound (symbolic only where it
        # does not converge, within a short budget)
        r = denote_program(program, q, timeout=min(timeout, SHIFTED_TIMEOUT), symbolic=False)
        return r.value, r.error

    (p1, e1), (m1, f1) = shifted(h), shifted(-h)
    (p2, e2), (m2, f2) = shifted(2 * h), shifted(-2 * h)
    fd1, fd2 = (p1 - m1) / (2 * h), (p2 - m2) / (4 * h)
    estimate = (4 * fd1 - fd2) / 3  # Richardson: cancels the h² term
    error = abs(fd1 - fd2) + (e1 + f1) / (2 * h) + (e2 + f2) / (4 * h)
    quadrature_part = (e1 + f1) / (2 * h) + (e2 + f2) / (4 * h)
    point = Point({k: float(v) for k, v in at.items()}, estimate, der.value)
    note = f"{why}: D⟦p⟧·γ' estimated by central finite differences of ⟦p⟧ (h = {h:g}) with error bound {error:.2g}"
    # One-sided second-order differences on each side, with their own bounds: where they disagree,
    # ⟦p⟧ switches (a kink, a parameter cell's boundary) within the step, and the central
    # difference straddles it: only the side that stays in one cell can be compared.
    f0, e0 = den.value, den.error
    sides = {"forward": ((-3 * f0 + 4 * p1 - p2) / (2 * h), (p1 - f0) / h, (3 * e0 + 4 * e1 + e2) / (2 * h)),
             "backward": ((3 * f0 - 4 * m1 + m2) / (2 * h), (f0 - m1) / h, (3 * e0 + 4 * f1 + f2) / (2 * h))}
    one_sided = {k: (d2, abs(d2 - d1) + q) for k, (d2, d1, q) in sides.items()}
    (df, ef), (db, eb) = one_sided["forward"], one_sided["backward"]
    if _close(df, db, ef + eb):
        return TheoremCheck(_close(estimate, der.value, error + der.error), estimate, der.value,
                            How.FINITE_DIFFERENCE, (point,), [note], error), quadrature_part
    agreeing = [k for k, (d, e) in one_sided.items() if _close(d, der.value, e + der.error)]
    if agreeing:
        d, e = min((one_sided[k] for k in agreeing), key=lambda de: de[1])
        side = next(k for k in agreeing if one_sided[k] == (d, e))
        return TheoremCheck(True, d, der.value, How.FINITE_DIFFERENCE,
                            (Point(point.params, d, der.value),),
                            [f"{why}: ⟦p⟧ switches within {2 * h:g} of the parameters (its one-sided differences "
                             f"differ: forward {df:.6g}, backward {db:.6g}); the {side} one, which stays in "
                             f"one parameter cell, is {d:.10g} ± {e:.2g} and agrees"], e), None
    return TheoremCheck(None, estimate, der.value, How.FINITE_DIFFERENCE, (point,),
                        [note, f"inconclusive: ⟦p⟧ switches within {2 * h:g} of the parameters (one-sided "
                               f"differences: forward {df:.6g} ± {ef:.2g}, backward {db:.6g} ± {eb:.2g}) and "
                               "neither side's difference decides"], error), None
