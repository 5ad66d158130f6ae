"""Completing a smooth condition in one variable that has no closed-form inverse (issue 18).

A condition ``f(x; θ) ≥ 0`` over one variable ``x`` that sympy cannot invert in closed form
(``x^3 − x − a``: three roots; ``x^51 + x − a``, ``exp(x) + x − a``: monotone, no closed form) is
still the condition of a piecewise diffeomorphism on the variable's interval ``[lo, hi]``
(paper §4, §5.2): split ``[lo, hi]`` at the *turning points* of ``f`` (the zeros of ``∂f/∂x``
where it changes sign), ``f`` is strictly monotone on each piece, so ``f = u₀`` has at most one
root there.  Each piece ``[c_i, c_{i+1}]`` is one inverse branch of Ψ̂ = f:

    x = ImplicitRoot(f, x, u₀, c_i, c_{i+1})    where (u₀ − f(c_i)) · (f(c_{i+1}) − u₀) ≥ 0,

the guard saying that u₀ lies between the piece's end values (so the root exists).  The branches'
images partition ``[lo, hi]``, exactly like the two branches of a quadratic: the delta of the
condition is the sum over the roots ``Σ h(x*)/|f'(x*)|``, and no split point is a discontinuity
of the program (the split lives in Ψ̂⁻¹ only), so the split adds no delta.

The condition must be continuous on one interval of ``[lo, hi]`` (``sympy``'s
``continuous_domain``, completed by the primitive registry where sympy does not know a function,
``erf``: :mod:`langur.syntax.continuity`; the brackets are limited to it: ``sqrt(x)`` on ``[-1, 1]``
uses ``[0, 1]``).
Turning points are found exactly when ``∂f/∂x`` has no parameters and ``sympy.solveset`` solves it
on the interval (time-boxed); one that has no closed form (a root of a quintic) is itself an
implicit root of ``∂f/∂x`` in a rational bracket on which ``∂f/∂x`` changes sign (checked
exactly); where sympy cannot solve it, there are none when interval enclosures prove ``∂f/∂x`` of
one strict sign on the interval (:func:`langur.syntax.monotone.certify_derivative`:
``1/(erf(x) + 2)``).  Infinitely many, or more than :data:`MAX_PIECES` − 1, are refused.  When they move
with the parameters (``sin(a·x) − 0.5``: ``x = (π/2 + kπ)/a``; ``x^3 − a·x``) or sympy cannot
solve for them, their number depends on θ, which the front end does not know (``--at``): the
completion has :data:`MOVING_PIECES` branches whose ends are the k-th sign changes of ``∂f/∂x``
(indexed implicit roots, ``hi`` past the last one, each carrying ``∂²f/∂x²`` as its ``slope``),
found by the engines where they evaluate, each sign change *certified* (an interval enclosure of
``∂f/∂x`` or of ``∂²f/∂x²`` that excludes 0 on every cell: :mod:`langur.operational.signchanges`,
:func:`langur.enclosures.certified_brackets`); a point with more, or with a cell neither enclosure
certifies (a degenerate turning point), raises :class:`~langur.core.TooManyRoots` there (X316).

An end of the interval that moves with the parameters (``int ([0, a + 1]) …``) is the bracket's
end as a term: one branch for a condition with no turning point on the whole line; for one with
turning points (fixed or moving) and continuous on the line, the pieces' ends are the k-th
certified sign changes of ``∂f/∂x`` on the moving interval itself, as for moving turning points,
so turning points enter and leave the domain as the parameters move.

In several variables (:func:`split_along`), a condition monotone in no variable is split along
one, ``v``, at its turning points in ``v``: fixed ones, ones that move with the parameters, and
ones that move with the *other variables* (``x^3 - x*y + y^3 - a``: ∂/∂y = 3y² − x), whose pieces'
ends are then the k-th certified sign changes of ``∂f/∂v`` as functions of Ψ̂⁻¹'s other inputs,
found by the engines at every point of the zero set.  The number of pieces is, for a ``∂f/∂v``
polynomial in ``v``, the most sign changes it can have whatever its coefficients
(:func:`turning_bound`), else :data:`MOVING_PIECES`.

A root on a turning point (``f = ∂f/∂x = 0``: two roots merge) lies at the common end of two
branches: the linter reports it (X306/X305, :mod:`langur.lint.tangent`), and so it does a
critical point (``∇f = 0``) of a condition in several variables on its zero set.
"""

