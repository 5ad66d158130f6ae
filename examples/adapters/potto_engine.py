"""Potto (Michel et al., OOPSLA 2024's prototype; github.com/divicomp/potto) behind Langur's engine
protocol (docs/engines.md), so that `langur fuzz` and `langur deriv` can test it against the exact
engine.  Our code against Potto's public API; Potto itself is installed by the user from its public
repository and never shipped here.

    PYTHONPATH=/path/to/potto-checkout:examples/adapters \\
        langur deriv examples/fig1.lgr --wrt theta --engine potto_engine:make

What is translated (the rest is declined, counted apart, never a disagreement):

* constants, parameters, variables, ``+``, ``*``, integer and half-integer powers (products and a
  ``Sqrt``; negative: a quotient) and the primitives Potto has (``sqrt``, ``exp``, ``abs``);
* ``let`` of a parameter term (the bound expression is used in its place);
* a conditional on the parameters alone (Potto's ``IfElse`` on an expression; Potto's test is
  ``> 0`` where Langur's is ``>= 0``, which differ only where the condition is exactly 0);
* a diffeomorphic conditional: Potto's ``IfElse`` on a ``Diffeomorphism`` whose ``function`` is
  Langur's Ψ̂ and whose ``inverse`` is one inverse branch.  Potto's diffeomorphisms have exactly
  one inverse (its own library writes ``t²x² − 1`` with the one root ``sqrt(y + 1)/t``); a Langur
  condition with several branches (``x² − a``: ±sqrt(u + a)) is given to Potto with its first
  branch, as a Potto user would write it — the campaign then shows what that costs.  Set
  ``LANGUR_POTTO_SINGLE_BRANCH=decline`` to decline such programs instead.  In two variables the
  variable the condition is solved for is Potto's first tvar (Potto weighs the delta by
  1/|∂Ψ₀/∂t₀|); a declared diffeomorphism in several variables is declined;
* integrals in one or two variables (``Int`` of ``BoundedLebesgue``): a declared domain's bounds
  become the measure's (Potto differentiates moving bounds by the Leibniz rule); without a domain,
  the body over its box, which must not move.

Potto estimates by Monte Carlo with numpy's global generator (and Python's ``random`` to pick a
trace): the answer is the mean of ``BATCHES`` independent estimates, each seeded, and its standard
error their sample standard deviation over √BATCHES (both generators are restored afterwards).
``LANGUR_POTTO_BATCHES`` and ``LANGUR_POTTO_SAMPLES`` change the 20 batches of 100 samples: Potto
is pure Python and samples each nested integral afresh (100 × 100 points per batch in two
variables), so a campaign over two-variable programs wants fewer.
"""

from __future__ import annotations

import math
import os
import random
import statistics
from collections.abc import Mapping
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from langur import core
from langur.engines import Answer, Declined, EngineFailure, Kind
from langur.primitives import REGISTRY

try:  # Potto is the user's install; without it every program is declined, with the reason
    import potto
    from potto import BoundedLebesgue, Const, Diffeomorphism, IfElse, Int, Sym, TegVar, Var, VarVal
    from potto import deriv as potto_deriv
    from potto import evaluate as potto_evaluate
    from potto.libs.pmath import Abs, Exp, Sqrt
except ImportError as e:  # pragma: no cover - depends on the user's machine
    potto = None
    MISSING = f"Potto is not importable ({e}); clone github.com/divicomp/potto and put it on PYTHONPATH"
else:
    MISSING = ""

#: Errors of arithmetic in Potto's evaluation are its failures (its ``Sqrt.deriv`` divides by
#: ``2*Sqrt(u')``: ZeroDivisionError when u' = 0); any other exception is taken as Potto's refusal.
ARITHMETIC = (ZeroDivisionError, OverflowError, ValueError)
BATCHES = int(os.environ.get("LANGUR_POTTO_BATCHES", "20"))
SAMPLES = int(os.environ.get("LANGUR_POTTO_SAMPLES", "100"))  # per batch (and per level of nested integrals)
SEED = 0


class Unsupported(Exception):
    """A construct Potto's language does not have: the program is declined."""


@dataclass
class _Scope:
    tvars: dict[str, object]  # Langur variable -> Potto expression
    params: dict[str, object]  # Langur parameter (or let-bound name) -> Potto expression
    values: Mapping[str, float] | None = None  # the parameters' values (to check inverse branches)
    lets: tuple[tuple[str, core.Term], ...] = ()  # the enclosing lets (variable-free bounds), outermost first


def _num(t: core.Term, env: Mapping[str, float]) -> float:
    """A term over parameters (and the inverse's inputs) at ``env``, in floats."""
    match t:
        case core.Const():
            return _number(t)
        case core.Var(name=n) | core.Param(name=n):
            return env[n]
        case core.Add(left=a, right=b):
            return _num(a, env) + _num(b, env)
        case core.Mul(left=a, right=b):
            return _num(a, env) * _num(b, env)
        case core.Prim(op=op, arg=a):
            return REGISTRY[op].scalar(_num(a, env))
        case core.Pow(base=b, exponent=e):
            return _num(b, env) ** float(e)
        case core.Let(name=n, bound=b, body=body):
            return _num(body, {**env, n: _num(b, env)})
        case core.IfGe0(cond=c, then=a, orelse=b):
            return _num(a, env) if _num(c, env) >= 0 else _num(b, env)
    raise Unsupported(f"{type(t).__name__} in an inverse branch's guard")


