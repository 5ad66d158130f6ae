"""One-sided derivatives of ⟦p⟧ where Theorem 8.1 does not apply (paper §8, §7.3).

Theorem 8.1 says ⦇p⦈ is the derivative of ⟦p⟧ for almost every parameter value.  At the values
where ``langur check --at`` reports X305 (a jump on the domain's end, two jumps meeting, a
condition whose completion degenerates) ⦇p⦈ is not defined, but ⟦p⟧ may or may not be
differentiable there:

* ``∫₀¹ [x ≤ θ] dx = Max(0, Min(1, θ))`` at θ = 1 has a corner: from below 1, from above 0;
* ``∫₀¹ [a·x ≥ 1/2] dx`` at a = 0 is 0 for every a ≤ 1/2: its derivative exists and is 0.

This module decides which, exactly, in the direction γ' asked for:

    D₊ = lim_{t→0+} (⟦p⟧(θ + tγ') − ⟦p⟧(θ)) / t,      D₋ = lim_{t→0+} (⟦p⟧(θ) − ⟦p⟧(θ − tγ')) / t,

from closed forms of ⟦p⟧ (:func:`langur.denote.denote_program`).  On each side the closed form is
one valid for all parameter values, or one valid in the cell of a point θ ± εγ' whose relations are
shown to hold on the whole ray θ ± tγ', 0 < t ≤ some t₀.  Along the ray every ``Max``, ``Min``,
``Abs``, ``sign``, ``Heaviside`` and ``Piecewise`` of the closed form is replaced by the branch that
holds for all small t > 0 — decided by the sign of a smooth difference for small t, which is the
sign of its first non-zero coefficient at t = 0 (:func:`_sign_near_0`) — leaving a smooth function
f(t) of t; D± is then f'(0), provided f(0) is ⟦p⟧(θ) (else ⟦p⟧ jumps and has no derivative).

The derivative exists (in the direction asked) exactly when D₋ = D₊, both finite.  Where a step
cannot be decided (no closed form, a cell fixed by numerically ordered roots, a tie sympy cannot
settle, the time budget) the answer says it was not decided, and why.
"""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction
from typing import Mapping

import sympy as sp

from .denote import denote_program
from .symbolic.pieces import Method
from .sympy_bridge import exact_number, symbol
from .timebox import run_with_timeout

#: The closed form's sides are looked up at θ ± ε·γ' (a rational, so the point stays exact).
EPSILON = sp.Rational(1, 2 ** 20)
#: How many Taylor coefficients a sign near t = 0 may need before it counts as a tie.
ORDERS = 6
#: CPU seconds for the whole decision (sympy's limits can blow up).
SECONDS = 10.0


class Undecided(Exception):
    """A step of the decision that sympy could not take; the message says which."""


@dataclass(frozen=True)
class OneSided:
    """D₋ and D₊ of ⟦p⟧ at the parameter values in the direction γ' (None: not decided, ``why``)."""

    below: sp.Expr | None
    above: sp.Expr | None
    why: str | None = None

    @property
    def exists(self) -> bool | None:
        """Whether ⟦p⟧ has a derivative here in the direction γ' (None: not decided)."""
        if self.below is None or self.above is None:
            return None
        finite = self.below.is_finite and self.above.is_finite
        return bool(finite and sp.simplify(self.below - self.above) == 0)

    def text(self, why_not: str = "⦇p⦈ is not defined here (Theorem 8.1 holds for almost every value, "
                                    "not at these)") -> str:
        """One line for the command's report; ``why_not``: why ⦇p⦈ does not give the derivative."""
        if self.exists is None:
            return f"whether ⟦p⟧ is differentiable here was not decided ({self.why})"
        if self.exists:
            return f"⟦p⟧ is differentiable here: its one-sided derivatives are both {_show(self.above)}, but {why_not}"
        return (f"the derivative does not exist here: ⟦p⟧'s one-sided derivatives differ "
                f"(from below {_show(self.below)}, from above {_show(self.above)})")

    def to_json(self) -> dict:
        return {"exists": self.exists,
                "below": None if self.below is None else _number(self.below),
                "above": None if self.above is None else _number(self.above),
                "why": self.why}


