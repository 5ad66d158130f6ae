"""X307: smooth primitives applied outside their domain on the domain of integration.

LANGUAGE.md §1: where a primitive is applied outside its domain (log of a non-positive number,
division by zero) the value is undefined, and "the checker warns when it can see it happen on the
domain of integration".  It looks at the parameter values in force (defaults or ``--at``) and
evaluates the integrand with numpy at random points of the box (fixed seed), each subterm only
where it is evaluated (a branch of a conditional only where its condition selects it), and warns
when a set of positive measure is out of the domain:

* ``log``: argument < 0 (a zero on a null set is an integrable singularity and is not reported);
* ``sqrt`` and fractional powers ``t ^ (p/q)``: base < 0;
* division, ``t ^ k`` with k < 0: the base takes both signs (it crosses zero inside the region);
* ``tan``: ``cos`` of the argument takes both signs (a pole inside the region);
* ``asin``/``acos``/``atanh`` (inverse branches only): argument outside [-1, 1].

Each primitive's domain is read from its entry in ``langur.primitives``; the ends of an interval
are a null set and are not reported.

A sampling check can miss a tiny bad region: it reports what it sees, never claims absence.
"""

from __future__ import annotations

import copy
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
from ..primitives import REGISTRY
from .findings import Finding, quote

SAMPLES = 4096


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
                 uses: dict[int, int] | None = None):
        self.xs = xs
        self.params = dict(params)
        self.report = report
        self.bad: dict[tuple[int, str], tuple[Term, str, np.ndarray]] = {}  # the first of each (node, why)
        self.uses = {} if uses is None else uses
        self.memo: dict[tuple[int, int], list] = {}  # (id(t), id(mask)) → [mask, value, uses left]
        self.kept = [0]  # memoized arrays of this scope and those around it

    def flag(self, t: Term, why: str, where: np.ndarray):
        if self.report and (id(t), why) not in self.bad and where.any():
            self.bad[id(t), why] = (t, why, where)

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
                if domain.poles:  # tan: undefined where cos vanishes
                    c = np.cos(v)
                    if (mask & (c > 0)).any() and (mask & (c < 0)).any():
                        self.flag(t, domain.why, mask & (c < 0))
                else:
                    self.flag(t, domain.why, mask & domain.outside_closure(v))
                return REGISTRY[op].value(v)
            case Pow(a, k):
                # LANGUAGE.md §1, constant power (t / s is t · s^-1)
                v = self.value(a, mask)
                if k < 0 and (mask & (v > 0)).any() and (mask & (v < 0)).any():
                    self.flag(
                        t,
                        "the denominator changes sign, so it divides by zero inside the region",
                        mask & (v < 0),
                    )
                if k < 0:
                    self.flag(t, "the denominator is zero (division by zero)", mask & (v == 0))
                if Fraction(k).denominator != 1:
                    self.flag(t, "a fractional power of a negative base", mask & (v < 0))
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
    rng = np.random.default_rng(0)
    xs = {x: rng.uniform(lo, hi, SAMPLES) for x, (lo, hi) in zip(program.variables, bounds)}
    ev = _Eval(xs, params, None, uses=_uses(program.body))
    mask = np.ones(SAMPLES, dtype=bool)
    try:
        with np.errstate(all="ignore"):
            ev.value(program.body, mask)
    except _Skip:
        return []
    out = []
    for t, why, where in ev.bad.values():
        k = int(np.argmax(where))
        example = ", ".join(f"{x} = {xs[x][k]:.3g}" for x in program.variables)
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