def _number(c: core.Const) -> float:
    if isinstance(c.value, str):
        raise Unsupported(f"constant {c.value}")
    return float(c.value)


def _power(base, n: int):
    out = base
    for _ in range(n - 1):
        out = out * base
    return out


def _pow(base, e: Fraction):
    """``base ** e`` for an integer or half-integer ``e``: repeated products, ``Sqrt``, a reciprocal."""
    if e.denominator not in (1, 2) or e == 0:
        raise Unsupported(f"power {e}")
    whole = int(abs(e))
    out = _power(base, whole) if whole else None
    if abs(e).denominator == 2:
        out = Sqrt(base) if out is None else out * Sqrt(base)
    return Const(1.0) / out if e < 0 else out


def _term(t: core.Term, s: _Scope):
    """A Langur core term as a Potto expression (one case per constructor of the core AST)."""
    match t:
        case core.Const():
            return Const(_number(t))
        case core.Var(name=n):
            return s.tvars[n]
        case core.Param(name=n):
            return s.params[n]
        case core.Add(left=a, right=b):
            return _term(a, s) + _term(b, s)
        case core.Mul(left=a, right=b):
            return _term(a, s) * _term(b, s)
        case core.Prim(op=op, arg=a):
            prim = {"sqrt": Sqrt, "exp": Exp, "abs": Abs}.get(op)
            if prim is None:
                raise Unsupported(f"Potto has no primitive {op}")
            return prim(_term(a, s))
        case core.Pow(base=b, exponent=e):
            return _pow(_term(b, s), e)
        case core.IfGe0(cond=c, then=a, orelse=b):
            return IfElse(_term(c, s), _term(a, s), _term(b, s))
        case core.IfDiffeo(psi=psi, then=a, orelse=b):
            return IfElse(_diffeo(psi, s), _term(a, s), _term(b, s))
        case core.Let(name=n, bound=b, body=body):
            values = None if s.values is None else {**s.values, n: _num(b, s.values)}
            return _term(body, _Scope(s.tvars, {**s.params, n: _term(b, s)}, values, (*s.lets, (n, b))))
        case core.Call():
            raise Unsupported("a call (programs reach engines inlined)")
    raise Unsupported(f"{type(t).__name__}")


def _diffeo(psi: core.Diffeo, s: _Scope):
    """Langur's Ψ̂ as a Potto Diffeomorphism: ``function`` = Ψ̂, ``inverse`` = one branch of Ψ̂⁻¹."""
    if len(psi.branches) != 1 and os.environ.get("LANGUR_POTTO_SINGLE_BRANCH") == "decline":
        raise Unsupported(f"a condition with {len(psi.branches)} inverse branches; Potto takes one")
    let_names = {n for n, _ in s.lets}
    names = sorted(n for n in s.params if n not in let_names)  # Potto's vars are its Var objects
    branch = psi.branches[0]
    if branch.guards:  # Potto's inverse is total: it is evaluated wherever Potto samples u'
        if len(psi.variables) > 1:
            raise Unsupported("an inverse branch that exists only where its guard holds, in several "
                              "variables (Potto's inverse is evaluated on the whole image box)")
        env = {**(s.values or {}), **{u: 0.0 for u in psi.inputs}}
        if not all(_num(g, env) >= 0 for g in branch.guards):
            raise Unsupported("the condition's inverse branch does not exist at these parameter values "
                              "(Potto would evaluate it anyway)")

    # Potto weighs a sample of the delta by 1/|∂Ψ₀/∂t₀| (reweight_samples_with_diffeo), the Jacobian
    # only when Ψ̂ = (condition, the other variables) with t₀ the variable the condition is solved
    # for: so that variable goes first (Langur's order gave 1/|∂(y − x² − a)/∂x| = 1/|2x|: a
    # heavy-tailed, biased estimate, and 1/0 for a condition on y alone).
    if len(psi.variables) > 1 and psi.solved_for is None:
        raise Unsupported("a declared diffeomorphism in several variables (Potto weighs its delta by "
                          "1/|∂Ψ₀/∂t₀|, the Jacobian only when Ψ̂ = (condition, the other variables))")
    order = (psi.solved_for, *[v for v in psi.variables if v != psi.solved_for]) if psi.solved_for \
        else psi.variables
    position = [psi.variables.index(v) for v in order]

    def params_of(vars_):  # the parameters, then the lets in scope, over Potto's vars
        params = dict(zip(names, vars_))
        for n, bound in s.lets:
            params[n] = _term(bound, _Scope({}, params))
        return params

    def function(self, vars_, tvars_):
        return tuple(_term(f, _Scope(dict(zip(order, tvars_)), params_of(vars_))) for f in psi.forward)

    def inverse(self, vars_, tvars_):  # the variables in Potto's order (``order``)
        return tuple(_term(branch.components[i], _Scope(dict(zip(psi.inputs, tvars_)), params_of(vars_)))
                     for i in position)

    def bounds_transfer(self, lower, upper, env):
        # Ψ̂'s image of the box, from Ψ̂ on a grid of it (Potto's Affine uses the corners)
        grids = np.meshgrid(*[np.linspace(potto_evaluate(lo, env), potto_evaluate(hi, env), 9)
                              for lo, hi in zip(lower, upper)], indexing="ij")
        points = np.stack([g.ravel() for g in grids], axis=1)
        images = np.array([[potto_evaluate(f, env) for f in self.function(self.vars, tuple(Const(float(c))
                                                                                        for c in p))]
                           for p in points])
        return tuple(images.min(axis=0)), tuple(images.max(axis=0))

    cls = type("LangurDiffeo", (Diffeomorphism,), {"function": function, "inverse": inverse,
                                                    "bounds_transfer": bounds_transfer})
    return cls(tuple(s.params[n] for n in names), tuple(s.tvars[x] for x in order))


