"""The direct (sympy-free) completion of affine conditions gives the sympy path's Diffeo, term for term.

``langur.syntax.affine.complete`` is compared with ``langur.syntax.diffeo``'s sympy solver (called
past the hook) on random affine conditions: random variables and parameters (names chosen to stress
sympy's ordering: ``u10`` vs ``u2``, upper case, underscores), random rational coefficients
(``1/2``, ``-1``, integers, other rationals), written in random nested shapes (sums, differences,
products and quotients by constants).  Non-affine conditions are refused (``None``), never solved.
"""

from dataclasses import replace
from fractions import Fraction

from hypothesis import given, settings
from hypothesis import strategies as st

from langur.core import Add, Const, Mul, Param, Pow, Prim, Var
from langur.syntax import affine, diffeo

NAMES = ["x", "y", "z", "u0", "u1", "u10", "u2", "B", "a", "theta", "_t", "Z9", "w_0", "xA"]
COEFFS = [Fraction(1), Fraction(-1), Fraction(1, 2), Fraction(-1, 2), Fraction(2), Fraction(-3), Fraction(3, 2),
          Fraction(-5, 7), Fraction(7, 3), Fraction(0), Fraction(10), Fraction(-1, 3)]


def _sympy_completion(cond, variables):
    psi = diffeo._complete_cached.__wrapped__(cond, tuple(variables), ())
    return replace(psi, forward=(cond,) + psi.forward[1:], span=getattr(cond, "span", None))


@st.composite
def affine_conditions(draw):
    names = draw(st.lists(st.sampled_from(NAMES), min_size=1, max_size=6, unique=True))
    n_vars = draw(st.integers(1, min(3, len(names))))
    variables, params = names[:n_vars], names[n_vars:]
    atoms = [Var(v) for v in variables] + [Param(p) for p in params]
    items = [Mul(Const(draw(st.sampled_from(COEFFS))), a) if draw(st.booleans()) else a for a in atoms]
    if draw(st.booleans()):
        items.append(Const(draw(st.sampled_from(COEFFS))))
    order = draw(st.permutations(items))
    term = order[0]
    for t in order[1:]:
        match draw(st.integers(0, 3)):
            case 0:
                term = Add(term, t)
            case 1:
                term = Add(term, Mul(Const(Fraction(-1)), t))  # t − s, as the desugarer writes it
            case 2:
                term = Mul(Add(term, t), Pow(Const(draw(st.sampled_from([Fraction(2), Fraction(-3), Fraction(5, 4)]))),
                                             Fraction(-1)))
            case 3:
                term = Add(Mul(Const(Fraction(draw(st.integers(1, 4)))), term), t)
    return term, tuple(variables)


@settings(max_examples=300, deadline=None, derandomize=True)
@given(affine_conditions())
def test_direct_completion_is_sympys(case):
    cond, variables = case
    direct = affine.complete(cond, variables)
    try:
        reference = _sympy_completion(cond, variables)
    except diffeo.CompletionError:
        assert direct is None  # every variable cancels: the sympy path says why
        return
    assert direct is not None
    assert direct == reference
    assert direct.branches == reference.branches  # Diffeo equality compares these; be explicit
    assert direct.inputs == reference.inputs and direct.solved_for == reference.solved_for


def test_complete_takes_the_direct_path_and_agrees():
    cond = Add(Var("x"), Mul(Const(Fraction(-1)), Param("theta")))
    assert diffeo.complete(cond, ("x",)) == _sympy_completion(cond, ("x",))


def test_not_affine_is_left_to_sympy():
    x, y, a = Var("x"), Var("y"), Param("a")
    for cond in (Add(y, Mul(Const(Fraction(-1)), Pow(x, Fraction(2)))),  # a graph y − x²
                 Mul(a, x),  # a parametric coefficient
                 Add(x, Prim("exp", y)),
                 Add(x, Const("pi"))):
        assert affine.complete(cond, ("x", "y")) is None


def test_rational_value():
    assert affine.rational_value(Mul(Const(Fraction(3)), Pow(Const(Fraction(2)), Fraction(-2)))) == Fraction(3, 4)
    assert affine.rational_value(Const("pi")) is None
    assert affine.rational_value(Param("a")) is None
    assert affine.rational_value(Pow(Const(Fraction(0)), Fraction(-1))) is None


def test_the_box_of_affine_indicators_is_sympys():
    # support.infer_box's direct path (rational bounds, no sympy) against its sympy path
    from langur.frontend import core_term_from_text
    from langur.syntax import support

    cases = [("[0 <= x <= 1] * [x <= y] * [y <= 2] * x", ("x", "y")),
             ("[0 <= y] * [y <= x] * [x <= 1/3] * [2*x - y >= -1] * y", ("x", "y")),
             ("[-1 <= x + y] * [x - y <= 2] * [0 <= y <= 1] * [x <= 3/2] * 1", ("x", "y")),
             ("[x >= 0] * [1 >= x] * (if y > 0 then 1 else 0) * [y <= 1] * [0 <= y]", ("x", "y"))]
    for text, xs in cases:
        body = core_term_from_text(text, xs)
        direct = support._rational_box(body, xs)
        assert direct is not None
        original = support._rational_box
        try:
            support._rational_box = lambda body, variables: None  # the sympy path
            reference = support.infer_box(body, xs)
        finally:
            support._rational_box = original
        assert direct == reference
