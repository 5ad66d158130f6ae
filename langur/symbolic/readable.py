"""Readable closed forms: the exact engine's ⟦p⟧ and ⦇p⦈ (§6, §7) as a function of the parameters
in cases, ``Min``/``Max``/``Piecewise``/``Heaviside`` resolved on each case and every case simplified.

The integrator's closed forms are right but nested (``Max(-1, -theta - 1, Min(1, 1 - theta))``):
its bounds of integration are clipped to the box by ``Min``/``Max``.  Here:

* **one parameter** p: the *switching functions* (differences of the arguments of every
  ``Min``/``Max``, the sides of every ``Piecewise`` relation, the argument of every ``Heaviside``,
  the relations of the closed form's parameter cell) have finitely many real roots, the
  breakpoints; between two breakpoints none of them changes sign, so each ``Min``/``Max``/
  ``Piecewise`` is one of its arguments there: it is resolved at an interior point and the piece
  simplified.  Each breakpoint is attached to the neighbouring piece that equals the closed form
  there; equal neighbours are merged.  The result is a list of disjoint intervals covering the set
  where the closed form holds (everywhere, or the cell of the evaluation point).
* **several parameters**: when every switching function is affine in the parameters (box bounds,
  window ends), their zero sets cut the parameter space into convex cells
  (:mod:`langur.symbolic.arrangement`); on each the closed form is resolved at an exact inner point
  and simplified, neighbouring cells with the same expression are joined and each case is stated by
  its essential bounding relations.  Otherwise: the case that contains the evaluation point (the
  signs of the switching functions there), the rest left in the engine's form.

Every case is an exact sympy expression (no floats are introduced); :func:`readable` gives up
(returns None) when a breakpoint cannot be found exactly.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from ..precise import real_number
from ..sympy_bridge import DOMAINS
from . import arrangement

#: Largest expression (sympy ``count_ops``) handed to ``sp.simplify``; bigger ones are only expanded.
SIMPLIFY_LIMIT = 400


@dataclass(frozen=True)
class Case:
    """``expr`` where ``condition`` holds (a sympy Boolean in the parameters).  For one parameter
    ``interval`` is the set as a sympy Interval (or FiniteSet for an isolated point)."""

    condition: sp.Basic
    expr: sp.Expr
    interval: sp.Set | None = None
    #: several parameters: an exact point inside the case (parameter symbol → value)
    point: Mapping[sp.Symbol, sp.Expr] | None = None
    #: several parameters: the bounding relations, in the order they are printed
    relations: tuple = ()
    #: the case is "everywhere else" (``condition`` is the negation of the other cases')
    otherwise: bool = False


@dataclass(frozen=True)
class Readable:
    """A closed form in cases.  ``complete``: the cases cover the whole set where the closed form
    holds (``domain``); otherwise only the case of the evaluation point is given and ``rest`` is
    the engine's form for the others."""

    cases: tuple[Case, ...]
    parameter: sp.Symbol | None
    domain: sp.Set | None
    complete: bool
    rest: sp.Expr | None = None
    #: intervals of the one parameter where the closed form is not real (it does not apply there)
    excluded: tuple[sp.Set, ...] = ()
    #: the engine established the closed form only near the evaluation point (its real roots there)
    near: bool = False
    #: several parameters: the closed form jumps between cases, whose boundaries are left out
    boundaries_open: bool = False

    def text(self, latex: bool = False) -> str:
        return readable_text(self, latex)

    def _repr_latex_(self) -> str:
        return "$\\displaystyle " + readable_text(self, latex=True) + "$"


def _switching(expr: sp.Expr) -> list[sp.Expr]:
    """The functions of the parameters whose sign decides every Min/Max/Piecewise/Heaviside."""
    out: list[sp.Expr] = []
    for node in sp.preorder_traversal(expr):
        if isinstance(node, (sp.Min, sp.Max)):
            args = node.args
            out += [args[i] - args[j] for i in range(len(args)) for j in range(i + 1, len(args))]
        elif isinstance(node, sp.Piecewise):
            for _, cond in node.args:
                out += [r.lhs - r.rhs for r in cond.atoms(sp.core.relational.Relational)]
        elif isinstance(node, (sp.Heaviside, sp.sign, sp.Abs)):
            out.append(node.args[0])
    return out


