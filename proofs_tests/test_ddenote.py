"""⦇t⦈ (paper Fig. 8) in the normal form of Theorem 7.1, on terms built by hand.

The delta terms are checked with the one-variable sifting property written out in this file
(``sift``: Σ over roots x* of Φ of h(x*)/|∂ₓΦ(x*)|, via the stored inverse branches), so these
tests do not depend on the integrator; every expected value is derived by hand in a comment.
"""

from fractions import Fraction

import sympy as sp
from test_denote import X, fig1, ge, indicator, interval, le, u0

from langur.core import (
    Add,
    Diffeo,
    IfDiffeo,
    IfGe0,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Var,
    const,
    neg,
    sub,
)
from langur.ddenote import NormalForm, ddenote
from langur.sympy_bridge import symbol

x = Var("x")
U0 = symbol("u0")


def sift(nf: NormalForm, at: dict[str, str], box=(0, 1)) -> sp.Expr:
    """Σ_k ∫_box h_k(x) δ(Φ_k(x)) dx in one variable, by hand: for each inverse branch x*(u0) of
    Φ_k, evaluate at u0 = 0 and multiply by |dx*/du0| (= 1/|Φ'(x*)|)."""
    pt = {symbol(k): sp.Rational(v) for k, v in at.items()}
    total = sp.Integer(0)
    for d in nf.deltas:
        for b in d.psi.branches:
            ((v, inv),) = b.inverse
            if any(g.subs(pt).subs(U0, 0) < 0 for g in b.guards):
                continue
            xs = inv.subs(pt).subs(U0, 0)
            jac = abs(sp.diff(inv, U0).subs(pt).subs(U0, 0))
            inside = all(c.expr.subs(pt).subs(v, xs) >= 0 for c in d.conditions)
            if inside and box[0] <= xs <= box[1]:
                total += d.weight.subs(pt).subs(v, xs) * jac
    return sp.nsimplify(sp.simplify(total))


def test_fig1_normal_form_is_one_delta():
    nf = ddenote(fig1().body, {"theta": 1}, variables=("x",))
    # ⦇[x ≥ 0]·[1 ≥ x]·[x ≤ θ]⦈: only θ moves, so no regular part; one delta δ(θ − x) with
    # D_θ(θ − x) = 1 and jump 1 − 0, times the two box indicators.
    assert nf.regular == []
    (d,) = nf.deltas
    assert d.weight == 1 and d.psi.forward[0] == symbol("theta") - X
    assert {c.expr for c in d.conditions} == {X, 1 - X}
    # sifting at θ = 1/2: the root x* = 1/2 is inside [0, 1], |∂ₓΦ| = 1: value 1
    assert sift(nf, {"theta": "1/2"}) == 1
    # at θ = 3/2 the root is outside the box: 0 (the value is clamp(θ, 0, 1))
    assert sift(nf, {"theta": "3/2"}) == 0


def test_two_roots_of_x_squared():
    # [x² ≤ a] = ifge0 a − x²: u0 = a − x², branches x = ±√(a − u0) where a − u0 ≥ 0.
    a = Param("a")
    psi = Diffeo(("x",), (sub(a, Mul(x, x)),), ("u0",),
                 (InverseBranch((Pow(sub(a, u0), Fraction(1, 2)),), (sub(a, u0),)),
                  InverseBranch((neg(Pow(sub(a, u0), Fraction(1, 2))),), (sub(a, u0),))), solved_for="x")
    nf = ddenote(indicator(psi), {"a": 1}, variables=("x",))
    # D_a(a − x²) = 1; roots ±√a each with |∂ₓΦ| = 2√a: total 2/(2√a) = 1/√a; at a = 1/4: 2
    assert sift(nf, {"a": "1/4"}, box=(-1, 1)) == 2
    assert sift(nf, {"a": "1/9"}, box=(-1, 1)) == 3


def test_parametric_slope():
    # [t·x − 1 ≥ 0] on [0, 1]: ∫ = 1 − 1/t for t > 1, derivative 1/t².
    # Φ = t·x − 1, D_tΦ = x; root x* = 1/t with |∂ₓΦ| = t: x*/t = 1/t²; at t = 2: 1/4
    t = Param("t")
    psi = Diffeo(("x",), (sub(Mul(t, x), const(1)),), ("u0",),
                 (InverseBranch((Mul(Add(u0, const(1)), Pow(t, Fraction(-1))),)),), solved_for="x",
                 nonzero=(t,))
    nf = ddenote(interval(indicator(psi), const(0), const(1)).body, {"t": 1}, variables=("x",))
    assert nf.regular == []
    assert sift(nf, {"t": "2"}) == sp.Rational(1, 4)


