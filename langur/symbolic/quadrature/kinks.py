"""Breakpoints and kinks of one level of the nested integral (paper §8.2): where a deeper level's
region changes shape as this level's variable moves — deeper conditions at box ends and critical
points, crossings of two conditions (resultants), conditions meeting a flat one — so that the
outer ``quad`` only sees integrands smooth between its breakpoints.
"""

from __future__ import annotations

import itertools

import sympy as sp
from sympy.polys.constructor import construct_domain
from sympy.polys.polyerrors import CoercionFailed

from langur.memo import make_room, remember
from langur.symbolic.quadrature.compiling import COMPILED, _lambdify
from langur.symbolic.quadrature.problem import NumProblem, _depends
from langur.symbolic.quadrature.roots import _poly_roots, _roots
from langur.symbolic.walks import degree, free_symbols, rational_form
from langur.timebox import run_with_timeout

#: CPU seconds sympy may spend on the critical points of one condition (:func:`_critical_points`):
#: CPU, not wall clock, so that the breakpoints found (and the error bounds) do not change with the
#: machine's load.
CRITICAL_SECONDS = 1.0


#: The kink expressions of :func:`_kink_functions` by (conditions, variables, bounds, level): the
#: same problem comes back (a value, its cross-check, a derivative's regular part at the same
#: point), and the critical points and crossings are sympy work; at most :data:`COMPILED` kept.
_KINKS: dict = {}


def _kink_functions(p: NumProblem, level: int):
    """Where the inner integral's region changes shape (kinks of this level's integrand): roots of
    the deeper conditions with each deeper variable at a box end or, for a condition quadratic in
    it, at its critical point (where a region in that variable appears or vanishes), and where two
    conditions of the next level cross (:func:`_crossings`).  With the problem's parameters kept as
    symbols (``p.sbounds``), these expressions are computed once per shape of problem and hold at
    every parameter point (only :func:`_at_levels`, numeric, is redone at each).  Returns the
    ``(function, polynomial roots or None)`` pairs and, for each, the outer levels whose variables
    it depends on (:func:`_depends`; all of them for the box-corner functions of conditions
    without an expression); a function is None where its roots are polynomial (only the grid
    search of the others evaluates one).  Records in ``p.kink_tangent[level]`` the positions (in the returned
    list) of the tangency kinks: those with a critical point substituted, where a deeper region
    appears or vanishes as this level's variable moves and the inner integral behaves like a half
    power of the distance (:func:`langur.symbolic.quadrature.nested._tangent_quad`)."""
    out, vary = [], []
    p.kink_tangent[level] = set()
    symbolic = [c for c in p.conds if c.level > level and c.expr is not None] if p.syms else []
    for c in p.conds:
        if c.level > level and c not in symbolic:
            for corner in itertools.product(*[p.bounds[j] for j in range(level + 1, c.level + 1)]):
                out.append((lambda *a, c=c, corner=corner: c.f(*a, *corner), None))
                vary.append(tuple(range(level)))
    if not symbolic:
        return out, vary
    parametric = p.sbounds is not None and all(c.sym is not None for c in symbolic)
    at = p.at if parametric else {}
    if parametric:
        key = ("sym", tuple((c.sym, c.level) for c in symbolic), tuple(p.syms), tuple(p.sbounds), level)
        bounds = p.sbounds
    else:
        key = (tuple((c.expr, c.level) for c in symbolic), tuple(p.syms), tuple(p.bounds), level)
        bounds = [(sp.Float(lo), sp.Float(hi)) for lo, hi in p.bounds]
    exprs = _KINKS.get(key)
    if exprs is None:
        exprs = []
        variables = set(p.syms)
        for c in symbolic:
            es = [(c.sym if parametric else c.expr, False)]  # (expression, a critical point substituted)
            for j in range(c.level, level, -1):
                v = p.syms[j]
                nxt = []
                for e, tangent in es:
                    nxt += [(e.xreplace({v: b}), tangent) for b in bounds[j]]
                    nxt += [(e.xreplace({v: r}), True) for r in _critical_points(e, v)]
                es = nxt
            exprs += [(e, tangent) for e, tangent in es if free_symbols(e) & variables]
        if level + 1 < len(p.syms):
            exprs += [(e, False) for e in _crossings(p, level, parametric)]
            if not parametric:
                exprs += [(e, False) for e in _at_levels(p, level)]
        remember(_KINKS, key, exprs, COMPILED)
    if parametric and level + 1 < len(p.syms):  # numeric roots at these parameter values
        key = (tuple((c.expr, c.level) for c in symbolic), tuple(p.syms), tuple(p.bounds), level, "levels")
        levels = _KINKS.get(key)
        if levels is None:
            make_room(_KINKS, COMPILED)
            levels = _KINKS[key] = _at_levels(p, level)
        exprs = exprs + [(e, False) for e in levels]
    for e, tangent in exprs:
        if tangent:
            p.kink_tangent[level].add(len(out))
        roots = _poly_roots(e, p.syms, level, at)
        # (the kink's own function only where there is no polynomial root finder: only
        # :meth:`NumProblem.moving`'s grid search evaluates it, as for the fold's kinks (None, roots))
        out.append((_lambdify(p.syms[: level + 1], e, at) if roots is None else None, roots))
        vary.append(_depends(e, p.syms, level))
    return out, vary