#: The sympy functions of the primitives defined on part of ℝ only, with their domains (``log``, ``asin``,
#: ``acos``, ``atanh``, ``tan``: :mod:`langur.primitives` declares each; ``sqrt`` is a power, below).
_PARTIAL = {f: dom for f, dom in DOMAINS.items() if not dom.everywhere}


def _domain_edges(expr: sp.Expr) -> list[sp.Expr]:
    """The functions of the parameters whose roots bound where ``expr`` is real and finite: the base of
    every fractional power (a root of a negative number) and of every negative one (a pole), the
    argument of every primitive defined on part of ℝ minus each finite end of its domain.  Between two
    of their roots the expression is real at every point or at none (a periodic pole, ``tan``'s, is
    not one of them: its roots are not a finite set).  Without them a case would be decided at one
    point for a whole interval across such an end: ``Max(log(t), 0)`` resolved at t = 0 (not real)
    excluded all of t < 1 although it is 0 on (0, 1), ``Min(sqrt(t), 1)`` at t = 0 claimed √t for t < 0."""
    out: list[sp.Expr] = []
    for node in sp.preorder_traversal(expr):
        if node.is_Pow and not node.exp.is_integer or node.is_Pow and node.exp.is_negative:
            out.append(node.base)
        elif type(node) in _PARTIAL and not _PARTIAL[type(node)].poles:
            dom = _PARTIAL[type(node)]
            out += [node.args[0] - sp.nsimplify(end) for end in (dom.lo, dom.hi) if math.isfinite(end)]
    return out


def _variants(e: sp.Expr, limit: int = 64) -> list[sp.Expr]:
    """``e`` with each inner Min/Max replaced by each of its arguments in turn: the functions one of
    which ``e`` is wherever the inner ones do not switch (their own roots are cuts already)."""
    out, todo = [], [e]
    while todo and len(out) + len(todo) <= limit:
        f = todo.pop()
        inner = next((n for n in sp.preorder_traversal(f) if isinstance(n, (sp.Min, sp.Max))), None)
        if inner is None:
            out.append(f)
        else:
            todo += [f.xreplace({inner: arg}) for arg in inner.args]
    if todo:
        raise ValueError("too many nested Min/Max")
    return out


def _decide(cond, subs) -> bool:
    v = cond.subs(subs)
    if v in (sp.true, sp.false):
        return bool(v)
    return bool(v.xreplace({r: sp.true if real_number(r.lhs - r.rhs) == 0 and r.rel_op in ("<=", ">=", "==")
                            else sp.true if r.func(real_number(r.lhs), real_number(r.rhs)) else sp.false
                            for r in v.atoms(sp.core.relational.Relational)}))


def resolve(expr: sp.Expr, subs: Mapping[sp.Symbol, sp.Expr]) -> sp.Expr:
    """``expr`` with every Min/Max/Piecewise/Heaviside replaced by the branch it takes at ``subs``
    (innermost first).  Valid on the whole set where no switching function changes sign."""
    if expr.is_Atom:
        return expr
    if isinstance(expr, sp.Piecewise):
        for e, cond in expr.args:
            if _decide(resolve_bool(cond, subs), subs):
                return resolve(e, subs)
        return sp.nan
    args = [resolve(a, subs) for a in expr.args]
    if isinstance(expr, (sp.Min, sp.Max)):
        vals = [real_number(a.subs(subs)) for a in args]
        pick = min if isinstance(expr, sp.Min) else max
        return args[vals.index(pick(vals))]
    if isinstance(expr, sp.Heaviside):
        v = real_number(args[0].subs(subs))
        return sp.Integer(1) if v > 0 else sp.Integer(0) if v < 0 else expr.func(*args)
    if isinstance(expr, sp.sign):
        v = real_number(args[0].subs(subs))
        return sp.Integer(1) if v > 0 else sp.Integer(-1) if v < 0 else sp.Integer(0)
    if isinstance(expr, sp.Abs):
        v = real_number(args[0].subs(subs))
        return args[0] if v >= 0 else -args[0]
    return expr.func(*args)


def resolve_bool(cond, subs):
    if isinstance(cond, sp.core.relational.Relational):
        return cond.func(resolve(cond.lhs, subs), resolve(cond.rhs, subs))
    if cond in (sp.true, sp.false):
        return cond
    return cond.func(*[resolve_bool(a, subs) for a in cond.args])


