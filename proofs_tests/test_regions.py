"""Regions from conditions (langur.symbolic.regions), the change of variables of delta pieces
(langur.symbolic.delta) and the time limits (timebox).

Expected values are derived by hand in the comments.
"""

import threading
import time

import pytest
import sympy as sp

from langur.symbolic import antiderivatives, delta, regions, solving
from langur.symbolic.context import Cond, Context, Unsupported
from langur.symbolic.pieces import Branch, DeltaPiece, Psi
from langur.timebox import Deadline, run_with_timeout

x, y = sp.symbols("x y", real=True)
theta, a, s, r, k = sp.symbols("theta a s r k", real=True)
u0, u1 = sp.symbols("u0 u1", real=True)


def ctx(**at):
    vals = {sp.Symbol(n, real=True): sp.nsimplify(v) for n, v in at.items()}
    return Context(vals, Deadline(20.0), frozenset(vals))


# ---------------------------------------------------------------------------------------------
# Solving one condition for one variable.


def test_linear_condition_directions():
    c = ctx(theta=0.5)
    # θ − x ≥ 0  ⟺  x ≤ θ (slope −1 < 0): an upper bound
    (alt,) = solving.alternatives(Cond(theta - x), x, [], c)
    assert alt.uppers == [theta] and alt.lowers == [] and c.cell == []
    # 2x − θ ≥ 0  ⟺  x ≥ θ/2
    (alt,) = solving.alternatives(Cond(2 * x - theta), x, [], c)
    assert alt.lowers == [theta / 2]


def test_parametric_slope_is_decided_at_the_point():
    # a·x − 1 ≥ 0 at a = −2: slope negative, x ≤ 1/a; the cell records a < 0 (as −a > 0)
    c = ctx(a=-2)
    (alt,) = solving.alternatives(Cond(a * x - 1), x, [], c)
    assert alt.uppers == [1 / a]
    assert c.cell == [sp.StrictGreaterThan(-a, 0)]


def test_slope_depending_on_an_outer_variable_is_a_case_split():
    # x·y − 1 ≥ 0 in y: y ≥ 1/x where x > 0, y ≤ 1/x where x < 0
    alts = solving.alternatives(Cond(x * y - 1), y, [x], ctx())
    assert [(alt.extra[0].expr, alt.lowers, alt.uppers) for alt in alts] == [
        (x, [1 / x], []), (-x, [], [1 / x])]


def test_quadratic_condition():
    # a − x² ≥ 0: between the roots ±√a, where the discriminant 4a ≥ 0
    (alt,) = solving.alternatives(Cond(a - x**2), x, [], ctx(a=0.25))
    assert alt.extra[0].expr == 4 * a
    assert alt.lowers == [-sp.sqrt(a)] and alt.uppers == [sp.sqrt(a)]
    # x² − a ≥ 0: everywhere when 4a < 0, else outside [−√a, √a]
    alts = solving.alternatives(Cond(x**2 - a), x, [], ctx(a=0.25))
    assert [(alt.lowers, alt.uppers) for alt in alts] == [([], []), ([], [-sp.sqrt(a)]), ([sp.sqrt(a)], [])]


def test_condition_solved_through_its_psi():
    # exp(x) − θ ≥ 0 with Psi solved for x: x = log(u0 + θ) (∂x/∂u0 > 0): x ≥ log θ
    psi = Psi((x,), (sp.exp(x) - theta,), (u0,), (Branch(((x, sp.log(u0 + theta)),)),), x)
    (alt,) = solving.alternatives(Cond(sp.exp(x) - theta, psi=psi), x, [], ctx(theta=2))
    assert alt.lowers == [sp.log(theta)]


def test_unsolvable_condition_is_unsupported():
    with pytest.raises(Unsupported):
        solving.alternatives(Cond(sp.sin(x * y) - x), y, [x], ctx())


# ---------------------------------------------------------------------------------------------
# Whole regions.


def test_half_line_closed_form_valid_for_all_theta():
    # ∫₀¹ [θ − x ≥ 0]·x dx = Min(Max(θ,0),1)²/2
    c = ctx(theta=0.5)
    e = regions.integrate_region([Cond(theta - x)], x, [x], {x: (0, 1)}, c)
    for q in [sp.Rational(n, 5) for n in range(-5, 11)]:
        assert e.subs(theta, q) == sp.Min(sp.Max(q, 0), 1) ** 2 / 2
    assert c.cell == []


def test_triangle_valid_for_all_s():
    # area of {x, y ∈ [0,1], x + y ≤ s}: 0 (s ≤ 0), s²/2 (0..1), 1 − (2 − s)²/2 (1..2), 1 (s ≥ 2)
    c = ctx(s=0.5)
    e = regions.integrate_region([Cond(s - x - y)], sp.Integer(1), [x, y], {x: (0, 1), y: (0, 1)}, c)

    def hand(q):
        if q <= 0:
            return 0
        if q <= 1:
            return q**2 / 2
        if q <= 2:
            return 1 - (2 - q) ** 2 / 2
        return 1

    for q in [sp.Rational(n, 4) for n in range(-4, 13)]:
        assert e.subs(s, q) == hand(q)