def _show(e: sp.Expr) -> str:
    if e.is_infinite:
        return "∞" if e.is_extended_positive else ("−∞" if e.is_extended_negative else "infinite")
    f = float(e)
    return str(e) if e.is_Rational and len(str(e)) < 12 else f"{f:.10g}"


def _number(e: sp.Expr) -> float | str:
    if e.is_infinite:
        return "inf" if e.is_extended_positive else ("-inf" if e.is_extended_negative else "complex infinity")
    return float(e)


def one_sided(program, at: Mapping[str, object], direction: Mapping[str, object],
              seconds: float = SECONDS) -> OneSided:
    """D₋ and D₊ of ⟦p⟧ at ``at`` in the direction ``direction`` (module doc), within ``seconds`` CPU."""
    try:
        return run_with_timeout(lambda: _one_sided(program, at, direction), seconds, cpu=True)
    except TimeoutError:
        return OneSided(None, None, f"not within {seconds:g} CPU seconds")
    except Undecided as e:
        return OneSided(None, None, str(e))


def closed_form_sides(expr: sp.Expr, at: Mapping[str, object], direction: Mapping[str, object],
                      seconds: float = SECONDS) -> OneSided:
    """D₋ and D₊ of the closed form ``expr`` (valid on both sides of ``at``) at ``at`` in the
    direction ``direction``, within ``seconds`` CPU (Theorem 8.1's check at a switching point)."""
    def sides():
        point = {k: exact_number(v) for k, v in at.items()}
        gamma = {k: exact_number(v) for k, v in direction.items()}
        forms = (sp.sympify(expr),) * 2
        return _sides(forms, sp.sympify(expr).xreplace(_at(point)), point, gamma, sp.Symbol("t", positive=True))
    try:
        return run_with_timeout(sides, seconds, cpu=True)
    except TimeoutError:
        return OneSided(None, None, f"not within {seconds:g} CPU seconds")
    except Undecided as e:
        return OneSided(None, None, str(e))


def _at(point):
    return {symbol(k): q for k, q in point.items()}


def _one_sided(program, at, direction) -> OneSided:
    point = {k: exact_number(v) for k, v in at.items()}
    gamma = {k: exact_number(v) for k, v in direction.items()}
    t = sp.Symbol("t", positive=True)
    here = denote_program(program, dict(at))
    if here.method != Method.CLOSED_FORM:
        raise Undecided("⟦p⟧ has no closed form at these values")
    v0 = sp.sympify(here.expr).xreplace(_at(point))
    forms = tuple((here if here.everywhere and not here.generic else _side_form(program, point, gamma, s, t)).expr
                  for s in (1, -1))
    return _sides(forms, v0, point, gamma, t)


def _sides(forms, v0, point, gamma, t) -> OneSided:
    """D₊ from ``forms[0]`` (valid on θ + tγ'), D₋ from ``forms[1]`` (valid on θ − tγ'), ⟦p⟧(θ) = v0."""
    sides = []
    for s, form in zip((1, -1), forms):
        ray = {symbol(k): point[k] + s * t * gamma.get(k, 0) for k in point}
        f = _resolve(sp.sympify(form).xreplace(ray), t)
        f0 = _limit0(f, t)
        if sp.simplify(f0 - v0) != 0:  # ⟦p⟧ jumps: an infinite one-sided difference quotient
            sides.append(sp.oo if s * (f0 - v0) > 0 else -sp.oo)
            continue
        sides.append(sp.simplify(s * _limit0(sp.diff(f, t), t)))
    return OneSided(below=sides[1], above=sides[0])


def _side_form(program, point, gamma, s, t):
    """A closed form of ⟦p⟧ valid on the ray θ + s·tγ' for small t > 0: the one of the cell of
    θ + s·εγ', its relations checked along the ray."""
    shifted = {k: q + s * EPSILON * gamma.get(k, 0) for k, q in point.items()}
    form = denote_program(program, {k: Fraction(int(q.p), int(q.q)) for k, q in shifted.items()})
    if form.method != Method.CLOSED_FORM:
        raise Undecided("⟦p⟧ has no closed form beside these values")
    if form.generic:
        raise Undecided("⟦p⟧'s closed form beside these values holds where its roots are ordered as there")
    ray = {symbol(k): point[k] + s * t * gamma.get(k, 0) for k in point}
    for rel in form.cell:
        if not _holds_near_0(rel.xreplace(ray), t):
            raise Undecided(f"the closed form's cell ({rel}) does not contain the ray beside these values")
    return form