def tidy(e: sp.Expr) -> sp.Expr:
    """The shortest of a few exact simplifications of a Min/Max-free expression."""
    cands = [e, sp.expand(e)]
    try:
        cands.append(sp.factor(cands[1]))
        cands.append(_exp_collected(cands[1]))
        if sp.count_ops(e) <= SIMPLIFY_LIMIT:
            cands.append(sp.simplify(e))
    except (NotImplementedError, TypeError, ValueError, sp.PolynomialError):
        pass
    return min(cands, key=lambda c: (len(sp.sstr(c)), sp.count_ops(c)))


def _exp_collected(e: sp.Expr) -> sp.Expr:
    """Exponentials merged and factored (``exp(-(mu - 2)^2/100)``) and the terms collected on them."""
    e = sp.powsimp(e)
    e = e.replace(lambda n: isinstance(n, sp.exp), lambda n: sp.exp(sp.factor(n.args[0])))
    return sp.factor_terms(sp.collect(e, list(e.atoms(sp.exp))))


def _roots(s: sp.Expr, p: sp.Symbol, edge: bool = False) -> list[sp.Expr] | None:
    """Real roots of ``s`` in p (None when not found exactly as a finite set).  ``edge`` (an end of the
    real domain, :func:`_domain_edges`): a zero set made of intervals gives its ends (``r/|r| − 1``,
    asin's argument at its end 1 for every r > 0: 0), where alone a continuous ``s`` can change sign."""
    if p not in s.free_symbols:
        return []
    try:
        sol = sp.solveset(s, p, sp.S.Reals)
    except (NotImplementedError, TypeError, ValueError):
        return None
    if sol is sp.S.Reals:  # identically zero: never switches
        return []
    if edge and isinstance(sol, (sp.Interval, sp.Union)) and isinstance(sol.boundary, sp.FiniteSet):
        return [r for r in sol.boundary if r.is_finite]
    if not isinstance(sol, sp.FiniteSet):
        try:
            found = sp.solve(s, p)
        except (NotImplementedError, TypeError, ValueError):
            return None
        return [r for r in found if r.is_real]
    return list(sol)


def _cell_set(cell, p: sp.Symbol) -> sp.Set | None:
    dom: sp.Set = sp.S.Reals
    for rel in cell:
        try:
            dom = dom.intersect(sp.solveset(rel, p, sp.S.Reals))
        except (NotImplementedError, TypeError, ValueError):
            return None
    return dom


def _inner_point(lo, hi) -> sp.Expr:
    if lo is sp.S.NegativeInfinity and hi is sp.S.Infinity:
        return sp.Integer(0)
    if lo is sp.S.NegativeInfinity:
        return sp.floor(hi) - 1
    if hi is sp.S.Infinity:
        return sp.ceiling(lo) + 1
    return (lo + hi) / 2


def _same(a: sp.Expr, b: sp.Expr) -> bool:
    return a == b or sp.expand(a - b) == 0