def test_generic_roots_ordered_at_the_point():
    # [exp(x) − θ ≥ 0] on [0, 2], no Psi: x ≥ log θ; length 2 − log θ for 1 < θ < e²; the cell
    # fixes the order 0 < log θ < 2
    c = ctx(theta=2)
    e = regions.integrate_region([Cond(sp.exp(x) - theta)], sp.Integer(1), [x], {x: (0, 2)}, c)
    assert sp.simplify(e - (2 - sp.log(theta))) == 0
    assert c.generic
    assert sp.StrictGreaterThan(sp.log(theta), 0) in c.cell


def test_parameter_only_condition_stays_exact():
    # [θ ≥ 0]·∫₀¹ 1 = Piecewise: 1 for θ ≥ 0, else 0 — for every θ, not just at the point
    e = regions.integrate_region([Cond(theta)], sp.Integer(1), [x], {x: (0, 1)}, ctx(theta=1))
    assert e.subs(theta, 3) == 1 and e.subs(theta, -3) == 0


def test_antiderivative_rejects_non_elementary_and_non_smooth():
    with pytest.raises(Unsupported):
        antiderivatives.antiderivative(sp.exp(x**3), x, ctx())
    with pytest.raises(Unsupported):
        antiderivatives.antiderivative(sp.Abs(sp.sin(x)), x, ctx())
    # |x| of an affine x is sign(x)·x (elementary.sign_split): the antiderivative x·|x|/2, continuous
    # across 0, so ∫_{-1}^{1} |x| dx = F(1) − F(−1) = 1 and ∫_{-1}^{1/2} = 1/2 + 1/8
    F = antiderivatives.antiderivative(sp.Abs(x), x, ctx())
    assert F.subs(x, 1) - F.subs(x, -1) == 1
    assert F.subs(x, sp.Rational(1, 2)) - F.subs(x, -1) == sp.Rational(5, 8)
    # shifted Gaussian by completing the square: d/dx F = w
    w = sp.exp(-(x - theta) ** 2 / 50) * sp.exp(-(x - 2) ** 2 / 50)
    F = antiderivatives.antiderivative(w, x, ctx(theta=1))
    assert F.has(sp.erf)
    assert sp.N((sp.diff(F, x) - w).subs({x: 0.3, theta: 1.7})) == pytest.approx(0, abs=1e-14)


# ---------------------------------------------------------------------------------------------
# Delta pieces: the zero set's coordinates.


def test_u_box_affine_and_nonlinear():
    box = {x: (0, 1), y: (0, 1)}
    # x + 2y over [0,1]²: [0, 3]
    psi = Psi((x, y), (k - 2 * x + y, x + 2 * y), (u0, u1), (), None)
    assert delta.u_box(psi, (x, y), box, ctx(k=0.5)) == [(0, 3)]
    # x + y² over [0,1]²: [0, 2] (interval arithmetic, padded by ~1e-9)
    psi = Psi((x, y), (y - x, x + y**2), (u0, u1), (), None)
    ((lo, hi),) = delta.u_box(psi, (x, y), box, ctx())
    assert -1e-8 < lo <= 0 and 2 <= hi < 2 + 1e-8


def test_vanishing_condition_is_true_on_its_zero_set():
    c = ctx(a=0.5)
    assert delta.vanishes_identically(sp.sqrt(a) ** 2 - a, [], [], c) is True
    assert delta.vanishes_identically(sp.sin(u1) ** 2 + sp.cos(u1) ** 2 - 1, [u1], [(0, 1)], c)
    assert not delta.vanishes_identically(u1 - a, [u1], [(0, 1)], c)


def test_delta_to_regular_disk_jacobian():
    # y = ±√(r − u0 − u1²), x = u1: |det DΨ̂⁻¹(0, u1)| = 1/(2√(r − u1²)); at r = 1/4, u1 = 0: 1
    root = sp.sqrt(r - u0 - u1**2)
    psi = Psi((x, y), (r - x**2 - y**2, x), (u0, u1),
              (Branch(((y, root), (x, u1)), (r - u0 - u1**2,)), Branch(((y, -root), (x, u1)), (r - u0 - u1**2,))),
              y)
    c = ctx(r=0.25)
    box = {x: (-1, 1), y: (-1, 1)}
    ubox = delta.u_box(psi, (x, y), box, c)
    assert ubox == [(-1, 1)]
    problems = delta.delta_to_regular(DeltaPiece(psi, (), sp.Integer(1)), (x, y), box, c, ubox)
    assert len(problems) == 2
    for conds, weight in problems:
        assert weight.subs({u1: 0, r: sp.Rational(1, 4)}) == 1
        # the guard r − u1² ≥ 0 is among the conditions
        assert any(sp.expand(cd.expr - (r - u1**2)) == 0 for cd in conds)


# ---------------------------------------------------------------------------------------------
# Time limits.


