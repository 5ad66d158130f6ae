"""sympy's ``solve`` failing on an equation in an implicit root, known from the equation's shape
(paper §6.3, Def. 6.1–6.2: a condition solved for the integration variable; issue 15, exact14t).

Used by :mod:`langur.symbolic.solving` before it asks sympy: the same message, without sympy's
0.1–0.2 s of trying every method.
"""

from __future__ import annotations

import sympy as sp

from langur.implicit import ImplicitRootFn

#: What sympy's ``solve`` says of an equation it has no algorithm for.
NO_ALGORITHM = "No algorithms are implemented to solve equation "


def unsolvable(expr: sp.Expr, v: sp.Symbol) -> str | None:
    """sympy's message (whitespace collapsed) when ``solve(expr, v)`` is certain to raise
    ``NotImplementedError``, decided from the equation's shape without asking sympy; else None.

    The shape: ``k·x* + c`` (or ``x*``) with ``x*`` an implicit root in which ``v`` occurs, ``k`` a
    non-zero rational and ``c`` free of ``v``, everything plain (:func:`_plain`: rationals, symbols,
    +, ·, integer powers, implicit roots of plain equations; no Float, which ``solve`` rewrites,
    nothing ``solve`` rewrites before solving).  ``v`` then occurs only inside the root, which has no
    inverse and no evaluation (:meth:`ImplicitRootFn.eval`): every one of ``solve``'s methods
    (linear, polynomial in the root as generator, then inverting the generator, ``unrad``,
    ``_tsolve``) ends in its "no algorithms" error naming the equation as given.  turning2d's
    ``root(…) + 1 = 0`` cost 0.1–0.2 s to fail (issue 15, exact14t)."""
    if isinstance(expr, ImplicitRootFn):
        root, rest = expr, ()
    elif isinstance(expr, sp.Add):
        dep = [t for t in expr.args if v in t.free_symbols]
        if len(dep) != 1:
            return None
        term, rest = dep[0], [t for t in expr.args if t is not dep[0]]
        coeff, root = term.as_coeff_Mul()
        if not (isinstance(coeff, sp.Rational) and coeff != 0 and isinstance(root, ImplicitRootFn)):
            return None
    else:
        return None
    if v not in root.free_symbols or not _plain(root) or not all(_plain(t) for t in rest):
        return None
    return NO_ALGORITHM + " ".join(str(expr).split())


def _plain(e) -> bool:
    """``e`` is built of rationals, symbols, +, ·, integer powers and implicit roots of such
    equations with such targets and brackets."""
    if isinstance(e, (sp.Rational, sp.Symbol)):
        return True
    if isinstance(e, (sp.Add, sp.Mul)):
        return all(_plain(a) for a in e.args)
    if isinstance(e, sp.Pow):
        return isinstance(e.exp, sp.Integer) and _plain(e.base)
    if isinstance(e, ImplicitRootFn):
        lam, *rest = e.args
        return isinstance(lam, sp.Lambda) and _plain(lam.expr) and all(_plain(a) for a in rest)
    return False