from __future__ import annotations

import math
from fractions import Fraction

import sympy as sp

from .. import failures
from ..core import (
    Add,
    Const,
    Diffeo,
    ImplicitRoot,
    InverseBranch,
    Mul,
    Term,
    Var,
    free_vars,
    neg,
    substitute,
)
from ..precise import NotReal, number, real_value, sign
from ..sympy_bridge import from_sympy
from ..timebox import run_with_timeout
from .continuity import continuous_domain
from .folding import refolded
from .monotone import Monotone, _enclose, certify, certify_derivative, rational

#: CPU-second limit of the search for turning points (CPU: the split must not change with the load).
TURNING_LIMIT = 4.0
#: More monotone pieces than this from exact turning points: found numerically instead.
MAX_PIECES = 32
#: Monotone pieces (inverse branches) of a condition whose turning points move with the parameters
#: (or have no closed form): at most MOVING_PIECES − 1 turning points on the domain where it is
#: evaluated (more: :class:`~langur.core.TooManyRoots`).
MOVING_PIECES = 8


def complete_by_pieces(cond: Term, e: sp.Expr, v: sp.Symbol, variables: tuple[str, ...], inputs: tuple[str, ...],
                       interval: tuple[float | Term, float | Term]) -> Diffeo | str:
    """The Diffeo of ``cond`` (sympy ``e``, over ``v`` and parameters only) with one implicit-root
    branch per monotone piece of ``[lo, hi]``, or the reason it cannot be built.  An end that
    depends on the parameters (a term) is the bracket's end as it is: then ``e`` must be monotone
    on the whole line (:func:`_monotone_on_the_line`), one branch."""
    lo, hi = interval
    if not (isinstance(lo, float | int) and isinstance(hi, float | int)):
        return _parametric(cond, e, v, variables, inputs, lo, hi)
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        return "its implicit inverse needs a bounded interval of the variable (give it a constant domain)"
    ends = _piece_ends(cond, e, sp.diff(e, v), v, lo, hi)
    if isinstance(ends, str):
        return ends
    return _by_roots(cond, v.name, variables, inputs, ends)


def _piece_ends(cond: Term, e: sp.Expr, d: sp.Expr, v: sp.Symbol, lo: float, hi: float) -> list[Term] | str:
    """The ends of the pieces of ``[lo, hi]`` on which ``e`` is strictly monotone in ``v`` (``d`` =
    ∂e/∂v, over ``v`` and parameters only): the interval where ``e`` is continuous cut at the
    turning points, exact or (moving, no closed form) the k-th certified sign changes of ``d``."""
    L, R = rational(lo), rational(hi)
    try:
        dom = run_with_timeout(lambda: continuous_domain(e, v, sp.Interval(L, R)), TURNING_LIMIT, cpu=True)
    except TimeoutError:
        return f"sympy could not find where it is continuous within {TURNING_LIMIT:g} CPU s"
    except Exception as err:  # noqa: BLE001 - sympy's own failures: refused with its reason
        return f"sympy could not find where it is continuous: {failures.why(err)}"
    if not (isinstance(dom, sp.Interval) and dom.start.is_number and dom.end.is_number and dom.start < dom.end):
        return f"it is continuous on {dom} only, not on one interval of the domain [{lo:g}, {hi:g}]"
    L, R = sp.nsimplify(dom.start, rational=True), sp.nsimplify(dom.end, rational=True)  # where it is defined
    ends = _exact_ends(d, v, L, R) if not (d.free_symbols - {v}) else None
    if isinstance(ends, str):
        return ends
    if ends is None:  # moving (or no closed form): the k-th sign change of ∂f/∂x, found where evaluated
        ends = _moving_ends(cond, d, v, from_sympy(L, (), ()), from_sympy(R, (), ()))
    return ends


