"""Interval enclosures over core terms, on arrays of boxes at once (the samplers' boxes, §9).

:func:`enclose` bounds ⟦t⟧ over boxes of its variables: each box given by arrays of lower and
upper ends (any shape that broadcasts with the parameters' arrays), so a whole grid of cells for
a whole batch of parameter points is enclosed in one pass (no Python recursion per cell).
Enclosures are conservative: a NaN end (an operation outside its domain) makes the interval
unbounded, never narrower.

Two kinds of tape (:func:`tape_of`).  The samplers' tapes compute each end in round-to-nearest
doubles: a cell cut away by a rounding error loses a sliver of width ~1e-16 of the zero set, which
no estimate can see.  A *certified* tape (``certified=True``: the sign changes of issue 18, where
an enclosure that excludes 0 is a proof) rounds every operation's ends outward: a sum's or a
product's lower end one double down (``np.nextafter``), its upper end one double up (a correctly
rounded result is within half a unit in the last place of the exact one, so one step suffices,
also at a power of two); a constant that is not a double is the two doubles around it; a power,
whose library ``pow`` is not correctly rounded, and a monotone primitive (the registry's rule)
two units; ``sin``/``cos`` by where their extrema lie, with a slack relative to the argument's
size; a ``let`` bound to a range encloses its body over that range.  So an interval enclosure
of a certified tape contains the exact real value of the term over the box, up to the one
assumption that the C library's ``exp``, ``log``, ``pow``, … err by less than two units in the
last place (glibc's: less than one).
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np

from ..core import Add, Const, IfDiffeo, IfGe0, ImplicitRoot, Let, Mul, Param, Pow, Prim, Term, Var, keep_memo
from ..primitives import REGISTRY
from ..records import frozen
from .consts import const_value

INF = np.inf


def enclose(t: Term, box: dict, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """Arrays (lo, hi) containing ⟦t⟧ for every point of each box (``box``: variable → (lo, hi)
    arrays) at ``params`` (name → number or array, broadcast with the boxes).  A subterm that
    occurs more than once in ``t`` — shared (substituted lets, inlined calls: a DAG) or merely
    equal (the same expression written out twice) — is enclosed once per parameter scope."""
    return _tape(t).run(box, params)[0]


def enclose_all(tape: "_Tape", box: dict, params: dict) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`enclose` of each term of ``tape`` (:func:`tape_of`), their shared and equal
    subterms enclosed once for all of them."""
    return tape.run(box, params)


def tape_of(terms, certified: bool = False) -> "_Tape":
    """One tape for several terms (e.g. every inverse branch's components and guards of a zero
    set, which share most of their subterms); the caller keeps it.  ``certified``: every end
    rounded outward (see the module's docstring) and ``sin``/``cos`` enclosed by where their
    extrema lie (:func:`_periodic`), not by their range (the certified sign changes of issue 18,
    which need enclosures that shrink with the cell and are proofs)."""
    return _build(tuple(terms), certified)


@frozen(eq=False)
class _Tape:
    """Terms as a straight line: one step per structurally distinct subterm (children first),
    each step a rule below applied to the enclosures of earlier steps; ``drop[i]``: the steps
    whose last reader is step i (their arrays are let go there); ``roots``: the terms' steps."""

    steps: tuple[tuple, ...]
    drop: tuple[tuple[int, ...], ...]
    roots: tuple[int, ...]

    def run(self, box: dict, params: dict) -> list:
        out: list = [None] * len(self.steps)
        for i, (rule, kids, data) in enumerate(self.steps):
            out[i] = rule(box, params, data, *[out[k] for k in kids])
            for k in self.drop[i]:
                out[k] = None
        return [out[i] for i in self.roots]


def _tape(t: Term, certified: bool = False) -> _Tape:
    """The tape of ``t``, built once and kept on the node (as core's derived facts are)."""
    key = "certified tape" if certified else "enclosure tape"
    memo = t.memo
    if memo is None:
        memo = {}
        keep_memo(t, memo)
    tape = memo.get(key)
    if tape is None:
        tape = memo[key] = _build((t,), certified)
    return tape


