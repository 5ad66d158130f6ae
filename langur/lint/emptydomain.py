"""X314: an interval of the program's box that is empty at the parameter values in force.

The domain is sugar, not calculus's oriented integral (LANGUAGE.md §6, paper §8.3):
``int ([l, u]) t d(x)`` is ``int [x ≥ l]·[u ≥ x]·t d(x)``.  When ``l > u`` no ``x`` satisfies both
conditions, the integrand is 0 everywhere and the program's value is 0, with derivative 0: that is
the language's answer, and both engines give it.  Calculus would read ``∫ from 1 to 0`` as
``−∫ from 0 to 1``; a reader who meant that gets a silent 0, so the checker warns, at the interval,
and says what the value is.  The same holds for a box inferred from bounding indicators
(``[1 <= x] * [x <= 0]``), located at the program.

Parametric bounds (``[0, a]``) are judged at the parameter values in force (defaults, or ``--at``):
reversed there, the warning names the values.  An interval that is empty only for *other* values
is not reported (the value is 0 there too, as the semantics says); where its ends cross, ``l = u``,
the integral has a kink, and X304 reports that set when the values in force lie in it.
"""

from __future__ import annotations

from collections.abc import Mapping
from fractions import Fraction

import sympy as sp

from ..core import Program, free_params
from ..diagnostics import Span
from ..sympy_bridge import NotSmooth, symbol, to_sympy
from ..syntax.printer import print_core
from .findings import Finding


def _value(t, point: Mapping[str, object]) -> sp.Expr | None:
    """The bound's exact value at ``point`` (None: not a real number there, or not evaluable)."""
    try:
        e = to_sympy(t)
    except (NotSmooth, TypeError, ValueError):
        return None
    subs = {symbol(k): sp.Rational(v.numerator, v.denominator) if isinstance(v, Fraction) else sp.sympify(v)
            for k, v in point.items()}
    v = e.xreplace(subs)
    return v if v.is_real and v.is_finite else None


def empty_domain_findings(program: Program, point: Mapping[str, object] | None,
                          domain_spans: Mapping[tuple[int, int], Span] | None = None) -> list[Finding]:
    """One X314 warning per variable whose interval ``[lo, hi]`` has ``lo > hi`` at ``point``."""
    if point is None:
        return []
    out: list[Finding] = []
    spans = domain_spans or {}
    for i, (x, (lo, hi)) in enumerate(zip(program.variables, program.box)):
        a, b = _value(lo, point), _value(hi, point)
        if a is None or b is None or not bool(sp.N(a - b, 30) > 0):
            continue
        first = spans.get((i, 0)) or lo.span
        last = spans.get((i, 1)) or hi.span
        span = Span(first.path, first.line, first.col, last.end_line, last.end_col) \
            if first is not None and last is not None and first.path == last.path else program.span
        interval = f"[{print_core(lo)}, {print_core(hi)}]"
        moving = sorted(free_params(lo) | free_params(hi))
        at = (" at " + ", ".join(f"{k} = {_show(point[k])}" for k in moving)) if moving else ""
        ends = "" if not moving else f" ({_show(a)} > {_show(b)})"
        written = first is not None  # a domain interval the user wrote (else inferred from indicators)
        what = (f"the interval {interval} of {x} is empty{at}{ends}: a domain means the factors "
                f"[{x} >= {print_core(lo)}] * [{print_core(hi)} >= {x}], 0 everywhere here"
                if written else
                f"the bounding indicators leave {x} the empty interval {interval}{at}{ends}: the integrand "
                "is 0 everywhere")
        out.append(Finding(
            span, "warning", "X314",
            f"{what}, so the integral is 0 (and so is its derivative), not minus the integral over "
            f"[{print_core(hi)}, {print_core(lo)}] as in calculus; write the lower end first if that is what "
            "you meant", params=tuple(moving)))
    return out


def _show(v) -> str:
    if isinstance(v, Fraction):
        return str(v.numerator) if v.denominator == 1 else f"{float(v):g}"
    try:
        f = float(v)
    except (TypeError, ValueError):
        return str(v)
    return f"{f:g}"
