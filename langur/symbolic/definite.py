"""``F(b) − F(a)`` for an antiderivative ``F`` in ``v``: the fundamental theorem of calculus with its
ends taken from inside the interval.

``F`` is continuous on the closed interval wherever the integrand is integrable there, so ``F(b)``
is ``F``'s value at ``b`` — except where ``F``'s formula is an indeterminate form at the end
itself: ``∫₀¹ log|x − a| dx`` has ``F = (x − a)·log(x − a) − x`` on ``x > a``, whose lower end
``x = Max(0, a)`` is ``a`` when ``a > 0``, and ``F(a)`` is ``0·log 0`` there, which sympy evaluates
to NaN although the limit is ``−a``.  Such an end is evaluated as the one-sided limit
``lim_{ε→0⁺} F(b − ε)`` (``F(a + ε)`` at the lower end), with the end's ``Max``/``Min`` taken as
the argument it is at the evaluation point (the comparisons recorded in the cell, so the closed
form is claimed only where that choice holds).  Only formulas with a ``log`` or a non-integer or
negative power can be such forms; a polynomial's, an exponential's … ends are substituted as
before, at no cost.  The closed form is cross-checked by quadrature like every other
(``integrate._exact_piece``).
"""

from __future__ import annotations

import math

import sympy as sp

from langur.symbolic.context import Context, Unsupported
from langur.symbolic.readable import resolve
from langur.symbolic.walks import atoms_of, has_any, mentions

#: CPU seconds sympy's ``limit`` may take at one end.  It is fast on the forms it can do (0.04–0.06 s
#: for ``ε·log ε`` on a quiet machine); with 0.5 s the closed form of ``∫₀¹ log|x − a|`` once became
#: quadrature in CI, in a long-lived test worker (not reproduced here: a full collection of a large
#: heap falling inside the call costs ~0.25 s per 12 M objects).  2 s leaves a wide margin and still
#: bounds a hard form.
LIMIT_CAP = 2.0
#: What sympy makes of 0·∞ and ∞ − ∞ (NaN) and of log 0, 1/0 (complex infinity).
_INDETERMINATE = (type(sp.nan), type(sp.zoo))


def definite(F, v, lo, hi, ctx: Context):
    """``F(hi⁻) − F(lo⁺)`` (see the module's docstring)."""
    singular = _singular_arguments(F, v)
    if not singular:
        return F.xreplace({v: hi}) - F.xreplace({v: lo})
    return _from_inside(F, v, hi, -1, ctx, singular) - _from_inside(F, v, lo, +1, ctx, singular)


def at_end(F, v, end, side: int, ctx: Context):
    """``F`` at ``end`` of the interval, approached from ``side`` (+1: from above, the lower end;
    −1: from below, the upper end): ``F(end)``, or its one-sided limit where ``F(end)`` is an
    indeterminate form at the evaluation point."""
    singular = _singular_arguments(F, v)
    if not singular:
        return F.xreplace({v: end})
    return _from_inside(F, v, end, side, ctx, singular)


def _from_inside(F, v, end, side: int, ctx: Context, singular: list):
    """:func:`at_end` for an ``F`` with ``singular`` arguments (:func:`_singular_arguments`)."""
    value = F.xreplace({v: end})
    if has_any(value, _INDETERMINATE):
        pass  # (indeterminate whatever the parameters: e.g. (y − y)·log(y − y) at an outer variable's end)
    elif sp.sympify(value).free_symbols - set(ctx.at) or not _vanishes_here(singular, v, end, ctx) \
            or _finite_here(value, ctx):
        return value  # (an outer variable's end not seen to be indeterminate; no singular argument 0 here; or
        # F's value there is a number all the same: √0 = 0)
    here = _resolved(sp.sympify(end), ctx)
    if here is None:
        return value
    eps = sp.Dummy("eps", positive=True)
    try:
        limit = ctx.deadline.run(lambda: sp.limit(F.xreplace({v: here + side * eps}), eps, 0, "+"),
                                 cap=min(LIMIT_CAP, max(0.0, ctx.deadline.remaining())))
    except TimeoutError:
        return value
    except Exception:  # noqa: BLE001 - sympy raises all sorts of errors on hard inputs
        return value
    if has_any(limit, (sp.Limit, *_INDETERMINATE, type(sp.oo), type(-sp.oo))) or v in limit.free_symbols:
        return value
    if not (limit.free_symbols - set(ctx.at)) and not _finite_here(limit, ctx):
        return value
    return limit


def _singular_arguments(F, v) -> list:
    """The arguments in ``v`` of ``F``'s logarithms and negative or non-integer powers: the only
    ways an elementary antiderivative's formula becomes 0·∞ or ∞ − ∞ at a point where the function
    itself is continuous (where one of them is 0).  Each distinct subterm looked at once."""
    vs, memo = frozenset((v,)), {}
    out = []
    for node in atoms_of(F, (sp.log, sp.Pow)):
        arg = node.args[0] if isinstance(node, sp.log) else node.base
        if isinstance(node, sp.Pow) and node.exp.is_Integer and node.exp >= 0:
            continue
        if mentions(arg, vs, memo):
            out.append(arg)
    return out


def _vanishes_here(singular: list, v, end, ctx: Context) -> bool:
    """Whether one of the ``singular`` arguments is 0 (or not valued) at ``end`` at the point:
    the small arguments are valued, not the whole formula."""
    for arg in singular:
        try:
            z = ctx.value(arg.xreplace({v: end}))
        except (TypeError, ValueError, ZeroDivisionError, Unsupported):
            return True
        if not (math.isfinite(z.real) and math.isfinite(z.imag)) or abs(z) < 1e-20:
            return True
    return False


def _finite_here(expr, ctx: Context) -> bool:
    try:
        z = ctx.value(expr)
    except (TypeError, ValueError, ZeroDivisionError, Unsupported):
        return False
    return math.isfinite(z.real) and math.isfinite(z.imag)


def _resolved(end, ctx: Context):
    """``end`` with each ``Max``/``Min`` replaced by the argument it is at the evaluation point, the
    comparisons that choice rests on recorded in the cell; None when one is a tie there (then no
    single formula holds on both sides)."""
    extrema = atoms_of(end, (sp.Max, sp.Min))
    if not extrema:
        return end
    for node in extrema:
        args = node.args
        for i in range(len(args)):
            for j in range(i + 1, len(args)):
                d = args[i] - args[j]
                if d.free_symbols - set(ctx.at):
                    return None  # (an outer variable: not decided at the point)
                try:
                    z = ctx.value(d)
                except (TypeError, ValueError, ZeroDivisionError):
                    return None
                if abs(z.real) < 1e-25:
                    return None
                ctx.record(">", d if z.real > 0 else -d)
    return resolve(end, ctx.at)