#: CPU seconds sympy may spend on the resultant of two conditions (:func:`_crossings`) (CPU: as
#: :data:`CRITICAL_SECONDS`).
RESULTANT_SECONDS = 0.5


#: Degree (in the next variable) up to which two conditions' crossings are computed.
RESULTANT_DEGREE = 4


def _at_levels(p: NumProblem, level: int) -> list[sp.Expr]:
    """Where a condition of the next level meets a condition on the next variable alone
    (``sqrt(y + 2) <= 1.71``: y = 0.9241): the first with the next variable at the second's roots,
    as box ends are substituted in :func:`_kink_functions` (found on a grid refined by ``brentq``
    when it is not a polynomial)."""
    v, (lo, hi) = p.syms[level + 1], p.bounds[level + 1]
    if not hi > lo:
        return []
    here = [c for c in p.here(level + 1) if c.expr is not None]
    flat = [c for c in here if c.expr.free_symbols <= {v}]
    if not flat:
        return []
    roots = set()
    for c in flat:
        poly = _poly_roots(c.expr, p.syms, level + 1)
        prefix = [0.0] * (level + 1)  # unused: the condition depends on the next variable alone
        found = poly(*prefix) if poly is not None else _roots(lambda t, c=c, z=prefix: c.f(*z, t), lo, hi)
        roots |= {r for r in found if lo < r < hi}
    out = []
    for c in here:
        if c in flat:
            continue
        out += [e for r in sorted(roots) if not (e := c.expr.xreplace({v: sp.Float(r)})).is_number]
    return out


def _crossings(p: NumProblem, level: int, parametric: bool = False) -> list[sp.Expr]:
    """Where two conditions of the next level cross (kinks of this level's integrand: there the
    inner integral's region changes shape too): the resultant of the two polynomials in the next
    variable, a polynomial in this level's variables whose roots include every crossing (a
    superset: extra breakpoints only split ``quad``'s intervals).  Pairs that are not polynomials
    of degree ≤ :data:`RESULTANT_DEGREE` in it, or whose resultant takes longer than
    :data:`RESULTANT_SECONDS`, are left to ``quad``'s subdivision as before."""
    v = p.syms[level + 1]
    polys = [e for c in p.here(level + 1) if (e := c.sym if parametric else c.expr) is not None and _crosses(e, v)]
    params = set(p.at) if parametric else set()
    out = []
    for e1, e2 in itertools.combinations(polys, 2):
        if p.syms[level] not in free_symbols(e1) and p.syms[level] not in free_symbols(e2):
            continue  # (their resultant is free of this level's variable too: no crossing kept below)
        r = _crossing(e1, e2, v, p.syms[level])
        if r is None:  # the pair is left to quad's subdivision
            continue
        if not r.is_number and p.syms[level] in r.free_symbols and r.free_symbols <= set(p.syms[: level + 1]) | params:
            out.append(r)
    return out


#: :func:`_crosses`' answers by (condition, variable); at most :data:`COMPILED` kept.
_CROSSES: dict = {}


def _crosses(e: sp.Expr, v: sp.Symbol) -> bool:
    """Whether ``e`` is a polynomial of degree 1 to :data:`RESULTANT_DEGREE` in ``v`` with
    coefficients free of ``v`` (sympy's ``Poly``; :func:`_coefficients_in`)."""
    return bool(_coefficients_in(e, v))