def _mentions_param(t) -> bool:
    match t:
        case core.Param():
            return True
        case core.Const() | core.Var():
            return False
        case core.Add(left=a, right=b) | core.Mul(left=a, right=b):
            return _mentions_param(a) or _mentions_param(b)
        case core.Prim(arg=a) | core.Pow(base=a):
            return _mentions_param(a)
        case core.Let(bound=a, body=b):
            return _mentions_param(a) or _mentions_param(b)
        case core.IfGe0(cond=c, then=a, orelse=b):
            return _mentions_param(c) or _mentions_param(a) or _mentions_param(b)
    return True


def _integral(program: core.Program, params: Mapping[str, float]):
    """Potto's ∫ of the program and its parameters.  A declared domain becomes Potto's measure
    bounds (parameters allowed: Potto differentiates them by the Leibniz rule) around the
    integrand; without one, the body (whose indicators bound it) over the box, which must not move."""
    if len(program.variables) > 2:
        raise Unsupported(f"{len(program.variables)} variables (this adapter translates 1 and 2)")
    pv = {n: Var(n) for n in sorted(params)}
    tv = {x: TegVar(x) for x in program.variables}
    scope = _Scope(tv, pv, {n: float(v) for n, v in params.items()})
    if program.domain:
        body = _term(program.integrand, scope)
        bounds = [(iv.variable, iv.lo, iv.hi) for iv in program.domain]
    else:
        body = _term(program.body, scope)
        bounds = [(x, lo, hi) for x, (lo, hi) in zip(program.variables, program.box)]
        if any(_mentions_param(lo) or _mentions_param(hi) for _, lo, hi in bounds):
            raise Unsupported("a box read off indicators that move (no declared domain)")
    for x, lo, hi in reversed(bounds):
        body = Int(body, BoundedLebesgue(_term(lo, scope), _term(hi, scope), tv[x]))
    return body, pv


class PottoEngine:
    name = "potto"
    kind = Kind.STOCHASTIC

    def value(self, program, params):
        return self._run(program, params, None)

    def derivative(self, program, params, direction):
        return self._run(program, params, direction)

    def _run(self, program, params, direction):
        if potto is None:
            return Declined(MISSING)
        try:
            expr, pv = _integral(program, params)
            vals = {pv[n].name: float(v) for n, v in params.items()}
            if direction is not None:
                ctx = {pv[n].name: Sym(f"d{n}") for n in pv}
                expr = potto_deriv(expr, ctx)
                vals.update({ctx[pv[n].name]: float(direction.get(n, 0.0)) for n in pv})
        except Unsupported as e:
            return Declined(str(e))
        except Exception as e:  # noqa: BLE001 - Potto's deriv refuses what it cannot do by raising
            return Declined(f"Potto failed: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        rng_state, py_state = np.random.get_state(), random.getstate()
        try:
            estimates = []
            for k in range(BATCHES):  # numpy's generator samples; Python's picks among traces (Samples.__or__)
                np.random.seed(SEED + k)
                random.seed(SEED + k)
                estimates.append(float(potto_evaluate(expr, VarVal(vals), SAMPLES)))
        except Unsupported as e:  # raised from inside Potto, when it asks a diffeomorphism for its inverse
            return Declined(str(e))
        except ARITHMETIC as e:  # a number Potto computed is wrong: a failure, not a refusal
            raise EngineFailure(f"Potto raised {type(e).__name__}: {e}") from None
        except Exception as e:  # noqa: BLE001 - Potto raises many kinds of errors on what it cannot do
            return Declined(f"Potto failed: {type(e).__name__}: {str(e).splitlines()[0] if str(e) else ''}")
        finally:
            np.random.set_state(rng_state)
            random.setstate(py_state)
        if not all(math.isfinite(v) for v in estimates):
            return Answer(math.nan, math.inf, ("Potto returned a non-finite estimate",))
        mean = statistics.fmean(estimates)
        se = statistics.stdev(estimates) / math.sqrt(BATCHES)
        return Answer(mean, se, (f"{BATCHES} batches of {SAMPLES} Potto samples",))


def make():
    return PottoEngine()
