"""Constructs the default draw never makes (``programs(wide=True)``, ``langur fuzz --wide``): each
well-typed (LANGUAGE.md §2, §6; docs/language.md) and registered in the scope like any condition
(:meth:`~.conditions.Scope.register`), so the program stays generic at its defaults.

* a finite loop (paper §9, unrolled by the front end): ``sum i in 1..n: [L CMP P + k + d*i] * v ^ i``
  or its ``prod`` of ``1 + …`` — a jump per copy, each with its delta, the index an exponent;
* conditions joined by ``&``, ``|`` and ``not`` (``[A | B]`` is ``1 − (1 − [A])·(1 − [B])``: its
  delta terms carry the other condition's complement), as a bracket or as an ``if``'s condition;
* a ``let`` inside a factor (Fig. 6 and 8, let): a parameter term bound to a fresh name that is a
  condition's level, so the delta's speed ``D_γ π₀Ψ̂`` goes through the let's tangent (γ′[z ↦ ⦇t⦈]);
* a partial primitive under a guard (LANGUAGE.md §1): ``if v >= P + k then log(v - (P + k) + c)
  else …``, defined everywhere the guard selects it and undefined elsewhere on the box, where an
  engine must not evaluate it into the answer;
* ``atan2(v - (P + k), w - 3)``: a branch cut (a jump of 2π along ``v = P + k``) with its delta;
* the primitives the default draw leaves out (``erf``, ``asin``, ``acos``, ``atanh``, ``tan``) as
  smooth factors, and the monotone ones as conditions (completed by implicit roots);
* ``ifge0`` on a parameter term written as such; a condition through a vector, ``[dot((v, w),
  (c1, c2)) CMP P + k]``;
* (fuzz29) ``erf`` in conditions (``erfinv``, an implicit root, turning points, a graph);
  ``ifge0`` on a term over the variables; a nested loop whose inner bound is the outer index;
  strict chains with ``pi``; a let-bound vector with ``cross`` and a component; negative and
  negative fractional exponents.

A declared diffeomorphism whose inverse and Jacobian depend on its parameter
(:data:`~.conditions.WIDE_DIFFEOS`) is drawn by :func:`~.conditions.declared`, boxes with both ends
moving and programs without a domain (the box as brackets in the body) by
:func:`langur.strategies.programs.programs`.
"""

from __future__ import annotations

from fractions import Fraction as F

from hypothesis import strategies as st

from ..syntax import surface as S
from . import conditions as C
from . import terms as T
from .terms import call, mul, name, num, offset, power, sub


def _else(scope: C.Scope) -> S.STerm:
    i = scope.index(3)
    return num((0, F(1, 2))[i]) if i < 2 else C.smooth(scope)


def _implicit(scope: C.Scope, lhs: S.STerm, rhs: S.STerm) -> S.Iverson:
    """``[lhs CMP rhs]`` (CMP ``<=`` or ``>=``), registered with the scope and kept among its
    implicit conditions: a monotone primitive without a closed-form inverse Langur uses, completed
    by an implicit root (LANGUAGE.md §6)."""
    cmp = scope.pick(("<=", ">="))
    scope.register(sub(lhs, rhs), key=(lhs, rhs))
    out = S.Iverson((lhs, rhs), (cmp,))
    scope.implicit.append(out)
    return out


def loop(scope: C.Scope) -> S.Loop:
    """``sum i in 1..n: [L CMP P + k + d*i] * v ^ i`` or ``prod i in 1..n: 1 + [L CMP P + k + d*i] * v ^ i``
    (``L`` affine): ``n`` parallel zero sets, one per copy."""
    lhs, cmp, rhs = C.affine(scope)
    n = scope.pick((2, 3))
    d = scope.pick((F(1, 5), F(-3, 10)))
    op = scope.pick(("sum", "prod"))
    v = name(scope.var())
    for k in range(1, n + 1):
        scope.register(sub(lhs, offset(rhs, d * k)), key=(lhs, rhs, "loop", d * k))
    step = mul(num(d), name("i")) if d > 0 else mul(num(-d), name("i"))
    level = S.BinOp("+" if d > 0 else "-", rhs, step)
    term = mul(S.Iverson((lhs, level), (cmp,)), S.BinOp("^", v, name("i")))
    return S.Loop(op, "i", num(1), num(n), term if op == "sum" else T.add(num(1), term))