def _coefficients_in(e: sp.Expr, v: sp.Symbol) -> tuple | bool:
    """``e``'s coefficients in ``v`` (sympy's ``Poly(e, v).all_coeffs()``, highest degree first)
    when ``e`` is a polynomial of degree 1 to :data:`RESULTANT_DEGREE` in ``v`` with coefficients
    free of ``v``, else False; remembered by (condition, variable) in :data:`_CROSSES`: the same
    conditions come back in every problem of a program (⟦p⟧, its cross-check, each derivative's
    pieces), and each ``Poly`` costs a millisecond or more (issue 15, exact15q); the coefficients
    serve :func:`_linear_crossing` (exact16q)."""
    key = (e, v)
    known = _CROSSES.get(key)
    if known is None:
        try:
            poly = sp.Poly(e, v)
            coeffs = tuple(poly.all_coeffs())
            eligible = 1 <= poly.degree() <= RESULTANT_DEGREE and not any(v in k.free_symbols for k in coeffs)
            known = coeffs if eligible else False
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            known = False
        remember(_CROSSES, key, known, COMPILED)
    return known


#: :func:`_crossing`'s answers by (first condition, second condition, eliminated variable, variable
#: kept), and whether the answer is the same for the pair in the other order (:func:`_crossing`);
#: at most :data:`COMPILED` kept.  The conditions of a program come back in every problem at every
#: parameter point, in another order when another piece lists them otherwise: the stylization
#: kernel's ⟦p⟧ (Theorem 8.1's check) has the box's conditions first, its partial derivatives'
#: regular parts last (exact14s).
_PAIRS: dict = {}


def _crossing(e1: sp.Expr, e2: sp.Expr, v: sp.Symbol, w: sp.Symbol) -> sp.Expr | None:
    """The square-free part in ``w`` of the resultant of ``e1`` and ``e2`` in ``v`` (:func:`_crossings`),
    or None when sympy fails or runs out of time (the pair is then left to ``quad``'s subdivision).

    Remembered by the ordered pair (:data:`_PAIRS`; the same computation would give the same
    expression), and used for the pair in the other order when that gives the same expression too:
    when both conditions are polynomials with rational coefficients in all their symbols (then
    sympy's coefficient domain is the integers or rationals with the other symbols adjoined, exact,
    where res(e2, e1) = (−1)^(deg e1 · deg e2)·res(e1, e2) as polynomials), and the answer is
    sympy's ``sqf_part`` itself, which first makes the polynomial's leading coefficient positive,
    so that r and −r have the same square-free part (:func:`_square_free_part`).  A time limit's or
    a failure's answer is not kept (asked again, as before)."""
    hit = _PAIRS.get((e1, e2, v, w))
    if hit is None:
        hit = _PAIRS.get((e2, e1, v, w))
        if hit is not None and not hit[1]:
            hit = None
    if hit is not None:
        return hit[0]
    try:
        out = run_with_timeout(lambda: _linear_crossing(e1, e2, v, w), RESULTANT_SECONDS, cpu=True)
    except Exception:  # noqa: BLE001 - a time limit (or a sympy failure): sympy's resultant, as before
        out = None
    if out is not None:
        remember(_PAIRS, (e1, e2, v, w), (out, True), COMPILED)
        return out
    try:
        r = run_with_timeout(lambda: sp.resultant(e1, e2, v), RESULTANT_SECONDS, cpu=True)
    except Exception:  # noqa: BLE001 - sympy fails in many ways (PolynomialDivisionFailed on floats, a time
        return None  # limit)
    r = sp.sympify(r)
    out, final, normalized = _square_free(r, w)
    if final:
        exact = _rational_polynomial(e1) and _rational_polynomial(e2)
        remember(_PAIRS, (e1, e2, v, w), (out, exact and normalized), COMPILED)
    return out


