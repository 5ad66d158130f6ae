"""What an implicit root's bracket implies (issue 18; paper §7.3's delta pieces through an
implicit root): a box condition on the root's variable that holds wherever the root exists, left
out of the delta's problem by :mod:`langur.symbolic.quadrature.deltaproblems`.
"""

from __future__ import annotations

import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.precise import real_number_at


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
        k, c0 = (real_number_at(c, at) for c in poly.all_coeffs())
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
    v = real_number_at(e, at)
    return v, v

