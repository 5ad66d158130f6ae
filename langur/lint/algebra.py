"""Sympy helpers for the transversality checker (paper Def. 7.2; LANGUAGE.md §5).

Every sympy call here is time-boxed (:func:`timed`), and every symbolic verdict is guarded by a
numeric spot check at random points, because ``simplify`` can both miss a zero and (rarely) invent
one:

* :func:`vanishes` — is an expression identically zero in the given symbols?
* :func:`bad_parameters` — the parameter values for which an expression vanishes identically in
  the remaining symbols (the parametric degeneracy sets of X304/X306), as solution dicts;
* :func:`solve_points` — common zeros of a system in the variables (tangency and triple points);
* :func:`describe_set` — a human reading of a union of solution dicts (``a = b``,
  ``theta ∈ {0, 1}``).
"""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Callable, Iterable, Mapping
from fractions import Fraction
from functools import lru_cache
from typing import TypeVar

import mpmath
import sympy as sp

from .. import failures
from ..memo import remember
from ..symbolic.nounits import units_unloaded
from ..sympy_bridge import magnitude
from ..timebox import Deadline
from ..timebox import run_with_timeout as _run_with_timeout  # nesting-safe SIGALRM limiter

T = TypeVar("T")

#: CPU-second limit of one sympy call made by the checker (CPU, not wall clock: the verdicts do not
#: change with the machine's load; ``timebox`` adds its wall-clock backstop).
TIME_LIMIT = 2.0
#: Random points of a numeric spot check.
SPOT_POINTS = 12
_TOL = 1e-8


class Undecided(Exception):
    """A sympy call ran out of time or failed: the checker cannot decide this question."""


class BudgetSpent(Undecided):
    """The whole analysis's CPU budget (``timebox.budget``, e.g. a fuzz unit's share) ran out during
    or before a call: undecided here, but not remembered as the question's answer (:func:`_memo`),
    since another program's analysis starts with a budget of its own."""


def timed(fn: Callable[[], T], seconds: float = TIME_LIMIT) -> T:
    """``fn()`` under a CPU-time limit of ``seconds``, or less when the enclosing analysis's budget
    (``timebox.budget``) has less left; :class:`Undecided` on time-out or on a sympy failure
    (:class:`BudgetSpent` when it was the analysis's budget that ran out)."""
    left = Deadline(seconds).remaining()
    if left <= 0:
        raise BudgetSpent("the analysis's CPU budget was spent")
    try:
        with units_unloaded():  # not the first simplify's import of physical units (~0.2 CPU s)
            return _run_with_timeout(fn, left, cpu=True)
    except TimeoutError as e:
        if left < 0.99 * seconds:  # the enclosing budget, not this limit, ended it
            raise BudgetSpent("the analysis's CPU budget ran out") from e
        raise Undecided(f"sympy took longer than {seconds:g} CPU s") from e
    except (
        NotImplementedError,
        TypeError,
        ValueError,
        ZeroDivisionError,
        AttributeError,
        RecursionError,
        sp.PolynomialError,
    ) as e:
        raise Undecided(failures.why(e)) from e


def exact(value) -> sp.Expr:
    """A parameter value as an exact sympy number (``0.3`` given on the command line is 3/10)."""
    if isinstance(value, sp.Basic):
        return value
    if isinstance(value, Fraction):
        return sp.Rational(value.numerator, value.denominator)
    if isinstance(value, int):
        return sp.Integer(value)
    if isinstance(value, float):
        if math.isfinite(value):
            return sp.Rational(str(value))
        return sp.nan
    return sp.sympify(value)


def _numeric(expr: sp.Expr, point: Mapping[sp.Symbol, float]) -> complex | None:
    try:
        v = complex(expr.evalf(15, subs=dict(point)))
    except (TypeError, ValueError, ZeroDivisionError, OverflowError):
        return None
    if not (math.isfinite(v.real) and math.isfinite(v.imag)):
        return None
    return v


