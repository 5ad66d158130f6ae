"""Compact support of a program's integrand (paper §8.3, Prop. 8.1–8.2): the program's box.

With a domain ``int ([l1, u1], …) t d(x⃗)`` the box is the domain.  Without one, the box is read
off the *bounding indicator factors* of the integrand: the factors of its top-level product that
are ``ifge0 ⌊Ψ⌋ then s else 0`` (the integrand vanishes where ``π₀Ψ̂ < 0``) or ``… then 0 else r``
(it vanishes where ``π₀Ψ̂ ≥ 0``), whose condition is affine in the variables with constant
coefficients (looking through ``let``, whose bound terms are substituted into the bounds).
A bound that mentions other variables (``[0 <= y <= x]``) is widened over their
box by interval reasoning (``y ≤ x ≤ 1``).  A variable nothing bounds makes the program not
compactly supported (T209, reported by the desugarer).
"""

from __future__ import annotations

import math

from .. import lazy
from ..core import Const, IfDiffeo, Let, Mul, Term, free_params, substitute
from .affine import linear, rational_value

#: sympy, imported when a box is inferred or a bound is not rational (``langur.lazy``): a program
#: with a rational domain is loaded without it.
sp = lazy.module("sympy")
bridge = lazy.module("langur.sympy_bridge")

Bound = tuple[Term | None, Term | None]


def top_factors(t: Term) -> list[tuple[Term, dict[str, Term]]]:
    """The factors of ``t``'s top-level product, left to right, looking through ``let`` (each
    factor with the substitution of the ``let``-bound names around it)."""
    out, stack = [], [(t, {})]
    while stack:
        u, env = stack.pop()
        if isinstance(u, Mul):
            stack.append((u.right, env))
            stack.append((u.left, env))
        elif isinstance(u, Let):
            bound = substitute(u.bound, {}, env)
            stack.append((u.body, {**env, u.name: bound}))
        else:
            out.append((u, env))
    return out


def _is_zero(t: Term) -> bool:
    return isinstance(t, Const) and t.value == 0


def _bounding(body: Term):
    """The bounding indicator factors: ``(sign, condition with the let-bound terms substituted)``."""
    for f, env in top_factors(body):
        if isinstance(f, IfDiffeo) and (_is_zero(f.orelse) or _is_zero(f.then)):
            yield (1 if _is_zero(f.orelse) else -1), substitute(f.psi.forward[0], {}, env)


def _rational_box(body: Term, variables: tuple[str, ...]) -> list[Bound] | None:
    """:func:`infer_box` without sympy when every bounding condition is affine with rational
    coefficients and no parameter (the bounds are then rationals: the same ``Const`` terms);
    ``None`` otherwise."""
    index = {x: i for i, x in enumerate(variables)}
    constraints = []
    for sign, cond in _bounding(body):
        form = linear(cond)
        if form is None or any(kind == "p" or name not in index for kind, name in form[0]):
            return None
        coeffs = dict(sorted((index[name], sign * c) for (_, name), c in form[0].items()))  # sympy's order: xs
        for i, c in coeffs.items():
            others = {j: -cj / c for j, cj in coeffs.items() if j != i}
            constraints.append((i, "lo" if c > 0 else "hi", others, -sign * form[1] / c))
    box = _propagate(constraints, len(variables))
    return [tuple(None if b is None else Const(b) for b in pair) for pair in box]


def _propagate(constraints, n: int, tidy=lambda v: v) -> list[list]:
    """The box the constraints ``(i, "lo"|"hi", {j: c_j}, base)`` — x_i ≥ (or ≤) base + Σ c_j·x_j —
    give, each side found once the other variables' sides it needs are known (widened over x_j's
    box: the minimum of c_j·x_j for a lower bound, the maximum for an upper one); ``tidy`` maps each
    bound found."""
    box: list[list] = [[None, None] for _ in range(n)]
    for _ in range(n + 1):
        changed = False
        for i, side, others, base in constraints:
            k = 0 if side == "lo" else 1
            if box[i][k] is not None:
                continue
            value = base
            for j, cj in others.items():
                b = box[j][1 if (cj > 0) == (side == "hi") else 0]
                if b is None:
                    value = None
                    break
                value = value + cj * b
            if value is not None:
                box[i][k] = tidy(value)
                changed = True
        if not changed:
            break
    return box


def infer_box(body: Term, variables: tuple[str, ...]) -> list[Bound]:
    """One ``(lo, hi)`` per variable (``None`` where nothing bounds that side)."""
    direct = _rational_box(body, variables)
    if direct is not None:
        return direct
    xs = [bridge.symbol(x) for x in variables]
    constraints = []  # (variable index, "lo"|"hi", {other index: coeff}, param part)
    for sign, cond in _bounding(body):
        try:
            e = sp.expand(sign * bridge.to_sympy(cond))
        except bridge.NotSmooth:
            continue
        coeffs = {}
        affine = True
        for i, x in enumerate(xs):
            d = sp.diff(e, x)
            if d.free_symbols:  # not affine with constant coefficients
                affine = False
                break
            if d != 0:
                coeffs[i] = d
        if not affine or not coeffs:
            continue
        rest = sp.expand(e - sum(c * xs[i] for i, c in coeffs.items()))
        if rest.free_symbols & set(xs):
            continue
        for i, c in coeffs.items():
            # c·x_i + Σ c_j x_j + rest ≥ 0  ⇒  x_i ≥ (−rest − Σ c_j x_j)/c  (c > 0), ≤ when c < 0
            others = {j: -cj / c for j, cj in coeffs.items() if j != i}
            constraints.append((i, "lo" if c > 0 else "hi", others, -rest / c))
    box = _propagate(constraints, len(variables), lambda v: sp.nsimplify(v) if v.is_Float else v)
    params = set()
    for _, _, _, base in constraints:
        params |= {s.name for s in base.free_symbols}
    return [tuple(_term(b, params) for b in pair) for pair in box]


def _term(b, params) -> Term | None:
    if b is None:
        return None
    try:
        return bridge.from_sympy(b, (), params)
    except ValueError:  # not expressible as a core term: leave this side unbounded
        return None


def numeric_box(variables: tuple[str, ...], box) -> tuple[tuple[str, float | Term, float | Term], ...]:
    """The box's constant bounds as floats (missing bounds: ±∞), for completion; a bound that
    depends on the parameters is kept as its term (an implicit root's bracket may follow it, issue
    18: everything else reads it as ±∞, :func:`float_bounds`)."""
    out = []
    for x, (lo, hi) in zip(variables, box):
        out.append((x, _num(lo, -math.inf), _num(hi, math.inf)))
    return tuple(out)


def float_bounds(box) -> dict[str, tuple[float, float]]:
    """The box as floats per variable: a parametric bound (a term) is unbounded."""
    return {v: (lo if isinstance(lo, float) else -math.inf, hi if isinstance(hi, float) else math.inf)
            for v, lo, hi in box}


def _num(t: Term | None, default: float) -> float | Term:
    if t is None:
        return default
    if free_params(t):
        return t
    exact = rational_value(t)  # a rational bound: no sympy
    if exact is not None:
        return float(exact)
    try:
        v = float(bridge.to_sympy(t))
    except (bridge.NotSmooth, TypeError, ValueError):
        return default
    return v if math.isfinite(v) else default
