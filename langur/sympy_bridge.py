"""Core terms ↔ sympy: the one ⟦·⟧ of Fig. 7 in sympy, under every sympy-using layer.

The front end (diffeomorphism completion, LANGUAGE.md §6), the exact engine and the linter read
core terms as sympy expressions through this module; the Monte Carlo engine never imports it.

* :func:`denote` is ⟦t⟧ (Fig. 7) as a sympy expression over one real symbol per name: conditionals
  become ``Piecewise`` (never ``Heaviside``), primitives the sympy functions their registry entries
  name (:mod:`langur.primitives`), ``pi`` is ``sp.pi``, ``let`` substitutes ⟦bound⟧.
  :func:`to_sympy` is ⟦t⟧ of a smooth term (no conditional, no call), :class:`NotSmooth` else.
* :func:`from_sympy` maps such an expression back to a core term; ``Pow(b, 1/2)`` becomes
  ``Prim('sqrt', b)``.  Sympy keeps its arguments in a canonical order, so the same expression
  always gives the same term (the completion of a condition is deterministic).
* :func:`symbol`, :func:`const_expr`, :func:`exact_number`, :func:`at_symbols`: names and numbers.
* :data:`MAX_EXPONENT`, :func:`exponent_weight`: the bound on the powers ⟦·⟧ computes (T234).
* :func:`magnitude`: the size of an expression's terms, against which a numeric zero test reads a
  value (the linter's and the quadrature's "vanishes identically on the zero set").
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from fractions import Fraction
from functools import cache
from types import MappingProxyType
from typing import TypeVar

import sympy as sp

from .core import (
    PI,
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Term,
    Var,
    children,
    free_vars,
    shared,
    smooth,
    subterms,
)
from .diagnostics import LangurError, error
from .implicit import implicit_root
from .primitives import REGISTRY, Domain

T = TypeVar("T")


class NotSmooth(Exception):
    """The term has a conditional or a call: it is not a smooth function we can hand to sympy."""


#: f ↦ its sympy function, for every primitive of the registry.
FUNCTIONS: dict[str, Callable[[sp.Expr], sp.Expr]] = {p.name: getattr(sp, p.sympy) for p in REGISTRY.values()}
#: sympy function ↦ the primitive's name.
PRIMITIVE_OF: dict[type, str] = {f: name for name, f in FUNCTIONS.items()}
#: sympy function class ↦ the primitive's domain, for every primitive that is one (``sqrt`` is a power).
DOMAINS: dict[type, Domain] = {f: REGISTRY[name].domain for name, f in FUNCTIONS.items() if isinstance(f, type)}


@cache
def symbol(name: str) -> sp.Symbol:
    """The real sympy symbol of a variable, parameter or diffeo input: same name, same symbol."""
    return sp.Symbol(name, real=True)


def symbols(names: Iterable[str]) -> tuple[sp.Symbol, ...]:
    return tuple(symbol(n) for n in names)


def const_expr(value: Fraction | str) -> sp.Expr:
    """A core constant: an exact rational, or π."""
    if value == PI:
        return sp.pi
    f = Fraction(value)
    return sp.Rational(f.numerator, f.denominator)


def exact_number(v) -> sp.Expr:
    """A parameter value as sympy: Fractions, ints and decimal floats become exact Rationals
    (``0.5`` → 1/2, ``0.1`` → 1/10 as typed); non-finite floats stay floats."""
    if isinstance(v, sp.Basic):
        return v
    if isinstance(v, Fraction):
        return sp.Rational(v.numerator, v.denominator)
    if isinstance(v, bool):
        return sp.Integer(int(v))
    if isinstance(v, int):
        return sp.Integer(v)
    if isinstance(v, float):
        return sp.Rational(repr(v)) if math.isfinite(v) else sp.Float(v)
    return sp.sympify(v)


def at_symbols(at: Mapping[str, object] | None) -> dict[sp.Symbol, sp.Expr]:
    """``{"theta": 0.5}`` → ``{theta: 1/2}`` (symbols and exact numbers)."""
    return {symbol(k): exact_number(v) for k, v in (at or {}).items()}


def magnitude(expr: sp.Expr) -> sp.Expr:
    """A bound of the size of ``expr``'s values made of its terms' sizes: sums and products of the
    terms' absolute values (a sum that cancels keeps a large magnitude; a term as small as
    ``y/10**13`` is all of its own), and at least 1 for a function's value, whose argument may
    cancel to 0.  A value far below its magnitude is rounding, whatever the scale."""
    if expr.is_Add or expr.is_Mul:
        return expr.func(*(magnitude(a) for a in expr.args))
    if expr.is_Pow and expr.exp.is_Integer and expr.exp > 0:
        return magnitude(expr.base) ** expr.exp
    if expr.is_Symbol or expr.is_number:
        return sp.Abs(expr)
    return sp.Abs(expr) + 1


def may_vanish(expr: sp.Expr, variables: Iterable[sp.Symbol]) -> bool:
    """Whether ``expr`` may be 0 somewhere in ℝⁿ (its parameters any reals): False only when that is
    proved — ``expr`` nonzero under real symbols (``exp(x)``, ``x² + 1``), or, in one variable and
    no parameter, without a real root (``solveset``).  A condition's zero set, where its delta sits
    (LANGUAGE.md §4): empty, it carries no delta, and ``Ψ̂⁻¹(0, u′)`` is never used."""
    if expr.is_zero is False:
        return False
    syms = expr.free_symbols
    if len(syms) == 1 and syms <= set(variables):
        (x,) = syms
        try:
            return sp.solveset(expr, x, sp.S.Reals) != sp.S.EmptySet
        except (NotImplementedError, TypeError, ValueError):
            return True
    return True


def derivative_function(op: str) -> Callable[[sp.Expr], sp.Expr]:
    """f' as a sympy function, for the chain rule (LANGUAGE.md §1).

    A radicand of f' in its argument (asin's and acos's 1 − y²) is put over one denominator when
    the argument holds a root itself: atan2's angle acos(x/√(x² + y²)) (LANGUAGE.md §1's
    desugaring) then has √(1 − w²) = |y|/√(x² + y²), the same function, which doubles evaluate near
    the branch cut y = 0 instead of cancelling 1 − x²/(x² + y²) to 0 (an exact-engine quadrature
    ending on the cut read the NaNs as "undefined")."""
    y = sp.Dummy("y", real=True)
    d = sp.diff(FUNCTIONS[op](y), y)
    radicands = {p.base for p in d.atoms(sp.Pow) if not p.exp.is_integer and p.base != y and p.base.has(y)}

    def at(w: sp.Expr) -> sp.Expr:
        if radicands and any(not p.exp.is_integer for p in w.atoms(sp.Pow)):
            return d.xreplace({r: sp.together(r.xreplace({y: w})) for r in radicands}).xreplace({y: w})
        return d.xreplace({y: w})

    return at


_NO_ENV: Mapping[str, sp.Expr] = MappingProxyType({})


@shared
def denote(t: Term, env: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
    """⟦t⟧ (Fig. 7) as a sympy expression; ``env`` maps names (let-bound parameters, or variables
    and parameters to replace) to expressions used instead of their symbols."""
    env = _NO_ENV if env is None else env  # the same object down the term: memoized per node
    if isinstance(t, (Pow, Let)) and exponent_weight(t) > MAX_EXPONENT:
        raise too_heavy(t)  # T234: a power sympy would take minutes to forever to compute exactly
    match t:
        case Const(value):  # Fig. 7, constant: ⟦c⟧ = c
            return const_expr(value)
        case Var(name):  # Fig. 7, variable: ⟦x⟧(ρ, γ) = ρ(x)
            return env.get(name, symbol(name))
        case Param(name):  # Fig. 7, parameter: ⟦z⟧(ρ, γ) = γ(z)
            return env.get(name, symbol(name))
        case Add(a, b):  # Fig. 7, sum
            return denote(a, env) + denote(b, env)
        case Mul(a, b):  # Fig. 7, product
            return denote(a, env) * denote(b, env)
        case Prim(op, a):  # LANGUAGE.md §1, smooth primitive f(t)
            return FUNCTIONS[op](denote(a, env))
        case Pow(a, k):  # LANGUAGE.md §1, constant power t ^ k
            return denote(a, env) ** const_expr(k)
        case IfGe0(c, a, b):  # Fig. 7, conditional: ⟦s⟧ if ⟦t⟧(·, γ) ≥ 0 else ⟦r⟧
            return sp.Piecewise((denote(a, env), denote(c, env) >= 0), (denote(b, env), True))
        case IfDiffeo(psi, a, b):  # Fig. 7, diffeomorphic conditional: ⟦s⟧ if π₀Ψ̂(ρ, γ) ≥ 0 else ⟦r⟧
            return sp.Piecewise((denote(a, env), denote(psi.forward[0], env) >= 0), (denote(b, env), True))
        case Let(name, bound, body):  # Fig. 7, let: ⟦s⟧(ρ, γ[z ↦ ⟦t⟧(·, γ)])
            return denote(body, {**env, name: denote(bound, env)})
        case Call(module, name, _):
            raise TypeError(f"call of {module}.{name} left in a core term: inline it first")
        case ImplicitRoot(eq, x, target, lo, hi, index, of):  # issue 18, an inverse branch with no closed form
            inner = {k: v for k, v in env.items() if k != x}
            return implicit_root(denote(eq, inner), symbol(x), denote(target, env), denote(lo, env), denote(hi, env),
                                 index, of, root=t, lenient=bool(free_vars(eq) - {x}))
    raise TypeError(f"not a core term: {t!r}")


#: The largest exponent ⟦·⟧ computes, multiplied along nested powers and lets (T234): sympy, the
#: exact engine and the checker raise a parameter's value or a constant to it as an exact
#: rational, about that many times its bits — ``(2^1000/3)^4096`` takes half a CPU second already,
#: ``a ^ 100000000`` or ``10 ^ 10 ^ 10`` minutes to forever.  (The Monte Carlo engine computes in
#: doubles and takes any exponent.)
MAX_EXPONENT = 4096


@shared
def exponent_weight(t: Term) -> int:
    """An upper bound of the factor by which ⟦t⟧'s exact values can exceed the bits of its
    constants and parameters: a leaf weighs 1, ``t ^ (p/q)`` weight(t)·max(|p|, q), ``let z = a in
    b`` at most weight(a)·weight(b), anything else the largest of its parts (a completed
    condition's components included).  A sum or a product does not multiply: ``a^4096 * a^4096``
    weighs 4096."""
    match t:
        case Pow(a, k):
            return exponent_weight(a) * max(abs(k.numerator), k.denominator)
        case Let(_, bound, body):
            return exponent_weight(bound) * exponent_weight(body)
        case IfDiffeo(psi, a, b):
            return max(exponent_weight(a), exponent_weight(b), *map(exponent_weight, psi.forward))
    return max(map(exponent_weight, children(t)), default=1)


def too_heavy(t: Pow | Let) -> LangurError:
    """T234 for the power or let ``t`` whose :func:`exponent_weight` exceeds :data:`MAX_EXPONENT`."""
    what = f"its exponent {t.exponent}" if isinstance(t, Pow) else "the exponent of a power in its body"
    return error(t.span, "T234", f"power too large to compute exactly: {what}, multiplied by those of the powers "
                 f"and lets it is nested in, exceeds {MAX_EXPONENT}; the exact engine and the checker compute powers "
                 "of rationals exactly (write a larger power as "
                 "exp(k * log(t)) for t > 0, or rescale)")


def to_sympy(t: Term, env: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
    """⟦t⟧ of the smooth core term ``t`` (no conditional, no call); ``env`` as in :func:`denote`.
    Raises :class:`NotSmooth` on conditionals and calls."""
    if not smooth(t):
        raise NotSmooth("a call" if any(isinstance(u, Call) for u in subterms(t)) else "a conditional")
    return denote(t, dict(env or {}))


def from_sympy(expr: sp.Expr, variables: Iterable[str], params: Iterable[str] = ()) -> Term:
    """The sympy expression ``expr`` as a core term: symbols named in ``variables`` become ``Var``,
    those in ``params`` become ``Param``.  Raises ``ValueError`` on anything not expressible
    (complex numbers, infinities, unknown functions, symbols not listed)."""
    vs, ps = set(variables), set(params)

    def go(e: sp.Expr) -> Term:
        if e is sp.pi:
            return Const(PI)
        if e.is_Rational:
            return Const(Fraction(int(e.p), int(e.q)))
        if e is sp.E:
            return Prim("exp", Const(Fraction(1)))
        if e.is_Symbol:
            if e.name in vs:
                return Var(e.name)
            if e.name in ps:
                return Param(e.name)
            raise ValueError(f"unexpected symbol {e.name}")
        if e.is_Add:
            return _fold(Add, [go(a) for a in e.args])
        if e.is_Mul:
            return _fold(Mul, [go(a) for a in e.args])
        if e.is_Pow:
            base, ex = e.args
            if not ex.is_Rational:
                if ex.is_Symbol or ex.free_symbols:
                    raise ValueError(f"non-constant exponent in {e}")
                raise ValueError(f"irrational exponent in {e}")
            k = Fraction(int(ex.p), int(ex.q))
            if base is sp.E:
                return Prim("exp", Const(k))
            if k == Fraction(1, 2):
                return Prim("sqrt", go(base))
            if k == Fraction(-1, 2):
                return Pow(Prim("sqrt", go(base)), Fraction(-1))
            return Pow(go(base), k)
        if isinstance(e, sp.Abs):  # |t| = sqrt(t^2), as sympy writes sqrt(u^2) for real u
            return Prim("sqrt", Pow(go(e.args[0]), Fraction(2)))
        op = PRIMITIVE_OF.get(type(e)) or PRIMITIVE_OF.get(e.func)
        if op is not None and len(e.args) == 1:
            return Prim(op, go(e.args[0]))
        raise ValueError(f"cannot express {e} in the core language")

    return go(sp.sympify(expr))


def _fold(node, parts: list[Term]) -> Term:
    out = parts[0]
    for p in parts[1:]:
        out = node(out, p)
    return out


def lambdify(t: Term, names: list[str]):
    """A numpy function of ``names`` (positional) evaluating the smooth term ``t`` (tests, checks)."""
    return sp.lambdify([symbol(n) for n in names], to_sympy(t), modules="numpy")
