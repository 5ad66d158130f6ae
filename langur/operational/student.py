"""Student's t tail, for the standard error of a design of a few independent replicates.

A design of R independent replicates (``--method stratified`` and ``qmc``: :mod:`.sample`) estimates
its variance from the R replicates' means, with R − 1 degrees of freedom.  Even when those means are
normal, (estimate − mean)/(estimated standard error) is then Student's t with R − 1 degrees of
freedom, not normal: the project's rule "agree within 5 standard errors" (false alarms 5.7e-7 for a
normal estimate) would fire 2.1e-5 of the time with R = 32.  :func:`widening` is the factor by which
such a standard error is multiplied so that 5 of them are t's quantile at the normal rule's rate.

The tail is Abramowitz & Stegun 26.7.3–4 (the t distribution's CDF for integer degrees of freedom
as a finite trigonometric sum), so this needs neither scipy nor mpmath.
"""

from __future__ import annotations

import functools
import math

#: The project's comparison rule: within this many standard errors.
SIGMA = 5.0


def two_sided_tail(t: float, nu: int) -> float:
    """P(|T| > t) for Student's t with ``nu`` ≥ 1 degrees of freedom (t ≥ 0)."""
    theta = math.atan(t / math.sqrt(nu))
    s, c2 = math.sin(theta), math.cos(theta) ** 2
    if nu % 2:  # A(t|ν) = (2/π)(θ + sin θ (cos θ + (2/3) cos³θ + … + (2·4…(ν−3))/(1·3…(ν−2)) cos^(ν−2) θ))
        term, total = math.cos(theta), 0.0
        for k in range(1, (nu - 1) // 2 + 1):
            total += term
            term *= c2 * (2 * k) / (2 * k + 1)
        inside = (2 / math.pi) * (theta + s * total) if nu > 1 else (2 / math.pi) * theta
    else:  # A(t|ν) = sin θ (1 + (1/2) cos²θ + (1·3)/(2·4) cos⁴θ + … + (1·3…(ν−3))/(2·4…(ν−2)) cos^(ν−2) θ)
        term, total = 1.0, 0.0
        for k in range(1, nu // 2 + 1):
            total += term
            term *= c2 * (2 * k - 1) / (2 * k)
        inside = s * total
    return max(0.0, 1.0 - inside)


@functools.cache
def widening(replicates: int) -> float:
    """The factor q/5, q = Student's t quantile with ``replicates`` − 1 degrees of freedom whose
    two-sided tail is the normal distribution's beyond 5 (5.7e-7): 1.2536 for 32 replicates."""
    target = math.erfc(SIGMA / math.sqrt(2.0))
    nu = replicates - 1
    lo, hi = SIGMA, SIGMA
    while two_sided_tail(hi, nu) > target:
        hi *= 2.0
    for _ in range(200):  # bisection to the last bit
        mid = 0.5 * (lo + hi)
        if mid in (lo, hi):
            break
        lo, hi = (mid, hi) if two_sided_tail(mid, nu) > target else (lo, mid)
    return hi / SIGMA