def _one_parameter(expr, p, cell, everywhere) -> Readable | None:
    cuts: set = set()
    try:
        switching = [v for s in _switching(expr) for v in _variants(s)]
        edges = [v for s in _domain_edges(expr) for v in _variants(s)]
    except ValueError:
        return None
    for s, edge in {**dict.fromkeys(switching + [r.lhs - r.rhs for r in cell], False), **dict.fromkeys(edges, True)}.items():
        roots = _roots(s, p, edge)
        if roots is None:
            return None
        cuts.update(r for r in roots if r.is_real)
    domain = sp.S.Reals if everywhere or not cell else _cell_set(cell, p)
    if domain is None:
        return None
    points = sorted(cuts, key=real_number)
    edges = [sp.S.NegativeInfinity, *points, sp.S.Infinity]
    cases: list[Case] = []
    excluded: list[sp.Set] = []
    for lo, hi in zip(edges, edges[1:]):
        x0 = _inner_point(lo, hi)
        if not domain.contains(x0) == sp.true:
            continue
        try:  # not real at x0 (a root of a negative number): nowhere between the two breakpoints
            piece = tidy(resolve(expr, {p: x0}))
            real_number(piece.subs(p, x0))
        except TypeError:
            excluded.append(sp.Interval.open(lo, hi))
            continue
        cases.append(Case(True, piece, sp.Interval.open(lo, hi)))
    # attach each breakpoint to a neighbour equal to the closed form there, merge equal neighbours
    merged: list[Case] = []
    for c in cases:
        if merged and _same(merged[-1].expr, c.expr) and merged[-1].interval.sup == c.interval.inf:
            b = c.interval.inf
            if domain.contains(b) == sp.true:
                merged[-1] = Case(True, merged[-1].expr, merged[-1].interval.union(c.interval))
                continue
        merged.append(c)
    final = list(merged)
    for b in points:
        if domain.contains(b) != sp.true or any(c.interval.contains(b) == sp.true for c in final):
            continue
        try:
            at_b = resolve(expr, {p: b}).subs(p, b)
            real_number(at_b)
        except TypeError:
            excluded.append(sp.FiniteSet(b))
            continue
        for i, c in enumerate(final):
            if (c.interval.sup == b or c.interval.inf == b) and _equal_at(c.expr.subs(p, b), at_b):
                final[i] = Case(True, c.expr, c.interval.union(sp.FiniteSet(b)))
                break
        else:
            final.append(Case(True, tidy(at_b), sp.FiniteSet(b)))
    final.sort(key=lambda c: real_number(c.interval.inf) if c.interval.inf.is_finite else -1e300)
    out = tuple(Case(c.interval.as_relational(p), c.expr, c.interval) for c in final)
    if not out:
        return None
    gaps = sp.Union(*excluded) if excluded else sp.S.EmptySet
    gaps = gaps.args if isinstance(gaps, sp.Union) else (gaps,) if excluded else ()
    return Readable(out, p, domain, True, excluded=tuple(gaps))


def _equal_at(a: sp.Expr, b: sp.Expr) -> bool:
    """Two values at a breakpoint are equal (a value that is not real there equals nothing)."""
    try:
        return real_number(a - b) == 0 and real_number(sp.simplify(a - b)) == 0
    except TypeError:
        return False


def readable(expr: sp.Expr, at: Mapping[sp.Symbol, sp.Expr] | None = None, *, cell=(),
             everywhere: bool = True, generic: bool = False) -> Readable | None:
    """``expr`` (a closed form in the parameters) in readable cases, or None when no exact case
    split was found.  ``at`` (parameter symbol → value) is the evaluation point; ``cell`` the
    relations that bound where ``expr`` holds (empty with ``everywhere``); ``generic``: it also
    needs the real roots seen at ``at`` (then only the case of ``at`` is given)."""
    free = sorted(expr.free_symbols, key=str)
    if not free:
        return Readable((Case(sp.true, tidy(expr)),), None, None, True)
    if len(free) == 1:
        r = _one_parameter(expr, free[0], tuple(cell), everywhere)
        if r is not None:
            return dataclasses.replace(r, near=generic)
    else:
        r = _several_parameters(expr, free, at, tuple(cell), everywhere)
        if r is not None:
            return dataclasses.replace(r, near=generic)
    if at is None or any(s not in at for s in free):
        return None
    return _local(expr, at, cell)


def _several_parameters(expr, free, at, cell, everywhere) -> Readable | None:
    """Cases over the cells of the arrangement of affine switching functions (module docstring)."""
    try:
        switching = [v for s in _switching(expr) for v in _variants(s)]
    except ValueError:
        return None
    switching += [r.lhs - r.rhs for r in cell]
    switching = [s for s in dict.fromkeys(switching) if s.free_symbols]
    params = sorted({p for s in switching for p in s.free_symbols}, key=str)
    planes = [arrangement.plane(s, params) for s in switching]
    if not params or any(pl is None for pl in planes):
        return None
    try:
        found = arrangement.cells(planes, len(params))
    except ArithmeticError:
        return None
    if found is None:
        return None
    fixed = {p: (at or {}).get(p, sp.Rational(1, 3)) for p in free if p not in params}
    pieces = []
    for c in found:
        point = {**fixed, **{p: sp.Rational(v.numerator, v.denominator) for p, v in zip(params, c.point)}}
        if not everywhere and not all(_decide(rel, point) for rel in cell):
            continue
        try:
            pieces.append((tidy(resolve(expr, point)), c))
        except TypeError:  # not real there: the closed form does not apply (left to the full form)
            return None
    if not pieces:
        return None
    continuous = not any(isinstance(n, (sp.Piecewise, sp.Heaviside, sp.sign))
                         for n in sp.preorder_traversal(expr))
    # the cell where the closed form holds (not everywhere): its relations hold in every case and
    # are stated once, by the caller's note, not in each case
    some = pieces[0][1].point
    given = tuple(dict.fromkeys((pl, 1 if pl.value(some) > 0 else -1)
                                for pl in (arrangement.plane(r.lhs - r.rhs, params) for r in cell)))
    within = [_isolated(pl, sgn, params, strict=True) for pl, sgn in given]
    try:
        joined = arrangement.merged(pieces, _same)
        cases = []
        for e, c in joined:
            rels = sorted((_isolated(pl, sgn, params, strict=not continuous)
                           for pl, sgn in arrangement.essential(c, len(params), given)),
                          key=lambda r: (params.index(r.lhs), r.func in (sp.Lt, sp.Le)))
            point = {p: sp.Rational(v.numerator, v.denominator) for p, v in zip(params, c.point)}
            cases.append(Case(sp.And(*rels, *within), e, None, point, tuple(rels)))
    except ArithmeticError:
        return None
    cases.sort(key=lambda c: [float(c.point[p]) for p in params])
    cases = _with_otherwise(cases, within)
    return Readable(tuple(cases), None, None, True, boundaries_open=not continuous)