def _moving_ends(cond: Term, d: sp.Expr, v: sp.Symbol, lo_t: Term, hi_t: Term,
                 inputs: dict[sp.Symbol, sp.Symbol] | None = None) -> list[Term] | str:
    """``lo_t``, the k-th sign changes of ``d`` = ∂f/∂x on ``[lo_t, hi_t]`` for k < the bound on
    their number (:func:`turning_bound`; indexed implicit roots, each ``hi_t`` where there are
    fewer, certified where evaluated), and ``hi_t``: the ends of the monotone pieces whatever the
    parameters (the interval's ends may be terms that move with them).  ``inputs``: the other
    variables ``d`` mentions (a condition split along ``v`` whose turning points move with them,
    ``x^3 − x·y``), each renamed to its input of Ψ̂⁻¹: the ends are then functions of those inputs."""
    x = v.name
    rename = inputs or {}
    d = d.xreplace(rename)
    names = sorted(s.name for s in d.free_symbols - {v} - set(rename.values()))
    variables = (x, *sorted(u.name for u in rename.values()))
    try:
        slope = from_sympy(d, variables, names)
    except ValueError as err:
        return f"∂/∂{x} = {d} is not a core term ({err})"
    try:  # ∂²f/∂x²: where its enclosure excludes 0, ∂f/∂x has at most one zero (certified count)
        bend = from_sympy(sp.diff(d, v), variables, names)
    except ValueError as err:
        return f"∂²/∂{x}² = {sp.diff(d, v)} is not a core term ({err})"
    cuts = turning_bound(d, v)
    return ([lo_t] + [ImplicitRoot(slope, x, Const(Fraction(0)), lo_t, hi_t, k, cuts, bend, span=cond.span)
                      for k in range(cuts)] + [hi_t])


def turning_bound(d: sp.Expr, v: sp.Symbol) -> int:
    """How many turning points (sign changes of ``d`` = ∂f/∂v in ``v``) the condition is split
    for when they move: for ``d`` a polynomial in ``v`` (any coefficients: parameters, other
    variables) with ``m`` monomials of degree at most ``n``, never more than ``min(n, 2m − 1)``
    whatever the coefficients' values (Descartes' rule of signs: at most ``m − 1`` positive and
    ``m − 1`` negative zeros, and 0), when that is at most :data:`MAX_PIECES` − 1, so such a
    condition is never refused for having too many (X316) and ``3x² − a`` costs 3 pieces, not 8;
    otherwise :data:`MOVING_PIECES` − 1 (``sin(a·x)``: unbounded as ``a`` grows; more at the
    values in force is X316)."""
    try:
        poly = sp.Poly(d, v)
    except sp.PolynomialError:
        return MOVING_PIECES - 1
    if any(v in c.free_symbols for c in poly.coeffs()) or poly.is_zero:
        return MOVING_PIECES - 1
    bound = min(poly.degree(), 2 * len(poly.monoms()) - 1)
    return bound if bound <= MAX_PIECES - 1 else MOVING_PIECES - 1


def complete_by_monotone(cond: Term, e: sp.Expr, v: sp.Symbol, variables: tuple[str, ...],
                         inputs: tuple[str, ...], bounds: dict[str, tuple[float, float]],
                         ends: dict | None = None) -> Diffeo | str:
    """The Diffeo of ``cond`` (sympy ``e``, over several variables) solved for ``v`` by one implicit
    root on ``v``'s interval, when ``e`` is proved strictly monotone in ``v`` on the box
    (:func:`langur.syntax.monotone.certify`); else the reason it cannot be built.

    Ψ̂ = (f, the other variables); Ψ̂⁻¹(u₀, u₁, …) has one branch: the other variables are their
    inputs, ``v = ImplicitRoot(f[other variables := u₁, …], v, u₀, lo, hi)``, guarded by
    ``(u₀ − f(v=lo)) · (f(v=hi) − u₀) ≥ 0`` (the root lies in the bracket).  ``ends``: the box
    with its parametric bounds as terms: a bracket may follow one (then monotone is proved on the
    whole line in ``v``)."""
    lo, hi = bounds.get(v.name, (-math.inf, math.inf))
    term_lo, term_hi = (ends or {}).get(v.name, (lo, hi))
    if not (isinstance(term_lo, float | int) and isinstance(term_hi, float | int)):
        box = {s: bounds.get(s.name, (-math.inf, math.inf)) for s in e.free_symbols if s.name in variables}
        proved = certify(e, v, box)  # v's own interval: the whole line (its bound moves)
        if isinstance(proved, str):
            return proved
        return _by_roots(cond, v.name, variables, inputs, [_end(term_lo), _end(term_hi)])
    if not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        return "its implicit inverse needs a bounded interval of the variable (give it a constant domain)"
    box = {s: bounds.get(s.name, (-math.inf, math.inf)) for s in e.free_symbols if s.name in variables}
    proved = certify(e, v, box)
    if isinstance(proved, str):
        return proved
    ends = [from_sympy(rational(lo), (), ()), from_sympy(rational(hi), (), ())]
    return _by_roots(cond, v.name, variables, inputs, ends)


