"""Delta pieces: the change of variables ``u = Ψ̂(x)`` through Psi (LANGUAGE.md §4, paper §7.2).

    ∫ h(x) δ(π₀Ψ̂(x)) dx = Σ_branches ∫_{guards ≥ 0} h(Ψ̂_b⁻¹(0, u')) |det DΨ̂_b⁻¹(0, u')| du'

:func:`delta_to_regular` turns a :class:`DeltaPiece` into regular problems over ``u'`` (the other
inputs of Ψ̂⁻¹, plus the variables Ψ̂ does not mention), integrated by
:func:`langur.symbolic.regions.integrate_region`.  The box's conditions are added (substituted), so
``u'`` only needs an enclosure (:func:`u_box`).  A substituted condition that vanishes identically on
the zero set is ``0 ≥ 0``: TRUE, the paper's convention (:func:`vanishes_identically`).  In one
variable there is no ``u'`` and this is the sifting property ``Σ h(x*)/|Φ'(x*)|``.
"""

from __future__ import annotations

import itertools
import math
import random
from typing import Sequence

import mpmath
import sympy as sp

from langur.implicit import ImplicitRootFn
from langur.memo import remember
from langur.symbolic import walks
from langur.symbolic.context import Cond, Context, Deferred
from langur.symbolic.pieces import NOT_FINITE, DeltaPiece, Psi
from langur.symbolic.quadrature import printable
from langur.symbolic.quadrature.deltaproblems import cofactor_det
from langur.symbolic.rational import dual_derivative
from langur.symbolic.regions import _probe_point as probe_point
from langur.symbolic.text import lambdify, shared_lambdify


def _sample(ctx: Context, syms, ubox, n=5, seed=0):
    rng = random.Random(seed)
    bounds = [(ctx.value(lo).real, ctx.value(hi).real) for lo, hi in ubox]
    for _ in range(n):
        yield {s: sp.Float(rng.uniform(a, b), 30) for s, (a, b) in zip(syms, bounds)}


def u_box(psi: Psi, variables: Sequence, box: dict, ctx: Context):
    """Bounds for ``u'`` = (inputs[1:], variables Psi does not mention): an enclosure of the image
    of the box under ``forward[1:]`` (exact for variables and affine maps; interval arithmetic at
    the evaluation point otherwise)."""
    out = []
    for f in psi.forward[1:]:
        f = sp.sympify(f)
        if f in box:
            out.append(box[f])
            continue
        poly = None
        try:
            poly = sp.Poly(f, *psi.variables)
        except sp.PolynomialError:
            pass
        if poly is not None and poly.total_degree() <= 1:
            lo = hi = f.xreplace({x: 0 for x in psi.variables})
            for x in psi.variables:
                a = poly.coeff_monomial(x)
                if a == 0:
                    continue
                xl, xh = box[x]
                if ctx.sign(a) > 0:
                    lo, hi = lo + a * xl, hi + a * xh
                else:
                    lo, hi = lo + a * xh, hi + a * xl
            out.append((lo, hi))
            continue
        out.append(_enclosure(f, psi.variables, box, ctx))
    for x in variables:
        if x not in psi.variables:
            out.append(box[x])
    return out


