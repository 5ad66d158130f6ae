"""exact14r (issue 15, raytrace ∂/∂t and disk ∂/∂r): work the closed form and the quadrature of a
delta piece no longer do when its answer does not need it.

* A delta piece whose Jacobian det DΨ̂⁻¹ is free of ``u'`` and not 0 gets a
  :class:`context.Deferred` weight: the determinant and sympy's simplification of it are made when
  an interval of the region needs the weight, and never for a region empty at the evaluation point
  (the ray tracer's pixel).  Decided without differentiating (``delta._constant_and_nonzero``:
  exact derivative values at a rational point by ``rational.dual_derivative``, the symbols a derivative can
  hold by ``delta._derivative_symbols``).  Values by hand: ∫_[0,1]² δ(x + 2y − a) = 1/4 at a = 1/2
  (|det DΨ̂⁻¹| = 1/2 along u₁ ∈ [0, 1/2]) and 0 at a = 5.
* The quadrature's weight ``h/|det DΨ̂|`` of a delta piece (``deltaproblems._Weight``) is compiled
  at its first call; its values are h/|det| computed here by hand.
* ``solving._away_from_zero``: a condition e + k·√A that stays away from 0 on the interval is not
  solved; checked against sympy's own candidates (the old path) on random instances.
* ``solving._nonreal_probe``: a sign probe's clearly non-real value from mpmath, non-real in the
  30-digit evaluation too.
"""

from __future__ import annotations

import random
from pathlib import Path

import mpmath
import sympy as sp

from langur.ddenote import ddenote_program
from langur.frontend import load
from langur.symbolic import context, delta, rational, regions, solving
from langur.symbolic.context import Cond, Context, Deferred
from langur.symbolic.pieces import Branch, DeltaPiece, Psi
from langur.symbolic.quadrature import deltaproblems
from langur.timebox import Deadline

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
x, y, a, r, b = sp.symbols("x y a r b", real=True)
u0, u1 = sp.symbols("u0 u1", real=True)


def _ctx(**at) -> Context:
    point = {sp.Symbol(k, real=True): sp.nsimplify(v) for k, v in at.items()}
    return Context(point, Deadline(20.0), frozenset(point))


def _line_piece(weight=1) -> DeltaPiece:
    """δ(x + 2y − a): Ψ̂ = (x + 2y − a, x), inverse x = u₁, y = (u₀ + a − u₁)/2."""
    psi = Psi((x, y), (x + 2 * y - a, x), (u0, u1), (Branch(((x, u1), (y, (u0 + a - u1) / 2))),), y)
    return DeltaPiece(psi, (), sp.sympify(weight))


def _integrate(piece: DeltaPiece, ctx: Context):
    box = {x: (sp.Integer(0), sp.Integer(1)), y: (sp.Integer(0), sp.Integer(1))}
    ubox = delta.u_box(piece.psi, (x, y), box, ctx)
    problems = delta.delta_to_regular(piece, (x, y), box, ctx, ubox)
    uvars = delta.u_prime(piece.psi, (x, y))
    total = sum((regions.integrate_region(c, w, uvars, dict(zip(uvars, ubox)), ctx) for c, w in problems),
                sp.Integer(0))
    return problems, total


def test_a_constant_jacobian_is_a_deferred_factor_with_the_hand_values():
    for at, want in ((sp.Rational(1, 2), sp.Rational(1, 4)), (sp.Integer(5), sp.Integer(0))):
        delta._JACOBIANS.clear()
        delta._SIMPLIFIED.clear()
        ctx = _ctx(a=at)
        problems, total = _integrate(_line_piece(), ctx)
        assert len(problems) == 1 and isinstance(problems[0][1], Deferred)
        assert sp.simplify(total.xreplace({a: at}) - want) == 0
        assert abs(ctx.value(total) - float(want)) < 1e-12
        # made, it is the weight the piece had before: h·|simplify(det DΨ̂⁻¹)| = 1/2
        assert problems[0][1].made() == sp.Rational(1, 2)


def _at_pixel(px, py):
    loaded = load(str(EXAMPLES / "raytrace" / "scene.lgr"))
    at = loaded.param_values()
    at.update(px=px, py=py)
    return loaded, at


