"""Integration next to a fold (issue 18; paper §7.3's delta pieces through an implicit root,
LANGUAGE.md §4): the weight 1/|f'(x*)| of a delta through an implicit root grows like 1/√ along the
fold curve where the root reaches a turning point of its piece.  The innermost integral substitutes
the ends away (:func:`_fold_innermost`), outer levels leave out abscissae at the fold within
rounding (:func:`_fold_outer`), and what rounding leaves uncertain is an allowance in the error
bound (:func:`_fold_allowance`); past :data:`FOLD_SECONDS` the answer is :class:`FoldUnresolved`.
"""

from __future__ import annotations

import math
import time
from typing import Callable

from langur.symbolic.quadrature.adaptive import _quad
from langur.symbolic.quadrature.problem import NumProblem, UndefinedIntegral
from langur.symbolic.quadrature.tolerance import BOUNDARY, NARROW

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
                raise _fold_timeout(p)
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


def _fold_outer(p: NumProblem, ends: list[float], span: float,
                inner: Callable[[float], float]) -> Callable[[float], float]:
    """The integrand of an outer level of a ``folds`` problem: the inner integral ``inner(t)``
    (the nested integrator's, passed in: this module sits below it), or 0 at an abscissa within
    :data:`FOLD_NEAR` of one of the ``ends`` (the interval's ends and its kinks), where the fold is
    met within rounding and the inner integral cannot be evaluated in doubles.  The part left out,
    η = the distance to the end, is bounded assuming the inner integral grows at most
    logarithmically there (the fold curve's turning point): ∫₀^η
    |I| ≤ η·|I₁|·(2 + ln(span/η)), |I₁| the largest inner integral evaluated on the interval."""
    near = FOLD_NEAR * max(1.0, span)
    seen = [0.0]

    def h(t):
        eta = min(abs(t - e) for e in ends)
        if eta <= near:
            eta = max(eta, 1e-300)
            p.fold_extra += eta * max(seen[0], 1.0) * (2.0 + math.log(max(span, eta) / eta))
            return 0.0
        v = inner(t)
        if math.isfinite(v):
            seen[0] = max(seen[0], abs(v))
        return v

    return h


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


def _fold_message(p: NumProblem, what: str) -> str:
    return (f"the delta's weight 1/|f'| through an implicit root is singular along the fold where f' = 0 "
            f"(over {', '.join(map(str, p.syms))}); its nested quadrature {what}, so no value has an error "
            "bound to trust (an engine limitation, not an undefined integral: use the Monte Carlo engine)")


def _fold_deadline() -> float:
    """The CPU time (``time.process_time``) past which a ``folds`` problem started now gives up."""
    return time.process_time() + FOLD_SECONDS


def _fold_timeout(p: NumProblem) -> FoldUnresolved:
    """What a ``folds`` problem past its :data:`FOLD_SECONDS` raises."""
    return FoldUnresolved(_fold_message(p, f"did not reach its tolerance within {FOLD_SECONDS:g} CPU seconds"))


