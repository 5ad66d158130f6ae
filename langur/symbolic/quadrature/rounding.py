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
The nested integrator multiplies δ by the largest |h| sampled next to the end and carries inner
levels' allowances outward (:func:`~.nested._nested`).
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
