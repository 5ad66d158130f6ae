"""Where a condition is continuous in one variable: sympy's ``continuous_domain``, completed by the
primitive registry (issue 18's completion by implicit roots, :mod:`langur.syntax.turning`).

sympy's ``continuous_domain`` knows a fixed list of functions and refuses any other
(``NotImplementedError``), ``erf`` among them, although every primitive of LANGUAGE.md §1 is smooth
where it is defined and :mod:`langur.primitives` declares where that is.  So where sympy refuses:

* each application ``F(g)`` of a registry primitive defined on all of ℝ (``Domain.everywhere``: then
  continuous on ℝ) is a fresh symbol ``u``; when the condition is a polynomial in those symbols,
  ``Σ c_k(x)·u^k``, it is continuous wherever every coefficient ``c_k`` and every argument ``g`` are
  (each found the same way: ``erf(erf(x))``);
* any other shape (``1/(erf(x) + 2)``, ``sqrt(erf(x) + 2)``) is continuous on the whole domain when
  that is *proved*: every operation that is not continuous on all of ℝ — a power whose exponent is not
  a natural number, a primitive not defined on all of ℝ (``log``, ``tan``, ``asin``, …) — has a finite
  interval enclosure on every cell of the domain (mpmath's interval arithmetic, rounded outward:
  :mod:`langur.enclosures`), so its argument stays where it is continuous (an enclosure of ``1/z``
  is finite only if ``z``'s excludes 0, one of ``sqrt(z)`` exists only if ``z``'s is ≥ 0, of
  ``log(z)`` only if ``z``'s is > 0).  Not proved (``1/erf(x)``: a pole where ``erf`` vanishes;
  an operation whose argument mentions a parameter, whose range the front end does not know) is
  refused as sympy refused it.
"""

from __future__ import annotations

import mpmath
import sympy as sp
from sympy.calculus.util import continuous_domain as _sympy_continuous_domain

from ..enclosures import interval_function
from ..primitives import REGISTRY

#: sympy's function of each registry primitive continuous on all of ℝ.
EVERYWHERE: frozenset = frozenset(f for f in (getattr(sp, p.sympy) for p in REGISTRY.values() if p.domain.everywhere)
                                  if isinstance(f, type))
#: Cells a bounded domain is first cut into for the proof by enclosures, …
CELLS = 16
#: … and the most cells enclosed in all (a cell not proved is halved) before it is given up.
MAX_CELLS = 512


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
        if _proved_continuous(e, v, domain):
            return domain
        raise NotImplementedError(f"{e} is not a polynomial in its applications of "
                                  f"{', '.join(sorted({f.func.__name__ for f in used}))}, and no interval "
                                  f"enclosure proves it continuous on {domain}") from err
    dom = domain
    for part in (*poly.coeffs(), *(arg for f in used for arg in f.args)):
        if part.has(v):
            dom = sp.Intersection(dom, continuous_domain(part, v, domain))
    return dom


def _proved_continuous(e: sp.Expr, v: sp.Symbol, domain: sp.Set) -> bool:
    """``e`` is continuous in ``v`` on all of ``domain`` (an interval, ℝ included), proved as the
    module says: every operation of ``e`` not continuous on ℝ, over ``v`` alone, has a finite
    enclosure on each of :data:`CELLS` cells of the domain (one cell if it is unbounded), a cell
    not proved halved, at most :data:`MAX_CELLS` enclosed."""
    if not isinstance(domain, sp.Interval):
        return False
    risky = [n for n in sp.preorder_traversal(e) if n.has(v) and _not_continuous_on_the_line(n)]
    if any(n.free_symbols != {v} for n in risky):
        return False  # a pole or a domain end that moves with the parameters (or anything unknown)
    ends = [_end(domain.start, "a"), _end(domain.end, "b")]
    if None in ends:
        return False
    encl = [interval_function(v, n) for n in risky]
    if any(f.refused for f in encl):
        return False  # (not built of what interval arithmetic encloses: nothing is proved)
    lo, hi = ends
    if mpmath.isfinite(lo) and mpmath.isfinite(hi):
        points = [lo, *(lo + (hi - lo) * k / CELLS for k in range(1, CELLS)), hi]
        cells = list(zip(points, points[1:]))
    else:
        cells = [(lo, hi)]
    enclosed = 0
    while cells:
        a, b = cells.pop()
        enclosed += 1
        if enclosed > MAX_CELLS:
            return False
        X = mpmath.iv.mpf([a, b])
        if all(_finite(f(X)) for f in encl):
            continue
        if not (mpmath.isfinite(a) and mpmath.isfinite(b)) or b - a < (hi - lo) * mpmath.mpf(2) ** -20:
            return False
        mid = (a + b) / 2
        cells += [(a, mid), (mid, b)]
    return True


def _not_continuous_on_the_line(n: sp.Basic) -> bool:
    """A power with an exponent that is not a natural number, or a function other than a registry
    primitive continuous on all of ℝ (``log``, ``tan``, ``asin``, … and anything unknown)."""
    if n.is_Pow:
        return not (n.exp.is_Integer and n.exp >= 0)
    return isinstance(n, sp.Function) and n.func not in EVERYWHERE


def _end(end: sp.Expr, side: str):
    """A domain end as an mpmath number rounded outward (``side`` "a": down, "b": up); None unless
    rational or infinite."""
    if end.is_infinite:
        return mpmath.inf if end > 0 else -mpmath.inf
    if not end.is_Rational:
        return None
    return getattr(mpmath.iv.mpf(end.p) / end.q, side)


def _finite(r) -> bool:
    return r is not None and mpmath.isfinite(r.a) and mpmath.isfinite(r.b)