@lru_cache(maxsize=4096)
def _compiled(expr: sp.Expr, args: tuple[sp.Symbol, ...]) -> Callable | None:
    """``expr`` compiled once (mpmath, so complex values stay complex), or ``None`` when sympy
    cannot print it; each point then costs a call instead of an ``evalf(subs=…)`` walk (1,023 of
    those were 72 % of the linter's time on a 3-D campaign program)."""
    try:
        return sp.lambdify(args, expr, modules="mpmath")
    except Exception:  # noqa: BLE001 — sympy's printers raise anything; evalf is the fallback
        return None


#: Working precision (decimal digits) of a compiled spot value: twice what ``evalf(15)`` promises,
#: so that a cancellation of 15 digits still leaves a value far below ``_TOL``.
_SPOT_DPS = 30


def _spot(fn: Callable | None, expr: sp.Expr, values: tuple, pt: Mapping[sp.Symbol, sp.Expr]) -> complex | None:
    """``expr`` at one point: the compiled function at ``values``, or ``evalf`` where it cannot
    say (a printer without a rule, a comparison of complex numbers, a pole)."""
    if fn is not None:
        try:
            with mpmath.workdps(_SPOT_DPS):
                v = complex(fn(*values))
        except Exception:  # noqa: BLE001 — whatever the compiled code raises, evalf decides
            v = None
        if v is not None and math.isfinite(v.real) and math.isfinite(v.imag):
            return v
    return _numeric(expr, pt)


def spot_values(
    expr: sp.Expr,
    symbols: Iterable[sp.Symbol],
    guards: Iterable[sp.Expr] = (),
    seed: int = 0,
    points: int = SPOT_POINTS,
    fixed: Mapping[sp.Symbol, sp.Expr] | None = None,
) -> list[complex]:
    """``expr`` at random points of ``symbols`` (uniform in [-2, 2]) where every guard is ``≥ 0``
    and the value is real and finite.  Deterministic for a given ``seed``.  Each expression is
    compiled once (:func:`_compiled`) and falls back to ``evalf`` point by point."""
    rng = random.Random(seed)
    syms = sorted(set(symbols), key=str)
    fixed = dict(fixed or {})
    guards = tuple(guards)
    names = tuple(s for s in syms if s not in fixed) + tuple(fixed)
    try:
        with mpmath.workdps(_SPOT_DPS):
            fixed_values = tuple(sp.sympify(v)._to_mpmath(mpmath.mp.prec) for v in fixed.values())
        fns = [_compiled(g, names) for g in guards], _compiled(expr, names)
    except (TypeError, ValueError, AttributeError, sp.SympifyError):  # not numbers: evalf only
        fixed_values, fns = (), ([None] * len(guards), None)
    out: list[complex] = []
    tries = 0
    while len(out) < points and tries < points * 6:
        tries += 1
        draws = [rng.uniform(-2.0, 2.0) for _ in syms]
        pt = {s: sp.Float(u, 15) for s, u in zip(syms, draws)}
        pt.update(fixed)
        values = tuple(mpmath.mpf(u) for s, u in zip(syms, draws) if s not in fixed) + fixed_values
        ok = True
        for g, fn in zip(guards, fns[0]):
            gv = _spot(fn, g, values, pt)
            if gv is None or abs(gv.imag) > 1e-9 or gv.real < 0:
                ok = False
                break
        if not ok:
            continue
        v = _spot(fns[1], expr, values, pt)
        if v is None or abs(v.imag) > 1e-7 * max(1.0, abs(v.real)):
            continue
        out.append(v)
    return out