def _bracket(scope: C.Scope) -> S.Iverson:
    lhs, cmp, rhs = C.condition(scope)
    return S.Iverson((lhs, rhs), (cmp,))


def logic(scope: C.Scope) -> S.STerm:
    """``[A & B]``, ``[A | B]``, ``[not A]``, or ``if A & B then … else …`` (and ``|``, ``not``)."""
    op = scope.pick(("or", "and", "not"))
    parts = (_bracket(scope),) if op == "not" else (_bracket(scope), _bracket(scope))
    cond = S.Logic(op, parts)
    if scope.draw(st.booleans()):
        return cond
    return S.IfLogic(cond, C.smooth(scope), _else(scope))


def let_level(scope: C.Scope) -> S.LetIn:
    """``let tN = <parameter term> in [L CMP tN] * <smooth factor>`` (the smooth factor may use
    ``tN`` too)."""
    t = f"t{sum(1 for n in scope.names if n.startswith('t'))}"
    p, q = scope.param(), scope.param()
    forms = (lambda: T.add(mul(p, q), num(F(1, 10))),
             lambda: sub(mul(num(2), p), num(F(1, 2))),
             lambda: T.div(p, offset(q, 1)))
    bound = forms[scope.index(len(forms))]()
    scope.env[t] = T.evaluate(bound, scope.env)
    scope.lets[t] = bound
    scope.names.append(t)
    try:
        lhs, cmp, _ = C.affine(scope)
        scope.register(sub(lhs, name(t)), key=(lhs, name(t), bound))
        body = mul(S.Iverson((lhs, name(t)), (cmp,)), C.smooth(scope))
    finally:
        scope.names.remove(t)
    return S.LetIn(t, bound, body)


def guarded(scope: C.Scope) -> S.IfCmp:
    """``if v >= P + k then f(v - (P + k) + c) else …`` (or ``<=`` with ``P + k - v``): ``f`` a
    partial primitive (``log``, ``sqrt``, ``1/·``, ``·^1.5``) whose argument is at least ``c > 0``
    where the guard holds and negative on part of the box."""
    v = name(scope.var())
    level = C.shifted_param(scope)
    cmp = scope.pick((">=", "<="))
    c = num(scope.pick((F(1, 10), F(1, 4))))
    arg = T.add(sub(v, level), c) if cmp == ">=" else T.add(sub(level, v), c)
    forms = (lambda: call("log", arg), lambda: call("sqrt", arg), lambda: T.div(num(1), arg),
             lambda: power(arg, F(3, 2)))
    scope.register(sub(v, level), key=(v, level))
    return S.IfCmp(v, cmp, level, forms[scope.index(len(forms))](), _else(scope))


def branch_cut(scope: C.Scope) -> S.STerm:
    """``atan2(v - (P + k), w - 3)`` (``w`` a variable, < 0 on every box; or ``-1``): atan2's cut,
    a jump of 2π along ``v = P + k``, times a smooth factor."""
    v = name(scope.var())
    level = C.shifted_param(scope)
    second = sub(name(scope.var()), num(3)) if scope.draw(st.booleans()) else num(-1)
    scope.register(sub(v, level), key=(v, level))
    return mul(call("atan2", sub(v, level), second), C.smooth(scope))


#: ``acos(P*v/3)`` stays in acos's domain on boxes in [-1, 2] while |P| ≤ 1.4 (|P·v/3| ≤ 0.94); a
#: larger parameter term (``let s = 2*P``, up to 1.66) is divided by 6 instead.
ACOS_SCALE = 1.4


def primitive(scope: C.Scope) -> S.STerm:
    """``erf``, ``asin``, ``acos``, ``atanh``, ``tan`` as smooth factors (arguments inside their
    domains on every box in [-1, 2]), or the monotone ones against a parameter term as a condition
    (``asin(v / 3)``, ``acos(v / 3)``, ``atanh(v / 3)``, ``tan(v / 2)``: no closed-form inverse
    Langur uses, so implicit roots: on a variable with constant bounds, kept out of defs and
    of programs without a domain like :func:`~.conditions.turning_condition`'s)."""
    smooth = scope.draw(st.booleans()) or not scope.fixed
    v = name(scope.var() if smooth else scope.pick(scope.fixed))
    third = T.div(v, num(3))
    if smooth:
        p = scope.param()
        forms = (lambda: call("erf", sub(v, p)), lambda: call("asin", third),
                 lambda: call("acos", T.div(mul(p, v), num(3 if abs(scope.env[p.name]) <= ACOS_SCALE else 6))),
                 lambda: call("atanh", third),
                 lambda: call("tan", T.div(v, num(2))))
        return forms[scope.index(len(forms))]()
    forms = (lambda: (call("asin", third), offset(scope.param(), F(-1, 2))),
             lambda: (call("acos", third), offset(scope.param(), 1)),
             lambda: (call("atanh", third), offset(scope.param(), F(-1, 2))),
             lambda: (call("tan", T.div(v, num(2))), C.shifted_param(scope)))
    return _implicit(scope, *forms[scope.index(len(forms))]())