def split_along(cond: Term, e: sp.Expr, v: sp.Symbol, variables: tuple[str, ...], inputs: tuple[str, ...],
                bounds: dict[str, tuple[float, float]], moving: bool = False) -> Diffeo | str | None:
    """For a condition monotone in no variable on the box (tried first): split ``v``'s interval at
    the turning points of ``e`` in ``v`` (the sign changes of ``∂e/∂v``), so that ``e`` is strictly
    monotone in ``v`` on each piece: one implicit-root branch per piece (None: ``moving`` is not
    asked for and the turning points move, or ``v``'s interval is not constant; a string: why the
    split failed).

    * ``∂e/∂v`` depends on ``v`` alone (``x^3 - x + y^3 - y``): the turning points are fixed, the
      same for every value of the other variables: exact where sympy solves ``∂e/∂v = 0``.
    * ``moving``: ``∂e/∂v`` also depends on the parameters (``x^3 - a*x + y^3 - a*y``) or on the
      other variables (``x^3 - x*y + y^3 - a``: the turning points ``x = ±√(y/3)`` move with
      ``y``): the pieces' ends are the k-th certified sign changes of ``∂e/∂v`` on ``v``'s
      interval (as in one variable), functions of the parameters and of Ψ̂⁻¹'s other inputs (the
      other variables' values), evaluated by the engines at each point of the zero set.  The
      split lives in Ψ̂⁻¹ only (which root is which branch), so it adds no delta.

    The caller tries fixed turning points in every variable first."""
    lo, hi = bounds.get(v.name, (-math.inf, math.inf))
    d = sp.diff(e, v)
    others = {s.name for s in d.free_symbols - {v}}
    if (others and not moving) or not (math.isfinite(lo) and math.isfinite(hi)) or lo >= hi:
        return None  # turning points that move (with parameters or other variables): when asked
    if not others & set(variables):
        ends = _piece_ends(cond, e, d, v, lo, hi)
    else:
        why = _continuous_on_box(e, d, v, variables, bounds)
        if why is not None:
            return f"at the turning points of ∂/∂{v} = {d}, which move with the other variables: {why}"
        rest = [y for y in variables if y != v.name]
        rename = {sp.Symbol(y, real=True): sp.Symbol(u, real=True) for y, u in zip(rest, inputs[1:])
                  if y in others}
        L, R = (from_sympy(rational(b), (), ()) for b in (lo, hi))
        ends = _moving_ends(cond, d, v, L, R, rename)
    if isinstance(ends, str):
        return f"at the turning points of ∂/∂{v} = {d}: {ends}"
    return _by_roots(cond, v.name, variables, inputs, ends)


def _continuous_on_box(e: sp.Expr, d: sp.Expr, v: sp.Symbol, variables: tuple[str, ...],
                       bounds: dict[str, tuple[float, float]]) -> str | None:
    """None when ``e`` is continuous in ``v`` on ``v``'s interval whatever the other variables and
    parameters (sympy's ``continuous_domain`` is that whole interval), or when ``∂e/∂v`` (free of
    parameters) has a finite interval enclosure on the box (then ``e`` is smooth there); else why
    not (a pole or a branch point where the pieces' roots would be bisected across a jump)."""
    lo, hi = bounds[v.name]
    L, R = rational(lo), rational(hi)
    try:
        dom = run_with_timeout(lambda: continuous_domain(e, v, sp.Interval(L, R)), TURNING_LIMIT, cpu=True)
        if dom == sp.Interval(L, R):
            return None
    except Exception:  # noqa: BLE001 - sympy's own failures (multivariate sets): the enclosure decides
        dom = None
    names = {s.name for s in d.free_symbols}
    if names <= set(variables) and all(n in bounds and all(map(math.isfinite, bounds[n])) for n in names):
        box = {s: (rational(bounds[s.name][0]), rational(bounds[s.name][1])) for s in d.free_symbols}
        r = _enclose(d, box)
        if r is not None and all(x.is_finite for x in r):
            return None
    where = f"it is continuous in {v} on {dom} only" if dom is not None else f"sympy cannot tell where it is continuous in {v}"
    return f"{where}, not on its whole interval [{lo:g}, {hi:g}] for every value of the others"


