"""Constructs drawn with ``programs(poles=True)`` (``langur fuzz --poles``; fuzz32): conditions whose
sign changes where a completion of the whole condition does not look, and terms the front end's
folding simplifies (each well-typed, LANGUAGE.md §2, §6, its zero sets registered like any condition's
with :meth:`~.conditions.Scope.register`, so the program stays generic at its defaults).

* a moving pole (pole31, bench/history/2026-11-29.md#pole31): ``[F / G CMP k]`` with ``G`` an affine
  term over the variables minus a parameter term — the condition changes sign on ``F = k·G`` *and* on
  the pole ``G = 0``, which moves with the parameter; ``[1 / G CMP k]`` (``k ≠ 0``: a root at
  ``G = 1/k`` besides the pole; ``k = 0``: the pole only);
* a product of moving factors, ``[F · G CMP 0]`` and ``[F · G · H CMP 0]``, a factor squared or
  cubed (``[(F)^2 · G CMP 0]``: the square never changes sign), a factor that is a monotone primitive
  (``exp(v) - P - 1``); the front end splits such a condition into conditionals on its factors'
  signs (``langur/syntax/poles.py``);
* the same as an ``if``'s condition, nested inside another (the split under a conditional);
* folding edge cases (fold31): a condition or smooth factor spelled with ``· * 1``, ``1 * ·``,
  ``· - 0``, ``· + 0 * a``, ``· - k - -k``, ``-1 * -1 * ·``, ``· ^ 1`` and ``0 * (1 / (v - P))`` (undefined
  on the null set ``v = P`` only), each the same function off a null set.

Huge boxes (exact31's wide quadrature) are drawn by :func:`huge`, a program shape of its own
(``programs(huge=True)``, ``langur fuzz --huge``): a variable over ``[-L, L]`` or ``[0, L]`` with
``L`` up to 10¹⁰ and a decaying weight in it (a Gaussian, maybe narrow or far from 0, or
``1/(1 + v²)`` whose tails matter), against affine or moving-pole conditions.
"""

from __future__ import annotations

from fractions import Fraction as F

from hypothesis import strategies as st

from ..syntax import surface as S
from . import conditions as C
from . import terms as T
from .terms import call, mul, name, num, offset, power, sub

#: Right-hand sides of ``[F / G CMP k]`` (0 first: shrinking aims at it).
LEVELS = (F(0), F(1, 4), F(-1, 2))
#: Levels of ``[1 / G CMP k]``: ``1/G = k`` at ``G = 1/k``, inside the box for |G| ≤ 2 or so.
RECIPROCAL_LEVELS = (F(1), F(2), F(-1), F(0))


def moving(scope: C.Scope, monotone: bool = True) -> S.STerm:
    """A moving factor: ``Σ c_v·v - (P + k)`` (an affine term over the variables minus a parameter
    term, :func:`~.conditions.affine`; its zero set moves with the parameter), or with ``monotone``
    one of :func:`~.conditions.monotone` (``exp(v) - (P + 1)``, …; alone in a condition or a factor
    it has a closed-form inverse — a sum of two such terms, or a square of one times another,
    would need an implicit root, which a box with moving ends or a def cannot give, T207)."""
    lhs, _, rhs = (C.affine if not monotone or scope.index(4) < 3 else C.monotone)(scope)
    return sub(lhs, rhs)


def _signed(scope: C.Scope, lhs: S.STerm, rhs: S.STerm) -> S.Iverson:
    return S.Iverson((lhs, rhs), (scope.pick(C.CMPS),))


def ratio(scope: C.Scope) -> S.Iverson:
    """``[F / G CMP k]``: the pole ``G = 0`` moves; zero sets ``F - k·G`` and ``G`` (for ``k ≠ 0``
    both factors affine: ``F - k·G`` is then affine too)."""
    k = scope.pick(LEVELS)
    f, g = moving(scope, k == 0), moving(scope, k == 0)
    scope.register(f if k == 0 else sub(f, T.scaled(k, g)), key=("ratio", f, g, k))
    scope.register(g, key=("pole", g))
    return _signed(scope, T.div(f, g), num(k))


def reciprocal(scope: C.Scope) -> S.Iverson:
    """``[1 / G CMP k]``: the pole ``G = 0`` and, for ``k ≠ 0``, the root ``G = 1/k``."""
    g = moving(scope)
    k = scope.pick(RECIPROCAL_LEVELS)
    if k != 0:
        scope.register(offset(g, -1 / k), key=("reciprocal", g, k))
    scope.register(g, key=("pole", g))
    return _signed(scope, T.div(num(1), g), num(k))


def product(scope: C.Scope) -> S.Iverson:
    """``[F · G CMP 0]``, ``[F · G · H CMP 0]`` or ``[F^m · G CMP 0]`` (m = 2: no sign change on
    ``F = 0``; m = 3: one; both affine), each factor moving; each factor's zero set registered."""
    form = scope.index(3)
    f, g = moving(scope, form != 2), moving(scope, form != 2)
    factors = [f, g]
    if form == 1:
        factors.append(moving(scope))
    for u in factors:
        scope.register(u, key=("factor", u))
    term = mul(power(f, scope.pick((2, 3))), g) if form == 2 else mul(mul(f, g), factors[2]) if form == 1 else mul(f, g)
    return _signed(scope, term, num(0))


