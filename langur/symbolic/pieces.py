"""The simply decomposable normal form (paper Def. 6.2, Theorem 7.1) as sympy data.

The semantic functions (``langur.denote``, ``langur.ddenote``) produce these; the integrator
(``langur.symbolic.integrate``) consumes them.  Nothing here calls sympy's ``integrate``.

* A :class:`Condition` is ``[expr ≥ 0]`` for a sympy expression in variable and parameter symbols,
  with the inverse branches of its diffeomorphism when known (``Psi``), so regions can be computed
  from the roots instead of by solving.
* A :class:`Piece` is ``Π conditions · weight`` with a smooth ``weight`` (Def. 6.2's summand).
* A :class:`DeltaPiece` is ``δ(π₀Ψ̂) · Π conditions · weight`` (Theorem 7.1's ``h_ik · δ(Φ_ik)``):
  it is integrated through the change of variables ``u = Ψ̂(x)`` over every inverse branch.
* An :class:`Integral` is a result: an exact expression in the parameters when one was found,
  its value at the evaluation point, how it was obtained, and an error bound.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

import sympy as sp

from .readable import readable


@dataclass(frozen=True)
class Branch:
    """One inverse branch of Ψ̂: ``{variable symbol: expression in the input symbols and params}``,
    valid where every guard is ``≥ 0``."""

    inverse: tuple[tuple[sp.Symbol, sp.Expr], ...]
    guards: tuple[sp.Expr, ...] = ()


#: The classes of sympy's ``zoo`` and ``nan``: a :class:`Psi`'s inverse branch evaluated at
#: u₀ = 0 that holds one is infinite there (``(x − a)/(y + 1/2)`` solved for ``y``: its zero set
#: ``x = a`` is no graph over ``x``) and gives no root.
NOT_FINITE = (type(sp.zoo), type(sp.nan))


@dataclass(frozen=True)
class Psi:
    """A (piecewise) diffeomorphism in sympy form: forward components over the variables and the
    inverse branches over ``inputs`` (``inputs[0]`` is the coordinate of the condition π₀Ψ̂)."""

    variables: tuple[sp.Symbol, ...]
    forward: tuple[sp.Expr, ...]
    inputs: tuple[sp.Symbol, ...]
    branches: tuple[Branch, ...]
    solved_for: sp.Symbol | None = None


@dataclass(frozen=True)
class Condition:
    """``[expr ≥ 0]``, or ``[expr > 0]`` when ``strict``.  ``psi`` (optional) has
    ``psi.forward[0] == expr``; ``origin`` is an opaque tag for diagnostics (e.g. the core IfDiffeo
    node's span).

    Strictness is invisible to integrals over ℝⁿ (the zero set is null) but not to a delta
    restricted to that zero set: ``ifge0 Φ then s else r`` is ``[Φ ≥ 0]·s + [−Φ > 0]·r`` (Fig. 7
    takes the then-branch at Φ = 0), so on Φ = 0 exactly one branch counts."""

    expr: sp.Expr
    psi: Psi | None = None
    origin: object = field(default=None, compare=False)
    strict: bool = False


@dataclass(frozen=True)
class Piece:
    """``Π [c.expr ≥ 0] · weight`` with a smooth weight."""

    conditions: tuple[Condition, ...]
    weight: sp.Expr


@dataclass(frozen=True)
class DeltaPiece:
    """``δ(π₀Ψ̂) · Π [c.expr ≥ 0] · weight``.  ``weight`` already contains ``D_γ π₀Ψ̂ · γ'`` and the jump
    factor ``⟦s⟧ − ⟦r⟧`` when it is smooth; a non-smooth jump is expanded into several DeltaPieces with
    the same ``psi``."""

    psi: Psi
    conditions: tuple[Condition, ...]
    weight: sp.Expr


class Method(StrEnum):
    """How an :class:`Integral`'s value was obtained (written as its value in JSON output)."""

    CLOSED_FORM = "closed_form"  # an exact expression, cross-checked by quadrature
    QUADRATURE = "quadrature"  # numeric, with an error estimate (a bound where ``Integral.proved`` says so)


def accuracy(error: float | None, proved: float | None) -> str:
    """How accurate a quadrature's value is, for the text output (``eval``, ``deriv``, ``show``):
    ``error`` quadrature's estimate, ``proved`` a bound the interval enclosures prove (None: none);
    "error ≤" only for what is proved."""
    if error is None:
        return "quadrature"
    if proved is None:  # sampling alone: nothing excludes a peak between the samples
        return f"quadrature, error estimate {error:.3g}"
    if proved <= error:
        return f"quadrature, error ≤ {error:.3g}"
    return f"quadrature, error estimate {error:.3g}, proved ≤ {proved:.3g}"


def accuracy_of(r) -> str:
    """:func:`accuracy` of a result (an :class:`Integral`, a derivative's result), after its value:
    ``" (quadrature, error estimate …)"``, or "" for a closed form."""
    return "" if r.method == Method.CLOSED_FORM else f" ({accuracy(r.error, r.proved)})"


@dataclass
class Integral:
    """The result of integrating pieces over the box.

    ``expr``: exact sympy expression in the parameters (None when no closed form was found);
    ``value``: float at the evaluation point; ``method``: a :class:`Method`;
    ``error``: quadrature's estimate of |value − true value| (0.0 for a closed form that passed the
    cross-check; ``proved`` says what is proved); ``check``: the independent quadrature value used to cross-check a closed form
    (None if it could not be computed); ``notes``: human-readable remarks (e.g. "closed form valid
    for parameters near the evaluation point: theta in (0, 1)"); ``everywhere``: the closed form
    holds for every parameter value, not only in the evaluation point's cell; ``inconsistent``:
    closed forms found and discarded because their quadrature cross-check failed.
    """

    expr: sp.Expr | None
    value: float
    method: Method
    error: float = 0.0
    check: float | None = None
    notes: list[str] = field(default_factory=list)
    everywhere: bool = False
    #: closed forms that disagreed with the quadrature cross-check (an engine bug; the quadrature
    #: was reported instead)
    inconsistent: tuple[str, ...] = ()
    #: for a closed form: the relations on the parameters that define the cell where it holds
    #: (empty with ``everywhere``); ``generic``: it also needs the same set of real roots as at
    #: the evaluation point, which ``cell`` does not say
    cell: tuple = ()
    generic: bool = False
    #: for a quadrature: a proved bound on |value − true value| (interval enclosures,
    #: :mod:`langur.symbolic.quadrature.enclosed`), or None where nothing proves one (``error``
    #: is then quadrature's estimate)
    proved: float | None = None

    def _repr_latex_(self) -> str:
        """In a notebook: the closed form in readable cases when it has them (else the engine's
        form) and the value, or the value with its error bound."""
        if self.expr is not None and self.method == Method.CLOSED_FORM:
            try:
                rd = readable(self.expr, None, cell=self.cell, everywhere=self.everywhere, generic=self.generic)
            except Exception:  # noqa: BLE001 - presentation only: fall back to the engine's form
                rd = None
            shown = rd.text(latex=True) if rd is not None else sp.latex(self.expr)
            return f"$\\displaystyle {shown} \\quad (= {self.value:.12g} \\text{{ here}})$"
        return f"$\\displaystyle {self.value:.12g} \\pm {self.error:.2g} \\text{{ (quadrature)}}$"