def test_leibniz_bound():
    # int ([0, k]) k·x: ⦇k·x⦈ = x (regular), and δ(k − x)·1·(k·x) from the upper bound.
    # ∫₀ᵏ x dx + k·k = k²/2 + k² = 3k²/2.
    k = Param("k")
    p = interval(Mul(k, x), const(0), k)
    nf = ddenote(p.body, {"k": 1}, variables=("x",))
    (r,) = nf.regular
    assert r.weight == X and {c.expr for c in r.conditions} == {X, symbol("k") - X}
    assert sift(nf, {"k": "2"}, box=(0, 2)) == 4  # k² at k = 2


def test_product_rule_counts_a_coincident_jump_twice():
    # ⦇[x ≥ a]·[x ≥ a]⦈ = 2·δ(x − a)·(−1)·[x ≥ a] (paper §7.3.1): the jump counted twice.
    a = Param("a")
    nf = ddenote(Mul(ge(x, a), ge(x, a)), {"a": 1}, variables=("x",))
    (d,) = nf.deltas
    assert d.weight == -2 and [c.expr for c in d.conditions] == [X - symbol("a")]


def test_let_chain_rule():
    # let b = 2a in [x ≤ b]: γ'(b) = ⦇2a⦈ = 2, so δ(2a − x)·2
    a = Param("a")
    nf = ddenote(Let("b", Mul(const(2), a), le(x, Param("b"))), {"a": 1}, variables=("x",))
    (d,) = nf.deltas
    assert d.weight == 2 and d.psi.forward[0] == 2 * symbol("a") - X


def test_primitive_chain_rule_and_sum():
    # ⦇exp(a·x) + a⦈ = x·exp(a·x) + 1 (no deltas)
    a = Param("a")
    nf = ddenote(Add(Prim("exp", Mul(a, x)), a), {"a": 1})
    assert nf.deltas == []
    A = symbol("a")
    assert sp.simplify(sum(p.weight for p in nf.regular) - (X * sp.exp(A * X) + 1)) == 0


def test_direction_mixes_partials():
    # γ' = (a' = 2, b' = 3): ⦇a·b⦈ = a'·b + b'·a = 2b + 3a
    nf = ddenote(Mul(Param("a"), Param("b")), {"a": 2, "b": 3})
    assert sp.expand(sum(p.weight for p in nf.regular) - (2 * symbol("b") + 3 * symbol("a"))) == 0


def test_variable_free_conditional_picks_the_branch():
    # ⦇ifge0 a then a·x else 0⦈ is x where a ≥ 0, 0 otherwise
    a = Param("a")
    t = IfGe0(a, Mul(a, x), const(0))
    assert [p.weight for p in ddenote(t, {"a": 1}, at={"a": 1}).regular] == [X]
    assert ddenote(t, {"a": 1}, at={"a": -1}).regular == []
    (kept,) = ddenote(t, {"a": 1}).regular
    assert kept.weight.subs(symbol("a"), 2) == X


def test_diffeo_conditional_regular_part_is_piecewise_of_branches():
    # ⦇ifge0 ⌊x − a⌋ then a·x else a⦈ = [x − a ≥ 0]·x + [a − x ≥ 0]·1 + δ(x − a)·(−1)·(a·x − a)
    a = Param("a")
    psi = Diffeo(("x",), (sub(x, a),), ("u0",), (InverseBranch((Add(u0, a),)),), solved_for="x")
    nf = ddenote(IfDiffeo(psi, Mul(a, x), a), {"a": 1}, variables=("x",))
    A = symbol("a")
    assert {(p.conditions[0].expr, p.weight) for p in nf.regular} == {(X - A, X), (A - X, 1)}
    # sifting at a = 1/2 on [0, 1]: −(a·a − a) = a − a² = 1/4
    assert sift(nf, {"a": "1/2"}) == sp.Rational(1, 4)


def test_normal_form_renders():
    nf = ddenote(fig1().body, {"theta": 1}, variables=("x",))
    s = str(nf)
    assert "δ(theta - x)" in s and "[x >= 0]" in s
    assert "\\delta" in nf._repr_latex_()