def _memo(fn):
    """Remember a pure function of sympy expressions (and tuples of them) with its outcome, the
    exception included: a program that writes the same condition 10,000 times asks the same
    questions 10,000 times."""
    table: dict = {}

    def wrapper(*args):
        key = tuple(tuple(a) if isinstance(a, (list, tuple)) else a for a in args)
        try:
            hit = table.get(key)
        except TypeError:  # unhashable: not remembered
            return fn(*args)
        if hit is None:
            try:
                hit = (True, fn(*args))
            except BudgetSpent:
                raise  # this analysis's budget, not the question's answer: not remembered
            except Undecided as e:
                hit = (False, e)
            remember(table, key, hit, 100_000, at_once=True)
        ok, value = hit
        if not ok:
            raise value
        return [dict(v) for v in value] if isinstance(value, list) else value

    wrapper.__doc__, wrapper.__name__, wrapper.__wrapped__ = fn.__doc__, fn.__name__, fn
    return wrapper


def _distinct_monomials(expr: sp.Expr) -> bool:
    """Is ``expr`` written as a sum of distinct monomials (products of natural powers of symbols)
    with nonzero rational coefficients, ``-a·3/10`` or ``x² − 2·a + 1``?  Then it is a nonzero
    polynomial, not identically zero: a proof read off the written form, with no arithmetic
    (sympy's sums and products are usually collected this way; any other form says nothing)."""
    seen = set()
    for term in sp.Add.make_args(expr):
        c, m = term.as_coeff_Mul()
        if not c.is_Rational or c == 0:
            return False
        powers = {}
        for f in sp.Mul.make_args(m):
            base, k = f.as_base_exp()
            if f == 1 and len(sp.Mul.make_args(m)) == 1:
                continue  # the constant term
            if not (base.is_Symbol and k.is_Integer and k > 0) or base in powers:
                return False
            powers[base] = k
        key = frozenset(powers.items())
        if key in seen:
            return False
        seen.add(key)
    return True


#: CPU seconds of the cheap proofs of a zero tried before ``simplify`` (:func:`_plainly_zero`).
CHEAP_LIMIT = 0.2


def _plainly_zero(expr: sp.Expr) -> bool:
    """Is ``expr`` 0 by expansion, or as a rational function of its atoms (``cancel``)?  Each is a
    proof (what ``simplify`` would also find, at a fraction of its cost: it tries many rewrites
    before these); False says nothing."""
    if sp.expand(expr) == 0:
        return True
    return sp.cancel(sp.together(expr)) == 0


@_memo
def vanishes(
    expr: sp.Expr, symbols: Iterable[sp.Symbol], guards: Iterable[sp.Expr] = (), seed: int = 0
) -> bool:
    """Is ``expr`` identically zero in ``symbols`` (where the guards hold)?

    A numeric spot check first (a nonzero value at a valid random point settles "no" without
    simplifying); when every sampled value is zero, ``simplify`` must agree, except that a
    simplification that times out leaves the numeric verdict standing.  No valid sample point at
    all (the guards never hold) counts as "no": there is no zero set to speak of.
    """
    symbols = tuple(symbols)
    if expr == 0:
        return True
    if _distinct_monomials(expr):
        # a nonzero polynomial (a nonzero number): a valid point's value is nonzero, or there is
        # no valid point — "no" either way, without compiling it (a sum of 10⁴ distinct
        # conditions against a domain's bound asks this 2·10⁴ times)
        return False
    values = spot_values(expr, symbols, guards, seed)
    if not values:
        return False
    if any(abs(v) > _TOL for v in values):
        return False
    try:
        if timed(lambda: _plainly_zero(expr), CHEAP_LIMIT):
            return True
        if _rational_function(expr):
            return False  # ``cancel`` decides a rational function over the rationals exactly
    except BudgetSpent:
        raise
    except Undecided:
        pass  # simplify decides, with its whole limit
    try:
        s = timed(lambda: sp.simplify(expr))
    except BudgetSpent:
        raise  # the analysis's budget, not this question's: decided by no one
    except Undecided:
        return True
    if s == 0:
        return True
    # simplify could not show it; a few more samples decide, each value against the size of the
    # terms it is made of (``y/10**13`` is small, not zero: its value is all of its size).
    more = spot_values(expr / magnitude(expr), symbols, guards, seed + 1, points=3 * SPOT_POINTS)
    return bool(more) and all(abs(v) <= _RELATIVE_TOL for v in more)


