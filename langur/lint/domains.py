"""X307: smooth primitives applied outside their domain on the domain of integration.

LANGUAGE.md §1: where a primitive is applied outside its domain (log of a non-positive number,
division by zero) the value is undefined, and "the checker warns when it can see it happen on the
domain of integration".  At the parameter values in force (defaults or ``--at``), each subterm
where it is evaluated (a branch of a conditional only where its condition selects it, Fig. 7):

* **outside the domain on a set of positive measure** (``log`` or ``sqrt`` of a negative number,
  ``log(0)`` on a region, ``asin`` beyond [−1, 1], a fractional power ``t ^ (p/q)`` of a negative
  base, a denominator that is 0 on a region): the exact engine decides it
  (:func:`langur.symbolic.definedness.undefined_parts`, the decision X311 and ``eval`` use), and
  its witness, a point where the argument is proved outside the domain, is the example; the ends
  of the domain on a null set are not reported (an integrable singularity: ``log(x)`` on [0, 1]).
  Where it cannot decide (an argument with too many discontinuities to split), the integrand's
  values at random points of the box (numpy, fixed seed) outside the domain's closure are;
* **a pole crossed** (a null set, reported all the same): a division or ``t ^ k`` with k < 0 whose
  base takes both signs at the random points, ``tan`` whose argument's ``cos`` does.

Each primitive's domain is read from its entry in ``langur.primitives``.  Both searches can miss
a tiny bad region (the engine's grid, the random points): they report what they see, never claim
absence.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Mapping
from fractions import Fraction

import numpy as np

from ..core import (
    PI,
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Term,
    Var,
    children,
)
from ..denote import program_box
from ..precise import real_value
from ..primitives import REGISTRY, Domain
from ..symbolic.decompose import Ctx
from ..symbolic.definedness import Undefined, random_points, undefined_parts
from ..sympy_bridge import at_symbols
from .findings import Finding, quote


class _Skip(Exception):
    pass


def _const(v) -> float:
    return float(np.pi) if v == PI else float(v)


def _scalar(t: Term, params: Mapping[str, float]) -> float:
    """A variable-free term's value (for bounds and variable-free conditions)."""
    out = _Eval({}, params, np.ones(1, dtype=bool), report=False).value(t, np.ones(1, dtype=bool))
    return float(np.asarray(out).reshape(-1)[0])


def _operands(t: Term) -> tuple[Term, ...]:
    """The subterms :meth:`_Eval.value` evaluates to evaluate ``t``: its children
    (``core.children``) and, for a diffeomorphic condition, the condition's own term."""
    return (t.psi.forward[0], *children(t)) if type(t) is IfDiffeo else children(t)


def _uses(t: Term) -> dict[int, int]:
    """How many times each node of ``t`` that is used more than once (a DAG after inlining) is an
    operand of another (by identity, each distinct node's operands counted once)."""
    count: dict[int, int] = {}
    stack = [t]
    while stack:
        for u in _operands(stack.pop()):
            n = count.get(id(u), 0)
            count[id(u)] = n + 1
            if not n:
                stack.append(u)
    return {k: n for k, n in count.items() if n > 1}


#: Most sample arrays (4096 doubles, 32 kB each) the evaluation keeps for shared nodes at once
#: (128 MB): past it a shared node is evaluated again where it is used (time, which the linter's
#: budget bounds, instead of memory).
MEMO_ARRAYS = 4096