def test_show_renders_normal_form_with_inverse_branches():
    import os

    from paths import EXAMPLES

    from langur.ddenote import ddenote_program
    from langur.exact import show_denotation, show_derivative
    from langur.frontend import load

    loaded = load(os.path.join(str(EXAMPLES), "fig9.lgr"))
    p, at = loaded.program, loaded.param_values()
    text = show_derivative(p, {"theta": 1}, params=at)
    # Fig. 9: ⦇p⦈ = [y < x] + δ(x − y)·(1 + x + y) at θ = 0; one delta term with one inverse branch
    assert "regular part f = [theta + x - y >= 0]" in text
    assert "delta term 1: δ(theta + x - y)" in text and "delta term 2" not in text
    assert "inverse branch 1 in (u0, u1)" in text and "value at theta = 0: 4  (regular 2, boundary 2)" in text
    assert "\\delta\\left(" in show_derivative(p, {"theta": 1}, latex=True)
    den = show_denotation(loaded.program, params=at)
    assert den.startswith("⟦p⟧ = int_{x in [-1, 1], y in [-1, 1]}") and "value at theta = 0: 2" in den
    res = ddenote_program(p, at, {"theta": 1})
    assert res._repr_latex_().startswith("$") and "4" in res._repr_latex_()


# ----------------------------------------------------------------------------------------------
# Property: off the jump surfaces, Σ decomposition = ⟦t⟧ and Σ regular part of ⦇t⦈ = ∂_a⟦t⟧
# (the classical derivative of the Piecewise denotation, by sympy), on random terms.

from hypothesis import given, settings
from hypothesis import strategies as st

from langur.denote import denote
from langur.symbolic.decompose import Ctx, decompose

A, B = Param("a"), Param("b")
CONDITIONS = [  # (π₀Ψ̂, inverse x(u0))
    (lambda p: sub(x, p), lambda p: Add(u0, p)),
    (lambda p: sub(p, x), lambda p: sub(p, u0)),
    (lambda p: sub(Mul(const(2), x), p), lambda p: Mul(Add(u0, p), Pow(const(2), Fraction(-1)))),
]


def _ifdiffeo(i, p, s, r):
    cond, inv = CONDITIONS[i]
    psi = Diffeo(("x",), (cond(p),), ("u0",), (InverseBranch((inv(p),)),), solved_for="x")
    return IfDiffeo(psi, s, r)


leaves = st.sampled_from([x, A, B, const(1), const(-2), const(Fraction(1, 3))])
terms = st.recursive(leaves, lambda sub_: st.one_of(
    st.builds(Add, sub_, sub_), st.builds(Mul, sub_, sub_),
    st.builds(lambda t: Prim("exp", t), sub_), st.builds(lambda t: Pow(t, Fraction(2)), sub_),
    st.builds(_ifdiffeo, st.integers(0, 2), st.sampled_from([A, B]), sub_, sub_),
    st.builds(IfGe0, st.sampled_from([A, B, sub(A, B)]), sub_, sub_),
    st.builds(lambda t: Let("c", Mul(A, B), t), sub_),
), max_leaves=8)


@settings(max_examples=40, deadline=None)
@given(terms, st.sampled_from(["-0.9", "-0.35", "0.05", "0.45", "0.8"]))
def test_pieces_and_regular_part_agree_with_denotation_off_jumps(t, xv):
    a, b = symbol("a"), symbol("b")
    pt = {a: sp.Rational(3, 10), b: sp.Rational(-1, 5), X: sp.Rational(xv)}
    whole = denote(t)
    pieces = decompose(t, Ctx(variables=("x",)))
    conds = {c.expr for p in pieces for c in p.conditions}
    if any(abs(float(c.subs(pt))) < 1e-6 for c in conds):
        return  # on a jump surface: a null set
    total = sum((p.weight.subs(pt) for p in pieces if all(c.expr.subs(pt) >= 0 for c in p.conditions)),
                sp.Integer(0))
    assert abs(complex(sp.N(total - whole.subs(pt)))) < 1e-9
    nf = ddenote(t, {"a": 1}, variables=("x",))
    regular = sum((p.weight.subs(pt) for p in nf.regular
                   if all(c.expr.subs(pt) >= 0 for c in p.conditions)), sp.Integer(0))
    assert abs(complex(sp.N(regular - sp.diff(whole, a).subs(pt)))) < 1e-9