def param_ifge0(scope: C.Scope) -> S.IfGe0S:
    """``ifge0 P - Q then … else …`` (Fig. 6's conditional on parameters, written with ``ifge0``)."""
    p = scope.param()
    q = scope.pick([n for n in scope.names if n != p.name] + ["0.5"])
    rhs = num(F(1, 2)) if q == "0.5" else name(q)
    scope.register(sub(p, rhs), key=(p, rhs))
    return S.IfGe0S(sub(p, rhs), C.smooth(scope), _else(scope))


def dot_condition(scope: C.Scope) -> S.Iverson:
    """``[dot((v, w), (c1, c2)) CMP P + k]`` (a vector, desugared to ``c1*v + c2*w``); in one
    variable ``[dot((v, 1), (c1, c2)) CMP P + k]``."""
    v = scope.var()
    w = scope.pick(u for u in scope.variables if u != v) if len(scope.variables) > 1 else None
    c1, c2 = scope.pick(C.COEFFICIENTS), scope.pick((F(1), F(-1, 2)))
    rhs = C.shifted_param(scope)
    second = name(w) if w is not None else num(1)
    lhs = call("dot", S.Vector((name(v), second)), S.Vector((num(c1), num(c2))))
    flat = T.add(mul(num(c1), name(v)), mul(num(c2), second))
    scope.register(sub(flat, rhs), key=(lhs, rhs))
    return S.Iverson((lhs, rhs), (scope.pick(C.CMPS),))


def erf_condition(scope: C.Scope) -> S.STerm:
    """``erf`` in a condition (F3, completed since front28): on a variable with constant bounds,
    ``[erf(v) CMP P - 1/2]`` (inverted by ``erfinv``), ``[erf(2*v) + v CMP P + k]`` (monotone, no
    closed-form inverse: an implicit root) or ``[sin(3*erf(v)) CMP P - 1/2]`` (turning points at
    ``erfinv(±π/6)``), kept out of defs and of programs without a domain like :func:`primitive`'s;
    in two variables or more also the graph ``[w CMP erf(2*v) + P - 1/2]``; as a smooth
    ``erf`` factor when no variable has constant bounds and there is no second variable."""
    if len(scope.variables) > 1 and (not scope.fixed or scope.index(4) == 3):
        v, w = scope.two_vars()
        lhs, rhs = name(w), offset(T.add(call("erf", mul(num(2), name(v))), scope.param()), F(-1, 2))
        cmp = scope.pick(C.CMPS)
        scope.register(sub(lhs, rhs), key=(lhs, rhs))
        return S.Iverson((lhs, rhs), (cmp,))
    if not scope.fixed:
        return call("erf", sub(name(scope.var()), scope.param()))
    v = name(scope.pick(scope.fixed))
    forms = (lambda: (call("erf", v), offset(scope.param(), F(-1, 2))),
             lambda: (T.add(call("erf", mul(num(2), v)), v), C.shifted_param(scope, (F(0), F(3, 10), F(-1, 5)))),
             lambda: (call("sin", mul(num(3), call("erf", v))), offset(scope.param(), F(-1, 2))))
    return _implicit(scope, *forms[scope.index(len(forms))]())


def variable_ifge0(scope: C.Scope) -> S.IfGe0S:
    """``ifge0 L - R then … else …`` with ``L CMP R`` a condition over the variables (LANGUAGE.md §6:
    a diffeomorphic conditional written with ``ifge0``, completed like a bracket)."""
    lhs, cmp, rhs = C.condition(scope)
    cond = sub(lhs, rhs) if cmp in (">=", ">") else sub(rhs, lhs)
    return S.IfGe0S(cond, C.smooth(scope), _else(scope))


