"""Completing a condition over variables to a diffeomorphism: the front end's one entry (§4, §5.2).

``complete(cond, variables, box)`` is :func:`langur.syntax.diffeo.complete`: the direct path of
:mod:`langur.syntax.affine` when ``cond`` is affine with rational coefficients (the same Diffeo,
exact rational arithmetic), else sympy's solver.  ``diffeo`` (the sympy module, which also checks
and instantiates declared diffeos) is imported only when a condition or a declaration needs it
(:mod:`langur.lazy`), so that a program whose conditions are affine loads without sympy.

``complete_or_split(cond, variables, box)`` is the desugarer's: the same completion, or, for a
condition whose sign changes where that completion does not look (a moving pole, a product solved
for one factor), its factors to split on (:mod:`langur.syntax.poles`, imported likewise).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from .. import lazy
from ..core import Diffeo, IfGe0, Mul, Pow, Term, free_params, free_vars, subterms
from . import affine
from .folding import defined_everywhere

#: ``langur.syntax.diffeo``, imported when first needed.
diffeo = lazy.module("langur.syntax.diffeo")
#: ``langur.syntax.poles``, imported when first needed.
poles = lazy.module("langur.syntax.poles")

#: The sign of a condition as the sign of its factors: ``[c ≥ 0] ⊕ [f₁ ≥ 0] ⊕ …`` (``c`` None:
#: a positive constant), :func:`langur.syntax.poles.sign_factors`.
Split = tuple[Term | None, tuple[Term, ...]]


def complete(cond: Term, variables: tuple[str, ...], box=(), avoid: frozenset[str] = frozenset()) -> Diffeo:
    """``cond`` completed over ``variables``, isolating none of the variables in ``avoid`` (a
    completion that degenerates at some parameter values is replaced there by one solved for another
    variable: :mod:`langur.lint.recomplete`); raises ``diffeo.CompletionError``."""
    direct = affine.complete(cond, tuple(variables), avoid)
    return direct if direct is not None else diffeo.complete(cond, variables, box, avoid)


def complete_or_split(cond: Term, variables: tuple[str, ...], box=()) -> Diffeo | Split:
    """:func:`complete`, or the factors of ``cond`` whose signs are its sign a.e. when ``cond``
    changes sign on a moving set its completion does not reach (Fig. 8's delta would miss that
    jump; :mod:`langur.syntax.poles`).  An affine condition is one factor with no pole: completed
    at once.  Raises ``diffeo.CompletionError`` (also for ``poles.TooManyFactors`` and a pole that
    moves inside a factor no split reaches, ``poles.MovingPole``: refused before any number)."""
    direct = affine.complete(cond, tuple(variables))
    if direct is not None:
        return direct
    if not _may_split(cond):
        return diffeo.complete(cond, variables, box)
    try:
        psi, failed = diffeo.complete(cond, variables, box), None
    except diffeo.CompletionError as e:
        psi, failed = None, e
    try:
        split = poles.sign_factors(cond, psi)
    except poles.TooManyFactors as e:
        raise diffeo.CompletionError(f"{e}: its sign changes where its completion does not reach (a pole or "
                                     "a factor that moves with the parameters); write it as a product of "
                                     "fewer conditions") from None
    except poles.MovingPole as e:
        raise diffeo.CompletionError(str(e)) from None
    if split is not None and (failed is None or _each_completes(split[1], variables, box)):
        return split
    if failed is not None:
        raise failed  # (no completion, and a factor with none of its own: the condition's reason, once)
    if not defined_everywhere(cond) and (extension := poles.removable(cond)) is not None:
        psi = replace(psi, forward=(extension, *psi.forward[1:]))  # undefined at a pole only: D5, pole32
    return psi


def sign_chain(split: Split, then: Term, orelse: Term, conditional: Callable[[Term, Term, Term], Term],
               span=None) -> Term:
    """``ifge0 c·Π fᵢ^kᵢ then s else r`` as the parity of its factors' signs (a.e.;
    :mod:`langur.syntax.poles`): ``ifge0 f₁ then (… then s else r) else (… then r else s)``, each
    factor made a conditional by ``conditional(f, then, orelse)`` (completed on its own, so that each
    moving sign change — a pole's too — gets its delta, Fig. 8); the coefficient ``c`` (None:
    positive) a plain ifge0 outside.  The branches are shared: 2k − 1 conditionals for k factors."""
    coefficient, factors = split
    memo: dict[tuple[int, bool], Term] = {}

    def chain(i: int, flipped: bool) -> Term:  # the factors from i on, the sign so far flipped or not
        if i == len(factors):
            return orelse if flipped else then
        if (i, flipped) not in memo:
            memo[i, flipped] = conditional(factors[i], chain(i + 1, flipped), chain(i + 1, not flipped))
        return memo[i, flipped]

    out = chain(0, False)
    return out if coefficient is None else IfGe0(coefficient, out, chain(0, True), span)


def _each_completes(factors: tuple[Term, ...], variables: tuple[str, ...], box) -> bool:
    """Whether every factor completes on its own: a condition with no completion of its own is split
    only then (else each failing factor would be refused once per conditional of the chain, for a
    reason the condition as written does not show)."""
    try:
        for f in factors:
            complete(f, variables, box)
    except diffeo.CompletionError:
        return False
    return True


def _may_split(cond: Term) -> bool:
    """Whether ``cond`` can have a moving sign change away from one zero set: it mentions a
    parameter, and divides by a term over variables, multiplies two such terms, or raises a term
    over variables and parameters to a power other than 1 (a repeated moving factor)."""
    if not free_params(cond):
        return False
    for u in subterms(cond):
        if type(u) is Pow and free_vars(u.base) and (u.exponent < 0 or u.exponent > 1 and free_params(u.base)):
            return True
        if type(u) is Mul and free_vars(u.left) and free_vars(u.right):
            return True
    return False