def _holds_near_0(rel, t) -> bool:
    """Whether the relation holds for all small t > 0."""
    if rel in (sp.true, sp.false):
        return bool(rel)
    if isinstance(rel, sp.And):
        return all(_holds_near_0(a, t) for a in rel.args)
    if isinstance(rel, sp.Or):
        return any(_holds_near_0(a, t) for a in rel.args)
    if isinstance(rel, sp.Not):
        return not _holds_near_0(rel.args[0], t)
    if isinstance(rel, sp.Rel):
        d = _resolve(rel.lhs - rel.rhs, t)
        sign = _sign_near_0(d, t)
        return {">": sign > 0, ">=": sign >= 0, "<": sign < 0, "<=": sign <= 0,
                "==": sign == 0, "!=": sign != 0}[rel.rel_op]
    raise Undecided(f"a condition sympy does not decide along the ray: {rel}")


def _limit0(f, t):
    f = sp.sympify(f)
    if t not in f.free_symbols:
        return f
    try:
        return sp.limit(f, t, 0, "+")
    except (NotImplementedError, ValueError, TypeError) as e:
        raise Undecided(f"sympy found no limit of {f} as t → 0+") from e


def _sign_near_0(f, t) -> int:
    """The sign of the smooth function f(t) for all small t > 0: that of its first non-zero
    coefficient at t = 0 (0: f vanishes identically)."""
    g = sp.sympify(f)
    for _ in range(ORDERS):
        c = _limit0(g, t)
        if c.is_zero is False or c.is_infinite:
            if c.is_extended_positive:
                return 1
            if c.is_extended_negative:
                return -1
            raise Undecided(f"the sign of {c} as t → 0+")
        if c.is_zero is None:
            raise Undecided(f"whether {c} is zero")
        g = g / t
    if sp.simplify(f) == 0:
        return 0
    raise Undecided(f"the sign of {f} for small t > 0")


def _resolve(e, t):
    """``e`` along the ray with every non-smooth choice made for small t > 0 (module doc)."""
    e = sp.sympify(e)
    if e.is_Atom or t not in e.free_symbols:
        return e
    if isinstance(e, sp.Piecewise):
        for expr, cond in e.args:
            if cond is sp.true or _holds_near_0(_resolve_cond(cond, t), t):
                return _resolve(expr, t)
        raise Undecided(f"no branch of {e} holds along the ray")
    args = [_resolve(a, t) for a in e.args]
    if isinstance(e, (sp.Max, sp.Min)):
        best = args[0]
        for a in args[1:]:
            sign = _sign_near_0(a - best, t)
            if (sign > 0 and isinstance(e, sp.Max)) or (sign < 0 and isinstance(e, sp.Min)):
                best = a
        return best
    if isinstance(e, sp.Abs):
        return args[0] if _sign_near_0(args[0], t) >= 0 else -args[0]
    if isinstance(e, sp.sign):
        return sp.Integer(_sign_near_0(args[0], t))
    if isinstance(e, sp.Heaviside):
        sign = _sign_near_0(args[0], t)
        if sign == 0:
            raise Undecided(f"{e} at a tie")
        return sp.Integer(1 if sign > 0 else 0)
    if isinstance(e, (sp.floor, sp.ceiling, sp.frac)):
        raise Undecided(f"{e} along the ray")
    return e.func(*args)


def _resolve_cond(c, t):
    if isinstance(c, sp.Rel):
        return c.func(_resolve(c.lhs, t), _resolve(c.rhs, t))
    if isinstance(c, (sp.And, sp.Or, sp.Not)):
        return c.func(*[_resolve_cond(a, t) for a in c.args])
    return c