def _enclosure(f, xs, box: dict, ctx: Context):
    """Numeric bounds of ``f`` over the box at ``at``: interval arithmetic (AccumBounds), else a
    padded sample (noted as heuristic)."""
    num = {k: sp.Float(float(v), 30) for k, v in ctx.at.items()}
    ranges = {x: [ctx.value(b).real for b in box[x]] for x in xs}
    try:
        ab = f.xreplace(num).subs({x: sp.AccumBounds(*[sp.Float(b, 30) for b in ranges[x]]) for x in xs})
    except Exception:  # noqa: BLE001 - AccumBounds does not support every function
        ab = None
    if isinstance(ab, sp.AccumBounds) and ab.min.is_finite and ab.max.is_finite:
        lo, hi = float(ab.min), float(ab.max)
        pad = 1e-9 * (1 + hi - lo)
        ctx.notes.append(f"u-box of {f} from interval arithmetic at the evaluation point")
    else:
        fn = lambdify(list(xs), printable(f.xreplace(num)), modules=["math"])
        grid = itertools.product(*[[a + (b - a) * i / 24 for i in range(25)] for a, b in ranges.values()])
        vals = []
        for pt in grid:
            try:
                vals.append(float(fn(*pt)))
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                pass
        if not vals:
            raise ValueError(f"cannot bound {f} over the box")
        lo, hi = min(vals), max(vals)
        pad = 0.25 * (1 + hi - lo)
        ctx.notes.append(f"u-box of {f} from a padded sample at the evaluation point (heuristic)")
    return sp.Rational(lo - pad), sp.Rational(hi + pad)


def vanishes_identically(expr, syms, ubox, ctx: Context) -> bool:
    """True when a substituted condition is identically 0 on the zero set (then ``0 ≥ 0``: TRUE,
    the paper's convention — it is what makes coincident conditions count twice)."""
    expr = sp.sympify(expr)
    if expr == 0:
        return True
    if expr.is_number:
        return False
    for pt in _sample(ctx, syms, ubox):
        z = ctx.value_with(expr, pt)
        if abs(z) > 1e-12:
            return False
    try:
        return ctx.deadline.run(lambda: sp.simplify(expr), cap=3.0) == 0
    except TimeoutError:
        return True  # numerically zero at random points


#: sympy's simplification of the Jacobians det DΨ̂⁻¹ on the zero set, by Jacobian.
_SIMPLIFIED: dict = {}


#: det DΨ̂⁻¹ on the zero set (u₀ = 0) by inverse branch: the same branches come back for every
#: partial derivative and check, and sympy's determinant simplifies its products as it goes.
_JACOBIANS: dict = {}


#: CPU seconds sympy's ``Matrix.det`` of DΨ̂⁻¹ may take (within the call's one budget, ``ctx.deadline``)
#: before the determinant is written by cofactor expansion instead (:func:`_jacobian`): the lambert
#: shader's conic took seconds per branch in it (bench/history/2026-11-29.md#budget33.
DET_SECONDS = 1.0


def _jacobian(comps: tuple, inputs: tuple, ctx: Context):
    """det DΨ̂⁻¹ at u₀ = 0 for the inverse branch ``comps`` (the variables in the ``inputs``):
    sympy's determinant (which cancels as it goes) within :data:`DET_SECONDS` of the call's budget,
    else the same determinant by cofactor expansion, nothing cancelled (equal as a function; not
    remembered, so a call with more time left gets sympy's form)."""
    J = _JACOBIANS.get((comps, inputs))
    if J is None:
        m = sp.Matrix(_jacobian_entries(comps, inputs))
        try:
            jac = ctx.deadline.run(m.det, cap=DET_SECONDS)
        except TimeoutError:
            ctx.notes.append(f"det DΨ̂⁻¹ written by cofactor expansion (sympy's determinant took over "
                             f"{DET_SECONDS:g} CPU s)")
            return cofactor_det(m).xreplace({inputs[0]: sp.Integer(0)})
        J = jac.xreplace({inputs[0]: sp.Integer(0)})
        remember(_JACOBIANS, (comps, inputs), J, 512)
    return J


def _simplified(J, ctx: Context):
    """sympy's ``simplify`` of the Jacobian ``J`` (remembered; ``J`` itself when it is a number,
    holds implicit roots, or its simplification runs out of time)."""
    if J in _SIMPLIFIED:  # Ψ̂'s Jacobian comes back for every partial derivative and check
        return _SIMPLIFIED[J]
    if not (J.is_number or J.has(ImplicitRootFn)):
        # (an implicit root's Jacobian 1/f'(x*) has nothing to simplify, and costs seconds to try)
        try:
            simple = ctx.deadline.run(lambda: sp.simplify(J), cap=3.0)
            remember(_SIMPLIFIED, J, simple, 512)
            return simple
        except TimeoutError:
            pass
    return J