def nested_loop(scope: C.Scope) -> S.Loop:
    """``sum i in 1..2: sum j in 1..i: [L CMP P + k + 0.2*i - 0.1*j] * v ^ j`` (§9: an inner loop's
    bound is the outer index; three copies, each a jump of its own)."""
    lhs, cmp, rhs = C.affine(scope)
    v = name(scope.var())
    for i in (1, 2):
        for j in range(1, i + 1):
            scope.register(sub(lhs, offset(rhs, F(i, 5) - F(j, 10))), key=(lhs, rhs, "loop2", i, j))
    level = S.BinOp("-", S.BinOp("+", rhs, mul(num(F(1, 5)), name("i"))), mul(num(F(1, 10)), name("j")))
    inner = S.Loop("sum", "j", num(1), name("i"),
                   mul(S.Iverson((lhs, level), (cmp,)), S.BinOp("^", v, name("j"))))
    return S.Loop("sum", "i", num(1), num(2), inner)


def strict_window(scope: C.Scope) -> S.Iverson:
    """``[P + k < L < P + k + pi/8]`` or ``[P + k + pi/8 > L > P + k]``: a chain with strict
    comparisons and the constant ``pi`` (two parallel jumps, like :func:`~.conditions.window`)."""
    lhs, _, lo = C.affine(scope)
    hi = T.add(lo, T.div(name("pi"), num(8)))
    scope.register(sub(lhs, lo), key=(lhs, lo))
    scope.register(sub(lhs, hi), key=(lhs, hi))
    if scope.draw(st.booleans()):
        return S.Iverson((lo, lhs, hi), ("<", "<"))
    return S.Iverson((hi, lhs, lo), (">", ">"))


def cross_condition(scope: C.Scope) -> S.LetIn:
    """``let o = (P, 0.1, 0) in [cross((0.9, 0.3, 0) - o, (v, w, 0) - o).z CMP 0]``: a let-bound vector,
    vector differences, ``cross`` and a component (docs/language.md, vectors): the side of the
    line through (P, 0.1) and (0.9, 0.3), ``(0.9 - P)(w - 0.1) - 0.2(v - P)`` (``w`` the constant
    0.5 in one variable)."""
    v = name(scope.var())
    w = name(scope.pick(u for u in scope.variables if u != v.name)) if len(scope.variables) > 1 else num(F(1, 2))
    p = scope.param()
    o = name("o")
    z = num(0)
    flat = sub(mul(sub(num(F(9, 10)), p), sub(w, num(F(1, 10)))), mul(num(F(1, 5)), sub(v, p)))
    scope.register(flat, key=("cross", v, w, p))
    lhs = S.Component(call("cross", sub(S.Vector((num(F(9, 10)), num(F(3, 10)), z)), o),
                           sub(S.Vector((v, w, z)), o)), "z")
    return S.LetIn("o", S.Vector((p, num(F(1, 10)), z)), S.Iverson((lhs, z), (scope.pick(C.CMPS),)))


def powers(scope: C.Scope) -> S.STerm:
    """Smooth factors with what :func:`~.conditions.smooth` never writes: a negative or negative
    fractional exponent (``(v + 2) ^ -2``, ``(v + P + 1.5) ^ -0.5``) and ``pi`` (``cos(pi * v / 2)``)."""
    v, p = name(scope.var()), scope.param()
    forms = (lambda: power(offset(v, 2), -2), lambda: power(offset(T.add(v, scope.positive(p)), F(3, 2)), F(-1, 2)),
             lambda: call("cos", T.div(mul(name("pi"), v), num(2))))
    return forms[scope.index(len(forms))]()


#: fuzz29's additions besides ``erf`` conditions, drawn by :func:`more`.
MORE = (variable_ifge0, nested_loop, strict_window, cross_condition, powers)


def more(scope: C.Scope) -> S.STerm:
    """One of :data:`MORE` (one slot of :data:`FACTORS`, so that fuzz28's constructs keep most of
    their share)."""
    return MORE[scope.index(len(MORE))](scope)


#: The wide factors by kind and weight (the first is what shrinking aims at; ``logic`` twice: three
#: operators, two forms each; ``more`` twice: five kinds).
FACTORS = (loop, logic, let_level, guarded, branch_cut, primitive, logic, param_ifge0, dot_condition,
           erf_condition, more, more)


def factor(scope: C.Scope) -> S.STerm:
    """One factor of :data:`FACTORS`."""
    return FACTORS[scope.index(len(FACTORS))](scope)