#: A spot value (:data:`_SPOT_DPS` digits) this small against its :func:`~langur.sympy_bridge.magnitude` is rounding.
_RELATIVE_TOL = 1e-20


def _rational_function(expr: sp.Expr) -> bool:
    """Is ``expr`` made of rationals and symbols by +, · and integer powers?  Then
    :func:`_plainly_zero`'s ``cancel`` is a decision, not only a proof."""
    return all(n.is_Symbol or n.is_Rational or n.is_Add or n.is_Mul or (n.is_Pow and n.exp.is_Integer)
               for n in sp.preorder_traversal(expr))


def _equations(expr: sp.Expr, inner: tuple[sp.Symbol, ...], seed: int) -> list[sp.Expr]:
    """Equations in the parameters that say ``expr`` vanishes identically in ``inner``."""
    if not inner:
        return [expr]
    num = sp.numer(sp.together(expr))
    try:
        poly = timed(lambda: sp.Poly(sp.expand(num), *inner))
        coeffs = [c for c in poly.coeffs() if not c.free_symbols & set(inner)]
        if len(coeffs) == len(poly.coeffs()):
            return coeffs
    except (Undecided, sp.PolynomialError, sp.GeneratorsNeeded):
        pass
    rng = random.Random(seed)
    return [
        expr.subs({u: sp.Rational(rng.randint(-9, 9), rng.randint(1, 5)) for u in inner}) for _ in range(3)
    ]


@_memo
def bad_parameters(
    expr: sp.Expr,
    inner: Iterable[sp.Symbol],
    params: Iterable[sp.Symbol],
    guards: Iterable[sp.Expr] = (),
    seed: int = 0,
) -> list[dict[sp.Symbol, sp.Expr]]:
    """The parameter values at which ``expr`` vanishes identically in ``inner``, as ``sp.solve``
    solution dicts, each verified (the expression with the solution substituted vanishes).

    ``[]`` when there are none (or they cannot be found in time: then :class:`Undecided`)."""
    inner = tuple(inner)
    params = sorted(set(params) & expr.free_symbols, key=str)
    if not params:
        return []
    eqs = [e for e in _equations(expr, inner, seed) if e != 0]
    if not eqs:
        return []
    # one parameter, equations affine in it with rational coefficients (a sum of conditions
    # ``[x - a·k/n >= 0]``): the exact solution sympy's ``solve`` would give, without it
    sols = _affine_solution(eqs, tuple(params)) if len(params) == 1 else None
    if sols is None:
        sols = timed(lambda: _parameter_solutions(eqs, params))
    out = []
    for sol in sols:
        if not sol or any(v.has(sp.I) or v.free_symbols & set(inner) for v in sol.values()):
            continue
        rest = expr.subs(sol)
        rest_params = [p for p in params if p not in sol]
        if vanishes(rest, inner + tuple(rest_params), [g.subs(sol) for g in guards], seed):
            out.append(sol)
    return out


def _parameter_solutions(eqs: list[sp.Expr], params: list[sp.Symbol]) -> list[dict[sp.Symbol, sp.Expr]]:
    """``sp.solve(eqs, params, dict=True)``, by the cheapest of :func:`_solved_linearly`,
    :func:`solve_by_factors` and sympy's ``solve`` that applies."""
    for way in (_solved_linearly, solve_by_factors):
        sols = way(eqs, params)
        if sols is not None:
            return sols
    return sp.solve(eqs, params, dict=True)


#: At most this many choices of factors (:func:`solve_by_factors`) are solved one by one; past
#: it sympy's ``solve`` takes the whole system (a hostile product of many factors).
MAX_FACTOR_CHOICES = 64


