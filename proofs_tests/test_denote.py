"""⟦t⟧ (paper Fig. 7) and its decomposition into simply decomposable pieces (Def. 6.2, Thm 6.1).

Terms are built by hand in the core language (langur.core) with the brief's conventions: a
condition over variables is an IfDiffeo whose Diffeo is completed by solving for one variable.
Every expected value below is derived by hand in the comment next to it.
"""

from fractions import Fraction

import pytest
import sympy as sp

from langur.core import (
    Add,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Program,
    Var,
    const,
    neg,
    sub,
)
from langur.denote import denote
from langur.symbolic.decompose import Ctx, as_expr, complement, decompose
from langur.sympy_bridge import symbol

x, y, u0, u1 = Var("x"), Var("y"), Var("u0"), Var("u1")
X, Y, U0 = symbol("x"), symbol("y"), symbol("u0")


def diffeo1(cond, inverse, v="x"):
    """A completed one-variable condition: forward (cond,), inverse v = inverse(u0)."""
    return Diffeo((v,), (cond,), ("u0",), (InverseBranch((inverse,)),), solved_for=v)


def indicator(psi):
    return IfDiffeo(psi, const(1), const(0))


def le(v, p):
    """[v <= p] = ifge0 p − v, solved for v: v = p − u0."""
    return indicator(diffeo1(sub(p, v), sub(p, u0), v.name))


def ge(v, p):
    """[v >= p] = ifge0 v − p, solved for v: v = u0 + p."""
    return indicator(diffeo1(sub(v, p), Add(u0, p), v.name))


def interval(body, lo, hi, v=x):
    """int ([lo, hi]) body d(v): [v >= lo]·[hi >= v]·body with box (lo, hi)."""
    return Program(Mul(ge(v, lo), Mul(le(v, hi), body)), (v.name,), ((lo, hi),))


def fig1():
    """Paper Fig. 1: int ([0, 1]) [x <= theta] d(x)."""
    return interval(le(x, Param("theta")), const(0), const(1))


def check_pieces_equal_denotation(t, points, variables=("x",)):
    """Σ pieces = ⟦t⟧ at points off the discontinuities (a.e. equality of functions)."""
    whole = denote(t)
    parts = as_expr(decompose(t, Ctx(variables=tuple(variables))))
    for pt in points:
        sub_ = {symbol(k): sp.Rational(v) for k, v in pt.items()}
        assert sp.simplify(whole.subs(sub_) - parts.subs(sub_)) == 0, pt


def test_denote_fig1_is_piecewise_and_counts_the_interval():
    t = fig1().body
    e = denote(t)
    assert not e.has(sp.Heaviside)
    # ⟦[x ≥ 0]·[1 ≥ x]·[x ≤ θ]⟧ at θ = 1/2 is 1 at x = 1/4, 0 at x = 3/4 and 0 at x = -1/2.
    th = symbol("theta")
    assert e.subs({th: sp.Rational(1, 2), X: sp.Rational(1, 4)}) == 1
    assert e.subs({th: sp.Rational(1, 2), X: sp.Rational(3, 4)}) == 0
    assert e.subs({th: sp.Rational(1, 2), X: sp.Rational(-1, 2)}) == 0


def test_denote_smooth_formers_let_pi_power_primitives():
    a = Param("a")
    # let b = a·a in sqrt(b)·x^(1/2)·π + exp(b): ⟦⟧ = sqrt(a²)·sqrt(x)·π + exp(a²)
    t = Let("b", Mul(a, a), Add(Mul(Mul(Prim("sqrt", Param("b")), Pow(x, Fraction(1, 2))), Const("pi")),
                                Prim("exp", Param("b"))))
    A = symbol("a")
    assert sp.simplify(denote(t) - (sp.sqrt(A ** 2) * sp.sqrt(X) * sp.pi + sp.exp(A ** 2))) == 0
    # ifge0 a then 2 else 3 is a Piecewise in a only
    e = denote(IfGe0(a, const(2), const(3)))
    assert e.subs(A, 1) == 2 and e.subs(A, -1) == 3 and e.free_symbols == {A}


def test_same_name_same_real_symbol():
    assert symbol("x") is symbol("x") and symbol("x").is_real
    assert denote(x) == X and denote(Param("theta")) == symbol("theta")


def test_decompose_fig1_three_conditions_with_psi():
    (piece,) = decompose(fig1().body)
    # [x ≥ 0]·[1 − x ≥ 0]·[θ − x ≥ 0]·1
    assert piece.weight == 1
    th = symbol("theta")
    assert {c.expr for c in piece.conditions} == {X, 1 - X, th - X}
    for c in piece.conditions:
        assert c.psi is not None and c.psi.forward[0] == c.expr
        # every inverse branch maps u0 = Φ back: Φ(x(u0)) = u0
        (b,) = c.psi.branches
        assert sp.simplify(c.expr.subs(dict(b.inverse)) - U0) == 0