class _Eval:
    """One evaluation at the sample points, under one binding of the parameters.

    A node used more than once (``uses``: a DAG after inlining) keeps its value per mask until it
    has been used as many times as it is an operand: a node is evaluated under a given mask at most
    once per parent, so dropping it then loses no reuse.  Other nodes keep nothing, so a tree of
    any size holds O(depth) arrays at once, not one per node (a sum of 10⁵ terms held 3 GB)."""

    def __init__(self, xs: dict[str, np.ndarray], params: Mapping[str, float], mask, report=True,
                 uses: dict[int, int] | None = None, undefined: dict[int, Undefined] | None = None):
        self.xs = xs
        self.params = dict(params)
        self.report = report
        self.bad: dict[tuple[int, str], tuple[Term, str, str]] = {}  # the first of each (node, why): its example
        self.undefined = undefined  # the exact engine's verdicts by node (None: not decided, sampled)
        self.uses = {} if uses is None else uses
        self.memo: dict[tuple[int, int], list] = {}  # (id(t), id(mask)) → [mask, value, uses left]
        self.kept = [0]  # memoized arrays of this scope and those around it

    def flag(self, t: Term, why: str, where: np.ndarray):
        """``t`` is outside its domain at the sample points ``where`` (the first is the example)."""
        if self.report and (id(t), why) not in self.bad and where.any():
            k = int(np.argmax(where))
            self.bad[id(t), why] = (t, why, ", ".join(f"{x} = {v[k]:.3g}" for x, v in self.xs.items()))

    def flag_at(self, t: Term, why: str, example):
        """``t`` is outside its domain at the point ``example()`` describes (computed for the first
        report of ``(t, why)`` only)."""
        if self.report and (id(t), why) not in self.bad:
            self.bad[id(t), why] = (t, why, example())

    def sign_change(self, base: Term, v: np.ndarray, mask: np.ndarray) -> str:
        """Where ``base`` (``v`` at the sample points) changes sign: bisection on the segment between
        the samples of each sign where it is smallest, to its zero (``x = 0.53``), or to where
        ``base`` jumps across 0 instead (a sample point, 0.27, is no zero:
        fuzz33's F2; bench/history/2026-11-29.md#zero33."""
        size = np.where(mask, np.abs(v), np.inf)
        ends = [int(np.argmin(np.where(v < 0, size, np.inf))), int(np.argmin(np.where(v > 0, size, np.inf)))]
        lo, hi = (np.array([xs[k] for xs in self.xs.values()]) for k in ends)
        probe = copy.copy(self)
        probe.report, probe.undefined, probe.uses, probe.memo, probe.kept = False, None, {}, {}, [0]
        one = np.ones(1, dtype=bool)

        def at(point: np.ndarray) -> float:
            probe.xs = {x: point[i:i + 1] for i, x in enumerate(self.xs)}
            return float(np.asarray(probe.value(base, one)).reshape(-1)[0])

        for _ in range(60):
            mid = (lo + hi) / 2
            f = at(mid)
            if f == 0 or not np.isfinite(f) or np.array_equal(mid, lo) or np.array_equal(mid, hi):
                break
            lo, hi = (mid, hi) if f < 0 else (lo, mid)
        point = ", ".join(f"{x} = {m:.3g}" for x, m in zip(self.xs, mid))
        if abs(f) <= 1e-9 * float(np.max(size, initial=0.0, where=np.isfinite(size))):
            return point
        return f"{point} (where it jumps across 0)"

    def outside(self, t: Term, why, where):
        """``t`` outside its domain on a set of positive measure: as the exact engine decides, with
        its witness and ``why(witness)`` (its reason), or, where it did not decide, at the sample
        points ``where()``."""
        if self.undefined is None:
            self.flag(t, why(None), where())
            return
        u = self.undefined.get(id(t))
        if self.report and u is not None and (id(t), why(u)) not in self.bad:
            self.bad[id(t), why(u)] = (t, why(u), ", ".join(f"{x} = {float(p):.3g}" for x, p in u.point))

    def value(self, t: Term, mask: np.ndarray):
        """⟦t⟧ at the sample points (Fig. 7), computed once per mask for a node used more than
        once."""
        uses = self.uses.get(id(t))
        if uses is None:
            return self._value(t, mask)
        key = (id(t), id(mask))
        hit = self.memo.get(key)
        if hit is not None and hit[0] is mask:  # (the mask is kept alive with it: its id is its own)
            hit[2] -= 1
            if not hit[2]:  # its last use
                del self.memo[key]
                self.kept[0] -= 1
            return hit[1]
        out = self._value(t, mask)
        if self.kept[0] < MEMO_ARRAYS:
            self.memo[key] = [mask, out, uses - 1]
            self.kept[0] += 1
        return out

    def _value(self, t: Term, mask: np.ndarray):
        """⟦t⟧ at the sample points (Fig. 7), flagging primitives applied outside their domain on
        the points of ``mask`` (those where this subterm is actually evaluated)."""
        match t:
            case Const(v):
                # Fig. 7, constant
                return np.full(mask.shape, _const(v))
            case Var(name):
                # Fig. 7, variable
                return self.xs[name]
            case Param(name):
                # Fig. 7, parameter
                if name not in self.params:
                    raise _Skip(name)
                return np.full(mask.shape, float(self.params[name]))
            case Add(a, b):
                # Fig. 7, sum
                return self.value(a, mask) + self.value(b, mask)
            case Mul(a, b):
                # Fig. 7, product (an undefined factor makes the product undefined: both evaluated)
                return self.value(a, mask) * self.value(b, mask)
            case Prim(op, a):
                # LANGUAGE.md §1, primitive
                v = self.value(a, mask)
                domain = REGISTRY[op].domain
                if domain.poles:  # tan: undefined where cos vanishes (a pole crossed)
                    c = np.cos(v)
                    if (mask & (c > 0)).any() and (mask & (c < 0)).any():
                        self.flag(t, domain.why, mask & (c < 0))
                # outside the domain's closure; a constant argument at an end of it, or at a pole
                # of tan, on a region (the engine's reason: "its argument is 0 there")
                self.outside(t, lambda u: _primitive_why(domain, u), lambda: mask & domain.outside_closure(v))
                return REGISTRY[op].value(v)
            case Pow(a, k):
                # LANGUAGE.md §1, constant power (t / s is t · s^-1)
                v = self.value(a, mask)
                if k < 0 and (mask & (v > 0)).any() and (mask & (v < 0)).any():
                    self.flag_at(t, "the denominator changes sign, so it divides by zero inside the region",
                                 lambda: self.sign_change(a, v, mask))
                if k < 0 and self.undefined is None:
                    self.flag(t, "the denominator is zero (division by zero)", mask & (v == 0))
                if Fraction(k).denominator != 1 or self.undefined is not None:
                    self.outside(t, _power_why, lambda: mask & (v < 0))
                if Fraction(k).denominator != 1:
                    return np.power(np.where(v >= 0, v, np.nan), float(k))
                return np.power(v, float(k))
            case IfGe0(cond, s, r):
                # Fig. 7, conditional on a variable-free condition
                c = self.value(cond, mask) >= 0
                return np.where(c, self.value(s, mask & c), self.value(r, mask & ~c))
            case IfDiffeo(psi, s, r):
                # Fig. 7, diffeomorphic conditional: [π₀Ψ̂ ≥ 0]
                c = self.value(psi.forward[0], mask) >= 0
                return np.where(c, self.value(s, mask & c), self.value(r, mask & ~c))
            case Let(name, bound, body):
                # Fig. 7, let
                # a new scope, never a mutation: the pass is memoized per node and evaluator
                inner = copy.copy(self)
                inner.params = {**self.params, name: float(np.asarray(self.value(bound, mask)).reshape(-1)[0])}
                inner.memo = {}
                out = inner.value(body, mask)
                self.kept[0] -= len(inner.memo)  # (dropped with the scope)
                return out
            case Call():
                raise _Skip("call")
        raise TypeError(f"not a core term: {t!r}")


