"""The denotational semantics ⟦t⟧ and ⟦p⟧ (paper §6 Fig. 7, §8 Fig. 12) with sympy.

``denote(t)`` is ⟦t⟧(ρ, γ) as a sympy expression over real symbols for the variables and
parameters (``langur.symbolic.decompose.symbol``: same name, same symbol).  Conditionals become
``Piecewise`` (never ``Heaviside``), primitives sympy functions, ``pi`` is ``sp.pi``, and ``let``
substitutes ⟦bound⟧ for its parameter.

``denote_program(p, at)`` is ⟦int t d(x⃗)⟧(γ) = ∫ ⟦t⟧(ρ, γ) dρ (Fig. 12) at the parameters ``at``:
⟦t⟧ is decomposed into simply decomposable pieces (Def. 6.2, ``langur.symbolic.decompose``) and
integrated piece by piece by ``langur.symbolic.integrate`` (never sympy's integrate of a
Piecewise), which returns the closed form in the parameters when it finds one, else quadrature.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType

import sympy as sp

from .core import (
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
    check_values,
    shared,
)
from .symbolic.decompose import (
    PRIMITIVES,
    Ctx,
    at_symbols,
    const_expr,
    decompose,
    smooth_value,
    symbol,
    symbols,
)
from .symbolic.pieces import Integral, Method

__all__ = ["denote", "denote_program", "program_box", "symbol"]


_NO_ENV: Mapping[str, sp.Expr] = MappingProxyType({})


@shared
def denote(t: Term, env: Mapping[str, sp.Expr] | None = None) -> sp.Expr:
    """⟦t⟧ (Fig. 7) as a sympy expression; ``env`` maps let-bound parameters to their values."""
    env = _NO_ENV if env is None else env  # the same object down the term: memoized per node
    match t:
        case Const(value):  # Fig. 7, constant: ⟦c⟧ = c
            return const_expr(value)
        case Var(name):  # Fig. 7, variable: ⟦x⟧(ρ, γ) = ρ(x)
            return symbol(name)
        case Param(name):  # Fig. 7, parameter: ⟦z⟧(ρ, γ) = γ(z)
            return env.get(name, symbol(name))
        case Add(a, b):  # Fig. 7, sum
            return denote(a, env) + denote(b, env)
        case Mul(a, b):  # Fig. 7, product
            return denote(a, env) * denote(b, env)
        case Prim(op, a):  # LANGUAGE.md §1, smooth primitive f(t)
            return PRIMITIVES[op](denote(a, env))
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
    raise TypeError(f"not a core term: {t!r}")


def program_box(program: Program, ctx: Ctx) -> tuple[tuple[sp.Expr, sp.Expr], ...]:
    """The program's bounding box as sympy (lo, hi) pairs in the parameters."""
    return tuple((smooth_value(lo, ctx), smooth_value(hi, ctx)) for lo, hi in program.box)


def zero_integral() -> Integral:
    return Integral(sp.Integer(0), 0.0, Method.CLOSED_FORM, 0.0, 0.0)


def denote_program(program: Program, at: Mapping[str, object] | None = None, *,
                   timeout: float = 20.0) -> Integral:
    """⟦int t d(x⃗)⟧(γ) (Fig. 12) at the parameter values ``at`` (name → number; exact decimals
    are read as rationals).  The result's ``expr`` is the closed form in the parameters, valid
    near ``at``, when one was found.  Raises :class:`~langur.core.ParameterError` when ``at`` does
    not give every parameter of the program a finite value."""
    from .symbolic.integrate import integrate_pieces  # scipy: 0.3 s, only when integrating

    check_values(program, at)
    point = at_symbols(at)
    ctx = Ctx(at=point, variables=tuple(program.variables))
    pieces = decompose(program.body, ctx)
    if not pieces:
        return zero_integral()
    return integrate_pieces(pieces, symbols(program.variables), program_box(program, ctx), point,
                            timeout=timeout)