def solve_by_factors(eqs: list[sp.Expr], unknowns: list[sp.Symbol]) -> list[dict[sp.Symbol, sp.Expr]] | None:
    """The solutions of a system of polynomials with rational coefficients, component by component:
    each equation is factored into irreducible polynomials, and the system's zeros are those of
    every smallest choice of factors that contains one factor of each equation; each choice is
    solved by sympy's ``solve`` without its own check (each solution is exact, and the callers
    verify what they keep).  None when an equation is not such a polynomial or there are more
    than :data:`MAX_FACTOR_CHOICES` choices (sympy then solves the system as given).

    What ``sp.solve`` of the whole system finds, at a fraction of its cost where it matters: a
    factor common to the equations makes the system's zero set a curve or a surface, on which
    sympy's Gröbner-basis solver spends seconds (the z-depth shader against a triangle's edge,
    ``examples/raytrace/scene.lgr``: ``(zth − 3)·q(t)`` with q a cubic, and the pairs of
    equations sharing q: 1.8 to 12 CPU s, past the 2 s limit, X310 or X304 with the machine's
    load and sympy's caches), and its check of each cubic's roots in radicals costs ~0.3 s."""
    factored = []
    for e in eqs:
        try:
            poly = sp.Poly(e, *unknowns)
        except (sp.PolynomialError, sp.GeneratorsNeeded):
            return None
        if poly.domain not in (sp.ZZ, sp.QQ):
            return None
        if poly.is_zero:
            continue
        if poly.is_ground:
            return []  # a nonzero number: no solution
        factored.append({f.as_expr() for f, _ in poly.factor_list()[1]})
    choices: list[frozenset] = [frozenset()]
    for factors in factored:
        grown = set()
        for choice in choices:
            grown |= {choice} if choice & factors else {choice | {f} for f in factors}
        choices = [c for c in grown if not any(o < c for o in grown)]  # the smallest ones
        if len(choices) > MAX_FACTOR_CHOICES:
            return None
    found: list[dict] = []
    for choice in sorted((sorted(c, key=sp.default_sort_key) for c in choices), key=sp.default_sort_key):
        solved = _linear_in_one(choice[0], unknowns) if len(choice) == 1 else None
        for sol in solved or (sp.solve(choice, unknowns, dict=True, check=False) if choice else [{}]):
            if sol not in found:
                found.append(sol)
    return found


def _linear_in_one(f: sp.Expr, unknowns: list[sp.Symbol]) -> list[dict[sp.Symbol, sp.Expr]] | None:
    """``[{u: g}]`` for a polynomial ``f`` that is not linear but of degree 1 in its first unknown u,
    with a nonzero number as coefficient: the whole zero set of ``f``, exactly, ``g`` factored as
    sympy's ``solve`` writes it.  sympy finds the same only after solving for the other unknowns
    (``a = ((b + 1)² − 2)³ − (b + 1)² + 2``: the roots of a sextic in b, ~1 CPU s); a linear
    equation it solves at once (and writes expanded: left to it).  None otherwise."""
    u = next((v for v in unknowns if f.has(v)), None)
    if u is None or sp.Poly(f, *unknowns).total_degree() <= 1:
        return None
    p = sp.Poly(f, u)
    if p.degree() != 1 or not p.LC().is_number or p.LC() == 0:
        return None
    return [{u: sp.factor(-p.TC() / p.LC())}]


