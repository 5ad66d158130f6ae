"""exact15r (issue 15, disk ∂/∂r and Theorem 8.1's cost): sympy's ``solve`` no longer run where its
answer cannot change the closed form, and a Jacobian's sample signs without sympy's ``evalf``.

* ``solving._only_repeats``: the tidy solve (sympy's ``solve`` with its ``simplify`` pass) is skipped
  when every untidy candidate is, by a wide margin, not real, outside the interval, or a real number
  whose double is certain and already among the points: its tidy form would be dropped as a repeat.
  Checked on hand-made candidates (a root exactly on a rounding boundary of doubles is refused).
* ``solving._radicand``: no solve at all for k·√P when P came before and its roots are certain
  repeats; relies on sympy's roots of k·√P being P's: checked against sympy on random quadratics.
* ``delta._certain``: det DΨ̂⁻¹'s sample values from a 40-digit mpmath function where the decisions
  taken on them (real or not, sign) are certain; compared with sympy's 30-digit values.

Values by hand: the disc of radius r has area πr² and ∂/∂r = 2πr (π/4 and π at r = 1/2); the
ellipse x²/a² + y²/b² ≤ 1 has area πab.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import mpmath
import sympy as sp

from langur import ddenote as ddenote_module
from langur import denote as denote_module
from langur import observe
from langur.ddenote import ddenote_program
from langur.denote import denote_program
from langur.exact import exact_deriv
from langur.frontend import load, load_text
from langur.symbolic import antiderivatives, context, delta, regions, solving
from langur.symbolic import decompose as decompose_module
from langur.symbolic.context import Cond, Context
from langur.sympy_bridge import symbol
from langur.timebox import Deadline

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
x, r, a, b = symbol("x"), symbol("r"), symbol("a"), symbol("b")


def _ctx(**at) -> Context:
    point = {symbol(k): sp.nsimplify(v) for k, v in at.items()}
    return Context(point, Deadline(20.0), frozenset(point))


def _forget() -> None:
    """Drop the memos that would hand a second run the first run's answers."""
    for memo in (solving._SOLVED, context._VALUES, antiderivatives._CACHE, solving._VANISHES, solving._CLOSED_ROOTS, antiderivatives._MATCHES,
                 delta._SIMPLIFIED, denote_module._remembered, denote_module._DECOMPOSED, ddenote_module._NORMAL_FORMS):
        memo.clear()


def _solved(expr, v, sols) -> None:
    solving._SOLVED[(expr, v, False)] = list(sols)


def test_only_repeats_on_hand_made_candidates():
    ctx = _ctx(r=0.5)
    e = sp.Symbol("e_hand", real=True)  # (a key of its own in the solutions' memo)
    # ±|r| = ±1/2: doubles certain, both among the points
    _solved(e, x, [-sp.Abs(r), sp.Abs(r)])
    assert solving._only_repeats(e, x, -1.0, 1.0, {-1.0, 1.0, -0.5, 0.5}, ctx)
    assert not solving._only_repeats(e, x, -1.0, 1.0, {-1.0, 1.0, -0.5}, ctx)  # 1/2 is new
    # not real (r ± i), or outside [−1, 1] (3r): nothing to add
    _solved(e, x, [r + sp.I, r - sp.I, 3 * r + 1, -sp.Abs(r)])
    assert solving._only_repeats(e, x, -1.0, 1.0, {-1.0, 1.0, -0.5}, ctx)
    # a number exactly halfway between two doubles: its double is not certain
    half = sp.Integer(1) + sp.Rational(1, 2 ** 53)
    assert float(half) in (1.0, 1.0 + 2.0 ** -52)
    _solved(e, x, [half])
    assert not solving._only_repeats(e, x, 0.0, 2.0, {0.0, 2.0, 1.0, 1.0 + 2.0 ** -52}, ctx)
    # 1 ± 10⁻²⁵: its double is certainly 1.0, the interval's end (never inside: nothing added)
    _solved(e, x, [1 + sp.Rational(1, 10 ** 25), 1 - sp.Rational(1, 10 ** 25)])
    assert solving._only_repeats(e, x, -1.0, 1.0, {-1.0, 1.0}, ctx)
    # nearly real: left to the tidy solve
    _solved(e, x, [r + sp.I * sp.Rational(1, 10 ** 15)])
    assert not solving._only_repeats(e, x, -1.0, 1.0, {-1.0, 1.0, 0.5}, ctx)
    # nothing known, or no candidate: no claim
    solving._SOLVED.pop((e, x, False))
    assert not solving._only_repeats(e, x, -1.0, 1.0, {-1.0, 1.0}, ctx)


