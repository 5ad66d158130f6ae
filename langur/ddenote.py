"""The derivative denotation ⦇t⦈ and ⦇p⦈ (paper §7 Fig. 8, §8 Fig. 12) in the normal form of
Theorem 7.1, with sympy.

``ddenote(t, direction)`` builds ⦇t⦈(ρ, γ, γ') rule by rule from Fig. 8 directly in the normal form

    ⦇t⦈ = f · T₁ + Σ_ik h_ik · δ(Φ_ik)                                   (Theorem 7.1, Eq. 9)

as a :class:`NormalForm`: ``regular`` is f as simply decomposable pieces, ``deltas`` the terms
h_ik·δ(Φ_ik) as :class:`~langur.symbolic.pieces.DeltaPiece`s, each keeping its Ψ̂ with every
inverse branch (the change of variables that integrates it).  ``direction`` is γ' (parameter name
→ number); ``--wrt a`` is ``{"a": 1}``.

``ddenote_program(p, at, direction)`` is ⦇int t d(x⃗)⦈ = ∫ ⦇t⦈ dρ (Fig. 12): the regular part and the
delta terms are integrated separately by ``langur.symbolic.integrate`` (never sympy's integrate of
a DiracDelta); the regular part alone is standard AD (the paper's Dˢ).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import sympy as sp

from . import observe
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
    refusals_located,
    shared,
)
from .denote import point_free, program_box, require_defined, zero_integral
from .memo import remember
from .symbolic.decompose import (
    Ctx,
    apply_smooth,
    collapse,
    complement,
    condition_of,
    decided_cell,
    decompose,
    dedupe,
    gate,
    leaf,
    multiply,
    normalize,
    select,
    smooth_value,
    with_conditions,
)
from .symbolic.pieces import Condition, DeltaPiece, Integral, Method, Piece
from .symbolic.readable import readable
from .symbolic.text import derivative_result_text, normal_form_text
from .sympy_bridge import at_symbols, const_expr, derivative_function, exact_number, may_vanish, symbols
from .values import check_values

__all__ = ["DerivativeResult", "NormalForm", "ddenote", "ddenote_program", "tangent"]


@dataclass
class NormalForm:
    """⦇t⦈ = Σ regular + Σ deltas (Theorem 7.1)."""

    regular: list[Piece] = field(default_factory=list)
    deltas: list[DeltaPiece] = field(default_factory=list)

    def __add__(self, other: NormalForm) -> NormalForm:
        return NormalForm(normalize(self.regular + other.regular), merge_deltas(self.deltas + other.deltas))

    def times(self, ps: list[Piece]) -> NormalForm:
        """⦇t⦈ · T⟦s⟧ with ⟦s⟧ given by its decomposition: distribute over both parts."""
        return NormalForm(multiply(self.regular, ps),
                          merge_deltas(DeltaPiece(d.psi, d.conditions + p.conditions, d.weight * p.weight)
                                       for d in self.deltas for p in ps))

    def under(self, c: Condition) -> NormalForm:
        """[c ≥ 0] · ⦇t⦈."""
        return NormalForm(with_conditions(self.regular, (c,)),
                          merge_deltas(DeltaPiece(d.psi, (c,) + d.conditions, d.weight) for d in self.deltas))

    def _repr_latex_(self) -> str:
        return "$\\displaystyle " + normal_form_text(self, latex=True) + "$"

    def __str__(self) -> str:
        return normal_form_text(self)


def merge_deltas(deltas) -> list[DeltaPiece]:
    """Merge delta terms with the same Ψ̂ and conditions; drop zero weights.  Unlike regular pieces,
    a condition and its complement are kept together: on the delta's surface they need not
    cancel (that is the coincident, non-transverse case, whose result then shows the defect)."""
    merged: dict[tuple, DeltaPiece] = {}
    for d in deltas:
        conds = dedupe(d.conditions)
        key = (d.psi, frozenset(c.expr for c in conds))
        if key in merged:
            m = merged[key]
            merged[key] = DeltaPiece(m.psi, m.conditions, m.weight + d.weight)
        else:
            merged[key] = DeltaPiece(d.psi, conds, d.weight)
    return [d for d in merged.values() if d.weight != 0]


@dataclass(frozen=True)
class DCtx:
    """γ' for the declared parameters (``direction``) and for let-bound ones (``tangents``)."""

    direction: Mapping[str, sp.Expr]
    tangents: Mapping[str, sp.Expr] = field(default_factory=dict)