def test_complement_negates_condition_and_inverse():
    c = decompose(le(x, Param("theta")))[0].conditions[0]
    n = complement(c)
    th = symbol("theta")
    # [x − θ ≥ 0]: inverse of u0 = x − θ is x = u0 + θ, i.e. θ − (−u0)
    assert n.expr == X - th
    (b,) = n.psi.branches
    assert sp.simplify(b.inverse[0][1] - (U0 + th)) == 0
    assert complement(n).expr == c.expr


def test_diffeo_conditional_splits_into_complementary_pieces():
    # ifge0 ⌊x − a⌋ then x else 2: pieces [x − a ≥ 0]·x + [a − x ≥ 0]·2
    a = Param("a")
    t = IfDiffeo(diffeo1(sub(x, a), Add(u0, a)), x, const(2))
    ps = decompose(t)
    A = symbol("a")
    assert {(tuple(c.expr for c in p.conditions), p.weight) for p in ps} == {((X - A,), X), ((A - X,), 2)}
    check_pieces_equal_denotation(t, [{"x": "0.3", "a": "0.1"}, {"x": "-0.3", "a": "0.1"}])


def test_primitive_of_a_jump_splits_over_sign_patterns():
    # exp([x ≥ a] + [x ≥ b]) has four sign patterns with values e², e, e, 1
    a, b = Param("a"), Param("b")
    t = Prim("exp", Add(ge(x, a), ge(x, b)))
    ps = decompose(t)
    assert sorted(sp.srepr(p.weight) for p in ps) == sorted(
        sp.srepr(w) for w in (sp.exp(2), sp.E, sp.E, sp.Integer(1)))
    check_pieces_equal_denotation(t, [{"x": x_, "a": "0.2", "b": "0.6"} for x_ in ("0.1", "0.4", "0.9")])


def test_products_distribute_and_repeated_conditions_collapse():
    # [x ≥ a]·([x ≥ a] + x) = [x ≥ a]·(1 + x): [c]·[c] = [c] and equal condition sets merge
    a = Param("a")
    t = Mul(ge(x, a), Add(ge(x, a), x))
    (p,) = decompose(t)
    assert p.weight == 1 + X and len(p.conditions) == 1


def test_variable_free_conditional_is_decided_at_the_point_or_kept_piecewise():
    a = Param("a")
    t = Mul(IfGe0(a, x, neg(x)), ge(x, const(0)))
    A = symbol("a")
    (kept,) = decompose(t)
    assert kept.weight.has(sp.Piecewise) and kept.weight.subs({A: 1, X: 3}) == 3
    (decided,) = decompose(t, Ctx(at={A: sp.Integer(-1)}))
    assert decided.weight == -X


def test_two_variable_pieces_match_denotation():
    # Fig. 9 body without the box: [x + θ − y ≥ 0]·(1 + θ + x + y), solved for y = u1 + θ − u0
    th = Param("theta")
    psi = Diffeo(("x", "y"), (sub(Add(x, th), y), x), ("u0", "u1"),
                 (InverseBranch((u1, sub(Add(u1, th), u0))),), solved_for="y")
    t = Mul(indicator(psi), Add(Add(Add(const(1), th), x), y))
    check_pieces_equal_denotation(t, [{"x": "0.5", "y": "0.2", "theta": "0"},
                                      {"x": "0.1", "y": "0.7", "theta": "0"}], ("x", "y"))
    (p,) = decompose(t)
    (c,) = p.conditions
    assert c.psi.inputs == (symbol("u0"), symbol("u1"))


def test_call_is_rejected():
    from langur.core import Call
    with pytest.raises(TypeError):
        denote(Call("m", "f", ()))


@pytest.mark.parametrize("t,expected_value", [("0.3", "0.045"), ("0.8", "0.18")])
def test_a_closed_form_built_on_a_parameter_conditional_is_valid_only_in_its_cell(t, expected_value):
    # [x < min(t, t1)] is a parameter conditional (t < t1) around two jumps: at t = 0.3 the closed
    # form is t²/2 (by hand ∫₀ᵗ x dx), at t = 0.8 it is t1²/2 = 0.18; neither holds for all t,
    # so neither may be reported as valid everywhere, and each is valid in its cell.
    from langur.denote import denote_program
    from langur.frontend import load_text

    program = load_text("param t = 0.3, t1 = 0.6\nint ([0, 1]) [x < min(t, t1)] * x d(x)\n").program
    got = denote_program(program, {"t": t, "t1": "0.6"})
    assert sp.nsimplify(got.value) == sp.Rational(expected_value)
    assert not got.everywhere
    assert "valid for all parameter values" not in " ".join(got.notes)
    T, T1 = sp.Symbol("t", real=True), sp.Symbol("t1", real=True)
    other = {"0.3": sp.Rational(8, 10), "0.8": sp.Rational(3, 10)}[t]  # a point in the other cell
    wrong = got.expr.subs({T: other, T1: sp.Rational(6, 10)})
    right = denote_program(program, {"t": other, "t1": "0.6"}).value
    assert abs(float(wrong) - right) > 0.01  # the closed form indeed does not extend across