def test_radicand_shapes():
    P = 4 * r ** 2 - 4 * x ** 2
    seen = {P}
    assert solving._radicand(Cond(sp.sqrt(P)), x, seen) == P
    assert solving._radicand(Cond(3 * sp.sqrt(P) / 2), x, seen) == P
    assert solving._radicand(Cond(sp.sqrt(P)), x, set()) is None  # P not placed before
    assert solving._radicand(Cond(-sp.sqrt(P)), x, seen) is None  # a negative factor
    assert solving._radicand(Cond(r * sp.sqrt(P)), x, seen) is None  # a symbolic factor
    assert solving._radicand(Cond(sp.sqrt(P) - 1), x, seen) is None
    assert solving._radicand(Cond(sp.cbrt(P)), x, seen) is None
    cubic = x ** 3 - r
    assert solving._radicand(Cond(sp.sqrt(cubic)), x, {cubic}) is None  # degree 3


def test_sympys_roots_of_k_sqrt_p_are_those_of_p():
    """What :func:`solving._radicand` relies on: for P of degree 1 or 2 in x (parameters in its
    coefficients), sympy's solve of k·√P (as solving._roots asks it: check=False, untidied) gives,
    at random rational parameter values, the same set of numbers as its solve of P."""
    rng = random.Random(151)
    checked = 0
    for _ in range(40):
        c = [sp.Rational(rng.randint(-5, 5), rng.randint(1, 3)) for _ in range(6)]
        quad = int(rng.random() < 0.7)
        P = (c[0] or 1) * x ** 2 * quad + (c[1] + c[2] * r) * x + c[3] + c[4] * r ** 2 + c[5] * a
        if sp.Poly(P, x).degree() < 1:
            continue
        k = sp.Rational(rng.randint(1, 4), rng.randint(1, 3))
        of_root = sp.solve(k * sp.sqrt(P), x, dict=False, check=False, simplify=False)
        of_p = sp.solve(P, x, dict=False, check=False, simplify=False)
        for _ in range(3):
            pt = {r: sp.Rational(rng.randint(-9, 9), 4), a: sp.Rational(rng.randint(-9, 9), 5)}
            vals = [set(complex(sp.N(s.xreplace(pt), 30)) for s in sols) for sols in (of_root, of_p)]
            rounded = [{(round(z.real, 12), round(z.imag, 12)) for z in vs} for vs in vals]
            assert rounded[0] == rounded[1], (P, of_root, of_p, pt)
            checked += 1
    assert checked > 60


def test_the_disc_is_the_same_without_the_shortcuts(monkeypatch):
    """⟦p⟧ and ⦇p⦈ of the disc example, its ellipse and an off-centre disc: the same trees, values,
    notes and cells with the shortcuts and without (patched off, memos cleared), and the values by
    hand; the tidy solve of √(4r² − 4x²) is not asked for."""
    loaded = load(str(EXAMPLES / "adapters" / "programs" / "disk.lgr"))
    at = loaded.param_values()
    asked = []
    real_solve = solving._solve

    def spy(expr, v, tidy):
        asked.append((expr, tidy))
        return real_solve(expr, v, tidy)

    def run():
        _forget()
        den = denote_program(loaded.program, at, near=True)
        der = ddenote_program(loaded.program, at, {"r": 1})
        return den, der

    monkeypatch.setattr(solving, "_solve", spy)
    den, der = run()
    assert abs(den.value - math.pi / 4) < 1e-12 and abs(der.value - math.pi) < 1e-12  # πr², 2πr at r = 1/2
    root = sp.sqrt(4 * r ** 2 - 4 * x ** 2)
    assert (root, True) not in asked and (root, False) not in asked
    monkeypatch.setattr(regions, "_only_repeats", lambda *args: False)
    monkeypatch.setattr(regions, "_radicand", lambda *args: None)
    monkeypatch.setattr(delta, "_certain", lambda *args: None)
    asked.clear()
    old_den, old_der = run()
    assert (root, True) in asked  # the old path solves it, tidily
    for new, old in ((den, old_den), (der, old_der)):
        assert sp.srepr(new.expr) == sp.srepr(old.expr) and new.value == old.value
        assert new.notes == old.notes
    assert [str(c) for c in den.cell] == [str(c) for c in old_den.cell]