def _gate_nf(nf: NormalForm, cond: sp.Expr, branch: bool) -> NormalForm:
    return NormalForm([Piece(p.conditions, gate(p.weight, cond, branch)) for p in nf.regular],
                      [DeltaPiece(d.psi, d.conditions, gate(d.weight, cond, branch)) for d in nf.deltas])


@shared
@observe.nested
def ddenote_subterm(t: Term, ctx: Ctx, dctx: DCtx) -> NormalForm:
    """⦇t⦈ of one subterm under ``ctx`` (ρ's symbols, γ) and ``dctx`` (γ'): Fig. 8, one ``match``
    case per rule, recursing through this module's global of this name — the public hook a
    campaign's rule coverage wraps (:mod:`langur.fuzz.coverage`); :func:`ddenote` is the entry."""
    match t:
        case Const():  # Fig. 8, constant: ⦇c⦈ = 0
            observe.rule("Fig. 8, constant: ⦇c⦈ = 0", t)
            return NormalForm()
        case Var():  # Fig. 8, variable: ⦇x⦈ = 0
            observe.rule("Fig. 8, variable: ⦇x⦈ = 0", t)
            return NormalForm()
        case Param(name):  # Fig. 8, parameter: ⦇z⦈ = γ'(z)
            observe.rule("Fig. 8, parameter: ⦇z⦈ = γ'(z)", t)
            g = dctx.tangents[name] if name in dctx.tangents else dctx.direction.get(name, sp.Integer(0))
            return NormalForm(leaf(g))
        case Add(a, b):  # Fig. 8, sum: ⦇t⦈ + ⦇s⦈
            observe.rule("Fig. 8, sum: ⦇t + s⦈ = ⦇t⦈ + ⦇s⦈", t)
            return ddenote_subterm(a, ctx, dctx) + ddenote_subterm(b, ctx, dctx)
        case Mul(a, b):  # Fig. 8, product: ⦇t⦈·T⟦s⟧ + ⦇s⦈·T⟦t⟧
            observe.rule("Fig. 8, product: ⦇t·s⦈ = ⦇t⦈·T⟦s⟧ + ⦇s⦈·T⟦t⟧", t)
            return (ddenote_subterm(a, ctx, dctx).times(decompose(b, ctx))
                    + ddenote_subterm(b, ctx, dctx).times(decompose(a, ctx)))
        case Prim(op, a):  # LANGUAGE.md §1, primitive: chain rule f'(⟦t⟧)·⦇t⦈
            observe.rule("LANGUAGE.md §1, primitive: ⦇f(t)⦈ = f'(⟦t⟧)·⦇t⦈", t)
            return ddenote_subterm(a, ctx, dctx).times(apply_smooth(derivative_function(op), decompose(a, ctx)))
        case Pow(a, k):  # LANGUAGE.md §1, constant power: k·⟦t⟧^(k−1)·⦇t⦈
            observe.rule("LANGUAGE.md §1, constant power: ⦇t^k⦈ = k·⟦t⟧^(k−1)·⦇t⦈", t)
            k = const_expr(k)
            return ddenote_subterm(a, ctx, dctx).times(apply_smooth(lambda w: k * w ** (k - 1), decompose(a, ctx)))
        case IfGe0(c, a, b):  # Fig. 8, conditional: ⦇s⦈ if ⟦t⟧(·, γ) ≥ 0 else ⦇r⦈
            observe.rule("Fig. 8, conditional: ⦇s⦈ if ⟦t⟧(·, γ) ≥ 0 else ⦇r⦈", t)
            return select(smooth_value(c, ctx), ddenote_subterm(a, ctx, dctx), ddenote_subterm(b, ctx, dctx),
                          ctx.at, _gate_nf)
        case IfDiffeo(psi, a, b):  # Fig. 8, diffeomorphic conditional:
            # (⦇s⦈ if π₀Ψ̂ ≥ 0 else ⦇r⦈) + δ(π₀Ψ̂)·(D_γ π₀Ψ̂ · γ')·T⟦s⟧−⟦r⟧
            observe.rule("Fig. 8, diffeomorphic conditional: (⦇s⦈ if π₀Ψ̂ ≥ 0 else ⦇r⦈) + δ(π₀Ψ̂)·⦇π₀Ψ̂⦈·(⟦s⟧ − ⟦r⟧)", t)
            c = condition_of(psi, ctx, t.span)
            f = ddenote_subterm(a, ctx, dctx).under(c) + ddenote_subterm(b, ctx, dctx).under(complement(c))
            speed = tangent(psi.forward[0], ctx, dctx)  # D_γ π₀Ψ̂ · γ' = ⦇π₀Ψ̂⦈
            if speed == 0 or not may_vanish(c.expr, c.psi.variables):  # δ(π₀Ψ̂) = 0 off π₀Ψ̂'s zero set:
                return f  # an empty one (exp(x − a) > 0) carries no delta, Ψ̂⁻¹(0, u') is never used
            jump = normalize(decompose(a, ctx) + [Piece(p.conditions, -p.weight) for p in decompose(b, ctx)])
            return f + NormalForm([], [DeltaPiece(c.psi, p.conditions, speed * p.weight) for p in jump])
        case Let(name, bound, body):  # Fig. 8, let: ⦇s⦈(ρ, γ[z ↦ ⟦t⟧], γ'[z ↦ ⦇t⦈])
            observe.rule("Fig. 8, let: ⦇s⦈(ρ, γ[z ↦ ⟦t⟧], γ'[z ↦ ⦇t⦈])", t)
            return ddenote_subterm(body, ctx.bind(name, smooth_value(bound, ctx)),
                       DCtx(dctx.direction, {**dctx.tangents, name: tangent(bound, ctx, dctx)}))
        case Call(module, name, _):
            raise TypeError(f"call of {module}.{name} left in a core term: inline it first")
    raise TypeError(f"not a core term: {t!r}")


