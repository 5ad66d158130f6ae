"""Completing a condition over variables to a diffeomorphism: the front end's one entry (§4, §5.2).

``complete(cond, variables, box)`` is :func:`langur.syntax.diffeo.complete`: the direct path of
:mod:`langur.syntax.affine` when ``cond`` is affine with rational coefficients (the same Diffeo,
exact rational arithmetic), else sympy's solver.  ``diffeo`` (the sympy module, which also checks
and instantiates declared diffeos) is imported only when a condition or a declaration needs it
(:mod:`langur.lazy`), so that a program whose conditions are affine loads without sympy.
"""

from __future__ import annotations

from .. import lazy
from ..core import Diffeo, Term
from . import affine

#: ``langur.syntax.diffeo``, imported when first needed.
diffeo = lazy.module("langur.syntax.diffeo")


def complete(cond: Term, variables: tuple[str, ...], box=(), avoid: frozenset[str] = frozenset()) -> Diffeo:
    """``cond`` completed over ``variables``, isolating none of the variables in ``avoid`` (a
    completion that degenerates at some parameter values is replaced there by one solved for another
    variable: :mod:`langur.lint.recomplete`); raises ``diffeo.CompletionError``."""
    direct = affine.complete(cond, tuple(variables), avoid)
    return direct if direct is not None else diffeo.complete(cond, variables, box, avoid)