def test_ellipses_and_offcentre_discs_are_the_same_without_the_shortcuts(monkeypatch):
    """Random ellipses x²/a² + y²/b² ≤ 1 (area πab by hand) and discs of radius r centred at
    (c, 0), clipped by the box [−1, 1]² or not: ⟦p⟧ the same with and without the shortcuts."""
    rng = random.Random(15)
    cases = []
    for _ in range(3):
        A, B = rng.choice([0.3, 0.4, 0.5, 0.6]), rng.choice([0.25, 0.35, 0.45])
        cases.append((f"param a = {A}\nparam b = {B}\n"
                      "int ([-1, 1], [-1, 1]) [1 - x^2/a^2 - y^2/b^2 >= 0] d(x, y)\n", math.pi * A * B))
    for _ in range(3):
        R, C = rng.choice([0.3, 0.5, 0.7]), rng.choice([-0.4, 0.2, 0.5])
        cases.append((f"param r = {R}\nint ([-1, 1], [-1, 1]) [r^2 - (x - {C})^2 - y^2 >= 0] d(x, y)\n",
                      math.pi * R * R if abs(C) + R <= 1 else None))
    for text, area in cases:
        loaded = load_text(text)
        at = loaded.param_values()
        direction = {next(iter(at)): 1}

        def run(program=loaded.program, at=at, direction=direction):
            _forget()
            return denote_program(program, at, near=True), ddenote_program(program, at, direction)

        with monkeypatch.context() as m:
            new = run()
            m.setattr(regions, "_only_repeats", lambda *args: False)
            m.setattr(regions, "_radicand", lambda *args: None)
            m.setattr(delta, "_certain", lambda *args: None)
            old = run()
        for n, o in zip(new, old):
            assert sp.srepr(n.expr) == sp.srepr(o.expr) and n.value == o.value and n.notes == o.notes
        if area is not None:
            assert abs(new[0].value - area) < 1e-9, text


def test_certain_jacobian_values_give_the_30_digit_decisions():
    """delta._jacobian_values with the mpmath shortcut and with sympy's evalf only: the same
    decisions (real or not at 1e-12, sign) at random points, for Jacobians real on part of the
    box and complex on the rest; _certain refuses values near the decisions' thresholds."""
    ctx = _ctx(r=0.5, a=0.3)
    u1 = symbol("u1")
    rng = random.Random(3)
    jacobians = [1 / (2 * sp.sqrt(r ** 2 - u1 ** 2)), -u1 / sp.sqrt(a - u1 ** 2), (u1 - a) * r / (1 + u1 ** 2),
                 sp.sqrt(u1 + r) - sp.sqrt(a), sp.log(u1 + 1) * r]
    decided = 0
    for J in jacobians:
        points = [{u1: sp.Float(rng.uniform(-0.99, 0.99), 30)} for _ in range(40)]
        new = delta._jacobian_values(J, [u1], ctx, points)
        old = [ctx.value(J.xreplace(pt)) for pt in points]
        for zn, zo in zip(new, old):
            def decision(z):
                return (abs(z.imag) < 1e-12, z.real > 0 if abs(z.imag) < 1e-12 and z.real != 0 else None)
            assert decision(zn) == decision(zo), (J, zn, zo)
            decided += 1
    assert decided == 200
    fn = lambda z: mpmath.mpc(0, z)  # noqa: E731 - a value with a chosen imaginary part
    assert delta._certain(fn, [1e-12]) is None and delta._certain(fn, [1e-9]) is not None
    assert delta._certain(lambda z: z, [1e-20]) is None  # real, nearly 0: no sign
    assert delta._certain(lambda z: z, [0.25]) == 0.25
    assert delta._certain(lambda z: 1 / z, [0.0]) is None  # undefined


def test_disk_deriv_and_its_check_by_hand():
    """`langur deriv disk.lgr --wrt r --engine exact`: 2πr = π at r = 1/2, Theorem 8.1 holds, and
    the nearby points' two sides agree with 2πq (q their r)."""
    loaded = load(str(EXAMPLES / "adapters" / "programs" / "disk.lgr"))
    res = exact_deriv(loaded.program, loaded.param_values(), {"r": 1})
    assert abs(res.value - math.pi) < 1e-12 and res.theorem_8_1.holds is True
    for pt in res.theorem_8_1.points:
        q = pt.params["r"]
        assert abs(pt.d_denotation - 2 * math.pi * q) < 1e-9
        assert abs(pt.derivative_denotation - 2 * math.pi * q) < 1e-7


