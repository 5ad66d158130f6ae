"""Where a condition is continuous in one variable: sympy's ``continuous_domain``, completed by the
primitive registry (issue 18's completion by implicit roots, :mod:`langur.syntax.turning`).

sympy's ``continuous_domain`` knows a fixed list of functions and refuses any other
(``NotImplementedError``), ``erf`` among them, although every primitive of LANGUAGE.md §1 is smooth
where it is defined and :mod:`langur.primitives` declares where that is.  So where sympy refuses,
each application ``F(g)`` of a registry primitive defined on all of ℝ (``Domain.everywhere``: then
continuous on ℝ) is a fresh symbol ``u``; when the condition is a polynomial in those symbols,
``Σ c_k(x)·u^k``, it is continuous wherever every coefficient ``c_k`` and every argument ``g`` are
(each found the same way: ``erf(erf(x))``).  Any other shape (``1/erf(x)``: a pole where ``erf``
vanishes) is refused as sympy refused it.
"""

from __future__ import annotations

import sympy as sp
from sympy.calculus.util import continuous_domain as _sympy_continuous_domain

from ..primitives import REGISTRY

#: sympy's function of each registry primitive continuous on all of ℝ.
EVERYWHERE: frozenset = frozenset(f for f in (getattr(sp, p.sympy) for p in REGISTRY.values() if p.domain.everywhere)
                                  if isinstance(f, type))


def continuous_domain(e: sp.Expr, v: sp.Symbol, domain: sp.Set) -> sp.Set:
    """The subset of ``domain`` where ``e`` is continuous in ``v`` (sympy's, else by the registry as
    above); raises ``NotImplementedError`` where neither can tell."""
    try:
        return _sympy_continuous_domain(e, v, domain)
    except NotImplementedError:
        apps = {f for f in e.atoms(sp.Function) if f.func in EVERYWHERE and f.has(v)}
        if not apps:
            raise
    stand_in = {f: sp.Dummy(real=True) for f in apps}
    outer = e.xreplace(stand_in)  # top-down: an application inside another is replaced with it
    used = [f for f, u in stand_in.items() if outer.has(u)]
    try:
        poly = sp.Poly(outer, *(stand_in[f] for f in used))
    except sp.PolynomialError as err:
        raise NotImplementedError(f"{e} is not a polynomial in its applications of {', '.join(sorted({f.func.__name__ for f in used}))}") from err
    dom = domain
    for part in (*poly.coeffs(), *(arg for f in used for arg in f.args)):
        if part.has(v):
            dom = sp.Intersection(dom, continuous_domain(part, v, domain))
    return dom