def _end(end: float | Term | None) -> Term | None:
    """A bracket end as a core term (None: unbounded)."""
    if isinstance(end, float | int):
        return from_sympy(rational(float(end)), (), ()) if math.isfinite(end) else None
    return end


def _parametric(cond: Term, e: sp.Expr, v: sp.Symbol, variables, inputs, lo, hi) -> Diffeo | str:
    """The implicit-root branches on ``[lo, hi]``, an end of which moves with the parameters: one
    branch when ``e`` is monotone on the whole line; else (turning points, fixed or moving) one
    per piece between the k-th certified sign changes of ``∂e/∂v`` on the moving interval itself
    (:func:`_moving_ends`: no piece needs clamping to it), when ``e`` is continuous on the line."""
    a, b = _end(lo), _end(hi)
    if a is None or b is None:
        return "its implicit inverse needs a bounded interval of the variable (give it a domain)"
    why = _monotone_on_the_line(e, v)
    if why is None:
        return _by_roots(cond, v.name, variables, inputs, [a, b])
    try:
        dom = run_with_timeout(lambda: continuous_domain(e, v, sp.S.Reals), TURNING_LIMIT, cpu=True)
    except TimeoutError:
        dom = f"an unknown set (sympy did not decide within {TURNING_LIMIT:g} CPU s)"
    except Exception as err:  # noqa: BLE001 - sympy's own failures: refused with its reason
        dom = f"an unknown set ({failures.why(err)})"
    if dom != sp.S.Reals:
        return f"{why}; it is continuous on {dom}, and with a domain bound that moves with the parameters a " \
               "condition with turning points must be continuous on the whole line (give the variable a " \
               "constant domain)"
    ends = _moving_ends(cond, sp.diff(e, v), v, a, b)
    if isinstance(ends, str):
        return ends
    return _by_roots(cond, v.name, variables, inputs, ends)


def _monotone_on_the_line(e: sp.Expr, v: sp.Symbol) -> str | None:
    """None when ``e`` is continuous on ℝ and ``∂e/∂v`` (free of parameters) keeps its sign on ℝ
    (zeros where it does not change sign allowed: ``x³``); else the reason."""
    d = sp.diff(e, v)
    if d.free_symbols - {v}:
        return f"∂/∂{v} = {d} depends on the parameters"
    try:
        dom = run_with_timeout(lambda: continuous_domain(e, v, sp.S.Reals), TURNING_LIMIT, cpu=True)
        zeros = run_with_timeout(lambda: sp.solveset(d, v, sp.S.Reals), TURNING_LIMIT, cpu=True)
    except TimeoutError:
        return f"sympy could not decide within {TURNING_LIMIT:g} CPU s where ∂/∂{v} = {d} vanishes"
    except Exception as err:  # noqa: BLE001 - sympy's own failures: refused with its reason
        return f"sympy could not decide where ∂/∂{v} = {d} vanishes: {failures.why(err)}"
    if dom != sp.S.Reals:
        return f"it is continuous on {dom} only"
    if zeros is sp.S.EmptySet:
        points = []
    elif isinstance(zeros, sp.FiniteSet) and all(z.is_real for z in zeros) and len(zeros) < MAX_PIECES:
        points = sorted(zeros, key=lambda z: float(z))
    else:
        return f"the zeros of ∂/∂{v} = {d} on the line are {zeros}"
    probes = ([points[0] - 1] + [(p + q) / 2 for p, q in zip(points, points[1:])] + [points[-1] + 1]
              if points else [sp.Integer(0)])
    signs = {sign(d.subs(v, p)) > 0 for p in probes}
    if len(signs) > 1:
        return f"it has turning points (∂/∂{v} = {d} changes sign at {', '.join(map(str, points))})"
    return None


def _by_roots(cond: Term, x: str, variables: tuple[str, ...], inputs: tuple[str, ...], ends: list[Term]) -> Diffeo:
    """Ψ̂ = (cond, the other variables) with one implicit-root branch of ``x`` per piece between
    consecutive ``ends``; the other variables are Ψ̂⁻¹'s inputs u₁, … (also in the root's equation)."""
    u0 = Var(inputs[0])
    others = [y for y in variables if y != x]
    by_other = {y: Var(u) for y, u in zip(others, inputs[1:])}
    equation = substitute(cond, by_other) if any(y in free_vars(cond) for y in others) else cond
    branches = []
    for a, b in zip(ends, ends[1:]):
        root = ImplicitRoot(equation, x, u0, a, b)
        fa, fb = refolded(substitute(equation, {x: a})), refolded(substitute(equation, {x: b}))  # (the end's 1s)
        guard = Mul(Add(u0, neg(fa)), Add(fb, neg(u0)))  # u0 between f(a) and f(b)
        branches.append(InverseBranch(tuple(root if y == x else by_other[y] for y in variables), (guard,)))
    return Diffeo(variables=variables, forward=(cond,) + tuple(Var(y) for y in others), inputs=inputs,
                  branches=tuple(branches), solved_for=x, name=None)


