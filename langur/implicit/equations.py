"""What is known of an implicit root's equation beside its sympy term (paper §7.2: the equation
``f(x) = target`` whose root is a point of an inverse branch Ψ̂⁻¹; issue 18): the condition's place
in the source and whether it is certified leniently, both by the equation's bound variable; its
form up to that variable's identity (:func:`form`: the same compiled function and certified
brackets for every build of ⟦p⟧ or ⦇p⦈ that writes the same equation again, issue 15); its
coefficients as a polynomial in that variable, exact (:func:`polynomial_coefficients`, for
:func:`langur.sturm.sturm_brackets`); and the refusal when its sign changes outnumber those the
condition was split for (:func:`too_many_roots`, X316).
"""

from __future__ import annotations

from fractions import Fraction
from functools import lru_cache

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from ..codes import turning_points_beyond_split
from ..core import TooManyRoots

#: The core :class:`~langur.core.ImplicitRoot` a root was made of, by its bound variable (a Dummy of
#: its own, kept when parameter values are put in the equation): sympy terms carry no source place,
#: the node does (its ``span``, named when evaluating it is refused).
NODES: dict = {}
#: The bound variables of indexed roots whose equation mentions other integration variables (a
#: condition split along a variable at turning points that move with the others): certified
#: leniently on the null set where two of them merge (:func:`langur.enclosures.certified_brackets`).
LENIENT: set = set()

#: The bound variable of :func:`form`'s equations.
_CANONICAL = sp.Dummy("langur_bound", real=True)


def form(lam, free: tuple):
    """``lam``'s equation up to the identity of its bound variable, with everything else that
    decides what its compiled code computes and says: its other symbols, the bound variable's name and
    assumptions (they order the printed terms: the compiled code), its source place (named when
    refused) and whether it is certified leniently; None when the equation holds another Dummy
    (its order against the bound variable could depend on their creation).  Two equations of the
    same form print the same code but for the bound variable's name: the same function."""
    (x,), f = lam.variables, lam.expr
    if f.atoms(sp.Dummy) != {x}:
        return None
    root = NODES.get(x)
    span = None if root is None else root.span
    try:
        hash(span)
    except TypeError:
        span = ("unhashable", id(span))
    return (f.xreplace({x: _CANONICAL}), free, x.name, tuple(sorted(x.assumptions0.items())), span,
            x in LENIENT)


class _FractionPrinter(PythonCodePrinter):
    """lambdify's text for exact rational arithmetic: every constant a ``Fraction`` (a float
    constant its exact binary value), so a polynomial's coefficients at rational values of its
    other symbols are computed without rounding."""

    def _print_Rational(self, e):
        return f"Fraction({e.p}, {e.q})"

    def _print_Half(self, e):
        return self._print_Rational(e)

    def _print_Integer(self, e):
        return f"Fraction({e.p})"

    def _print_Float(self, e):
        return self._print_Rational(sp.Rational(e))


#: The degree up to which a root's polynomial equation is isolated exactly.
EXACT_DEGREE = 12


@lru_cache(maxsize=1024)
def polynomial_coefficients(x, f, free: tuple):
    """``f`` as a polynomial in ``x`` whose coefficients are polynomials with rational (or float)
    constants in the other symbols ``free``: a function of those symbols' values (Fractions)
    returning the coefficients exactly, highest first; None otherwise (or beyond
    :data:`EXACT_DEGREE`)."""
    try:
        poly = sp.Poly(f, x)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    coeffs = poly.all_coeffs()
    if poly.degree() < 1 or poly.degree() > EXACT_DEGREE:
        return None
    for c in coeffs:
        if not c.is_polynomial(*free) or any(not isinstance(n, (sp.Rational, sp.Float)) for n in c.atoms(sp.Number)) \
                or c.atoms(sp.Function) or (c.free_symbols - set(free)):
            return None
    return sp.lambdify(list(free), coeffs, modules=[{"Fraction": Fraction}], printer=_FractionPrinter(
        {"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True}))


#: Sign changes counted before a condition with more than it was split for is refused (X316 says
#: "at least N" past this many): counting all 31,831 of ``sin(100000·x) − a`` on [0, 1] took 26 CPU s
#: (bench/history/2026-11-29.md#hostile32.
COUNTED = 100


def too_many_roots(count: int, a: float, b: float, of, x, at_least: bool = False) -> TooManyRoots:
    """X316: ``count`` sign changes (``at_least``: at least that many) on ``[a, b]`` at these
    parameter values, more than the ``of`` the condition was split for; located at the condition
    of the equation bound by ``x``."""
    return TooManyRoots(turning_points_beyond_split(count, int(of), f"on [{a:g}, {b:g}]", at_least), NODES.get(x))