def _build(terms: tuple[Term, ...], certified: bool = False) -> _Tape:
    rule = _OUTWARD if certified else _NEAREST
    steps: list[tuple] = []
    index: dict = {}  # (rule, kids, data) → step: equal subterms are one step
    seen: dict[int, int] = {}  # id(node) → step: a shared node is looked at once

    def step(t: Term) -> int:
        hit = seen.get(id(t))
        if hit is not None:
            return hit
        match t:
            case Const():
                key = (rule["const"], (), _const_ends(t) if certified else np.float64(const_value(t)))
            case Var(name):
                key = (_var, (), name)
            case Param(name):
                key = (_param, (), name)
            case Add(a, b):
                key = (rule["add"], (step(a), step(b)), None)
            case Mul(a, b):
                key = (rule["mul"], (step(a), step(b)), None)
            case Pow(a, k):
                key = (rule["pow"], (step(a),), k)
            case Prim(op, a):
                key = ((_periodic if certified and op in _PHASE else _prim), (step(a),), op)
            case IfGe0(c, a, b):
                key = (_ifge0, (step(c), step(a), step(b)), None)
            case IfDiffeo(_, a, b):
                key = (_ifdiffeo, (step(a), step(b)), None)
            case Let(name, bound, body):  # the body under its own scope: a tape of its own
                key = (rule["let"], (step(bound),), (name, _tape(body, certified)))
            case ImplicitRoot(_, _, _, lo, hi):  # issue 18: the root lies in its bracket
                key = (_bracket, (step(lo), step(hi)), None)
            case _:
                raise TypeError(f"cannot enclose {t!r}")
        i = index.get(key)
        if i is None:
            i = index[key] = len(steps)
            steps.append(key)
        seen[id(t)] = i
        return i

    roots = tuple(step(t) for t in terms)
    last = {k: i for i, (_, kids, _) in enumerate(steps) for k in kids}
    for k in roots:  # a term's enclosure is kept to the end
        last.pop(k, None)
    drop = [[] for _ in steps]
    for k, i in last.items():
        drop[i].append(k)
    return _Tape(tuple(steps), tuple(tuple(d) for d in drop), roots)


# -- the rules: each takes (box, params, the step's data, its children's enclosures) ------------

def _const(box, params, c):
    return c, c


def _var(box, params, name):
    return box[name]


def _param(box, params, name):
    v = params[name]
    if isinstance(v, tuple):  # a certified let's name bound to a range (:func:`_let_out`)
        return v
    v = np.asarray(v, dtype=float)
    return v, v


def _add(box, params, _, a, b):
    (al, ah), (bl, bh) = a, b
    if al is ah and bl is bh:  # a point stays a point (the one sum is both ends)
        s = al + bl
        return s, s
    return al + bl, ah + bh


def _mul(box, params, _, a, b):
    (al, ah), (bl, bh) = a, b
    if al is ah and bl is bh:  # a point times a point: one product, still a point
        with np.errstate(invalid="ignore"):
            p = al * bl
        nan = np.isnan(p)
        if not nan.any():
            return p, p
        return np.where(nan, -INF, p), np.where(nan, INF, p)
    with np.errstate(invalid="ignore"):
        if al is ah or bl is bh:  # a point times an interval: two products
            p0, p1 = (al * bl, al * bh) if al is ah else (al * bl, ah * bl)
            # NaN products ignored… (fmin/fmax keep their first argument on a tie, so these are
            # the four-product reductions below with the repeated products left out)
            lo, hi = np.fmin(p0, p1), np.fmax(p0, p1)
        else:
            p0, p1, p2, p3 = al * bl, al * bh, ah * bl, ah * bh
            lo = np.fmin(np.fmin(np.fmin(p0, p1), p2), p3)  # left to right, as a reduction would
            hi = np.fmax(np.fmax(np.fmax(p0, p1), p2), p3)
    none = np.isnan(lo)  # …unless all are NaN: then anything
    if not none.any():
        return lo, hi
    return np.where(none, -INF, lo), np.where(none, INF, hi)


def _ifge0(box, params, _, c, a, b):
    (cl, ch), (al, ah), (bl, bh) = c, a, b
    lo = np.where(cl >= 0, al, np.where(ch < 0, bl, np.minimum(al, bl)))
    hi = np.where(cl >= 0, ah, np.where(ch < 0, bh, np.maximum(ah, bh)))
    return lo, hi


def _ifdiffeo(box, params, _, a, b):
    (al, ah), (bl, bh) = a, b
    return np.minimum(al, bl), np.maximum(ah, bh)


def _let(box, params, data, bound):
    name, body = data
    lo, hi = bound
    [(bl, bh)] = body.run(box, {**params, name: lo})
    wide = lo != hi  # a let bound to a range: its body is not enclosed per value
    return np.where(wide, -INF, bl), np.where(wide, INF, bh)


def _let_out(box, params, data, bound):
    name, body = data
    [out] = body.run(box, {**params, name: bound})  # the body over the bound's whole range
    return out


def _bracket(box, params, _, lo, hi):
    return lo[0], hi[1]


def _prim(box, params, op: str, a):
    """An interval containing f([lo, hi]): the primitive registry's own rule (one declaration)."""
    return REGISTRY[op].interval(*a)


#: sin(x) = sin(x + 0), cos(x) = sin(x + π/2): the phase that makes each a sine.
_PHASE = {"sin": 0.0, "cos": np.pi / 2}
#: Outward slack of a tight sine enclosure per unit of the argument's size (the phase's and the
#: extrema's rounding, which grow with it; sin is 1-Lipschitz) and of the library's sin.
_SLACK = 1e-12