def tangent(t: Term, ctx: Ctx, dctx: DCtx) -> sp.Expr:
    """⦇t⦈ of a term without diffeomorphic conditionals: its ordinary derivative D_γ⟦t⟧·γ'."""
    nf = ddenote_subterm(t, ctx, dctx)
    if nf.deltas:
        raise TypeError("a variable-free term has no delta terms")
    return collapse(nf.regular, "term")


def _direction(direction: Mapping[str, object]) -> dict[str, sp.Expr]:
    return {k: exact_number(v) for k, v in direction.items()}


def ddenote(t: Term, direction: Mapping[str, object], *, env: Mapping[str, sp.Expr] | None = None,
            at: Mapping[str, object] | None = None, variables: tuple[str, ...] | None = None) -> NormalForm:
    """⦇t⦈ in the normal form of Theorem 7.1 (Fig. 8).

    ``direction``: γ', parameter name → number.  ``at`` (name → number), when given, decides the
    variable-free conditionals there (else they stay Piecewise in the parameters); ``variables``
    (the program's) extends every Ψ̂ to all of them.
    """
    ctx = Ctx(env=dict(env or {}), at=at_symbols(at) if at is not None else None,
              variables=tuple(variables) if variables is not None else None)
    return ddenote_subterm(t, ctx, DCtx(_direction(direction)))


@dataclass
class DerivativeResult:
    """⦇p⦈(γ, γ') = regular + boundary (Fig. 12 with Theorem 7.1's split).

    ``regular``: ∫ f (the delta-free part; also the paper's standard AD Dˢ); ``boundary``: the
    integrals of the delta terms; ``expr``: the closed form of the sum when both are exact.
    """

    value: float
    regular: Integral
    boundary: Integral
    expr: sp.Expr | None
    method: str
    error: float
    normal_form: NormalForm
    notes: list[str] = field(default_factory=list)
    inconsistent: tuple[str, ...] = ()
    #: the evaluation point (parameter symbols → exact values), for presenting ``expr``
    at: dict = field(default_factory=dict)
    #: a proved bound on |value − ⦇p⦈| (the parts' :attr:`Integral.proved`, a closed form's 0), or None
    proved: float | None = None

    @property
    def standard_ad(self) -> float:
        return self.regular.value

    def _repr_latex_(self) -> str:
        """In a notebook: ⦇p⦈ in readable cases when its closed form has them, and its value."""
        rd = None
        if self.expr is not None and self.method == Method.CLOSED_FORM:
            try:
                rd = readable(self.expr, self.at, cell=tuple(self.regular.cell) + tuple(self.boundary.cell),
                              everywhere=self.regular.everywhere and self.boundary.everywhere,
                              generic=self.regular.generic or self.boundary.generic)
            except Exception:  # noqa: BLE001 - presentation only: fall back to the engine's form
                rd = None
        if rd is None:
            return "$\\displaystyle (\\!|p|\\!) = " + derivative_result_text(self, latex=True) + "$"
        return (f"$\\displaystyle (\\!|p|\\!) = {rd.text(latex=True)}"
                f" \\quad (= {self.value:.12g} \\text{{ here; regular }} {self.regular.value:.12g}"
                f" \\text{{, boundary }} {self.boundary.value:.12g})$")