def _solved_linearly(eqs: list[sp.Expr], params: list[sp.Symbol]) -> list[dict] | None:
    """``sp.solve(eqs, params, dict=True)`` for one equation, not polynomial in them, in several
    parameters one of which it is linear in with a nonzero number as coefficient (``−20·b + 20·sin(3a·x*(a)) + 9``: b), without
    sympy's attempts on the others; None otherwise (sympy decides).

    It is sympy's own first pass over the symbols (``solvers._solve`` with several symbols: each
    symbol the equation is linear in, in order, solved for with ``solve_linear`` and simplified,
    unless its solution contains one already solved for), and it stops there: sympy then solves for
    each remaining symbol s and keeps only solutions free of the symbols already solved for, and
    there are none, because with ∂f/∂b a nonzero number no s = S free of b makes f vanish for
    every b.  Those attempts are what cost (transcendental in s: up to the 2 CPU s limit each,
    and X310 when they do not finish); the solution set they would have described is the one
    ``b = …`` already describes.  The same parameter, the same value; sympy's last
    simplification may write it differently (``cos(2b)`` for ``1 − 2·sin(b)²``): on the
    examples and 150 campaign programs the 20 solutions it gave were identical."""
    if len(eqs) != 1 or len(params) < 2:
        return None
    f = eqs[0]
    if f.has(sp.Float, sp.Piecewise, sp.Abs, sp.sign, sp.Heaviside, sp.DiracDelta):
        return None  # sympy's solve rewrites these first: left to it
    if f.is_polynomial(*params):
        return None  # sympy solves a polynomial system its own way (and quickly): left to it
    result, got, anchored = [], set(), False
    for s in params:
        xi, v = sp.solve_linear(f, symbols=[s])
        if xi != s:
            continue
        v = sp.simplify(v)
        if v.free_symbols & got:
            continue
        got.add(s)
        result.append({s: v})
        k = sp.diff(f, s)
        anchored = anchored or (k.is_number and k.is_nonzero)
    if not anchored or any(v.has(sp.I, sp.nan, sp.zoo, sp.oo, -sp.oo) for sol in result for v in sol.values()):
        return None
    return result


def solve_points(eqs: list[sp.Expr], unknowns: Iterable[sp.Symbol]) -> list[dict[sp.Symbol, sp.Expr]]:
    """Cached :func:`_solve_points` (the same family of conditions recurs in many products)."""
    return list(_solve_points_cached(tuple(eqs), tuple(unknowns)))


@lru_cache(maxsize=2048)
def _solve_points_cached(eqs: tuple, unknowns: tuple) -> tuple:
    return tuple(_solve_points(list(eqs), unknowns))


def _solve_points(eqs: list[sp.Expr], unknowns: Iterable[sp.Symbol]) -> list[dict[sp.Symbol, sp.Expr]]:
    """Real common zeros of ``eqs`` in ``unknowns`` (other symbols are generic parameters).

    A solution may leave some unknowns free (a curve of solutions); solutions with complex values
    are dropped; each is verified by substituting it back (:func:`vanishes` in the parameters and
    the free unknowns), so a solution that only holds for special parameter values is dropped."""
    unknowns = tuple(unknowns)
    eqs = [e for e in eqs if e != 0]
    if not eqs:
        return []
    decided = _affine_solution(eqs, unknowns)
    if decided is not None:
        return decided
    if _contradictory(eqs, unknowns) or _never_together(eqs):
        return []
    sols = timed(lambda: sp.solve(eqs, unknowns, dict=True))
    others = set().union(*(e.free_symbols for e in eqs)) - set(unknowns)
    out = []
    for sol in sols:
        if not sol or any(v.has(sp.I) for v in sol.values()):
            continue
        free = set(unknowns) - set(sol)
        if all(vanishes(e.subs(sol), others | free) for e in eqs):
            out.append(sol)
    return out


def _affine_rows(eqs: list[sp.Expr], unknowns: tuple[sp.Symbol, ...]) -> list[list[Fraction]] | None:
    """Each equation as a row ``[c₁, …, cₙ, −c₀]`` of ``c₀ + Σ cᵢ·xᵢ = 0`` (exact rationals), or
    None when one is not affine in the unknowns with rational coefficients and no other symbol."""
    rows = []
    for e in eqs:
        row = _affine_row(e, tuple(unknowns))
        if row is None:
            return None
        rows.append(list(row))
    return rows


