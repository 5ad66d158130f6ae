"""Affine programs the transversality analysis would find nothing in, decided without sympy.

``langur deriv`` asks the transversality analysis (:func:`langur.transversality.check_loaded`,
sympy) whether ⦇p⦈ is the derivative at the parameter values (X301, X305), and the
integrability analysis (:mod:`langur.lint.singular`, sympy) whether ⦇p⦈ is an integral (X313).
For a program whose conditions are *affine with constant coefficients in the variables* —
``[x <= θ]`` (Fig. 1), microbenchmark 1's ``[x + 1/i + a − 1 >= 0]`` (§10.3.2), Fig. 9's
``[y < x + θ]``: ``a·x + b(z)`` with ``a ∈ ℚⁿ \\ {0}`` and ``b`` affine in the parameters with
rational coefficients — every question those analyses ask has an answer in exact rational
arithmetic, and :func:`nothing_to_find` answers them; like :func:`langur.lint.bounded.nothing_to_find`
it is conservative: ``False`` means "not decided here" and the full analysis runs.

What the full analysis reports (``langur.transversality``'s docstring, Def. 7.2, §7.3) and why
none of it can happen when :func:`nothing_to_find` says ``True``:

* **which conditions multiply** (:mod:`langur.lint.collect`): the products are computed as it does
  (Fig. 8: summands never multiply; a product, a conditional's branches and a primitive or a power
  of a discontinuous term multiply), each conditional one condition by identity; a conditional on
  the parameters contributes both branches (the collector takes one: a superset of its pairs).  A
  condition multiplied by itself (``[x<=t]^2``, ``exp([x<=t])``, one node in both factors: X301,
  X308) is not decided;
* **pairs** (:mod:`langur.lint.coincidence`): two zero sets ``a·x + b = 0`` and ``c·x + d = 0``
  with non-parallel normals meet transversally for every parameter value (no restriction of one
  to the other vanishes identically, and the tangency check skips linear conditions).  Parallel
  normals ``c = λa`` coincide exactly where ``r(z) = d(z) − λ·b(z) = 0``: never when ``r`` is a
  nonzero constant; for every value when ``r ≡ 0`` (X301/X308: not decided); on a hyperplane of
  parameters otherwise, which is reported whatever the values when both jumps move on the same
  side (X304, λ > 0: not decided), and else only when the values lie in it (a kink: X305; not
  decided when ``r`` vanishes at the values);
* **families** (:mod:`langur.lint.nullsets`, n ≥ 2): k = 3 … n+1 conditions of one product are
  reported (X302, X303) only with a common point inside the box (tolerance 1e-9) at the values
  and one of them moving; k ≤ n conditions with independent normals never.  The common points of
  the others are solved for exactly at the values: none, or a unique one outside the box by more
  than :data:`MARGIN`, is nothing; anything else is not decided;
* **the rest**: no parameter coefficient (``Diffeo.nonzero`` empty: no X306), no implicit root (no
  turning point: X305/X306 of :mod:`langur.lint.tangent`), a constant slope (no double root, X315),
  primitives defined on all of ℝ, integer powers ≥ 0 and powers of nonzero constants (no X307),
  a rational non-empty box (no X314), and :func:`derivative_bounded` (no X311, X312, X313).
  A ``let`` around a condition, a declared diffeomorphism, a parametric box are not decided.

The parameter values are those the analysis uses: a float as its decimal text (``0.1`` is 1/10,
``langur.lint.algebra.exact``).  What the analysis says of itself — X310, its CPU budget spent —
is no finding about the program; the ``deriv`` gate reads only X301 and X305.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from fractions import Fraction

from ..core import Add, IfDiffeo, IfGe0, ImplicitRoot, Let, Mul, Pow, Prim, Program, Term, subterms
from ..syntax.affine import linear, rational_value
from . import bounded

#: The primitives whose value and derivative are continuous on all of ℝ, hence bounded on the
#: compact box (``Domain.everywhere`` alone is not enough for the derivative: a cube root's is not).
SMOOTH = frozenset({"exp", "sin", "cos", "tanh", "atan", "erf"})

#: Beyond this many products of conditions, or families to solve, the question is left to the
#: full analysis (which caps its own work, and says so in an X310).
MAX_PRODUCTS = 2000
MAX_FAMILIES = 20000
#: More pairs of multiplying conditions than this (counted with repeats): not vouched for here; the
#: checker decides, within its budget (``langur.lint.classify``).
MAX_PAIRS = 200_000

#: A common point of a family this far outside the box (the analysis's tolerance is 1e-9) is
#: outside it for the analysis too.
MARGIN = Fraction(1, 10**6)


class _Undecided(Exception):
    """Not decided here: the full analysis runs."""


def _value(v) -> Fraction:
    """A parameter value as the analysis reads it (``langur.lint.algebra.exact``)."""
    if isinstance(v, bool):
        return Fraction(int(v))
    if isinstance(v, (int, Fraction)):
        return Fraction(v)
    if isinstance(v, float) and math.isfinite(v):
        return Fraction(repr(v))
    raise _Undecided


class _Condition:
    """``normal·x + offset(z) ≥ 0`` with ``offset`` affine in the parameters."""

    def __init__(self, normal: tuple[Fraction, ...], params: dict[str, Fraction], constant: Fraction,
                 point: Mapping[str, Fraction]):
        self.normal, self.params, self.constant = normal, params, constant
        self.moving = any(params.values())
        self.here = constant + sum(c * point[p] for p, c in params.items())  # the offset at the values


def _condition(node: IfDiffeo, variables: tuple[str, ...], point: Mapping[str, Fraction]) -> _Condition:
    psi = node.psi
    if psi.name is not None or psi.solved_for is None or psi.nonzero or len(psi.branches) != 1:
        raise _Undecided
    b = psi.branches[0]
    if any(isinstance(u, ImplicitRoot) for c in (*b.components, *b.guards) for u in subterms(c)):
        raise _Undecided
    form = linear(psi.forward[0])
    if form is None:
        raise _Undecided
    coeffs, constant = form
    normal = {v: Fraction(0) for v in variables}
    params: dict[str, Fraction] = {}
    for (kind, name), c in coeffs.items():
        if kind == "v" and name in normal:
            normal[name] = c
        elif kind == "p" and name in point:
            params[name] = c
        else:
            raise _Undecided
    out = tuple(normal[v] for v in variables)
    if not any(out):
        raise _Undecided
    return _Condition(out, params, constant, point)


def _products(body: Term) -> frozenset[frozenset[int]]:
    """Which conditionals multiply in ``body`` (by ``id``), as :mod:`langur.lint.collect` finds them
    (a superset: both branches of a conditional on the parameters); raises :class:`_Undecided` on a
    condition multiplied by itself."""
    memo: dict[int, frozenset[frozenset[int]]] = {}
    one = frozenset({frozenset()})

    def times(a, b):
        if len(a) * len(b) > MAX_PRODUCTS:
            raise _Undecided
        out = set()
        for m in a:
            for n in b:
                if m & n:
                    raise _Undecided  # squared: X301 or X308
                out.add(m | n)
        return frozenset(out)

    def go(t: Term):
        key = id(t)
        if key in memo:
            return memo[key]
        match t:
            case Add(a, b):  # summands never multiply
                out = go(a) | go(b)
                if len(out) > MAX_PRODUCTS:
                    raise _Undecided
            case Mul(a, b):  # each delta meets the other factor's jumps
                out = times(go(a), go(b))
            case Prim(_, a):  # the chain rule: f'(⟦a⟧) jumps where a does
                a_ = go(a)
                out = times(a_, a_)
            case Pow(a, k):
                out = one if k == 0 else go(a) if k == 1 else times(go(a), go(a))
            case IfGe0(_, s, r):  # the collector takes the branch selected at the values: a superset
                out = go(s) | go(r)
            case IfDiffeo(_, s, r):
                out = frozenset(m | {key} for m in go(s) | go(r))
            case Let():
                if any(isinstance(u, IfDiffeo) for u in subterms(t)):
                    raise _Undecided  # (the collector reads conditions under a let with its value)
                out = one
            case _:
                if any(isinstance(u, IfDiffeo) for u in subterms(t)):
                    raise _Undecided
                out = one
        memo[key] = out
        return out

    return go(body)


def _parallel(a: tuple[Fraction, ...], c: tuple[Fraction, ...]) -> Fraction | None:
    """λ with c = λ·a, or None."""
    k = next(i for i, v in enumerate(a) if v)
    lam = c[k] / a[k]
    return lam if all(ci == lam * ai for ai, ci in zip(a, c)) else None


def _pair_clear(f: _Condition, g: _Condition) -> bool:
    """No X301, X304, X305, X308 for these two multiplying conditions (module docstring)."""
    lam = _parallel(f.normal, g.normal)
    if lam is None:
        return True  # transverse for every parameter value
    names = set(f.params) | set(g.params)
    moves = any(g.params.get(p, 0) - lam * f.params.get(p, 0) for p in names)
    if not moves:
        return g.constant - lam * f.constant != 0  # never coincide (≡ 0: the same zero set always)
    if f.moving and g.moving and lam > 0:
        return False  # X304 for the whole set, whatever the values
    return g.here - lam * f.here != 0  # a kink only at values in the set


def _solve(rows: list[list[Fraction]]) -> tuple[bool, tuple[Fraction, ...] | None]:
    """The affine system ``row[:-1]·x = row[-1]`` (Gauss–Jordan, exact): (consistent, its unique
    solution or None)."""
    m = [list(r) for r in rows]
    n = len(m[0]) - 1
    pivots = []
    r = 0
    for col in range(n):
        p = next((i for i in range(r, len(m)) if m[i][col]), None)
        if p is None:
            continue
        m[r], m[p] = m[p], m[r]
        for i in range(len(m)):
            if i != r and m[i][col]:
                q = m[i][col] / m[r][col]
                m[i] = [x - q * y for x, y in zip(m[i], m[r])]
        pivots.append(col)
        r += 1
    if any(not any(row[:-1]) and row[-1] for row in m):
        return False, None
    if len(pivots) < n:
        return True, None
    return True, tuple(m[i][-1] / m[i][pivots[i]] for i in range(n))


def _family_clear(fam: list[_Condition], box: list[tuple[Fraction, Fraction]]) -> bool:
    """No X302/X303 for this family (module docstring)."""
    if not any(f.moving for f in fam):
        return True  # nothing moves: the analysis skips it
    n = len(box)
    if len(fam) <= n and _rank([list(f.normal) for f in fam]) == len(fam):
        return True  # independent normals everywhere (a nonzero constant minor)
    consistent, x = _solve([[*f.normal, -f.here] for f in fam])
    if not consistent:
        return True
    if x is None:
        return False
    return any(v < lo - MARGIN or v > hi + MARGIN for v, (lo, hi) in zip(x, box))


def _rank(rows: list[list[Fraction]]) -> int:
    m = [list(r) for r in rows]
    rank = 0
    for col in range(len(m[0])):
        p = next((i for i in range(rank, len(m)) if m[i][col]), None)
        if p is None:
            continue
        m[rank], m[p] = m[p], m[rank]
        for i in range(rank + 1, len(m)):
            q = m[i][col] / m[rank][col]
            m[i] = [x - q * y for x, y in zip(m[i], m[rank])]
        rank += 1
    return rank


def _terms_clear(program: Program, point: Mapping[str, Fraction]) -> dict[int, _Condition]:
    """Every condition read (by id), after the checks of the integrand's terms: smooth
    primitives, conditionals on the parameters away from their switch (the rest:
    :func:`langur.lint.bounded.bounded`, checked first)."""
    conditions = {}
    for u in subterms(program.body):
        match u:
            case Prim(op, _) if op not in SMOOTH:
                raise _Undecided
            case IfGe0(c, _, _):
                form = linear(c)
                if form is None or any(k != "p" or p not in point for k, p in form[0]):
                    raise _Undecided
                if form[1] + sum(v * point[p] for (_, p), v in form[0].items()) == 0:
                    raise _Undecided
            case IfDiffeo():
                conditions[id(u)] = _condition(u, program.variables, point)
    return conditions


def _bounded_conditions(program: Program, at: Mapping[str, Fraction]) -> dict[int, _Condition]:
    """:func:`derivative_bounded`'s conditions, read, or :class:`_Undecided`."""
    if not bounded.nothing_to_find(program, at):
        raise _Undecided
    return _terms_clear(program, at)


