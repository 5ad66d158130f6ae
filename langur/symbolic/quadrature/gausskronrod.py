"""QUADPACK's 21-point Gauss–Kronrod rule on one panel, vectorized (issue 13, camp5/camp8): the
innermost integrals of paper §8.2's ⟦p⟧ first try one panel with the weight evaluated by one numpy
call; when QUADPACK's ``dqagse`` would stop after that panel the answer is the same numbers.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

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


def _first_panel(vw: Callable, prefix: tuple, a: float, b: float, eps: float, top: list | None = None):
    """``(value, error)`` of ∫_a^b when QUADPACK's ``dqagse`` (scipy's ``quad``) would stop after
    its first 21-point panel — the panel's error estimate within ``max(eps, eps·|value|)`` and not
    saturated, every value finite — computed with the weight vectorized (one numpy call instead
    of 21 Python calls); None otherwise (then ``quad`` integrates it as before), and
    :data:`UNVECTORIZABLE` when the vectorized weight raises (its problem stops trying).  ``top``,
    when given, gets the largest |value| of the panel as its first item (:mod:`.rounding`)."""
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
        if top is not None:
            top[0] = float(np.abs(y).max())
        return float(result), float(abserr)
    return None