def test_timeout_interrupts_and_returns():
    assert run_with_timeout(lambda: 42, 1.0) == 42
    start = time.monotonic()
    with pytest.raises(TimeoutError):
        run_with_timeout(lambda: time.sleep(5), 0.2)
    assert time.monotonic() - start < 2


def test_nested_timeouts_never_extend_the_outer_one():
    start = time.monotonic()
    with pytest.raises(TimeoutError):
        run_with_timeout(lambda: run_with_timeout(lambda: time.sleep(5), 10.0), 0.3)
    assert time.monotonic() - start < 2
    # an inner limit that expires is reported by the inner call; the outer call goes on
    def outer():
        with pytest.raises(TimeoutError):
            run_with_timeout(lambda: time.sleep(5), 0.1)
        return "outer done"
    assert run_with_timeout(outer, 5.0) == "outer done"


def test_timeout_off_the_main_thread_checks_elapsed_time():
    out = {}

    def work():
        try:
            run_with_timeout(lambda: time.sleep(0.3), 0.05)
        except TimeoutError:
            out["raised"] = True
        out["value"] = run_with_timeout(lambda: 7, 1.0)

    th = threading.Thread(target=work)
    th.start()
    th.join()
    assert out == {"raised": True, "value": 7}


def test_sympy_integrate_under_a_deadline_falls_back():
    # no time at all: the antiderivative step reports Unsupported (so callers use quadrature);
    # x·eˣ needs no sympy (integration by parts, symbolic/elementary.py), x/(1 + x²) does
    c = Context({}, Deadline(0.0), frozenset())
    with pytest.raises(Unsupported):
        antiderivatives.antiderivative(x / (1 + x**2), x, c)
    F = antiderivatives.antiderivative(x * sp.exp(x), x, c)
    assert sp.simplify(sp.diff(F, x) - x * sp.exp(x)) == 0


def test_time_limit_survives_a_swallowed_alarm():
    # the first alarm fires inside a bare ``except:`` that swallows it; the repeated alarm still
    # ends the call
    def stubborn():
        end = time.monotonic() + 0.5
        while time.monotonic() < end:
            try:
                time.sleep(0.01)
            except BaseException:  # noqa: B036 - deliberately swallows the first alarm
                break
        time.sleep(5)

    start = time.monotonic()
    with pytest.raises(TimeoutError):
        run_with_timeout(stubborn, 0.1)
    assert time.monotonic() - start < 2


def test_a_shared_budget_bounds_every_deadline_and_the_engine_falls_back_to_quadrature():
    # `with budget(s)` caps each Deadline made or used inside it (the fuzzer gives the exact engine
    # one symbolic budget per program).  With nothing left, ∫₀¹ x⁵/(7 + x²) is not looked for in
    # closed form: the integral is the quadrature, which says so, and agrees with the closed form.
    # (A polynomial times eˣ would not do: it is integrated by parts without sympy, in no time.)
    from langur import exact as api
    from langur.frontend import load_text
    from langur.timebox import Deadline, budget

    d = Deadline(100.0)
    with budget(1.0):
        assert 0 < d.remaining() <= 1.0
        with budget(50.0):  # nesting only shortens
            assert d.remaining() <= 1.0
    assert d.remaining() > 50
    program = load_text("int ([0, 1]) x^5 / (7 + x^2) d(x)\n").program  # a weight no other test has
    with budget(0.0):
        with pytest.raises(TimeoutError):
            Deadline(10.0).run(lambda: 1)
        r = api.exact_eval(program, {})
    assert r.method == "quadrature"
    closed = api.exact_eval(program, {})  # the time-out is remembered with its budget, retried with more
    assert closed.method == "closed_form" and abs(r.value - closed.value) <= r.error + 1e-12


def test_an_equation_sympy_cannot_solve_is_not_read_as_having_no_root():
    """sympy's solve returns [] for y^5 + y - a = 0 (a quintic with a parameter); the delta of the
    domain's parametric bound x = a + 1 integrates [y^5 + y >= a] over y, which gave the closed form
    1 (no root, condition true at the midpoint) instead of 1 - y*.  Found by `langur fuzz --turning`.
    By hand: d/da ∫_0^{a+1} ∫_0^1 [y^5 + y >= a] dy dx = (1 - y*) - (a + 1)/(5 y*^4 + 1)."""
    from scipy.optimize import brentq

    from langur.exact import exact_deriv
    from langur.frontend import load_text

    a = 0.29
    loaded = load_text(f"param a = {a}\nint ([0, a + 1], [0, 1]) [y ^ 5 + y >= a] d(x, y)\n", "q.lgr")
    r = exact_deriv(loaded.program, {"a": sp.Rational(29, 100)}, {"a": 1}, check=False)
    ys = brentq(lambda y: y ** 5 + y - a, 0, 1, xtol=1e-15)
    assert not r.inconsistent, r.notes
    assert abs(r.value - ((1 - ys) - (a + 1) / (5 * ys ** 4 + 1))) <= 1e-8 + (r.error or 0)
