"""What the command line calls for the exact (symbolic) engine (CLI.md, JSON shapes).

* :func:`exact_eval` → the ``exact`` object of ``langur eval --json``;
* :func:`exact_deriv` → the ``exact`` object of ``langur deriv --json`` plus ``standard_ad`` (the
  regular part alone, the paper's Dˢ) and ``theorem_8_1`` (the check of Theorem 8.1).

Parameter values may be floats or Fractions; exact decimals are used as sympy Rationals (``0.5``
is 1/2).  When neither a closed form nor quadrature works, :class:`ExactUnavailable` is raised with
a one-line reason (the CLI then prints ``"exact": null`` and the reason on standard error);
:class:`ExactUndefined`, its subclass, when the integral does not exist (divergent, or undefined
on part of the domain).
"""

from __future__ import annotations

from collections.abc import Mapping

import sympy as sp

from ..core import Program
from .pieces import Integral, Method
from .quadrature import UndefinedIntegral, printable


class ExactUnavailable(Exception):
    """The symbolic engine cannot evaluate this program (the message says why, on one line)."""


class ExactUndefined(ExactUnavailable):
    """The integral does not exist (it diverges, or its integrand is undefined on part of the
    domain): an answer about the program, not a failure of the engine."""


def _number(v) -> float:
    """A plain float (NaN and infinities included, as the operational API returns them; the CLI
    writes them as CLI.md's strings ``"nan"``, ``"inf"``, ``"-inf"``)."""
    return float(v)


def _expr_text(e: sp.Expr | None) -> str | None:
    """The closed form as text; a rational of more than about 1,200 digits (Python refuses to
    print more than 4300) is written as a 30-digit float, and the text says so."""
    if e is None:
        return None
    shown = printable(e)
    return sp.sstr(shown) + ("   [numbers of more than 1,200 digits rounded to 30 digits in this text]"
                             if shown != e else "")


def _integral_fields(r: Integral) -> dict:
    out = {"value": _number(r.value), "expr": _expr_text(r.expr), "method": r.method}
    if r.method != Method.CLOSED_FORM:
        out["error"] = _number(r.error)
    out["notes"] = list(r.notes)
    return out


def _guard(fn, *args, **kwargs):
    try:
        return fn(*args, **kwargs)
    except UndefinedIntegral as e:
        raise ExactUndefined(f"undefined: {e.reason}") from e
    except (NotImplementedError, TypeError, ValueError, ZeroDivisionError, ArithmeticError, TimeoutError) as e:
        reason = str(e).splitlines()[0] if str(e) else type(e).__name__
        raise ExactUnavailable(f"symbolic engine: {reason}") from e


def exact_eval(program: Program, params: Mapping[str, float | object]) -> dict:
    """⟦p⟧ at ``params``: ``{"value", "expr", "method", "error" (quadrature only), "notes"}``."""
    from ..denote import denote_program

    return _integral_fields(_guard(denote_program, program, dict(params)))


def exact_deriv(program: Program, params: Mapping[str, float | object], direction: Mapping[str, float | object],
                *, check: bool = True) -> dict:
    """⦇p⦈ at ``params`` in the direction γ' = ``direction`` (``--wrt a`` is ``{"a": 1}``).

    Returns ``{"value", "regular", "boundary", "expr", "method", "error" (quadrature only),
    "notes", "standard_ad", "theorem_8_1"}``; ``regular + boundary = value`` and
    ``standard_ad = regular``; ``theorem_8_1`` is :func:`~langur.symbolic.theorem.check_theorem_8_1`'s
    dict (None when ``check`` is false or the check itself cannot be computed).
    """
    from ..ddenote import ddenote_program
    from .theorem import check_theorem_8_1

    params, direction = dict(params), dict(direction)
    res = _guard(ddenote_program, program, params, direction)
    out = {"value": _number(res.value), "regular": _number(res.regular.value),
           "boundary": _number(res.boundary.value), "expr": _expr_text(res.expr), "method": res.method}
    if res.method != Method.CLOSED_FORM:
        out["error"] = _number(res.error)
    out["notes"] = list(res.notes)
    out["standard_ad"] = _number(res.standard_ad)
    theorem = None
    if check:
        try:
            theorem = check_theorem_8_1(program, params, direction, derivative=res)
        except ExactUnavailable:
            raise
        except Exception as e:  # noqa: BLE001 - the check is a report, not a reason to lose the derivative
            out["notes"].append(f"Theorem 8.1 check not computed: {str(e).splitlines()[0] if str(e) else e!r}")
    if theorem is not None:
        theorem = {**theorem, "d_denotation": _number(theorem["d_denotation"]),
                   "derivative_denotation": _number(theorem["derivative_denotation"])}
    out["theorem_8_1"] = theorem
    return out
