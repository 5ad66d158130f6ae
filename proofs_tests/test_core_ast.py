"""Unit tests of the core AST's structural helpers (langur/core/structural.py)."""

from fractions import Fraction

from langur.core import (
    Add,
    Const,
    Diffeo,
    IfDiffeo,
    InverseBranch,
    Let,
    Param,
    Var,
    extend_diffeo,
    free_params,
    free_vars,
    sub,
    substitute,
)


def shift(a="a"):
    return Diffeo(("x",), (sub(Var("x"), Param(a)),), ("u0",), (InverseBranch((Add(Var("u0"), Param(a)),)),),
                  solved_for="x")


def test_let_binds_its_name():
    t = Let("b", Param("a"), IfDiffeo(shift("b"), Param("b"), Const(Fraction(0))))
    assert free_params(t) == {"a"}
    assert free_vars(t) == {"x"}


def test_extend_adds_identity_components_in_requested_order():
    psi = extend_diffeo(shift(), ("y", "x"))
    assert psi.variables == ("y", "x")
    assert psi.forward[1] == Var("y")
    (b,) = psi.branches
    # y = u1 (the fresh input), x = u0 + a
    assert b.components == (Var("u1"), Add(Var("u0"), Param("a")))


def test_substitute_renames_diffeo_variables_and_params():
    t = IfDiffeo(shift(), Var("x"), Const(Fraction(0)))
    s = substitute(t, {"x": Var("z")}, {"a": Param("c")})
    assert s.psi.variables == ("z",) and s.psi.solved_for == "z"
    assert s.psi.forward[0] == sub(Var("z"), Param("c"))
    assert s.then == Var("z")
