"""Teg (Bangaru, Michel et al., SIGGRAPH Asia 2021; github.com/ChezJrk/Teg) behind Langur's engine
protocol (docs/engines.md), so that `langur fuzz` and `langur deriv` can test it against the exact
engine.  Our code against Teg's public API; Teg itself is installed by the user from its public
repository and never shipped here.

    PYTHONPATH=/path/to/teg-checkout:examples/adapters \\
        langur deriv examples/fig1.lgr --wrt theta --engine teg_engine:make

What is translated (the rest is declined, counted apart, never a disagreement):

* constants, parameters, variables, ``+``, ``*``, integer and half-integer powers (products and a
  ``Sqrt``; negative: Teg's ``Invert``), the primitives Teg has (``sqrt``, ``sin``, ``cos``, ``exp``);
* ``let`` of a parameter term (the bound expression is used in its place);
* conditionals: Teg's ``IfElse`` on the comparison ``condition >= 0``.  Teg integrates any
  condition, but its derivative handles only discontinuities affine in the variables: on a curved
  one ``reduce_to_base`` raises "Cannot find any handler for delta expression", and the adapter
  declines the derivative with Teg's words (its value is still compared);
* integrals in one or two variables (nested ``Teg``); a declared domain's bounds are Teg's bounds
  (Teg differentiates moving bounds by the Leibniz rule); without a domain, the body over its box,
  which must not move.

The derivative is Teg's ``fwd_deriv`` reduced by ``reduce_to_base`` (which eliminates the deltas
by the sifting property), evaluated by Teg's numpy backend: a *deterministic* trapezoidal rule with
``N`` points per variable (no sampling; Teg's C backend uses a rectangle rule).  The adapter
declares it ``bounded``, with the error *estimated* as ``SAFETY`` = 4 times the largest
|I(N) − I(M)| over two coarser, non-nested grids M = N/2 and 2N/3 + 1: on a jump the rule's error
is of the order of the step with a size and sign that depend on where the jump falls in its cell,
so grids can agree by coincidence (a generated program's value at N = 120, 60, 81, 240 points:
−0.9941, −0.9915, −0.9913, −1.0063, truth −1.001: the differences under-estimate the error 2.4
times).  This is an estimate, not a guaranteed bound, and the notes say so: a disagreement
that is quadrature error shrinks when ``LANGUR_TEG_POINTS`` (a factor on ``N``, default 1) grows,
a wrong answer does not.
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from fractions import Fraction

from langur import core
from langur.engines import Answer, Declined, Kind

try:  # Teg is the user's install; without it every program is declined, with the reason
    from teg import Const, IfElse, Invert, Teg, TegVar, Var
    from teg.derivs.fwd_deriv import fwd_deriv
    from teg.eval import evaluate as teg_evaluate
    from teg.math.smooth import Cos, Exp, Sin, Sqrt
    from teg.passes.reduce import reduce_to_base
except (ImportError, AssertionError) as e:  # pragma: no cover - depends on the user's machine
    Teg = None
    MISSING = f"Teg is not importable ({e}); clone github.com/ChezJrk/Teg and put it on PYTHONPATH"
else:
    MISSING = ""

POINTS = {1: 2000, 2: 120}  # trapezoidal points per variable, by the number of variables
SAFETY = 4.0  # the error estimate's factor over the largest difference between grids


class Unsupported(Exception):
    """A construct Teg's language does not have: the program is declined."""


def _number(c: core.Const) -> float:
    if isinstance(c.value, str):
        raise Unsupported(f"constant {c.value}")
    return float(c.value)


def _power(base, n: int):
    out = base
    for _ in range(n - 1):
        out = out * base
    return out


def _mentions(t: core.Term, kind) -> bool:
    match t:
        case core.Var() | core.Param():
            return isinstance(t, kind)
        case core.Const():
            return False
        case core.Add(left=a, right=b) | core.Mul(left=a, right=b):
            return _mentions(a, kind) or _mentions(b, kind)
        case core.Prim(arg=a) | core.Pow(base=a):
            return _mentions(a, kind)
        case core.Let(bound=a, body=b):
            return _mentions(a, kind) or _mentions(b, kind)
        case core.IfGe0(cond=c, then=a, orelse=b):
            return _mentions(c, kind) or _mentions(a, kind) or _mentions(b, kind)
        case core.IfDiffeo(psi=psi, then=a, orelse=b):
            return any(_mentions(f, kind) for f in psi.forward) or _mentions(a, kind) or _mentions(b, kind)
    return True