def _with_otherwise(cases: list[Case], within=()) -> list[Case]:
    """The expression most cases share (the shortest among equals) stated once, last, as
    "otherwise" when it takes two cases or more."""
    groups: list[list[Case]] = []
    for c in cases:
        g = next((g for g in groups if _same(g[0].expr, c.expr)), None)
        if g is None:
            groups.append([c])
        else:
            g.append(c)
    big = max(groups, key=lambda g: (len(g), -len(sp.sstr(g[0].expr))))
    if len(big) < 2 or len(big) == len(cases):
        return cases
    rest = [c for c in cases if not any(c is b for b in big)]
    other = sp.And(*within, *[sp.Not(sp.And(*c.relations)) for c in rest])
    return [*rest, Case(other, big[0].expr, None, big[0].point, (), True)]


def _isolated(pl, sign: int, params, strict: bool):
    """``sign · plane > 0`` with its last parameter isolated (``b > a``, ``a <= -10``)."""
    k = max(i for i, c in enumerate(pl.coeffs) if c != 0)
    p, c = params[k], pl.coeffs[k]
    rest = (pl.expr(params) - c * p) / -c
    up = (sign > 0) == (c > 0)
    if strict:
        return sp.Gt(p, rest) if up else sp.Lt(p, rest)
    return sp.Ge(p, rest) if up else sp.Le(p, rest)


def _local(expr, at, cell) -> Readable | None:
    """The case containing the evaluation point: signs of the switching functions there, and of the
    functions whose roots bound where the closed form is real (:func:`_domain_edges`)."""
    conds = []
    edges = {resolve(s, at) for s in _domain_edges(expr)}
    for s in dict.fromkeys([resolve(s, at) for s in _switching(expr)] + list(edges)):
        if not s.free_symbols:
            continue
        v = real_number(s.subs(at))
        if v == 0 and s in edges:  # on an end of the real domain: the case's closure holds it
            continue
        if v == 0:
            return None
        rel = _solved(sp.Gt(s, 0) if v > 0 else sp.Lt(s, 0))
        if rel not in (sp.true,) and rel not in conds:
            conds.append(rel)
    conds += [r for r in cell if r not in conds]
    conds = _tightest(conds)
    piece = tidy(resolve(expr, at))
    if not conds and piece == expr:
        return None
    return Readable((Case(sp.And(*conds), piece),), None, None, not conds, rest=expr if conds else None)


def _solved(rel):
    """``s > 0`` with s linear in its one parameter as ``p > c`` / ``p < c``; else as it is."""
    s = rel.lhs - rel.rhs
    if len(s.free_symbols) != 1:
        return rel
    (p,) = s.free_symbols
    try:
        poly = sp.Poly(s, p)
    except sp.PolynomialError:
        return rel
    if poly.degree() != 1:
        return rel
    a, b = poly.all_coeffs()
    c = -b / a
    up = (rel.func in (sp.Gt, sp.Ge)) == bool(a > 0)
    strict = rel.func in (sp.Gt, sp.Lt)
    return (sp.Gt if strict else sp.Ge)(p, c) if up else (sp.Lt if strict else sp.Le)(p, c)


