"""How far a breakpoint's float may be from the region's true boundary (paper §8.2: ⟦p⟧'s
integrand jumps where a condition changes sign; the quadrature's error bound must hold whatever
the program's scale).

A breakpoint of :func:`~.nested._nested` is a root of one of its level's conditions, computed in
doubles from a condition whose constants are the parameters' values in doubles.  Where the
integrand is h next to it, a breakpoint δ from the true root changes the integral by about
|h|·δ.  For an ordinary program that is ~10⁻¹⁵·|h|, far below the quadrature's tolerance; for a
sliver of width 10⁻¹³ next to x = 0.5 with the Jacobian weight 10¹³ (``[x − θ + y/10¹³ ≥ 0]``'s
delta piece) a root's rounding of 2·10⁻¹⁷ is 2·10⁻⁴ of the value, which no tolerance sees.

:func:`uncertainty` bounds δ at a breakpoint t (linearizing each condition c whose value there is
zero within its rounding and a root finder's tolerance, :func:`~langur.sympy_bridge.magnitude`):
δ = 4·ulp(t) + max over such c of (|c(t)| + ROUNDING·ε·|c|(t)) / |c'(t)|, where |c|(t) is the
magnitude (the size of the terms whose rounding the float value carries: the parameters'
values, the coefficients, the cancellation in the sum) and c'(t) a central difference; the root
finders' own tolerances (``brentq``'s xtol, the quadratic formula's roundings) show in |c(t)|.
:func:`end_allowance` turns δ into an amount of integral: 2δ times |h| sampled next to the end
where h is bounded there, nothing at a singular end (its docstring says why); the nested
integrator adds it to the level's error and carries inner levels' allowances outward
(:func:`~.nested._nested`).
"""

from __future__ import annotations

import math
import sys

import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.memo import remember
from langur.symbolic.quadrature.compiling import COMPILED, _lambdify
from langur.symbolic.quadrature.problem import NumCond, NumProblem
from langur.sympy_bridge import magnitude

#: The rounding of a condition's float value, in units of ε = 2⁻⁵² times its magnitude (a few
#: operations' worth: each +, · and constant rounds relatively by ε/2, and the magnitude bounds
#: every partial sum's size).
ROUNDING = 8.0


#: A condition is taken to have its root at t when it is zero there within :data:`AT_ROOT` times
#: its rounding plus its slope times a root finder's tolerance (for a condition without a
#: polynomial root finder ``brentq``'s xtol 10⁻¹⁵ and rtol 4ε, :data:`XTOL`; :data:`FINDER`·ε·|t|
#: for a root formula's last roundings): a root of another condition 10⁻¹³ away is not this
#: one's (the sliver ``θ − 10⁻¹³ ≤ x ≤ θ``).  Taking a condition for the root's that is not only
#: widens the bound.
AT_ROOT = 4.0
XTOL = 2e-15
FINDER = 4.0


#: A condition whose root is, by its linearization |c(t)|/|c'(t)|, farther from t than this
#: times max(|t|, the range) is not asked for its magnitude (compiled only for the conditions that
#: are): it could pass :data:`AT_ROOT`'s test only with a rounding noise ROUNDING·ε·|c|(t) above
#: 10⁻⁶ of its slope times the range, a root known to no digit the quadrature could use.
NEAR = 1e-6


EPS = sys.float_info.epsilon


_SIZES: dict = {}


def _size_function(p: NumProblem, c: NumCond):
    """``c``'s magnitude as a function of the level's variables (the parameters as trailing
    arguments when ``c`` has its parametric form, so other parameter points reuse the compiled
    function); None when ``c`` has no expression or one through an implicit root (whose size is
    the root solved again, at every breakpoint: its root finder's bracket is its uncertainty)."""
    expr = c.sym if c.sym is not None and p.sbounds is not None else c.expr
    if expr is None or expr.has(ImplicitRootFn):
        return None  # (an implicit root's magnitude is the root again: its own tolerance stands)
    m = _SIZES.get(expr)
    if m is None:
        m = magnitude(sp.sympify(expr))
        remember(_SIZES, expr, m, COMPILED)
    return _lambdify(p.syms[: c.level + 1], m, p.at if expr is c.sym else {})