def _constant_and_nonzero(comps: tuple, inputs: tuple, uprime) -> bool:
    """Whether det DΨ̂⁻¹ at u₀ = 0 (:func:`_jacobian`) is known, without differentiating, to be free
    of ``u'`` and not 0: no entry :func:`_jacobian_entries` differentiates can mention ``u'``
    (:func:`_derivative_symbols`; sympy's determinant and its simplification have no symbols the
    entries do not have), and the determinant of the entries' exact values at u₀ = 0 and one
    rational point (:func:`langur.symbolic.rational.dual_derivative`, along ``u``) is a non-zero
    rational (a function not 0 there: no form of it is the number 0).  False when that is not
    known (then the Jacobian is made at once)."""
    comps = [sp.sympify(e) for e in comps]
    wanted = _differentiated(comps, inputs)
    point = {s: sp.Integer(0) if s == inputs[0] else q
             for s, q in probe_point(set().union(*[walks.free_symbols(e) for e in comps])).items()}
    values = []
    for i, e in enumerate(comps):
        row = []
        for j, u in enumerate(inputs):
            if not wanted[i][j]:
                row.append(sp.Integer(0))
                continue
            if _derivative_symbols(e, u) & set(uprime):
                return False
            slope = dual_derivative(e, point, {u: 1})
            if slope is None:
                return False
            row.append(sp.Rational(slope.numerator, slope.denominator))
        values.append(row)
    return cofactor_det(sp.Matrix(values)) != 0


def _derivative_symbols(e, u) -> set:
    """Symbols that ``∂e/∂u`` may hold (a superset: those of ``e``'s subterms that the product, power
    and sum rules carry into it)."""
    if u not in walks.free_symbols(e):
        return set()
    if e == u:
        return set()
    if isinstance(e, sp.Add):
        return set().union(*[_derivative_symbols(a, u) for a in e.args])
    if isinstance(e, sp.Mul):
        out: set = set()
        for k, f in enumerate(e.args):
            if u in walks.free_symbols(f):
                out |= _derivative_symbols(f, u)
                out |= set().union(*[walks.free_symbols(g) for m, g in enumerate(e.args) if m != k])
        return out
    if isinstance(e, sp.Pow) and e.exp.is_number:
        return _derivative_symbols(e.base, u) | (walks.free_symbols(e.base) if e.exp != 1 else set())
    return set(walks.free_symbols(e))  # (∂e/∂u has no symbol e lacks)


def _differentiated(comps: list, inputs: tuple) -> list[list[bool]]:
    """Which entries of DΨ̂⁻¹ :func:`_jacobian_entries` differentiates (the others are written 0)."""
    free = [walks.free_symbols(sp.sympify(e)) for e in comps]
    n = len(comps)
    zero = [[u not in free[i] for u in inputs] for i in range(n)]
    skip = [[False] * n for _ in range(n)]
    if n == 2:
        for i, j in ((0, 0), (0, 1), (1, 0), (1, 1)):
            skip[i][j] = zero[1 - i][1 - j]
    return [[not (zero[i][j] or skip[i][j]) for j in range(n)] for i in range(n)]


def _jacobian_entries(comps: tuple, inputs: tuple) -> list[list]:
    """DΨ̂⁻¹ = (∂comps_i/∂inputs_j), 0 without differentiating where ``inputs_j`` is not in
    ``comps_i``.  In a 2×2, whose determinant is the formula ``a·d − b·c`` (sympy's for at most
    3×3), an entry whose partner in its product is such a 0 is not differentiated either and is
    written 0: the product is 0 all the same (for Ψ̂⁻¹ = (u₁, g(u₀, u₁)) only ∂g/∂u₀ is computed)."""
    wanted = _differentiated(list(comps), inputs)
    return [[sp.diff(e, u) if wanted[i][j] else sp.Integer(0) for j, u in enumerate(inputs)]
            for i, e in enumerate(comps)]