@lru_cache(maxsize=8192)
def _affine_row(e: sp.Expr, unknowns: tuple[sp.Symbol, ...]) -> tuple[Fraction, ...] | None:
    """One equation's row of :func:`_affine_rows` (remembered: the box's faces and the zero sets at
    the parameter values in force recur in every family and tangency system of a program)."""
    if not e.free_symbols <= set(unknowns):
        return None
    if any(not (a.is_Add or a.is_Mul or a.is_Pow or a.is_Symbol or a.is_Rational)
           for a in sp.preorder_traversal(e)):
        return None  # a function or a float: not affine with rational coefficients (no Poly built)
    try:
        poly = sp.Poly(e, *unknowns)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    if poly.domain not in (sp.ZZ, sp.QQ) or poly.total_degree() > 1:
        return None
    row = [Fraction(0)] * (len(unknowns) + 1)
    for monomial, c in poly.terms():
        c = Fraction(int(c.numerator), int(c.denominator))
        if sum(monomial) == 0:
            row[-1] = -c
        else:
            row[monomial.index(1)] = c
    return tuple(row)


def _eliminated(rows: list[list[Fraction]], n: int) -> tuple[list[list[Fraction]], int, list[int]]:
    """Gauss–Jordan elimination of ``rows`` in exact rationals: ``(rows, rank, pivot columns)``;
    rows past ``rank`` are ``0 = rows[i][-1]``."""
    rows = [list(r) for r in rows]
    rank, pivots = 0, []
    for col in range(n):
        pivot = next((r for r in range(rank, len(rows)) if rows[r][col] != 0), None)
        if pivot is None:
            continue
        rows[rank], rows[pivot] = rows[pivot], rows[rank]
        p = rows[rank][col]
        rows[rank] = [v / p for v in rows[rank]]
        for r in range(len(rows)):
            if r != rank and rows[r][col] != 0:
                k = rows[r][col]
                rows[r] = [a - k * b for a, b in zip(rows[r], rows[rank])]
        pivots.append(col)
        rank += 1
    return rows, rank, pivots


#: A number with at least this magnitude at 30 digits is certainly not zero (:func:`_contradictory`).
NONZERO = 1e-20


def _contradictory(eqs: list[sp.Expr], unknowns: tuple[sp.Symbol, ...]) -> bool:
    """Do ``eqs`` certainly have no common zero, by exact algebra on their affine part?  The
    equations affine in the unknowns with rational coefficients and no other symbol (box faces
    ``x = 0``, ``1 − x = 0``, affine zero sets at the parameters in force) are solved exactly: no
    solution, or unknowns they fix to values at which another equation is a nonzero number, means
    the whole system has none.  What :func:`_solve_points` then returns without ``sp.solve``
    (which decides the same, at up to a second per system: most tangency/triple-point systems of
    generated programs pair two parallel box faces with a transcendental zero set).  False: not
    decided here."""
    affine, rest = [], []
    for e in eqs:
        (affine if _affine_rows([e], unknowns) is not None else rest).append(e)
    if not affine:
        return False
    rows, rank, pivots = _eliminated(_affine_rows(affine, unknowns), len(unknowns))
    if any(row[-1] != 0 for row in rows[rank:]):
        return True  # the affine equations alone are inconsistent
    fixed = {}
    for i, col in enumerate(pivots):
        if all(rows[i][j] == 0 for j in range(len(unknowns)) if j != col):  # this unknown alone
            v = rows[i][-1]
            fixed[unknowns[col]] = sp.Rational(v.numerator, v.denominator)
    if not fixed:
        return False
    for e in rest:
        r = e.xreplace(fixed)
        if r.free_symbols:
            continue
        try:
            v = complex(sp.N(r, 30))
        except (TypeError, ValueError, ZeroDivisionError, OverflowError):
            continue
        if math.isfinite(v.real) and math.isfinite(v.imag) and abs(v) >= NONZERO:
            return True  # nonzero where the affine equations put the unknowns
    return False