def _linear_crossing(e1: sp.Expr, e2: sp.Expr, v: sp.Symbol, w: sp.Symbol) -> sp.Expr | None:
    """:func:`_crossing`'s answer for two conditions of degree 1 in ``v`` with integer
    coefficients whose resultant is of degree 1 in ``w`` (the stylization kernel's half-planes and
    box sides: every pair), without sympy's ``resultant`` and ``sqf_part`` (~5 ms a pair, a tenth
    of stylize/quadratic's kinks); None when that does not apply (then :func:`_crossing` asks
    sympy, as before).

    The same expression:
    - e₁ = a₁v + b₁ and e₂ = a₂v + b₂ (:func:`_coefficients_in`, sympy's ``Poly`` coefficients)
      have res_v(e₁, e₂) = a₁b₂ − a₂b₁ (the 2×2 Sylvester determinant, over any commutative ring),
      the polynomial of sympy's resultant up to its sign.  It is formed here as ``Poly`` products
      in ``w`` over ℤ[the conditions' other symbols] (sympy's ``construct_domain``, which orders
      the symbols as it does for the resultant's own ``Poly``), not by expanding expressions.
    - Of degree 1 in ``w``, f = A·w + B: gcd(f, f′) = gcd(f, A) is a constant (the content
      gcd(A, B), up to a unit), so ``sqf_part`` — which makes the leading coefficient positive
      (``is_negative`` of the coefficient domain), divides by that gcd and takes the primitive part
      over the ring — gives f's primitive part with a positive leading coefficient, the same for
      −f.  That is unique (the units of ℤ[…] are ±1): ``Poly.primitive()``, its sign made positive
      the same way, converted by the same ``as_expr``.  A symbol of the conditions that cancels
      from f is a generator with exponent 0 in every term: it changes neither the leading term
      (lexicographic order) nor the expression.
    A coefficient outside ℤ[…] (a rational, a float) is left to sympy.  No time limit is lost:
    :func:`_crossing` runs this under the resultant's.  proofs_tests/test_exact_speed16q.py
    compares it with sympy's ``sqf_part(resultant)`` on the examples' pairs and random ones
    (issue 15, exact16q)."""
    c1, c2 = _coefficients_in(e1, v), _coefficients_in(e2, v)
    if not (c1 and c2 and len(c1) == 2 and len(c2) == 2) or not (_rational_polynomial(e1) and _rational_polynomial(e2)):
        return None
    others = (free_symbols(e1) | free_symbols(e2)) - {v, w}
    if not others:
        return None
    ring = construct_domain([sp.Add(*others)])[0]  # ℤ[others], ordered as sympy orders them
    if not (ring.is_PolynomialRing and ring.domain.is_ZZ):
        return None
    try:
        (a1, b1), (a2, b2) = [[sp.Poly(k, w, domain=ring) for k in cs] for cs in (c1, c2)]
    except (sp.PolynomialError, sp.GeneratorsNeeded, CoercionFailed):
        return None
    f = a1 * b2 - a2 * b1
    if f.degree() != 1:
        return None
    f = f.primitive()[1]
    if ring.is_negative(ring.from_sympy(f.LC())):
        f = -f
    return f.as_expr()


def _rational_polynomial(e: sp.Expr) -> bool:
    """Whether ``e`` is a polynomial with rational coefficients in all its symbols."""
    return rational_form(e) and degree(e, frozenset(free_symbols(e))) is not None


#: :func:`_square_free`'s answers by (resultant, variable): the same pair of conditions comes back in
#: every problem of a program at every parameter point (the value, each derivative's pieces, the
#: finite differences' shifted points); at most :data:`COMPILED` kept.
_SQUARE_FREE: dict = {}


def _square_free(r: sp.Expr, v: sp.Symbol) -> tuple[sp.Expr, bool, bool]:
    """:func:`_square_free_part`, remembered (:data:`_SQUARE_FREE`)."""
    key = (r, v)
    hit = _SQUARE_FREE.get(key)
    if hit is not None:
        return hit[0], True, hit[1]
    out, final, normalized = _square_free_part(r, v)
    if final:  # (a time limit's fallback is not kept: asked again, as :func:`_critical_points` does)
        remember(_SQUARE_FREE, key, (out, normalized), COMPILED)
    return out, final, normalized


def _square_free_part(r: sp.Expr, v: sp.Symbol) -> tuple[sp.Expr, bool, bool]:
    """The resultant ``r`` without its repeated factors (as a polynomial in ``v``), within
    :data:`RESULTANT_SECONDS` (else ``r``): two conditions that cross where they are both simple
    give a resultant with double roots — the cylinders x² + z² ≤ a, y² + z² ≤ a give (x² − y²)²
    in y — and ``numpy.roots`` finds a double root as two roots ~10⁻⁸ apart or as a complex pair
    it drops (:data:`~.roots.REAL_SLACK`): the kink y = x was missing and the middle level
    subdivided there.  The same zeros, each simple (tang13); whether the answer is final (not
    cut short by the time limit); and whether it is sympy's ``sqf_part`` (which first makes the
    leading coefficient positive: then −r has the same answer) rather than ``r`` itself."""
    try:
        out = run_with_timeout(lambda: sp.sqf_part(r, v), RESULTANT_SECONDS, cpu=True)
    except TimeoutError:
        return r, False, False
    except Exception:  # noqa: BLE001 - sympy fails in many ways on floats; the resultant itself is kept
        return r, True, False
    out = sp.sympify(out)
    return (out, True, True) if v in out.free_symbols else (r, True, False)