def _pow(base, e: Fraction):
    """``base ** e`` for an integer or half-integer ``e``: repeated products, ``Sqrt``, a reciprocal."""
    if e.denominator not in (1, 2) or e == 0:
        raise Unsupported(f"power {e}")
    whole = int(abs(e))
    out = _power(base, whole) if whole else None
    if abs(e).denominator == 2:
        out = Sqrt(base) if out is None else out * Sqrt(base)
    return Invert(out) if e < 0 else out


def _term(t: core.Term, scope: Mapping[str, object]):
    """A Langur core term as a Teg expression (one case per constructor of the core AST)."""
    match t:
        case core.Const():
            return Const(_number(t))
        case core.Var(name=n) | core.Param(name=n):
            return scope[n]
        case core.Add(left=a, right=b):
            return _term(a, scope) + _term(b, scope)
        case core.Mul(left=a, right=b):
            return _term(a, scope) * _term(b, scope)
        case core.Prim(op=op, arg=a):
            prim = {"sqrt": Sqrt, "sin": Sin, "cos": Cos, "exp": Exp}.get(op)
            if prim is None:
                raise Unsupported(f"Teg has no primitive {op}")
            return prim(_term(a, scope))
        case core.Pow(base=b, exponent=e):
            return _pow(_term(b, scope), e)
        case core.IfGe0(cond=c, then=a, orelse=b):
            return IfElse(_term(c, scope) >= 0, _term(a, scope), _term(b, scope))
        case core.IfDiffeo(psi=psi, then=a, orelse=b):
            return IfElse(_term(psi.condition, scope) >= 0, _term(a, scope), _term(b, scope))
        case core.Let(name=n, bound=b, body=body):
            return _term(body, {**scope, n: _term(b, scope)})
        case core.Call():
            raise Unsupported("a call (programs reach engines inlined)")
    raise Unsupported(f"{type(t).__name__}")


def _integral(program: core.Program, params: Mapping[str, float]):
    """Teg's ∫ of the program, and its parameters as Teg variables bound to their values."""
    if len(program.variables) > 2:
        raise Unsupported(f"{len(program.variables)} variables (this adapter translates 1 and 2)")
    pv = {n: Var(n, float(v)) for n, v in params.items()}
    tv = {x: TegVar(x) for x in program.variables}
    scope = {**pv, **tv}
    if program.domain:
        body = _term(program.integrand, scope)
        bounds = [(iv.variable, iv.lo, iv.hi) for iv in program.domain]
    else:
        body = _term(program.body, scope)
        bounds = [(x, lo, hi) for x, (lo, hi) in zip(program.variables, program.box)]
        if any(_mentions(lo, core.Param) or _mentions(hi, core.Param) for _, lo, hi in bounds):
            raise Unsupported("a box read off indicators that move (no declared domain)")
    for x, lo, hi in reversed(bounds):
        body = Teg(_term(lo, scope), _term(hi, scope), body, tv[x])
    return body, pv


class TegEngine:
    name = "teg"
    kind = Kind.BOUNDED

    def value(self, program, params):
        return self._run(program, params, None)

    def derivative(self, program, params, direction):
        return self._run(program, params, direction)

    def _run(self, program, params, direction):
        if Teg is None:
            return Declined(MISSING)
        n = round(POINTS.get(len(program.variables), 100) * float(os.environ.get("LANGUR_TEG_POINTS", "1")))
        grids = (n, n // 2, (2 * n) // 3 + 1)
        try:
            results = []
            for points in grids:  # Teg caches values in its tree: build it afresh each time
                expr, pv = _integral(program, params)
                if direction is not None:
                    expr = reduce_to_base(fwd_deriv(expr, [(pv[k], float(direction.get(k, 0.0))) for k in pv]))
                results.append(float(teg_evaluate(expr, num_samples=points, backend="numpy")))
        except Unsupported as e:
            return Declined(str(e))
        except AssertionError as e:
            if "Cannot find any handler" in str(e):  # Teg's refusal of a delta it has no rule for
                return Declined("Teg cannot differentiate this discontinuity (no handler for its delta: "
                                "Teg's derivative takes conditions affine in the variables)")
            return Declined(f"Teg failed: AssertionError: {str(e).splitlines()[0] if str(e) else ''}")
        except Exception as e:  # noqa: BLE001 - Teg raises many kinds of errors on what it cannot do
            return Declined(f"Teg failed: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        fine, *coarse = results
        if not math.isfinite(fine):
            return Answer(math.nan, math.inf, ("Teg returned a non-finite value",))
        error = SAFETY * max(abs(fine - c) for c in coarse)
        return Answer(fine, error, (f"Teg's trapezoidal rule with {n} points per variable; error estimated "
                                    f"from {grids[1]} and {grids[2]} points (not a guaranteed bound)",))


def make():
    return TegEngine()