def _never_together(eqs: list[sp.Expr]) -> bool:
    """Do ``eqs`` certainly have no common zero, by an exact argument cheaper than ``sp.solve``: one
    of them is a nonzero number over a denominator (``−1/(2·sqrt(y + 2))``, the tangency minor of a
    monotone condition: its numerator is −1), or two differ by a nonzero number (``y − x³ − 29/100``
    and ``y − x³ − 31/100``, parallel zero sets).  False: not decided here."""
    for e in eqs:
        n = sp.fraction(sp.together(e))[0] if e.is_Mul or e.is_Pow or e.is_Add else e
        if n.is_number and n.is_nonzero:
            return True
    for e, g in itertools.combinations(eqs, 2):
        d = sp.expand(e - g)
        if d.is_number and d.is_nonzero:
            return True
    return False


def _affine_solution(eqs: list[sp.Expr], unknowns: tuple[sp.Symbol, ...]) -> list[dict] | None:
    """What :func:`_solve_points` finds, without ``sp.solve``, for equations affine in the unknowns
    with rational coefficients and no other symbol (the conditions at the parameter values in
    force, most zero sets of generated programs): ``[]`` when they have no common zero,
    ``[{x: value, …}]`` (exact rationals) when exactly one; None when they leave an unknown free
    or are not of that kind (``sp.solve`` decides, and words its curve of solutions)."""
    rows = _affine_rows(eqs, unknowns)
    if rows is None:
        return None
    rows, rank, _ = _eliminated(rows, len(unknowns))
    if any(row[-1] != 0 for row in rows[rank:]):
        return []  # inconsistent
    if rank < len(unknowns):
        return None  # a line or plane of solutions: sympy words it
    return [{x: sp.Rational(rows[i][-1].numerator, rows[i][-1].denominator) for i, x in enumerate(unknowns)}]


def _text(e: sp.Expr) -> str:
    return sp.sstr(e)


def describe_set(solutions: list[dict[sp.Symbol, sp.Expr]]) -> str:
    """``[{θ: 0}, {θ: 1}]`` → ``theta ∈ {0, 1}``; ``[{a: b}]`` → ``a = b``; mixed → joined by "or"."""
    singles: dict[sp.Symbol, list[sp.Expr]] = {}
    parts: list[str] = []
    for sol in solutions:
        if len(sol) == 1:
            ((k, v),) = sol.items()
            if not v.free_symbols:
                if v not in singles.setdefault(k, []):
                    singles[k].append(v)
                continue
        text = " and ".join(
            f"{_text(k)} = {_text(v)}" for k, v in sorted(sol.items(), key=lambda kv: str(kv[0]))
        )
        if text not in parts:
            parts.append(text)
    head = []
    for k, vals in sorted(singles.items(), key=lambda kv: str(kv[0])):
        vals = sorted(vals, key=lambda v: float(v) if v.is_real else 0.0)
        if len(vals) == 1:
            head.append(f"{_text(k)} = {_text(vals[0])}")
        else:
            head.append(f"{_text(k)} ∈ {{{', '.join(_text(v) for v in vals)}}}")
    return " or ".join(head + parts)


def describe_point(point: Mapping[str, object], names: Iterable[str]) -> str:
    """``a = 0.3, b = 0.3`` for the named parameters (in the given order)."""
    out = []
    for n in names:
        if n in point:
            v = point[n]
            out.append(f"{n} = {_num(v)}")
    return ", ".join(out)


def _num(v) -> str:
    if isinstance(v, Fraction):
        return str(v.numerator) if v.denominator == 1 else f"{float(v):g}"
    if isinstance(v, float):
        return f"{v:g}"
    return str(v)