def test_point_free_programs_decompose_once_and_the_same(monkeypatch):
    """A program without a variable-free conditional is decomposed once for all points (Theorem
    8.1's shifted and nearby points), and its ⦇p⦈ normal form made once per γ': the values at other
    points are those of a fresh decomposition (patched off); a program with an ``if`` on a
    parameter is decomposed at each point (its pieces depend on it)."""
    from langur.core import Add, IfGe0, Param, Program, Var, const, sub

    loaded = load(str(EXAMPLES / "adapters" / "programs" / "disk.lgr"))
    program = loaded.program
    assert denote_module.point_free(program)
    calls = []
    real = denote_module.decompose

    def spy(t, *rest):  # (the program's decompositions, not their recursion)
        if t is program.body:
            calls.append(1)
        return real(t, *rest)

    monkeypatch.setattr(denote_module, "decompose", spy)
    monkeypatch.setattr(decompose_module, "decompose", spy)  # (the recursion too: no observer, memo on)
    _forget()
    points = [{"r": q} for q in (0.3, 0.45, 0.6)]
    new = [denote_program(program, q, symbolic=False) for q in points]
    assert len(calls) == 1
    derivs = [ddenote_program(program, q, {"r": 1}, symbolic=False) for q in points]
    for q, d in zip(points, derivs):  # 2πr by hand (quadrature)
        assert abs(d.value - 2 * math.pi * q["r"]) < 1e-7
    for q, v in zip(points, new):
        assert abs(v.value - math.pi * q["r"] ** 2) < 1e-9  # πr² by hand
    monkeypatch.setattr(denote_module, "point_free", lambda program: False)
    monkeypatch.setattr(ddenote_module, "point_free", lambda program: False)
    _forget()
    old = [denote_program(program, q, symbolic=False) for q in points]
    old_derivs = [ddenote_program(program, q, {"r": 1}, symbolic=False) for q in points]
    assert len(calls) == 4
    assert [(v.value, v.error) for v in new] == [(v.value, v.error) for v in old]
    assert [(d.value, d.error) for d in derivs] == [(d.value, d.error) for d in old_derivs]
    # an observer wrapping decompose alone (a campaign's rule coverage): every point decomposed
    monkeypatch.undo()
    counted = []
    monkeypatch.setattr(decompose_module, "decompose",
                        lambda *args: counted.append(1) or real(*args))  # (sees the recursion)
    _forget()
    with observe.counted():
        denote_program(program, points[0], symbolic=False)
        once = len(counted)
        for q in points[1:]:
            denote_program(program, q, symbolic=False)
    assert once > 0 and len(counted) == 3 * once
    monkeypatch.undo()
    # ∫₀¹ (if a ≥ 0 then x else 1) dx: 1/2 or 1 by the sign of a — decided at each point
    body = IfGe0(Param("a"), Var("x"), const(1))
    branching = Program(body, ("x",), ((const(0), const(1)),))
    assert not denote_module.point_free(branching)
    in_box = IfGe0(Param("a"), const(2), const(1))  # (an if in the box only)
    assert not denote_module.point_free(Program(Add(Var("x"), const(1)), ("x",), ((const(0), sub(const(3), in_box)),)))
    assert denote_program(branching, {"a": 0.5}).value == 0.5
    assert denote_program(branching, {"a": -0.5}).value == 1.0


def test_derivative_matches_is_remembered_with_the_same_verdicts(monkeypatch):
    """sympy's antiderivative r·asin(u/|r|) of r/√(r² − u²) (by hand: d/du asin(u/|r|) = 1/√(r² − u²))
    passes, 0 and u·r fail; each (F, w) is checked once per point."""
    ctx = _ctx(r=0.5)
    u = symbol("u1")
    w = r / sp.sqrt(r ** 2 - u ** 2)
    calls = []
    real = antiderivatives._derivative_matches_here
    monkeypatch.setattr(antiderivatives, "_derivative_matches_here", lambda *args: calls.append(1) or real(*args))
    antiderivatives._MATCHES.clear()
    good = r * sp.asin(u / sp.Abs(r))
    assert antiderivatives._derivative_matches(good, w, u, ctx) is True
    assert antiderivatives._derivative_matches(good, w, u, ctx) is True
    assert len(calls) == 1
    assert antiderivatives._derivative_matches(sp.Integer(0), w, u, ctx) is False
    assert antiderivatives._derivative_matches(u * r, w, u, ctx) is False
    assert antiderivatives._derivative_matches(good, w, u, _ctx(r=0.25)) is True  # another point: computed
    assert len(calls) == 4