#: The condition kinds above (the first is what shrinking aims at).
BRACKETS = (ratio, product, reciprocal)


def bracket(scope: C.Scope) -> S.Iverson:
    return BRACKETS[scope.index(len(BRACKETS))](scope)


def nested(scope: C.Scope) -> S.IfCmp:
    """``if F / G >= 0 then <a bracket of this module, or a smooth factor> else …`` (or a product):
    a split condition as an ``if``'s, with another inside its branch."""
    inner = bracket(scope)
    cond = bracket(scope)
    lhs, rhs = cond.terms
    then = mul(inner, C.smooth(scope)) if scope.draw(st.booleans()) else inner
    orelse = num(F(1, 2)) if scope.draw(st.booleans()) else C.smooth(scope)
    return S.IfCmp(lhs, cond.ops[0], rhs, then, orelse)


# ---------------------------------------------------------------------------------------------
# Folding edge cases (fold31): the same function spelled with neutral elements
# ---------------------------------------------------------------------------------------------

def _dressed(scope: C.Scope, t: S.STerm) -> S.STerm:
    """``t`` with a neutral element around it (one of eight spellings)."""
    v, p = name(scope.var()), scope.param()
    forms = (lambda: mul(t, num(1)), lambda: mul(num(1), t), lambda: sub(t, num(0)),
             lambda: T.add(t, mul(num(0), p)), lambda: sub(sub(t, num(F(1, 2))), S.Neg(S.Num(F(1, 2)))),
             lambda: mul(S.Neg(S.Num(F(1))), mul(S.Neg(S.Num(F(1))), t)), lambda: power(t, 1),
             lambda: T.add(t, mul(num(0), T.div(num(1), sub(v, p)))))
    return forms[scope.index(len(forms))]()


def folded(scope: C.Scope) -> S.STerm:
    """A condition of :func:`~.conditions.condition` or a smooth factor, spelled with neutral
    elements (:func:`_dressed`) on one side or both."""
    if scope.draw(st.booleans()):
        return _dressed(scope, C.smooth(scope))
    lhs, cmp, rhs = C.condition(scope)
    side = scope.index(3)
    if side != 1:
        lhs = _dressed(scope, lhs)
    if side != 0:
        rhs = _dressed(scope, rhs)
    return S.Iverson((lhs, rhs), (cmp,))


#: The factors of ``poles`` by weight (the first is what shrinking aims at).
FACTORS = (bracket, bracket, nested, folded)


def factor(scope: C.Scope) -> S.STerm:
    """One factor of :data:`FACTORS`, maybe times a smooth factor."""
    made = FACTORS[scope.index(len(FACTORS))](scope)
    return mul(made, C.smooth(scope)) if scope.draw(st.booleans()) else made


# ---------------------------------------------------------------------------------------------
# Huge boxes (exact31's wide quadrature)
# ---------------------------------------------------------------------------------------------

#: Half-widths of a huge box.
HUGE = (F(10) ** 3, F(10) ** 6, F(10) ** 8, F(10) ** 10)


def _weight(draw, v: S.Name, p: S.Name) -> S.STerm:
    """A weight decaying along ``v``: ``exp(-v^2)``, a narrow ``exp(-100 (v - P)^2)``, a Gaussian
    centred away from 0 (``exp(-(v - 3)^2)``), or ``1 / (1 + v^2)`` (tails of order 1/L)."""
    forms = (lambda: call("exp", S.Neg(power(v, 2))),
             lambda: call("exp", S.Neg(mul(num(100), power(sub(v, p), 2)))),
             lambda: call("exp", S.Neg(power(sub(v, num(3)), 2))),
             lambda: T.div(num(1), T.add(num(1), power(v, 2))))
    return forms[draw(st.integers(0, len(forms) - 1))]()


@st.composite
def huge(draw, params: tuple[str, ...]):
    """A program over a huge box: one or two variables, each over ``[-L, L]`` or ``[0, L]``
    (:data:`HUGE`), the body ``[cond] · w(x) (· w(y))`` summed once or twice, ``cond`` an affine
    condition against a parameter term or a moving pole (``[(x - P)/(y + Q) >= 0]``); returns
    (domain, body, variables)."""
    variables = ("x", "y")[:draw(st.integers(1, 2))]
    domain = []
    for _ in variables:
        half = num(draw(st.sampled_from(HUGE)))
        domain.append(S.Interval(S.Neg(half) if draw(st.booleans()) else num(0), half))
    p = name(draw(st.sampled_from(params)))
    x = name(variables[0])
    summands = []
    for _ in range(draw(st.integers(1, 2))):
        form = draw(st.integers(0, 2 if len(variables) == 2 else 0))
        k = draw(st.sampled_from(C.OFFSETS))
        if form == 0:
            cond = S.Iverson((x, offset(p, k)), (draw(st.sampled_from(C.CMPS)),))
        elif form == 1:
            cond = S.Iverson((T.add(x, name("y")), offset(p, k)), (draw(st.sampled_from(C.CMPS)),))
        else:
            q = name(draw(st.sampled_from(params)))
            cond = S.Iverson((T.div(sub(x, offset(p, k)), T.add(name("y"), q)), num(0)), (">=",))
        term = cond
        for v in variables:
            term = mul(term, _weight(draw, name(v), p))
        summands.append(term)
    body = summands[0] if len(summands) == 1 else T.add(summands[0], summands[1])
    return tuple(domain), body, variables
