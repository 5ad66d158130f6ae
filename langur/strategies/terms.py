"""Surface terms as the parser builds them, evaluated numerically, and the zero sets they create
(the bookkeeping behind :mod:`langur.strategies`; no hypothesis here).

* Builders (:func:`num`, :func:`add`, :func:`sub`, :func:`mul`, …) give exactly the AST the parser
  gives for the printed text: literals are non-negative (a negative one is ``Neg(Num(k))``), so
  ``parse_term(print_term(t)) == t``.
* :func:`evaluate` is the float value of a surface term at a point (variables and parameters by
  name), for the genericity check only: the engines never see it.
* :class:`ZeroSet` is one zero set a program creates (a condition's, or a kink's: ``abs``, ``min``
  and ``max`` are conditionals, §6), with its flat pieces (hyperplanes ``n·x = c``) found
  numerically; :func:`generic` is LANGUAGE.md §5's transversality at the parameter defaults in the
  simple sufficient form the fuzzer has always used: no two zero sets coincide, none lies on a
  face of the box, none passes through a corner, and no condition on parameters alone sits on its
  boundary.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from fractions import Fraction

from ..syntax import surface as S

# ---------------------------------------------------------------------------------------------
# Builders: the parser's AST for the printed text
# ---------------------------------------------------------------------------------------------


def num(value) -> S.STerm:
    """A literal (``Fraction``, ``int`` or decimal text); a negative one is ``Neg(Num(-k))``."""
    v = Fraction(value)
    return S.Neg(S.Num(-v)) if v < 0 else S.Num(v)


def name(n: str) -> S.Name:
    return S.Name(n)


def _is_zero(t: S.STerm) -> bool:
    return isinstance(t, S.Num) and t.value == 0


def add(a: S.STerm, b: S.STerm) -> S.STerm:
    """``a + b``; ``a - k`` for a negative literal ``b``."""
    if isinstance(b, S.Neg):
        return S.BinOp("-", a, b.arg)
    return S.BinOp("+", a, b)


def sub(a: S.STerm, b: S.STerm) -> S.STerm:
    return S.BinOp("-", a, b)


def offset(t: S.STerm, k) -> S.STerm:
    """``t + k`` (``t - |k|`` when k < 0, ``t`` when k = 0)."""
    k = Fraction(k)
    return t if k == 0 else add(t, num(k))


def mul(a: S.STerm, b: S.STerm) -> S.STerm:
    return S.BinOp("*", a, b)


def scaled(c, t: S.STerm) -> S.STerm:
    """``c*t`` for a literal coefficient (``t`` for 1, ``-t`` for −1)."""
    c = Fraction(c)
    if c == 1:
        return t
    if c == -1:
        return S.Neg(t)
    return mul(num(c), t)


def div(a: S.STerm, b: S.STerm) -> S.STerm:
    return S.BinOp("/", a, b)


def power(a: S.STerm, k) -> S.STerm:
    return S.BinOp("^", a, num(k))


def call(f: str, *args: S.STerm) -> S.Apply:
    return S.Apply(f, tuple(args))


def linear(coefs: dict[str, S.STerm | Fraction]) -> S.STerm:
    """``Σ c_v·v`` in the order given, each coefficient a literal or a parameter term."""
    out: S.STerm | None = None
    for v, c in coefs.items():
        if isinstance(c, (Fraction, int)):
            if c == 0:
                continue
            if out is not None and c < 0:
                out = sub(out, scaled(-c, name(v)))
                continue
            term = scaled(c, name(v))
        else:
            term = mul(c, name(v))
        out = term if out is None else add(out, term)
    assert out is not None, "a linear form needs a nonzero coefficient"
    return out


# ---------------------------------------------------------------------------------------------
# Numbers
# ---------------------------------------------------------------------------------------------

_PRIMS: dict[str, Callable[..., float]] = {
    "exp": math.exp, "log": math.log, "sin": math.sin, "cos": math.cos, "tan": math.tan,
    "sqrt": math.sqrt, "atan": math.atan, "tanh": math.tanh, "abs": abs, "min": min, "max": max,
    "erf": math.erf, "asin": math.asin, "acos": math.acos, "atanh": math.atanh, "atan2": math.atan2,
}

_BINOPS: dict[str, Callable[[float, float], float]] = {
    "+": lambda x, y: x + y, "-": lambda x, y: x - y, "*": lambda x, y: x * y, "/": lambda x, y: x / y,
    "^": lambda x, y: x ** y,
}


def evaluate(t: S.STerm, env: dict[str, float]) -> float:
    """The float value of the surface term ``t`` (no ``let``, conditionals or calls) at ``env``."""
    match t:
        case S.Num(v):
            return float(v)
        case S.Name("pi"):
            return math.pi
        case S.Name(n):
            return env[n]
        case S.Neg(a):
            return -evaluate(a, env)
        case S.BinOp(op, a, b):
            x, y = evaluate(a, env), evaluate(b, env)
            return _BINOPS[op](x, y)
        case S.Apply(f, args):
            return _PRIMS[f](*(evaluate(a, env) for a in args))
    raise TypeError(f"cannot evaluate {t!r}")


def names_in(t) -> set[str]:
    """Every name a surface term mentions (variables, parameters, let names, called defs)."""
    out: set[str] = set()
    stack = [t]
    while stack:
        u = stack.pop()
        if isinstance(u, S.Name):
            out.add(u.name)
        elif isinstance(u, S.Apply):
            out.add(u.name)
            stack.extend(u.args)
        elif isinstance(u, S.DiffeoApp):
            out.add(u.name)
            stack.extend((*u.variables, *u.params))
        elif isinstance(u, tuple):
            stack.extend(u)
        elif hasattr(u, "__dataclass_fields__") and not isinstance(u, S.Num):
            stack.extend(getattr(u, f) for f in u.__dataclass_fields__ if f not in ("span", "name_span", "name"))
    return out


def substitute(t, mapping: dict[str, S.STerm]):
    """``t`` with each name in ``mapping`` replaced by its term, simultaneously (like :func:`rename`:
    the names a ``let`` or a loop binds are never in ``mapping``)."""
    return _at_names(t, lambda n: mapping.get(n.name, n))


def rename(t, mapping: dict[str, str]):
    """``t`` with the names in ``mapping`` replaced (surface terms have no binders here but ``let``,
    whose bound name is never renamed)."""
    return _at_names(t, lambda n: S.Name(mapping.get(n.name, n.name)))


def _at_names(t, at_name):
    """``t`` with each :class:`~langur.syntax.surface.Name` ``n`` in it replaced by ``at_name(n)`` (the
    one walk of :func:`substitute` and :func:`rename`; spans, bound names and operators are kept)."""
    match t:
        case S.Name():
            return at_name(t)
        case S.Num():
            return t
        case tuple():
            return tuple(_at_names(u, at_name) for u in t)
    if hasattr(t, "__dataclass_fields__"):
        kw = {f: _at_names(getattr(t, f), at_name) if f not in ("span", "name_span", "name", "op", "ops")
              else getattr(t, f) for f in t.__dataclass_fields__}
        return type(t)(**kw)
    return t


# ---------------------------------------------------------------------------------------------
# Zero sets and genericity
# ---------------------------------------------------------------------------------------------

Plane = tuple[tuple[float, ...], float]  # n·x = c


@dataclass
class ZeroSet:
    """The zero set of ``g`` over ``variables`` at the parameter defaults; ``key`` names it (two
    zero sets with one key are the same set); ``planes``: its flat pieces, each ``n·x = c``;
    ``term``: the surface term ``g`` evaluates (a zero set of the same term at other parameter
    terms is :func:`zero_set` of it :func:`substitute`-d)."""

    key: object
    g: Callable[[dict[str, float]], float]
    variables: tuple[str, ...]
    planes: tuple[Plane, ...] = field(default=())
    term: S.STerm | None = None


def zero_set(term: S.STerm, variables: tuple[str, ...], env: dict[str, float],
             span: tuple[float, float] = (-2.0, 3.0), key=None) -> ZeroSet:
    """The zero set of ``term`` (over the variables it mentions): its flat pieces found by looking
    — affine in the variables (the hyperplane from its values at 0 and the unit vectors, checked
    at two more points), or depending on one variable only (its roots on ``span``, by sign change
    and bisection)."""
    used = tuple(v for v in variables if v in names_in(term))

    def g(point: dict[str, float]) -> float:
        try:
            return evaluate(term, {**env, **point})
        except (ValueError, ZeroDivisionError, OverflowError):
            return math.nan

    zs = ZeroSet(key if key is not None else term, g, used, term=term)
    if not used:
        return zs
    origin = {v: 0.0 for v in variables}
    g0 = g(origin)
    normal = tuple(g({**origin, v: 1.0}) - g0 for v in variables)
    probes = ({v: 0.3 + 0.7 * i for i, v in enumerate(variables)}, {v: -1.3 + 0.4 * i for i, v in enumerate(variables)})
    if all(math.isfinite(g(p)) and abs(g(p) - g0 - sum(n * p[v] for n, v in zip(normal, variables))) < 1e-9
           for p in probes) and math.isfinite(g0):
        zs.planes = ((normal, -g0),)
        return zs
    if len(used) == 1:
        v = used[0]
        e = tuple(1.0 if w == v else 0.0 for w in variables)
        zs.planes = tuple((e, r) for r in _roots(lambda s: g({**origin, v: s}), *span))
    return zs


def _roots(f, lo: float, hi: float, n: int = 400) -> list[float]:
    xs = [lo + (hi - lo) * i / n for i in range(n + 1)]
    ys = [f(x) for x in xs]
    out = []
    for (a, fa), (b, fb) in zip(zip(xs, ys), zip(xs[1:], ys[1:])):
        if not (math.isfinite(fa) and math.isfinite(fb)):
            continue
        if fa == 0:
            out.append(a)
        elif fa * fb < 0:
            for _ in range(60):
                m = (a + b) / 2
                fm = f(m)
                if fa * fm <= 0:
                    b = m
                else:
                    a, fa = m, fm
            out.append((a + b) / 2)
    return out


def _normed(plane: Plane) -> tuple[float, ...]:
    n, c = plane
    size = math.sqrt(sum(x * x for x in n))
    vec = [x / size for x in n] + [c / size]
    first = next(x for x in vec if abs(x) > 1e-12)
    return tuple(-x for x in vec) if first < 0 else tuple(vec)


def generic(zero_sets: list[ZeroSet], box: list[tuple[float, float]], variables: tuple[str, ...],
            tol: float = 1e-6) -> bool:
    """LANGUAGE.md §5 at the defaults, checked the simple way (module doc)."""
    keys = [z.key for z in zero_sets]
    if len(set(keys)) != len(keys):
        return False
    planes: list[tuple[object, tuple[float, ...]]] = []
    for i, (lo, hi) in enumerate(box):
        e = tuple(1.0 if j == i else 0.0 for j in range(len(box)))
        planes += [("box", _normed((e, lo))), ("box", _normed((e, hi)))]
    for j, z in enumerate(zero_sets):
        for n, c in z.planes:
            if not any(n):  # the variables cancel (``F/G >= k`` with F = k·G + c, fuzz33): empty, or everywhere
                if abs(c) < tol:
                    return False
                continue
            planes.append((j, _normed((n, c))))
    for i in range(len(planes)):
        for j in range(i + 1, len(planes)):
            if planes[i][0] == planes[j][0] == "box":
                continue
            if all(abs(a - b) < tol for a, b in zip(planes[i][1], planes[j][1])):
                return False
    corners: list[dict[str, float]] = [{}]
    for v, (lo, hi) in zip(variables, box):
        corners = [{**c, v: x} for c in corners for x in (lo, hi)]
    for z in zero_sets:
        for c in corners if z.variables else [{}]:
            value = z.g(c)
            if not math.isfinite(value) or abs(value) < tol:
                return False
    return True