def test_the_ray_tracers_empty_pixel_makes_no_jacobian():
    loaded = load(str(EXAMPLES / "raytrace" / "scene.lgr"))
    at = loaded.param_values()
    delta._JACOBIANS.clear()
    delta._SIMPLIFIED.clear()
    deltaproblems._FORWARD_DETS.clear()
    res = ddenote_program(loaded.program, at, {k: int(k == "t") for k in at})
    # 5 zero sets, each in two delta pieces: the 3 edges, the depth boundary and (since pole31) the depth
    # shader's pole n·d = 0 (the ray parallel to the triangle's plane), which moves with t: the shader is split
    # there into conditionals on its factors' signs (docs/language.md "Signs of factors"), so every jump is
    # taken on each side of the pole (2 × 5; before the split 4 pieces, the pole's jump missed)
    assert len(res.normal_form.deltas) == 10
    assert len({p.psi.forward[0] for p in res.normal_form.deltas}) == 5
    assert res.boundary.expr == 0 and res.value == 0.0
    # no determinant was made, forward or inverse, nor simplified: every region is empty here
    assert not delta._JACOBIANS and not delta._SIMPLIFIED and not deltaproblems._FORWARD_DETS
    # independently: the three edge lines and the pole's line miss the pixel [0, h]² (one sign at its four corners)
    point = {sp.Symbol(k, real=True): sp.nsimplify(v) for k, v in at.items()}
    h = point[sp.Symbol("h", real=True)]
    edges = {p.psi.forward[0] for p in res.normal_form.deltas if sp.Symbol("zth", real=True) not in p.psi.forward[0].free_symbols}
    assert len(edges) == 4
    for f in edges:
        assert len({sp.sign(f.xreplace(point).xreplace({x: cx, y: cy})) for cx in (0, h) for cy in (0, h)}) == 1


def test_a_deferred_jacobian_made_gives_the_eager_closed_form(monkeypatch):
    # the z-depth boundary crosses the pixel [0, 0.015] × [−0.06, −0.045]: its weight is made
    loaded, at = _at_pixel(0, -0.06)
    direction = {k: int(k == "t") for k in at}
    delta._JACOBIANS.clear()
    delta._SIMPLIFIED.clear()
    new = ddenote_program(loaded.program, at, direction)
    assert delta._JACOBIANS  # made, for the crossing piece
    delta._JACOBIANS.clear()
    delta._SIMPLIFIED.clear()
    monkeypatch.setattr(delta, "_constant_and_nonzero", lambda *args: False)  # the eager path, as before
    old = ddenote_program(loaded.program, at, direction)
    assert sp.srepr(new.expr) == sp.srepr(old.expr)
    assert new.value == old.value and new.value != 0.0
    assert new.notes == old.notes


def _random_rational(rng, syms, depth=3):
    if depth == 0 or rng.random() < 0.25:
        return rng.choice(list(syms) + [sp.Rational(rng.randint(-5, 5), rng.randint(1, 4))])
    p, q = _random_rational(rng, syms, depth - 1), _random_rational(rng, syms, depth - 1)
    op = rng.randrange(4)
    if op == 0:
        return p + q
    if op == 1:
        return p * q
    if op == 2:
        return p ** rng.randint(-2, 3)
    return p / (q ** 2 + 1)


def test_dual_is_the_exact_derivative_at_the_point():
    """The entries' values ``_constant_and_nonzero`` decides by: rational.dual_derivative along one
    input (and rational_value) against sympy's diff, substituted exactly."""
    rng = random.Random(14)
    syms = (u0, u1, a)
    point = {u0: sp.Integer(0), u1: sp.Rational(3, 7), a: sp.Rational(-5, 11)}
    checked = 0
    for _ in range(200):
        e = _random_rational(rng, syms)
        for u in syms:
            got = rational.dual_derivative(e, point, {u: 1})
            d = sp.diff(e, u)
            value = e.xreplace(point)
            want = d.xreplace(point)
            if got is None:
                # only at a pole (or 0 to a negative power) of the tree
                assert not (value.is_Rational and want.is_Rational) or any(
                    p.exp.is_negative and p.base.xreplace(point) == 0 for p in e.atoms(sp.Pow))
                continue
            v = rational.rational_value(e, point)
            assert sp.Rational(v.numerator, v.denominator) == value
            assert sp.Rational(got.numerator, got.denominator) == want
            checked += 1
    assert checked > 300
    assert rational.dual_derivative(sp.sqrt(u0 + 1), point, {u0: 1}) is None
    assert rational.dual_derivative(sp.sin(u1), point, {u1: 1}) is None
    assert rational.dual_derivative(1 / u0, point, {u0: 1}) is None  # a pole at u0 = 0