#: :func:`_critical_points`' answers by (expression, variable): one condition's come back at every
#: outer level of its problem, in every piece it is a factor of, and in every problem at the same
#: parameter values (the value, its cross-check, each derivative, Theorem 8.1's shifted points
#: of the pieces that do not move); a non-polynomial one costs a sympy ``solve`` (a third of a
#: second for ``tanh(z − 0.53) − 0.1``).  A time limit's empty answer is not kept (asked again,
#: as before); at most :data:`COMPILED` kept.
_CRITICAL: dict = {}


def _critical_points(e: sp.Expr, v: sp.Symbol) -> list[sp.Expr]:
    """Where ``∂e/∂v`` vanishes, as expressions in the outer variables: there a region in ``v``
    appears or vanishes as they move (the top of a circle, ``sqrt(x² + y²) < r`` at y = 0).
    A quadratic's vertex directly; otherwise sympy's solve on the derivative's numerator within
    :data:`CRITICAL_SECONDS` (none found: none used, the grid search of :func:`_roots` remains);
    remembered (:data:`_CRITICAL`)."""
    key = (e, v)
    known = _CRITICAL.get(key)
    if known is None:
        known, final = _solve_critical(e, v)
        if final:
            remember(_CRITICAL, key, known, COMPILED)
    return list(known)


def _solve_critical(e: sp.Expr, v: sp.Symbol) -> tuple[list[sp.Expr], bool]:
    """:func:`_critical_points`' answer, and whether it is final (not cut short by the time limit).

    An expression of degree at most 1 in ``v`` (:func:`~langur.symbolic.walks.degree`: an upper
    bound of the polynomial degree, from the tree, coefficients any expressions free of ``v``) has
    none, without building sympy's ``Poly`` (a millisecond per condition; the stylization kernel's
    half-planes are all affine): ``Poly(e, v)`` would have degree ≤ 1 and coefficients free of
    ``v``, the answer below (issue 15, exact15q)."""
    bound = degree(e, frozenset((v,)))
    if bound is not None and bound <= 1:
        return [], True
    try:
        poly = sp.Poly(e, v)
        if poly.degree() == 2 and not any(v in k.free_symbols for k in poly.all_coeffs()):
            a2, a1, _ = poly.all_coeffs()
            return [-a1 / (2 * a2)], True
        if poly.degree() <= 1 and not any(v in k.free_symbols for k in poly.all_coeffs()):
            return [], True
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        pass
    try:
        numerator = sp.numer(sp.together(sp.diff(e, v)))
        sols = run_with_timeout(lambda: sp.solve(numerator, v), CRITICAL_SECONDS, cpu=True)
    except TimeoutError:
        return [], False
    except (NotImplementedError, ValueError, TypeError, sp.PolynomialError):
        return [], True
    return [r for r in sols if v not in r.free_symbols and not r.has(sp.I)][:8], True


def _breakpoints(p: NumProblem, level: int, prefix: tuple, vary: bool,
                 tangent: set | None = None) -> tuple[dict, set]:
    """``level``'s breakpoints in (lo, hi) at the outer abscissae ``prefix`` (roots of its
    conditions, each with the positions in :meth:`~.problem.NumProblem.here` of the conditions it is
    a root of, from their polynomial root finders, a grid search, or their Psi's inverse) and its
    kinks (:func:`_kink_functions`): those that depend on the outer variables (``vary``), or those
    that do not — the same at every outer abscissa, so :func:`_nested` finds them once per problem
    (the same numbers: the same functions of the same arguments).  ``tangent``, when given, gets
    the kinks that are tangency points (``p.kink_tangent``)."""
    lo, hi = p.bounds[level]
    pts: dict = {}
    points, hinted, kink_fns, tangents = p.moving(level, vary)
    for i, roots in points:
        for r in roots(*prefix):
            if lo < r < hi:
                pts.setdefault(r, set()).add(i)
    for i, c in hinted:
        for r in c.hints(*prefix):
            if lo < r < hi:
                pts.setdefault(r, set()).add(i)
    kinks: set = set()
    for roots, is_tangent in zip(kink_fns, tangents):
        found = [r for r in roots(*prefix) if lo < r < hi]
        kinks.update(found)
        if is_tangent and tangent is not None:
            tangent.update(found)
    return pts, kinks