def uncertainty(p: NumProblem, level: int, prefix: tuple, t: float, span: float, owners=None) -> float:
    """δ at the breakpoint ``t`` of ``level`` (module doc); ``span`` the level's range (the central
    difference's step is 2⁻²⁶ of max(|t|, span)); ``owners``: the positions (in ``p.here(level)``) of
    the conditions ``t`` was found as a root of, or None (a range's end: every condition is asked;
    the stylization's large conditions, asked three times at each breakpoint, were 2 % of a partial
    derivative's instructions)."""
    delta = 4.0 * EPS * abs(t)
    sizes = p.sizes.get(level)
    if sizes is None:
        sizes = p.sizes[level] = [0] * len(p.here(level))  # (0: not compiled yet)
    scale = max(abs(t), span)
    here = p.here(level)
    for i in (range(len(here)) if owners is None else owners):
        c = here[i]
        v = c.f(*prefix, t)
        if not math.isfinite(v):
            continue
        step = 2.0 ** -26 * scale
        up, down = c.f(*prefix, t + step), c.f(*prefix, t - step)
        if math.isfinite(up) and math.isfinite(down):
            slope = (up - down) / (2.0 * step)
        elif math.isfinite(up):
            slope = (up - v) / step
        elif math.isfinite(down):
            slope = (v - down) / step
        else:
            continue
        if slope == 0.0 or not math.isfinite(slope) or abs(v) > NEAR * scale * abs(slope):
            continue
        size = sizes[i]
        if size == 0:
            size = sizes[i] = _size_function(p, c)
        if size is None:
            continue
        m = size(*prefix, t)
        if not math.isfinite(m):
            continue
        if abs(v) > AT_ROOT * ROUNDING * EPS * m + abs(slope) * ((0.0 if c.roots else XTOL) + FINDER * EPS * abs(t)):
            continue  # (its root is elsewhere)
        delta = max(delta, 4.0 * EPS * abs(t) + (abs(v) + ROUNDING * EPS * m) / abs(slope))
    return delta


#: :func:`end_allowance` takes the rough estimate (both ends' δ times the largest |integrand|
#: sampled on the sub-interval) as the allowance, without sampling next to the ends, when it is
#: below this fraction of the tolerance ``quad`` was asked for on the sub-interval
#: (max(eps, eps·|value|)): it is then a small share of what the bound already allows, whatever
#: the integrand does next to the ends.
QUIET = 0.1


#: The local samples of :func:`end_allowance` lie at d, 2d and 4d inward from the end, d = REACH·δ
#: (at least 4 units in the last place, the farthest sample inside the level's range): far enough from
#: the end that a condition's rounding noise (at most δ times its slope) does not decide the
#: integrand's value there, near enough to see its growth.  They may lie past the other end of a
#: sub-interval narrower than 64δ (the weight is one expression there too): sampled inside it, at
#: fractions of a width of a few units in the last place, the island's 1/√R read only R's noise.
REACH = 16.0


#: An end where the integrand sampled nearer to it is more than GROWTH times its value farther
#: away (d against 2d, 2d against 4d, d against 4d) is a singular end (|h| ~ s^-α with α above
#: log2(1.25) ≈ 0.32): there the breakpoint's rounding is not counted (:func:`end_allowance`).
GROWTH = 1.25