def derivative_bounded(program: Program, point: Mapping[str, object]) -> bool:
    """⟦p⟧ and ⦇p⦈ in every direction are integrals of bounded integrands at ``point`` (with
    :func:`langur.lint.bounded.nothing_to_find`): the integrability analysis (X311, X312, X313)
    would report nothing.  The regular part is built from the integrand's pieces, smooth
    primitives' derivatives and powers: bounded on the box; each delta's weight
    ``D_γ c / |∂_x c|`` has a constant, nonzero denominator and multiplies a bounded jump."""
    try:
        _bounded_conditions(program, {k: _value(v) for k, v in point.items()})
    except (_Undecided, RecursionError):  # (a term nested too deep to read recursively)
        return False
    return True


def nothing_to_find(program: Program, point: Mapping[str, object]) -> bool:
    """The transversality analysis of ``program`` at the parameter values ``point`` (as
    ``check_loaded(…, at=point)`` gets them) would report nothing (module docstring)."""
    try:
        at = {k: _value(v) for k, v in point.items()}
        conditions = _bounded_conditions(program, at)  # (a rational, non-empty box)
        box = [(rational_value(lo), rational_value(hi)) for lo, hi in program.box]
        products = _products(program.body)
        pairs: set[tuple[int, int]] = set()
        families: set[tuple[int, ...]] = set()
        n = len(program.variables)
        for p in products:
            ids = sorted(p)
            if len(pairs) + len(ids) * (len(ids) - 1) // 2 > MAX_PAIRS:
                return False  # (a product of 10⁴ conditions: 5·10⁷ pairs, gigabytes to list)
            pairs.update(itertools.combinations(ids, 2))
            for k in range(3, min(n + 1, len(ids)) + 1):
                for fam in itertools.combinations(ids, k):  # (one at a time: C(10⁴, 3) would not end)
                    families.add(fam)
                    if len(families) > MAX_FAMILIES:
                        return False
        if not all(_pair_clear(conditions[i], conditions[j]) for i, j in pairs):
            return False
        return all(_family_clear([conditions[i] for i in fam], box) for fam in families)
    except (_Undecided, RecursionError):  # (a term nested too deep to read recursively)
        return False