def _periodic(box, params, op: str, a):
    """An interval containing sin or cos of ``[lo, hi]``: [−1, 1] where it is 2π wide or more,
    else the ends' values widened to ±1 where a maximum (π/2 + 2kπ) or minimum (−π/2 + 2kπ)
    lies inside, rounded outward."""
    lo, hi = (np.asarray(v, dtype=float) + _PHASE[op] for v in a)
    with np.errstate(all="ignore"):
        slack = _SLACK * (1.0 + np.abs(lo) + np.abs(hi))
        sl, sh = np.sin(lo), np.sin(hi)
        k_max = np.ceil((lo - np.pi / 2) / (2 * np.pi))
        k_min = np.ceil((lo + np.pi / 2) / (2 * np.pi))
        has_max = np.pi / 2 + 2 * np.pi * k_max <= hi + slack
        has_min = -np.pi / 2 + 2 * np.pi * k_min <= hi + slack
        # a lower k whose extremum the rounding of k may have skipped, still within the slack
        has_max |= np.pi / 2 + 2 * np.pi * (k_max - 1) >= lo - slack
        has_min |= -np.pi / 2 + 2 * np.pi * (k_min - 1) >= lo - slack
    wide = ~(np.isfinite(lo) & np.isfinite(hi)) | (hi - lo >= 2 * np.pi)
    out_lo = np.where(wide | has_min, -1.0, np.maximum(np.minimum(sl, sh) - slack, -1.0))
    out_hi = np.where(wide | has_max, 1.0, np.minimum(np.maximum(sl, sh) + slack, 1.0))
    return out_lo, out_hi


def _pow(box, params, k: Fraction, a):
    lo, hi = a
    f = float(k)
    if lo is hi:  # a point: one power, still a point where it is bounded
        with np.errstate(all="ignore"):
            p = np.power(lo, f)
        if k.denominator == 1 and k > 0:
            return p, p
        unbounded = (lo < 0) if k.denominator != 1 else np.zeros(np.shape(lo), dtype=bool)
        if k < 0:
            unbounded = unbounded | (lo == 0)
        if not unbounded.any():
            return p, p
        return np.where(unbounded, -INF, p), np.where(unbounded, INF, p)
    with np.errstate(all="ignore"):
        a, b = np.power(lo, f), np.power(hi, f)
    if k.denominator == 1 and k > 0:
        out_lo, out_hi = np.minimum(a, b), np.maximum(a, b)
        if int(k) % 2 == 0:
            straddles = (lo < 0) & (hi > 0)
            out_lo = np.where(straddles, np.minimum(out_lo, 0.0), out_lo)
        return out_lo, out_hi
    unbounded = (lo < 0) if k.denominator != 1 else np.zeros(np.shape(lo), dtype=bool)
    if k < 0:
        unbounded = unbounded | ((lo <= 0) & (hi >= 0))
    return np.where(unbounded, -INF, np.minimum(a, b)), np.where(unbounded, INF, np.maximum(a, b))



# -- outward rounding (certified tapes) -----------------------------------------------------------

def _down(v, steps: int = 1):
    """``v`` moved ``steps`` doubles towards −∞ (+∞ and NaN stay: +∞ becomes the largest double)."""
    for _ in range(steps):
        v = np.nextafter(v, -INF)
    return v


def _up(v, steps: int = 1):
    for _ in range(steps):
        v = np.nextafter(v, INF)
    return v


def _const_ends(c: Const) -> tuple[np.float64, np.float64]:
    """The doubles around a constant: itself when it is one, else the two it lies between (π, 1/3)."""
    v = np.float64(const_value(c))
    exact = c.value if not isinstance(c.value, str) else None
    if exact is not None and (isinstance(exact, float) or (np.isfinite(v) and Fraction(float(v)) == exact)):
        return v, v
    return _down(v), _up(v)


def _const_out(box, params, ends):
    return ends


def _unbounded_nan(lo, hi):
    """NaN ends (∞ − ∞, 0·∞ with nothing else) made unbounded."""
    lo_nan, hi_nan = np.isnan(lo), np.isnan(hi)
    if lo_nan.any() or hi_nan.any():
        bad = lo_nan | hi_nan
        return np.where(bad, -INF, lo), np.where(bad, INF, hi)
    return lo, hi


def _add_out(box, params, _, a, b):
    (al, ah), (bl, bh) = a, b
    with np.errstate(invalid="ignore", over="ignore"):
        return _unbounded_nan(_down(al + bl), _up(ah + bh))


def _mul_out(box, params, _, a, b):
    lo, hi = _mul(box, params, _, a, b)  # the exact products' hull, each end rounded to nearest…
    return _down(lo), _up(hi)  # …then one double outward


def _pow_out(box, params, k, a):
    lo, hi = _pow(box, params, k, a)
    return _down(lo, 2), _up(hi, 2)  # the C library's pow: within two units of the exact power


#: Each mode's rules for the arithmetic that rounds: to nearest (the samplers) or outward.
_NEAREST = {"const": _const, "add": _add, "mul": _mul, "pow": _pow, "let": _let}
_OUTWARD = {"const": _const_out, "add": _add_out, "mul": _mul_out, "pow": _pow_out, "let": _let_out}