def end_allowance(deltas: tuple[float, float], a: float, b: float, bounds: tuple[float, float], size: float,
                  tol: float, sample) -> float:
    """What moving the ends of the sub-interval [a, b] by their rounding ``deltas`` (δ_a, δ_b,
    :func:`uncertainty`) may change in ∫_a^b h, h bounded near the end (paper §8.2's ⟦p⟧ at a point;
    the module's error analysis: nested quadrature's error is ``quad``'s estimate per level plus
    the allowances of :func:`~.nested.integrate_problem`, none of which sees where an end is).

    The true boundary lies within δ of the float end e, so the change is the integral of |h| over
    part of [e − δ, e + δ]: at most 2δ·max |h| there where h is bounded at that scale (the weight is
    one expression on both sides of a condition's root, so it is continuous across e).  That
    maximum is read from ``sample`` (a list of abscissae ↦ the integrand's values there) at d, 2d and
    4d inward from e (:data:`REACH`), not from the largest value sampled anywhere on [a, b]: next to
    an integrable singularity at e that largest value is the singularity's (4.5·10¹⁵ in
    test_undefined_sliver's island, 1/√ at a root of its guard) and times δ it made a bound of 8.46
    on −0.66.  Where the three samples grow towards e by more than :data:`GROWTH` (|h| ~ s^-α,
    α > 0.32), or one is not finite or not defined, the end is singular and nothing is added: there
    the weight's singularity is the condition's root computed again from the same float expression
    (the island's 1/(6√R) at R's root), so it moves with the breakpoint; its mass next to the end,
    2A√δ for A/√s, is the error of evaluating a singular weight in floating point, which this
    module does not count anywhere (nor at an integrable singularity inside a sub-interval,
    :func:`~.adaptive._quad`).  Below that growth, |h| ≤ max(samples)·(1 − α)⁻¹ ≤ 1.47·max on
    the δ-strip, within the factor 2 taken.  When the rough estimate (2(δ_a + δ_b) times ``size``,
    the largest |h| sampled on [a, b]) is below :data:`QUIET` times ``tol``, the tolerance ``quad``
    was asked for on [a, b], it is the allowance, unsampled (an ordinary program: δ ~ 10⁻¹⁵ of a
    sub-interval of width ~1, nothing to look at).  ``bounds`` is the level's range (the samples stay
    inside it: the weight may not be defined outside the box, and a sample there would make a bounded end look
    singular); ``sample`` is called once, with the six abscissae of both ends."""
    if not size > 0.0:
        return 0.0
    rough = 2.0 * (deltas[0] + deltas[1]) * size
    if rough <= QUIET * tol:
        return rough
    ends = ((a, 1.0, deltas[0]), (b, -1.0, deltas[1]))
    ts = []
    for end, side, delta in ends:
        room = bounds[1] - end if side > 0 else end - bounds[0]  # (the samples inside the range)
        d = max(min(REACH * delta, room / 4.0), 4.0 * math.ulp(end))  # (distinct floats)
        ts += [end + side * d, end + 2.0 * side * d, end + 4.0 * side * d]
    try:
        values = [abs(v) for v in sample(ts)]
    except (ArithmeticError, ValueError, TypeError, AttributeError):  # (UndefinedIntegral is a ValueError)
        return 0.0
    out = 0.0
    for (_, _, delta), (near, mid, far) in zip(ends, (values[:3], values[3:])):
        if not (math.isfinite(near) and math.isfinite(mid) and math.isfinite(far)):
            continue
        if near > GROWTH * mid or mid > GROWTH * far or near > GROWTH * far:
            continue  # a singular end (docstring)
        out += 2.0 * delta * max(near, mid, far)
    return out


def flat_size(values: list[float]) -> float | None:
    """The largest of ``values`` (the integrand at a point and at both sides of it) when all are
    finite and none is more than :data:`GROWTH` times another, i.e. the integrand is bounded and
    nearly constant there at the scale of the samples; None otherwise (a singularity, or rounding
    noise deciding the value)."""
    sizes = [abs(v) for v in values]
    if not all(math.isfinite(v) for v in sizes) or max(sizes) > GROWTH * min(sizes):
        return None
    return max(sizes)