def _exact_ends(d, v, L, R) -> list[Term] | str | None:
    """The ends of the monotone pieces from the exact zeros of ``d`` = ∂f/∂x (no parameters) on
    ``[L, R]``; None when sympy cannot solve ``d = 0`` (then they are found numerically where the
    condition is evaluated); a reason when there are too many or infinitely many."""
    try:
        zeros = run_with_timeout(lambda: sp.solveset(d, v, sp.Interval(L, R)), TURNING_LIMIT, cpu=True)
    except (TimeoutError, ValueError):  # (ValueError: mpmath's erfinv asked outside [-1, 1] inside solveset)
        zeros = None
    if zeros is None or isinstance(zeros, sp.ConditionSet):  # sympy cannot solve ∂f/∂x = 0: …
        if not isinstance(certify_derivative(d, v, {v: (L, R)}), Monotone):
            return None  # … the turning points are found numerically where evaluated
        zeros = sp.S.EmptySet  # … but ∂f/∂x is proved of one strict sign on [L, R] (1/(erf(x) + 2)): none
    if zeros is sp.S.EmptySet:
        points = []
    elif isinstance(zeros, sp.FiniteSet) and all(z.is_real or not math.isnan(real_value(z)) for z in zeros):  # erfinv(π/6)/2
        if len(zeros) >= MAX_PIECES:
            return f"it has {len(zeros)} turning points (zeros of ∂/∂{v} = {d}) on the domain, more than {MAX_PIECES - 1}"
        points = sorted(zeros, key=lambda z: float(z))
    else:
        return f"it has infinitely many turning points (zeros of ∂/∂{v} = {d}) on the domain: {zeros}"
    cuts = _sign_changes(d, v, [L] + [z for z in points if L < z < R] + [R])
    if isinstance(cuts, str):
        return cuts
    try:
        return [_point(c, d, v, v.name) for c in cuts]
    except ValueError as err:
        return str(err)


def _sign_changes(d, v, cuts):
    """The cuts where ``∂f/∂x`` changes sign (the ends always kept): a zero where it keeps its
    sign (``x^3`` at 0) is no turning point; a piece where it vanishes identically is refused."""
    keep = [cuts[0]]
    signs = []
    for a, b in zip(cuts, cuts[1:]):
        try:
            mid = sign(d.subs(v, (a + b) / 2))
        except NotReal:
            mid = 0
        if mid == 0:
            return f"∂/∂{v} = {d} vanishes or is undefined between {a} and {b}"
        signs.append(mid)
    for k, c in enumerate(cuts[1:-1]):
        if signs[k] != signs[k + 1]:
            keep.append(c)
    keep.append(cuts[-1])
    return keep


def _point(c: sp.Expr, d: sp.Expr, v: sp.Symbol, x: str) -> Term:
    """A turning point (or an end) as a core term: its closed form, else the root of ``∂f/∂x``
    in a rational bracket on which ``∂f/∂x`` changes sign (checked exactly)."""
    try:
        return from_sympy(c, (), ())
    except ValueError:
        pass
    value = number(c)
    for digits in (6, 9, 12):  # decimals around the value: the first bracket with a sign change
        scale = 10**digits
        a = sp.Rational(sp.floor(value * scale) - 1, scale)
        b = sp.Rational(sp.ceiling(value * scale) + 1, scale)
        da, db = d.subs(v, a), d.subs(v, b)
        if da.is_real and db.is_real and (da > 0) != (db > 0) and da != 0 and db != 0:
            term_a, term_b = (from_sympy(w, (), ()) for w in (a, b))
            return ImplicitRoot(from_sympy(d, (x,), ()), x, Const(Fraction(0)), term_a, term_b)
    raise ValueError(f"cannot bracket the turning point {c}")