def test_derivative_symbols_hold_those_of_the_derivative():
    rng = random.Random(15)
    syms = (u0, u1, a, b)
    for _ in range(200):
        e = _random_rational(rng, syms)
        if rng.random() < 0.3:
            e = e + sp.sqrt(e ** 2 + b) * sp.exp(a * u0)
        for u in (u0, u1):
            assert delta._derivative_symbols(e, u) >= sp.diff(e, u).free_symbols
    # the ray tracer's shape: y = (u₁·A + B + C/(u₀ − z))/D has ∂y/∂u₀ free of u₁
    comp = (u1 * (a + 1) + b + a / (u0 - b)) / (a + 2)
    assert u1 not in delta._derivative_symbols(comp, u0)
    assert u1 not in sp.diff(comp, u0).free_symbols


def test_constant_and_nonzero():
    inputs = (u0, u1)
    # x = u₁, y = (u₀ + a − u₁)/2: det = −1/2
    assert delta._constant_and_nonzero((u1, (u0 + a - u1) / 2), inputs, [u1])
    # the disc's branch y = √(r − u₀ − u₁²): its Jacobian holds u₁ (and √)
    assert not delta._constant_and_nonzero((u1, sp.sqrt(r - u0 - u1 ** 2)), inputs, [u1])
    # det DΨ̂⁻¹ ≡ 0 (not a diffeomorphism): not known to be non-zero, so made at once
    assert not delta._constant_and_nonzero((u0 + u1, 2 * u0 + 2 * u1), inputs, [u1])
    # a Jacobian with u₁ in it
    assert not delta._constant_and_nonzero((u1, u0 * u1 + a), inputs, [u1])
    # sympy's det of the entries agrees on the first (−1/2)
    m = sp.Matrix(delta._jacobian_entries((u1, (u0 + a - u1) / 2), inputs))
    assert m.det() == sp.Rational(-1, 2)


def test_the_quadratures_weight_is_made_at_its_first_call_and_is_h_over_det():
    deltaproblems._FORWARD_DETS.clear()
    piece = _line_piece(weight=x + 1)
    at = {a: sp.Rational(1, 2)}
    ubox = [(sp.Integer(0), sp.Integer(1))]
    box = [(0, 1), (0, 1)]
    problems = deltaproblems.delta_problems(piece, (x, y), box, at, ubox)
    assert len(problems) == 1 and not deltaproblems._FORWARD_DETS  # nothing made yet
    for u in (0.1, 0.25, 0.4):
        # det DΨ̂ = det [[1, 2], [1, 0]] = −2; h = x + 1 at x = u₁
        assert abs(problems[0].weight(u) - (u + 1) / 2) < 1e-15
    assert deltaproblems._FORWARD_DETS[(piece.psi.forward, piece.psi.variables)] == -2
    value, error = deltaproblems.quad_delta_pieces([piece], (x, y), box, at, [ubox])
    # ∫_0^{1/2} (u + 1)/2 du = 1/16 + 1/4
    assert abs(value - 5 / 16) < 1e-9


def _old_candidates_inside(c, v, lo, hi, ctx):
    """What the old path found: sympy's untidied roots that pass the check, inside (lo, hi)."""
    try:
        rs = solving._roots(c, v, ctx, tidy=False)
    except context.Unsupported:
        return None
    return [rt for rt in rs if solving._inside(rt, lo, hi, ctx)]