def infinite_on_zero_set(psi: Psi) -> str | None:
    """The first inverse branch component not finite on the zero set (``u₀ = 0``), as
    ``x = Ψ̂⁻¹ₓ``, or None.  There Ψ̂⁻¹(0, u') — the zero set the delta sits on (LANGUAGE.md §4) —
    does not exist: Ψ̂ is no diffeomorphism on the zero set (Def. 3.4), and δ(π₀Ψ̂) cannot be taken
    through it.  (The front end completes no condition so and refuses such a declared diffeo, T216:
    this is the engine's own check, for a core program built otherwise.)"""
    u0 = psi.inputs[0]
    for b in psi.branches:
        for x, c in b.inverse:
            if walks.has_any(sp.sympify(c).xreplace({u0: sp.Integer(0)}), NOT_FINITE):
                return f"{x} = {c}"
    return None


def delta_to_regular(piece: DeltaPiece, variables: Sequence, box: dict, ctx: Context, ubox):
    """The delta piece as regular problems over ``u'`` (:func:`u_prime`, box ``ubox`` from
    :func:`u_box`): ``[(conds, weight), …]``."""
    psi = piece.psi
    uprime = u_prime(psi, variables)
    u0 = psi.inputs[0]
    problems = []
    for b in psi.branches:
        inv = dict(b.inverse)
        comps = [inv[x] for x in psi.variables]
        sub = {u0: sp.Integer(0)}
        xsub = {x: inv[x].xreplace(sub) for x in psi.variables}
        key = (tuple(comps), tuple(psi.inputs))
        # a Jacobian free of u' and not 0 is only a factor of the weight: its entries, determinant
        # and simplification are left until the integration needs the weight (Deferred), and never
        # made when the region is empty at the evaluation point
        deferred = key not in _JACOBIANS and _constant_and_nonzero(*key, uprime)
        J = None if deferred else _simplified(_jacobian(*key, ctx), ctx)
        exprs = [sp.sympify(c.expr).xreplace(xsub) for c in piece.conditions]
        guards = [sp.sympify(g).xreplace(sub) for g in b.guards]
        if not all(ctx.decide(g) for g in guards if not (g.free_symbols - ctx.params)):
            continue  # the branch does not meet the zero set here (the cell records the guard)
        exprs += [g for g in guards if g.free_symbols - ctx.params]
        for x in variables:
            xl, xh = box[x]
            exprs += [xsub.get(x, x) - xl, xh - xsub.get(x, x)]
        conds = []
        strict = [c.strict for c in piece.conditions]  # guards and box conditions are non-strict
        empty = False
        for k, e in enumerate(exprs):
            if vanishes_identically(e, uprime, ubox, ctx):
                if k < len(strict) and strict[k]:
                    empty = True  # [0 > 0] is false: this branch of the piece is 0 on the zero set
                    break
                continue  # [0 ≥ 0] is true
            conds.append(Cond(e))
        if empty:
            continue
        weight = sp.sympify(piece.weight).xreplace(xsub)
        if deferred and weight != 0:
            problems.append((conds, Deferred(
                lambda weight=weight, key=key: weight * sp.Abs(_simplified(_jacobian(*key, ctx), ctx)))))
            continue
        if J is None:
            J = _simplified(_jacobian(*key, ctx), ctx)
        if not (J.free_symbols & set(uprime)):
            problems.append((conds, weight * sp.Abs(J)))
            continue
        signs = set()
        for z in _jacobian_values(J, uprime, ctx, list(_sample(ctx, uprime, ubox, n=16, seed=1))):
            if abs(z.imag) < 1e-12 and z.real != 0:
                signs.add(1 if z.real > 0 else -1)
        if len(signs) == 1:
            s = signs.pop()
            ctx.notes.append(f"sign of det DΨ̂⁻¹ = {J} taken as {'+' if s > 0 else '-'} "
                             "(sampled at the evaluation point; checked by quadrature)")
            problems.append((conds, weight * s * J))
        else:
            problems.append((conds + [Cond(J)], weight * J))
            problems.append((conds + [Cond(-J)], -weight * J))
    return problems