def _primitive_why(domain: Domain, u: Undefined | None) -> str:
    """Why a primitive is outside its domain: the domain's reason; for a constant argument in the
    closure of the domain (``log(0)``, ``tan`` at a pole, on a region), the engine's ("its
    argument is 0 there")."""
    if u is None or u.argument.free_symbols:
        return domain.why
    z = real_value(u.argument)
    return domain.why if math.isnan(z) or domain.outside_closure(z) else u.why


def _power_why(u: Undefined | None) -> str:
    """Why a power is outside its domain: its base 0 under a negative exponent, else negative."""
    return "the denominator is zero (division by zero)" if u is not None and u.argument.is_zero \
        else "a fractional power of a negative base"


def _undefined(program: Program, point: Mapping[str, object]) -> dict[int, Undefined] | None:
    """The exact engine's applications outside their domain (:func:`~langur.symbolic.definedness.undefined_parts`)
    at ``point`` (as X311 asks, ``langur.lint.singular``), by node; None when it cannot decide."""
    ctx = Ctx(at=at_symbols({k: v for k, v in point.items() if v is not None}), variables=tuple(program.variables))
    try:
        found = undefined_parts(program.body, ctx, program.variables, program_box(program, ctx))
    except TimeoutError:  # (the analysis's budget: not the engine's failure)
        raise
    except Exception:  # noqa: BLE001 - the engine could not decide (sympy failed): the samples do
        return None
    return None if found is None else {id(u.application): u for u in found}


def domain_findings(program: Program | None, point: Mapping[str, object] | None, sources: Mapping[str, str]):
    """X307 findings of ``program`` at the parameter ``point`` (nothing when a value is missing)."""

    if program is None or point is None or len(program.box) != len(program.variables):
        return []
    params = {k: float(v) for k, v in point.items()}
    try:
        with np.errstate(all="ignore"):
            bounds = [(_scalar(lo, params), _scalar(hi, params)) for lo, hi in program.box]
    except (_Skip, KeyError):
        return []
    if not all(np.isfinite(lo) and np.isfinite(hi) and lo < hi for lo, hi in bounds):
        return []
    pts = random_points(bounds)  # (the exact engine looks for its witnesses at the same points)
    xs = {x: pts[:, i] for i, x in enumerate(program.variables)}
    ev = _Eval(xs, params, None, uses=_uses(program.body), undefined=_undefined(program, point))
    mask = np.ones(len(pts), dtype=bool)
    try:
        with np.errstate(all="ignore"):
            ev.value(program.body, mask)
    except _Skip:
        return []
    out = []
    for t, why, example in ev.bad.values():
        span = t.span
        text = quote(span, sources, limit=None)
        what = f"`{text}`" if text else (f"`{t.op}`" if isinstance(t, Prim) else "a power")
        vals = ", ".join(f"{k2} = {v:g}" for k2, v in params.items())
        at = f" (at {vals})" if vals else ""
        out.append(
            Finding(
                span,
                "warning",
                "X307",
                f"{what} is applied outside its domain on the domain of integration{at}: {why}, e.g. at "
                f"{example}; the integrand is undefined there (LANGUAGE.md §1)",
                (),
                tuple(params),
            )
        )
    return out