def _tightest(conds):
    """Drop a bound ``p > c`` implied by a tighter one on the same parameter."""
    out = []
    for r in conds:
        if isinstance(r.lhs, sp.Symbol) and r.rhs.is_number:
            same = [q for q in conds if q.lhs == r.lhs and q.rhs.is_number and q.func == r.func and q is not r]
            lower = r.func in (sp.Gt, sp.Ge)
            if any((real_number(q.rhs) > real_number(r.rhs)) if lower else (real_number(q.rhs) < real_number(r.rhs)) for q in same):
                continue
        out.append(r)
    return out


def _relations_text(c: Case, latex: bool) -> str:
    """``a <= -10 and -10 <= b <= 10``: two bounds of one parameter as a chain."""
    if c.otherwise:
        return "\\text{otherwise}" if latex else "otherwise"
    parts, rels = [], list(c.relations)
    while rels:
        r = rels.pop(0)
        up = next((q for q in rels if q.lhs == r.lhs and q.func in (sp.Lt, sp.Le)), None)
        if r.func in (sp.Gt, sp.Ge) and up is not None:
            rels.remove(up)
            op = {sp.Ge: "\\leq" if latex else "<=", sp.Gt: "<"}
            ops = {sp.Le: "\\leq" if latex else "<=", sp.Lt: "<"}
            parts.append(f"{_e(r.rhs, latex)} {op[r.func]} {_e(r.lhs, latex)} {ops[up.func]} {_e(up.rhs, latex)}")
        else:
            parts.append(_e(r, latex))
    return (" \\text{ and } " if latex else " and ").join(parts)


def _cond_text(c: Case, p, latex: bool) -> str:
    if c.relations or c.otherwise:
        return _relations_text(c, latex)
    if c.condition is sp.true:
        return "\\text{for all parameters}" if latex else "for all parameters"
    iv = c.interval
    if isinstance(iv, sp.Interval) and p is not None:
        lo, hi = iv.inf, iv.sup
        le = "\\leq" if latex else "<="
        ps = sp.latex(p) if latex else str(p)
        if lo is sp.S.NegativeInfinity and hi is sp.S.Infinity:
            return "\\text{for all } " + ps if latex else f"for all {ps}"
        if hi is sp.S.Infinity:
            ge = "\\geq" if latex else ">="
            return f"{ps} {'>' if iv.left_open else ge} {_e(lo, latex)}"
        left = "" if lo is sp.S.NegativeInfinity else f"{_e(lo, latex)} {le if not iv.left_open else '<'} "
        return f"{left}{ps} {le if not iv.right_open else '<'} {_e(hi, latex)}"
    if isinstance(iv, sp.FiniteSet) and p is not None:
        return (f"{sp.latex(p)} = " if latex else f"{p} = ") + ", ".join(_e(v, latex) for v in iv)
    if latex:
        return sp.latex(c.condition)
    parts = c.condition.args if isinstance(c.condition, sp.And) else (c.condition,)
    return " and ".join(_e(a, False) for a in parts)


def _e(e, latex):
    return sp.latex(e) if latex else sp.sstr(e).replace("**", "^")


def readable_text(r: Readable, latex: bool = False) -> str:
    """Text: one line per case (``theta <= -2 : 0``); LaTeX: a ``cases`` environment."""
    if len(r.cases) == 1 and r.cases[0].condition is sp.true and r.complete and not r.near:
        return _e(r.cases[0].expr, latex)
    rows = [(_e(c.expr, latex), _cond_text(c, r.parameter, latex)) for c in r.cases]
    if latex:
        body = " \\\\ ".join(f"{e} & {c}" for e, c in rows)
        if not r.complete:
            body += " \\\\ \\text{(other cases: see the full form)} & "
        return "\\begin{cases} " + body + " \\end{cases}"
    width = max(len(c) for _, c in rows)
    lines = [f"{c:<{width}} : {e}" for e, c in rows]
    for iv in r.excluded:
        lines.append(f"({_cond_text(Case(sp.false, sp.nan, iv), r.parameter, latex)}: the closed form is not real "
                     "there, it does not apply)")
    if r.boundaries_open:
        lines.append("(on the boundaries between the cases: the full form, `langur show --raw`)")
    if r.near:
        lines.append("(the engine's closed form is established near the evaluation point only)")
    if not r.complete:
        lines.append("(the case of the evaluation point; the other cases: `langur show --raw`)")
    return "\n".join(lines)