def _jacobian_values(J, uprime, ctx: Context, points) -> list:
    """det DΨ̂⁻¹ at the sample points, for :func:`delta_to_regular`'s decisions on them (whether
    a value is real, |imag| < 1e-12, and its sign): sympy's 30-digit ``evalf``, except
    * for a Jacobian holding implicit roots, compiled once and evaluated in doubles (each ``evalf``
      would solve every root to 30 digits, and only the sign is wanted);
    * for any other, compiled once into a 40-digit mpmath function of the same inputs (the doubles
      of the point and of the sample), whose value stands where those decisions are certain
      (:func:`_certain`): it and the 30-digit value differ by ~1e-28 of their size;
    a point where neither gives a value is evaluated by ``evalf``."""
    fn = mp = None
    params = ()
    if J.has(ImplicitRootFn):
        try:
            fn = lambdify(list(uprime), printable(J.xreplace({k: sp.Float(float(v), 30) for k, v in ctx.at.items()})),
                          modules=["math"])
        except Exception:  # noqa: BLE001 - then sympy's evalf, as for any other Jacobian
            fn = None
    else:
        free = walks.free_symbols(J)
        params = tuple(sorted((k for k in ctx.at if k in free), key=str))
        try:
            mp = shared_lambdify([*uprime, *params], J, "mpmath")
        except Exception:  # noqa: BLE001 - anything mpmath cannot print: sympy's evalf
            mp = None
    out = []
    for pt in points:
        z = None
        if fn is not None:
            try:
                z = complex(fn(*[float(pt[u]) for u in uprime]))
            except (ValueError, ZeroDivisionError, OverflowError, TypeError):
                z = None
        elif mp is not None:
            z = _certain(mp, [float(pt[u]) for u in uprime] + [float(ctx.at[k]) for k in params])
        if z is None or not (math.isfinite(z.real) and math.isfinite(z.imag)):
            z = ctx.value(J.xreplace(pt))
        out.append(z)
    return out


def _certain(fn, args: list) -> complex | None:
    """``fn`` (a compiled mpmath function) at ``args`` (doubles) with 40 digits, when the decisions
    :func:`delta_to_regular` takes on a Jacobian's value are certain from it — its size below
    1e10, and its imaginary part above 1e-10 (not real: the threshold is 1e-12), or below 1e-14
    with its real part farther than 1e-15 of its size from 0 (real, of that sign): then sympy's
    30-digit value of the same form at the same inputs, within ~1e-28 of its size, gives the
    same decisions.  None otherwise."""
    try:
        with mpmath.workdps(40):
            z = complex(fn(*[mpmath.mpf(a) for a in args]))
    except Exception:  # noqa: BLE001 - undefined there, or not a number: sympy's evalf decides
        return None
    if not (math.isfinite(z.real) and math.isfinite(z.imag)):
        return None
    size = max(1.0, abs(z))
    if size >= 1e10 or 1e-14 <= abs(z.imag) <= 1e-10 or abs(z.imag) < 1e-14 and abs(z.real) <= 1e-15 * size:
        return None
    return z


def u_prime(psi: Psi, variables: Sequence) -> list:
    """The coordinates of the zero set: ``inputs[1:]`` and the variables Psi does not mention."""
    return list(psi.inputs[1:]) + [x for x in variables if x not in psi.variables]