def test_away_from_zero_on_the_disc_and_against_sympys_roots():
    ctx = _ctx(r=0.5)
    # the disc's case splits: √(r² − u₁²) + 1, 1 − √(r² − u₁²), √(4r² − 4x²)/2 − 1 on [−1, 1]
    for e, v in ((sp.sqrt(r ** 2 - u1 ** 2) + 1, u1), (1 - sp.sqrt(r ** 2 - u1 ** 2), u1),
                 (sp.sqrt(4 * r ** 2 - 4 * x ** 2) / 2 - 1, x), (1 - sp.sqrt(4 * r ** 2 - 4 * x ** 2) / 2, x)):
        assert solving._away_from_zero(Cond(e), v, -1.0, 1.0, ctx)
        assert _old_candidates_inside(Cond(e), v, -1.0, 1.0, ctx) == []
    # roots inside: not away from 0
    assert not solving._away_from_zero(Cond(sp.sqrt(4 * r ** 2 - 4 * x ** 2)), x, -1.0, 1.0, ctx)
    assert not solving._away_from_zero(Cond(sp.Rational(1, 4) - sp.sqrt(r ** 2 - x ** 2)), x, -1.0, 1.0, ctx)
    # not of the form: a cube root, two roots, x outside the root
    assert not solving._away_from_zero(Cond(sp.cbrt(r - x) + 1), x, -1.0, 1.0, ctx)
    assert not solving._away_from_zero(Cond(x + sp.sqrt(r - x)), x, -1.0, 1.0, ctx)
    rng = random.Random(16)
    seen = 0
    for _ in range(60):
        cs = [sp.Rational(rng.randint(-6, 6), rng.randint(1, 3)) for _ in range(5)]
        A = cs[0] * x ** 2 + cs[1] * x + cs[2] * r
        e = cs[3] + (cs[4] or 1) * sp.sqrt(A)
        lo, hi = sorted(rng.uniform(-3, 3) for _ in range(2))
        if not isinstance(e, sp.Add):
            continue
        if solving._away_from_zero(Cond(e), x, lo, hi, ctx):
            seen += 1
            assert _old_candidates_inside(Cond(e), x, lo, hi, ctx) in ([], None)
            # and no sign change at a fine grid of real values (30 digits, mpmath at r = 1/2)
            f = sp.lambdify(x, e.xreplace({r: sp.Rational(1, 2)}), "mpmath")
            with mpmath.workdps(30):
                vals = [f(mpmath.mpf(lo) + (mpmath.mpf(hi) - mpmath.mpf(lo)) * k / 200) for k in range(201)]
            assert min(abs(z) for z in vals) > 1e-6
    assert seen > 10


def test_the_disc_is_the_same_without_the_shortcuts(monkeypatch):
    loaded = load(str(EXAMPLES / "adapters" / "programs" / "disk.lgr"))
    at = loaded.param_values()
    new = ddenote_program(loaded.program, at, {"r": 1})
    assert abs(new.value - 3.141592653589793) < 1e-12  # 2πr at r = 1/2
    solving._SOLVED.clear()
    context._VALUES.clear()
    monkeypatch.setattr(regions, "_away_from_zero", lambda *args: False)
    monkeypatch.setattr(solving, "_nonreal_probe", lambda *args: None)
    old = ddenote_program(loaded.program, at, {"r": 1})
    assert sp.srepr(new.expr) == sp.srepr(old.expr) and new.value == old.value
    assert new.notes == old.notes


def test_nonreal_probe_agrees_with_the_30_digit_value():
    ctx = _ctx(r=0.5)
    e = 1 - sp.sqrt(r ** 2 - x ** 2)
    params = (r,)
    for m in (-0.9, -0.6, 0.55, 0.8, 0.99):
        z = solving._nonreal_probe(e, x, m, params, ctx)
        old = ctx.value(e.xreplace({x: sp.Float(m, 40)}))
        assert z is not None and abs(z.imag) > 1e-3 and abs(old.imag) > 1e-20
        assert abs(z - old) < 1e-14
    for m in (-0.4, 0.0, 0.3):  # real there: the 30-digit evaluation decides
        assert solving._nonreal_probe(e, x, m, params, ctx) is None
    assert solving._nonreal_probe(sp.log(x - r), x, 0.2, params, ctx) is not None  # log of a negative
    assert solving._nonreal_probe(1 / (x - r), x, 0.5, params, ctx) is None  # a pole