#: Normal forms of point-free programs (:func:`~langur.denote.point_free`) by (the program's
#: identity, γ'), with the program.
_NORMAL_FORMS: dict = {}


def normal_form(program: Program, direction: Mapping[str, object], at) -> NormalForm:
    """⦇p⦈'s normal form at ``at``; remembered by (program, γ') when the program is point-free (the
    same normal form at every point: Theorem 8.1's check computes ⦇p⦈ at nearby points), except
    while the rules are observed (:func:`langur.observe.watched`)."""
    key = None
    # (not while an observer records or counts the rules: a campaign's rule coverage wraps
    # ddenote_subterm and must see the same applications as without this memo)
    if not observe.watched() and point_free(program):
        # by the program's identity (the entry keeps it alive: its spans, which equality ignores,
        # are in the pieces) and γ' exactly
        key = (id(program), tuple(sorted((k, exact_number(v)) for k, v in direction.items())))
        hit = _NORMAL_FORMS.get(key)
        if hit is not None and hit[0] is program:
            return NormalForm(list(hit[1].regular), list(hit[1].deltas))
    nf = ddenote(program.body, direction, at=at or {}, variables=tuple(program.variables))
    if key is not None:
        remember(_NORMAL_FORMS, key, (program, NormalForm(list(nf.regular), list(nf.deltas))), 16)
    return nf


@refusals_located
def ddenote_program(program: Program, at: Mapping[str, object] | None, direction: Mapping[str, object], *,
                    timeout: float = 20.0, symbolic: bool = True) -> DerivativeResult:
    """⦇int t d(x⃗)⦈(γ, γ') = ∫ ⦇t⦈ dρ (Fig. 12) at ``at`` in the direction γ' = ``direction``
    (without ``symbolic``: the value by quadrature, as :func:`~langur.denote.denote_program`'s).

    Raises :class:`~langur.values.ParameterError` when ``at`` does not give every parameter of the
    program a finite value or ``direction`` names a parameter without one."""
    from .symbolic.integrate import (  # scipy: 0.3 s, only when integrating
        integrate_delta_pieces,
        integrate_pieces,
    )

    check_values(program, at, direction)
    nf = normal_form(program, direction, at)
    point = at_symbols(at)
    ctx = Ctx(at=point, variables=tuple(program.variables))
    variables, box = symbols(program.variables), program_box(program, ctx)
    cell = decided_cell(program.body, ctx)
    regular = (integrate_pieces(nf.regular, variables, box, point, timeout=timeout, cell=cell, symbolic=symbolic)
               if nf.regular else zero_integral())
    boundary = (integrate_delta_pieces(nf.deltas, variables, box, point, timeout=timeout, cell=cell,
                                       symbolic=symbolic)
                if nf.deltas else zero_integral())
    # ⦇p⦈ = ∫ ⦇t⦈ does not exist where ⟦p⟧ does not (T⟦t⟧ undefined), nor where its regular part is not
    # integrable, nor where a delta term's weight is not integrable on its zero set
    require_defined(program, ctx, nf.regular, nf.deltas)
    exact = regular.method == Method.CLOSED_FORM and boundary.method == Method.CLOSED_FORM
    expr = regular.expr + boundary.expr if regular.expr is not None and boundary.expr is not None else None
    return DerivativeResult(
        value=regular.value + boundary.value, regular=regular, boundary=boundary, expr=expr,
        method=Method.CLOSED_FORM if exact else Method.QUADRATURE, error=regular.error + boundary.error,
        normal_form=nf, notes=list(regular.notes) + [n for n in boundary.notes if n not in regular.notes],
        inconsistent=regular.inconsistent + boundary.inconsistent, at=dict(point),
        proved=_proved(regular, boundary))


def _proved(*parts: Integral) -> float | None:
    """The sum of the parts' proved error bounds (a closed form's is 0); None if one has none."""
    total = 0.0
    for part in parts:
        if part.method != Method.CLOSED_FORM:
            if part.proved is None:
                return None
            total += part.proved
    return total
