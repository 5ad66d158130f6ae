"""One condition solved for one variable, at the evaluation point (paper §6.3, Def. 6.1–6.2: the
simple discontinuities ``[Φ ≥ 0]`` of a decomposable integrand, turned into intervals of the
integration variable; LANGUAGE.md §3–§4).

* :func:`alternatives`: ``[c ≥ 0]`` as intervals in ``v`` with conditions on the other symbols —
  linear and quadratic polynomials in ``v`` exactly, a Psi solved for ``v`` with one branch through
  its inverse; a direction that depends on parameters only is decided at the evaluation point.
* :func:`_roots` (sympy's ``solve``, time-boxed, each root checked at the point), the closed root
  formulas of large problems (:func:`_closed_roots`), and the shortcuts that avoid a solve: a
  condition that stays away from 0 (:func:`_away_from_zero`), roots that can only repeat points
  already placed (:func:`_only_repeats`, :func:`_radicand`).
* A periodic condition's roots, which sympy gives in one period, copied by whole periods over the
  interval (:func:`_periodic_copies`).
* Sign probes (:func:`_probe`) and the check that sympy missed no root (:func:`_no_missed_root`).

Used by :mod:`langur.symbolic.regions`' iterated integration and generic 1-D method.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mpmath
import sympy as sp

from langur import failures
from langur.memo import remember as _remember
from langur.symbolic import root_formulas, walks
from langur.symbolic.context import Cond, Context, Unsupported, _floats40, nearly_real
from langur.symbolic.pieces import NOT_FINITE
from langur.symbolic.text import math_lambdify, shared_lambdify
from langur.symbolic.unsolvable import unsolvable

# ------------------------------------------------------------------------------------------
# Solving one condition for one variable.


@dataclass
class Alt:
    extra: list  # Conds free of v
    lowers: list  # v ≥ each
    uppers: list  # v ≤ each


def _direction(d, v, outer, ctx: Context, root) -> list[Alt]:
    """Half-line(s) for a condition with one root ``root`` whose derivative in v has sign of d."""
    d = sp.sympify(d)
    if not (d.free_symbols & set(outer)):
        s = ctx.sign(d)
        return [Alt([], [root], [])] if s > 0 else [Alt([], [], [root])]
    return [Alt([Cond(d, strict=True)], [root], []), Alt([Cond(-d)], [], [root])]


#: :func:`_polynomial_roots`' answers by (expression, variable).
_POLY_ROOTS: dict = {}


def _polynomial_roots(e, v):
    """For ``e`` a polynomial of degree 1 in ``v`` (coefficients free of it): ``(a, −b/a)`` (its
    leading coefficient and root, cancelled); of degree 2: ``(a, disc, r₋, r₊)`` (the roots
    (−b ∓ √disc)/2a); else None.  :func:`alternatives`' formulas, remembered by (expression,
    variable), of which they are a pure function: the same conditions come back in each case
    split and for each partial derivative; what depends on the point is decided after."""
    key = (e, v)
    if key in _POLY_ROOTS:
        return _POLY_ROOTS[key]
    poly = None
    try:
        poly = sp.Poly(e, v)
        if any(v in k.free_symbols for k in poly.all_coeffs()):
            poly = None
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        poly = None
    out = None
    if poly is not None and poly.degree() == 1:
        a, b = poly.all_coeffs()
        out = (a, sp.cancel(-b / a))
    elif poly is not None and poly.degree() == 2:
        a, b, d = poly.all_coeffs()
        disc = sp.expand(b**2 - 4 * a * d)
        out = (a, disc, (-b - sp.sqrt(disc)) / (2 * a), (-b + sp.sqrt(disc)) / (2 * a))
    _remember(_POLY_ROOTS, key, out)
    return out


def alternatives(c: Cond, v, outer, ctx: Context) -> list[Alt]:
    """``[c ≥ 0]`` as a disjoint union (up to null sets) of intervals in ``v``.

    A condition changes sign in ``v`` at its roots and at its poles: a quotient N/D of
    polynomials in ``v`` is solved as the sign of N times the sign of D (:func:`_quotient`); a Psi
    solved for ``v`` with one branch gives the one root and the direction of a condition that is
    monotone and continuous on the whole line, which one with a pole in ``v`` is not
    (``1/(x + y + 1/2) − a`` falls from +∞ to ``−a`` on each side of ``y = −x − 1/2``), so then it
    is not used."""
    e = c.expr
    solved = _polynomial_roots(e, v)
    if solved is not None and len(solved) == 2:
        a, root = solved
        return _direction(a, v, outer, ctx, root)
    if solved is not None:
        a, disc, r_minus, r_plus = solved
        if a.free_symbols & set(outer):
            raise Unsupported("quadratic with a variable leading coefficient")
        if ctx.sign(a) < 0:  # c ≥ 0 between the roots
            return [Alt([Cond(disc)], [r_plus], [r_minus])]
        return [Alt([Cond(-disc, strict=True)], [], []),
                Alt([Cond(disc)], [], [r_minus]), Alt([Cond(disc)], [r_plus], [])]
    pole = _has_pole(e, v)
    if pole:
        parts = _quotient_parts(e, v)
        if parts is not None:
            return _quotient(c, parts, v, outer, ctx)
    psi = c.psi
    if psi is not None and psi.solved_for == v and len(psi.branches) == 1 and not psi.branches[0].guards:
        if pole:
            raise Unsupported(f"{e} has a pole in {v}, where it changes sign without a root")
        sub = {psi.inputs[0]: sp.Integer(0)}
        sub.update(dict(zip(psi.inputs[1:], [x for x in psi.variables if x != v])))
        comp = dict(psi.branches[0].inverse)[v]
        root = comp.xreplace(sub)
        if walks.has_any(sp.sympify(root), NOT_FINITE):
            raise Unsupported(f"the inverse of {e} solved for {v} is infinite on its zero set")
        d = sp.diff(comp, psi.inputs[0]).xreplace(sub)
        return _direction(d, v, outer, ctx, root)
    raise Unsupported(f"cannot solve {e} >= 0 for {v} in closed form")


def _has_pole(e, v) -> bool:
    """Whether ``e`` divides by an expression in ``v`` (a power with a negative exponent whose base
    mentions ``v``): where that vanishes ``e`` may change sign without passing through 0."""
    vs = frozenset((v,))
    seen: dict = {}
    return walks.any_node(e, lambda n: isinstance(n, sp.Pow) and n.exp.is_negative is True
                          and walks.mentions(n.base, vs, seen))


#: :func:`_pole_bases`' answers by (expression, variable).
_POLE_BASES: dict = {}


def _pole_bases(e, v) -> list:
    """The expressions in ``v`` whose zeros are poles of ``e``: the bases of its powers with a
    negative exponent, and ``cos u`` for each ``tan u`` in it; remembered by (expression,
    variable).  (A logarithm's −∞ at 0 is an end of its domain, not a sign change inside it.)"""
    key = (e, v)
    out = _POLE_BASES.get(key)
    if out is None:
        vs, seen, out = frozenset((v,)), {}, []

        def collect(n) -> bool:  # (each distinct subtree once; never stops the walk)
            if isinstance(n, sp.Pow) and n.exp.is_negative is True and walks.mentions(n.base, vs, seen):
                base = n.base
            elif isinstance(n, sp.tan) and walks.mentions(n.args[0], vs, seen):
                base = sp.cos(n.args[0])
            else:
                return False
            if base not in out:
                out.append(base)
            return False
        walks.any_node(e, collect)
        _remember(_POLE_BASES, key, out)
    return out


def poles(c: Cond, v, ctx: Context, within: tuple[float, float]) -> list:
    """The real poles of ``c`` in ``v`` at the evaluation point (:func:`_pole_bases`' zeros, by
    :func:`_roots`), where it may change sign without a root: :func:`_generic_1d`'s points besides
    the roots.  A base sympy cannot solve adds none (then :func:`_no_missed_root`'s probes are
    what finds a sign change there, as for a root sympy misses)."""
    out = []
    for base in _pole_bases(c.expr, v):
        try:  # (untidy first, as for the roots: the tidy solve only for a pole inside)
            found = _roots(Cond(base), v, ctx, tidy=False, within=within)
            if any(_inside(r, *within, ctx) for r in found):
                out += _roots(Cond(base), v, ctx, within=within)
        except Unsupported:
            continue
    return out


#: :func:`_quotient_parts`' answers by (expression, variable).
_QUOTIENTS: dict = {}


def _quotient_parts(e, v):
    """``(N, D)`` with ``e = N/D``, N and D polynomials of degree ≤ 2 in ``v`` (coefficients free of
    it), D of degree ≥ 1; None when ``e`` is not such a quotient.  Remembered by (expression,
    variable), of which it is a pure function."""
    key = (e, v)
    if key in _QUOTIENTS:
        return _QUOTIENTS[key]
    n, d = sp.fraction(sp.together(e))
    degrees = []
    for part in (n, d):
        try:
            poly = sp.Poly(part, v)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            poly = None
        if poly is None or poly.degree() > 2 or any(v in k.free_symbols for k in poly.all_coeffs()):
            degrees = None
            break
        degrees.append(poly.degree())
    out = (n, d) if degrees and degrees[1] >= 1 else None
    _remember(_QUOTIENTS, key, out)
    return out


def _quotient(c: Cond, parts, v, outer, ctx: Context) -> list[Alt]:
    """``[N/D ≥ 0]`` = ``[N ≥ 0]·[D > 0] + [−N ≥ 0]·[−D > 0]`` (up to the null set D = 0, where
    the condition is undefined): each side's alternatives for N and for D, intersected; disjoint
    because D's sign differs between the two sides and each condition's alternatives are."""
    n, d = parts
    out = []
    for s in (1, -1):
        ns = _sides(Cond(sp.expand(s * n), strict=c.strict), v, outer, ctx)
        ds = _sides(Cond(sp.expand(s * d), strict=True), v, outer, ctx)
        out += [Alt(a.extra + b.extra, a.lowers + b.lowers, a.uppers + b.uppers) for a in ns for b in ds]
    return out


def _sides(c: Cond, v, outer, ctx: Context) -> list[Alt]:
    """:func:`alternatives`, and a condition free of ``v`` as an extra condition on the others."""
    if v not in c.expr.free_symbols:
        return [Alt([c], [], [])]
    return alternatives(c, v, outer, ctx)


#: sympy's solutions (unchecked: each call checks them at its own evaluation point) per condition
#: and variable.
_SOLVED: dict = {}


def _roots(c: Cond, v, ctx: Context, tidy: bool = True, within: tuple[float, float] | None = None):
    """The real roots of ``c`` in ``v`` at the evaluation point (checked there); ``tidy``: sympy's
    solutions simplified (as they appear in closed forms), else as ``solve`` finds them without
    its ``simplify`` pass (the same roots, several times cheaper: enough to learn where they are).
    ``within``: the interval ``(lo, hi)`` of ``v`` at the point; sympy's solutions of a periodic
    condition are one period's, and their copies shifted by whole periods into it are added
    (:func:`_periodic_copies`)."""
    psi = c.psi
    if psi is not None and psi.solved_for == v and psi.branches:
        sub = {psi.inputs[0]: sp.Integer(0)}
        out = []
        for b in psi.branches:
            if all(ctx.decide(g.xreplace(sub)) for g in b.guards):
                out.append(dict(b.inverse)[v].xreplace(sub))
        if any(walks.has_any(sp.sympify(r), NOT_FINITE) for r in out):  # Ψ̂⁻¹ infinite at u₀ = 0
            raise Unsupported(f"the inverse of {c.expr} solved for {v} is infinite on its zero set")
        return out
    # check=False: sympy's own check drops roots whose validity depends on a parameter's sign
    # (yu + sqrt(r² − x²) = 0 has the roots ±sqrt(r² − yu²) exactly when yu ≤ 0); each candidate
    # is checked at the evaluation point instead, which is where the closed form is valid.
    key = (c.expr, v, tidy)
    sols = _SOLVED.get(key)  # the same conditions come back for ⟦p⟧, each ⦇p⦈ and the checks
    if sols is None:
        try:
            sols = ctx.deadline.run(lambda: _solve(c.expr, v, tidy), cap=max(2.0, ctx.deadline.seconds / 4))
        except TimeoutError:
            raise Unsupported(f"solving {c.expr} = 0 for {v} timed out") from None
        except (NotImplementedError, ValueError, TypeError) as exc:
            raise Unsupported(f"cannot solve {c.expr} = 0 for {v}: {failures.why(exc)}") from None
        _remember(_SOLVED, key, sols)
    if not isinstance(sols, list):
        raise Unsupported(f"infinitely many roots of {c.expr} in {v}")
    found = [r for r in sols if not isinstance(r, (dict, tuple)) and _vanishes_at(c.expr, v, r, ctx)]
    return found if within is None else found + _periodic_copies(c.expr, v, found, within, ctx)


#: :func:`_period`'s answers by (expression, variable).
_PERIODS: dict = {}
#: Periods of a condition within one interval beyond which its roots are not enumerated (the
#: piece goes to quadrature): each copy is a point of the closed form.
MAX_PERIODS = 64


#: CPU seconds sympy's ``periodicity`` may take on one condition (milliseconds on sin(3z) + 4/25).
PERIOD_CAP = 1.0


def _period(expr, v, ctx: Context):
    """The period of ``expr`` in ``v`` when it holds a trigonometric function of ``v`` and sympy's
    ``periodicity`` finds one (free of ``v``) within :data:`PERIOD_CAP`, else None; remembered by
    (expression, variable)."""
    key = (expr, v)
    if key in _PERIODS:
        return _PERIODS[key]
    out = None
    if walks.any_node(expr, lambda e: isinstance(e, sp.functions.elementary.trigonometric.TrigonometricFunction)
                      and v in e.free_symbols):
        try:
            out = ctx.deadline.run(lambda: sp.periodicity(expr, v), cap=PERIOD_CAP)
        except TimeoutError:
            return None  # (not remembered: another budget may see it through)
        except (NotImplementedError, ValueError, TypeError, RecursionError):
            out = None
        if out is not None and (out == 0 or v in out.free_symbols):
            out = None
    _remember(_PERIODS, key, out)
    return out


def _periodic_copies(expr, v, roots: list, within: tuple[float, float], ctx: Context) -> list:
    """``r + k·T`` for each root ``r`` and each whole k ≠ 0 that puts it strictly inside
    ``within`` at the evaluation point, T the period of ``expr`` in ``v`` (:func:`_period`; none
    when it has none).  sympy's ``solve`` gives a periodic condition's roots in one period only
    (sin(3z) = −0.16: −asin(0.16)/3 and (π + asin(0.16))/3), and a root between the interval's end
    and the first of those — z = (asin(0.16) − π)/3 on [−1, 1], 0.0064 from −1 — lies where
    :func:`_no_missed_root`'s equally spaced probes need not look."""
    period = _period(expr, v, ctx) if roots else None
    if period is None:
        return []
    try:
        t = ctx.value(period)
    except (TypeError, ValueError, ZeroDivisionError):
        return []
    if not nearly_real(t) or not math.isfinite(t.real) or t.real == 0:
        return []
    t_v, (lo, hi) = abs(t.real), within
    if (hi - lo) / t_v > MAX_PERIODS:
        raise Unsupported(f"{expr} has more than {MAX_PERIODS} periods in {v} between {lo:.6g} and {hi:.6g}")
    step = period if t.real > 0 else -period
    out = []
    for r in roots:
        z = ctx.value(r).real
        for k in range(math.ceil((lo - z) / t_v), math.floor((hi - z) / t_v) + 1):
            if k != 0 and lo < z + k * t_v < hi:
                out.append(r + k * step)
    return out


def _solve(expr, v, tidy: bool):
    """sympy's ``solve`` as :func:`_roots` asks it, or its failure when it is known from the shape
    (:func:`langur.symbolic.unsolvable.unsolvable`: 0.1–0.2 s saved each time, the same message)."""
    known = unsolvable(expr, v)
    if known is not None:
        raise NotImplementedError(known)
    return sp.solve(expr, v, dict=False, check=False, simplify=tidy)


#: :func:`_closed_roots` and :func:`_vanishes_at` by (condition, variable[, root], point): the same
#: conditions come back at the same point for ⟦p⟧ (the check), ⦇p⦈'s regular and delta pieces.
_CLOSED_ROOTS: dict = {}
_VANISHES: dict = {}


def _closed_roots(c: Cond, v, ctx: Context):
    """The roots, and the poles, of a condition (one of a large problem's) whose numerator and
    denominator are of degree ≤ 2 in ``v`` (:func:`root_formulas.closed_roots`), the roots checked at the
    evaluation point; None when it is not of that shape."""
    if c.psi is not None:
        return None
    key = (c.expr, v, tuple(ctx.at.items()))
    if key in _CLOSED_ROOTS:
        out = _CLOSED_ROOTS[key]
        return None if out is None else list(out)
    found = root_formulas.closed_roots(c.expr, v, ctx.value)
    out = None
    if found is not None:
        roots, poles = found
        out = [r for r in roots if _vanishes_at(c.expr, v, r, ctx)] + list(poles)
    _remember(_CLOSED_ROOTS, key, None if out is None else tuple(out))
    return out


def _vanishes_at(expr, v, root, ctx: Context) -> bool:
    """``expr`` is zero at ``v = root`` at the evaluation point (a true root there, not one that
    only an unchecked solution formula gives)."""
    key = (expr, v, root, tuple(ctx.at.items()))
    hit = _VANISHES.get(key)
    if hit is None:
        hit = _remember(_VANISHES, key, _vanishes_at_point(expr, v, root, ctx))
    return hit


def _vanishes_at_point(expr, v, root, ctx: Context) -> bool:
    try:
        z = ctx.value(root)
        if not nearly_real(z):
            return False
        residual = ctx.value_with(expr, {v: sp.Float(z.real, 40)})
    except (TypeError, ValueError, ZeroDivisionError):
        return False
    return abs(residual) <= 1e-9 * max(1.0, abs(z.real))


def _away_from_zero(c: Cond, v, lo: float, hi: float, ctx: Context) -> bool:
    """Whether ``c.expr`` = e + k·√A (e, k free of ``v``, A a polynomial of degree 1 or 2 in ``v``;
    no Psi solved for ``v``) stays away from 0 on [lo, hi] at the evaluation point, by far more
    than :func:`_vanishes_at_point`'s tolerance: then no root sympy's ``solve`` gives passes that
    check and :func:`_inside` (lo, hi), and solving is not needed to know it (a quadratic
    condition's roots compared with the box: √(4r² − 4x²)/2 − 1 ≥ 0 for the disc of radius r).
    |e + k√A| ≥ |e| where A < 0 (k√A imaginary) and where k√A has e's sign; else
    ≥ |e| − |k|·√(max A)."""
    psi, expr = c.psi, c.expr
    if psi is not None and psi.solved_for == v and psi.branches:
        return False
    shape = _root_shape(expr, v)
    if shape is None:
        return False
    e, k, coeffs = shape
    try:
        nums = [ctx.value(x) for x in [e, k, *coeffs]]
    except (TypeError, ValueError, ZeroDivisionError):
        return False
    if any(abs(z.imag) > 1e-20 * max(1.0, abs(z.real)) for z in nums):
        return False
    e_v, k_v, *a = [z.real for z in nums]
    if k_v == 0:
        return False
    bound = abs(e_v)
    if e_v * k_v <= 0:
        def at(x):
            return sum(ak * x ** (len(a) - 1 - i) for i, ak in enumerate(a))
        tops = [at(lo), at(hi)]
        if len(a) == 3 and a[0] < 0 and lo < -a[1] / (2 * a[0]) < hi:
            tops.append(at(-a[1] / (2 * a[0])))
        if max(tops) > 0:
            bound = abs(e_v) - abs(k_v) * max(tops) ** 0.5
    return bound > 1e-6 * max(1.0, abs(lo), abs(hi), abs(e_v))


#: :func:`_root_shape`'s answers by (expression, variable).
_ROOT_SHAPES: dict = {}


def _root_shape(expr, v):
    """``(e, k, [A's coefficients])`` when ``expr`` = e + k·√A with e, k free of ``v`` and A a
    polynomial of degree 1 or 2 in ``v``, else None (:func:`_away_from_zero`'s shape); remembered
    by (expression, variable), of which it is a pure function (the same conditions come back in
    each case split of ⟦p⟧ and each branch of a delta piece)."""
    key = (expr, v)
    if key in _ROOT_SHAPES:
        return _ROOT_SHAPES[key]
    out = None
    with_v = [t for t in expr.args if v in t.free_symbols] if isinstance(expr, sp.Add) else []
    roots = [f for f in sp.Mul.make_args(with_v[0]) if v in f.free_symbols] if len(with_v) == 1 else []
    if len(roots) == 1 and isinstance(roots[0], sp.Pow) and roots[0].exp == sp.S.Half:
        try:
            poly = sp.Poly(roots[0].base, v)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            poly = None
        if poly is not None:
            coeffs = poly.all_coeffs()
            if poly.degree() in (1, 2) and not any(v in a.free_symbols for a in coeffs):
                e = sp.Add(*[t for t in expr.args if v not in t.free_symbols])
                k = sp.Mul(*[f for f in sp.Mul.make_args(with_v[0]) if v not in f.free_symbols])
                out = (e, k, coeffs)
    _remember(_ROOT_SHAPES, key, out)
    return out


#: How far (relative) a root's 30-digit value must be from every double's rounding boundary, from
#: the interval's ends and from the imaginary-part thresholds for :func:`_only_repeats` to vouch
#: for the double of another form of it: sympy's ``evalf(30)`` of two forms of one number agree
#: to ~1e-30 of it, ten orders of magnitude inside this margin.
REPEAT_MARGIN = 1e-20


def _only_repeats(expr, v, lo: float, hi: float, known: set, ctx: Context) -> bool:
    """Whether every root of the condition ``expr`` that :func:`_generic_1d` would add with the tidy
    solve (sympy's ``solve`` with its ``simplify`` pass) is certainly a repeat of a point already
    there (a double in ``known``), so that the tidy solve — most of ``solve``'s time — cannot
    change anything; from sympy's untidy solutions, which must be known (:data:`_SOLVED`).

    The tidy solutions are the untidy ones simplified (:func:`_roots`: the same numbers; that is
    what :func:`_generic_1d` already relies on when no untidy root is inside).  Each untidy
    candidate's value is taken with 30 digits, and it must be, by :data:`REPEAT_MARGIN` relative,
    either clearly not real (then no form of it passes :func:`_vanishes_at_point`), or clearly
    outside ``[lo, hi]`` (then no form of it is :func:`_inside`), or a real number whose double
    is certain — farther than the margin from both rounding boundaries around it — and is one of
    ``known``.  Such a number's other forms have the same double, so the tidy root would be
    sorted right after the point already there and dropped as its repeat (whatever else is kept,
    a repeat with an equal double placed after its twin is dropped when its twin is, or is not:
    it is compared with the same last kept point)."""
    sols = _SOLVED.get((expr, v, False))
    if not isinstance(sols, list) or not sols:
        return False
    floats = _floats40(ctx.at)
    for s in sols:
        if isinstance(s, (dict, tuple)):
            return False
        try:
            z = sp.sympify(s).xreplace(floats).evalf(30)
            re, im = (mpmath.mpmathify(part) for part in z.as_real_imag())
        except (TypeError, ValueError, AttributeError):
            return False
        if not (mpmath.isfinite(re) and mpmath.isfinite(im)):
            return False
        size = max(1, abs(re))
        if abs(im) > 1e-9 * size:
            continue  # not real: every form of it fails the 1e-12 test of _vanishes_at_point
        if abs(im) > REPEAT_MARGIN * size:
            return False  # (nearly real: leave it to the tidy solve)
        margin = REPEAT_MARGIN * size
        if re < lo - margin or re > hi + margin:
            continue  # outside: no form of it is inside (lo, hi)
        d = float(re)
        if d not in known or d == 0.0:
            return False
        below, above = math.nextafter(d, -math.inf), math.nextafter(d, math.inf)
        with mpmath.workprec(200):  # (the midpoints of doubles are exact at 200 bits)
            if not (re - (mpmath.mpf(d) + mpmath.mpf(below)) / 2 > margin
                    and (mpmath.mpf(d) + mpmath.mpf(above)) / 2 - re > margin):
                return False
    return True


def _radicand(c: Cond, v, seen: set):
    """``P`` when ``c.expr`` is k·√P with k a positive rational, ``P`` a polynomial of degree 1 or 2
    in ``v`` (coefficients free of it) and ``P`` the expression of a condition whose roots
    :func:`_generic_1d` has already placed (``seen``); None otherwise.  The real zeros of k·√P are
    those of P, and sympy's ``solve`` of k·√P finds P's (it squares the radical away: checked on
    the examples' and random conditions, proofs_tests/test_exact_speed15r.py), so with P's roots
    certain repeats (:func:`_only_repeats`) so are those of k·√P: neither solve can change the
    points (the √(4r² − 4x²) ≥ 0 of the disc's ⟦p⟧, the width of its inner interval)."""
    if c.psi is not None:
        return None
    k, root = c.expr.as_coeff_Mul()
    if not (k.is_Rational and k > 0 and isinstance(root, sp.Pow) and root.exp == sp.S.Half):
        return None
    base = root.base
    if base not in seen:
        return None
    try:
        poly = sp.Poly(base, v)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if poly.degree() not in (1, 2) or any(v in a.free_symbols for a in poly.all_coeffs()):
        return None
    return base


#: Points per sub-interval at which :func:`_no_missed_root` looks for a sign change.
MISSED_ROOT_PROBES = 8


def _inside(r, lo: float, hi: float, ctx: Context) -> bool:
    """The root ``r`` is real and strictly between ``lo`` and ``hi`` at the evaluation point."""
    z = ctx.value(r)
    return nearly_real(z) and lo < z.real < hi


#: Compiled (float) conditions by (expression, variable, parameters), for the sign probes.
_PROBES: dict = {}
#: A probe's float value at most this large (absolute) is recomputed with 30 digits.
PROBE_DOUBT = 1e-6


def _probe(expr, v, m: float, ctx: Context) -> complex | None:
    """``expr`` at ``v = m`` at the evaluation point, for a sign: in floats (compiled once per
    condition), recomputed with 30 digits (:meth:`Context.value`) when the float is within
    :data:`PROBE_DOUBT` of 0, not finite or not real; None where it is undefined."""
    params = _probe_parameters(expr, ctx)
    key = (expr, v, params)
    fn = _PROBES.get(key)
    if fn is None:
        try:
            fn = math_lambdify((v, *params), expr)  # (shared subtrees printed once)
        except Exception:  # noqa: BLE001 - anything math cannot print: the exact path only
            fn = False
        _remember(_PROBES, key, fn)
    if fn is not False:
        try:
            x = float(fn(m, *[float(ctx.at[k]) for k in params]))
            if abs(x) > PROBE_DOUBT and x == x and abs(x) != float("inf"):
                return complex(x)
        except (ValueError, ZeroDivisionError, OverflowError, TypeError, NameError):
            pass
    z = _nonreal_probe(expr, v, m, params, ctx)
    if z is not None:
        return z
    try:
        return ctx.value(expr.xreplace({v: sp.Float(m, 40)}))
    except (TypeError, ValueError, ZeroDivisionError):
        return None


#: :func:`_probe_parameters`' answers by (expression, the point's symbols).
_PARAMETERS: dict = {}


def _probe_parameters(expr, ctx: Context) -> tuple:
    """The point's symbols that ``expr`` holds, sorted by name: a probe's arguments after the
    variable; remembered by (expression, the point's symbols) — a pure function of the key —
    instead of a walk of the expression at each of the 8 probes per sub-interval."""
    key = (expr, tuple(ctx.at))
    out = _PARAMETERS.get(key)
    if out is None:
        free = walks.free_symbols(expr)
        out = tuple(sorted((k for k in ctx.at if k in free), key=str))
        _remember(_PARAMETERS, key, out)
    return out


#: The sign probes' mpmath functions, by the key of :data:`_PROBES`.
_MP_PROBES: dict = {}


def _nonreal_probe(expr, v, m: float, params: tuple, ctx: Context) -> complex | None:
    """:func:`_probe`'s value when it is clearly not real (a square root or logarithm of a
    negative number: the float function's domain error), from a compiled mpmath function with
    40 digits and the same inputs as :meth:`Context.value`'s (the doubles of the point, and ``m``):
    an imaginary part above 1e-15 of the value's size, where the 30-digit evaluation differs by
    ~1e-30 of it, so that its imaginary part is above the 1e-20 under which the probes' callers
    take a value as real — they use a probe only to ask whether it is real and, if so, its sign.
    None otherwise (then the 30-digit evaluation, as before)."""
    key = (expr, v, params)
    fn = _MP_PROBES.get(key)
    if fn is None:
        try:
            fn = shared_lambdify([v, *params], expr, "mpmath")
        except Exception:  # noqa: BLE001 - anything mpmath cannot print: the 30-digit path only
            fn = False
        _remember(_MP_PROBES, key, fn)
    if fn is False:
        return None
    try:
        with mpmath.workdps(40):
            z = complex(fn(mpmath.mpf(m), *[mpmath.mpf(float(ctx.at[k])) for k in params]))
    except Exception:  # noqa: BLE001 - undefined there, or not a number: the 30-digit path decides
        return None
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        return None
    return z if abs(z.imag) > 1e-15 * max(1.0, abs(z.real)) else None


def _no_missed_root(conds, v, a: float, b: float, ctx: Context) -> None:
    """No condition changes sign strictly between two consecutive roots ``a < b`` (at the
    evaluation point): sympy's ``solve`` returns ``[]`` for equations it cannot solve (a quintic
    with a parameter: ``y^5 + y - a``), which would otherwise read as "no root" and give a wrong
    closed form.  Raises :class:`Unsupported` (the piece goes to quadrature)."""
    for c in conds:
        signs = set()
        for k in range(1, MISSED_ROOT_PROBES + 1):
            m = a + (b - a) * k / (MISSED_ROOT_PROBES + 1)
            z = _probe(c.expr, v, m, ctx)
            if z is not None and abs(z.imag) <= 1e-20 and z.real != 0:
                signs.add(z.real > 0)
        if len(signs) == 2:
            raise Unsupported(f"{c.expr} changes sign between {a:.6g} and {b:.6g} in {v}, where sympy "
                              "found no root")
