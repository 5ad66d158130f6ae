"""The attributes a core node keeps (langur/core/attributes.py, issue 15) against the
walks they replace, and typing read off them (``typesys.well_typed``) against Fig. 6's rules
applied one by one (an observer recording forces the rules: ``show --typing`` sees every one).

The walks here are written out independently of the kept attributes (plain recursion over
``children``); the rules are ``typesys.type_term`` itself.  ``well_typed`` must never say yes
where the rules report something (it is used in their place); on the front end's output it must
say yes (else it saves nothing)."""

from __future__ import annotations

import glob
import os
import pickle
from fractions import Fraction

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from langur import observe
from langur import strategies as ls
from langur import typesys as ty
from langur.core import (
    Add,
    Call,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    ImplicitRoot,
    InverseBranch,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Var,
    children,
    depth,
    free_params,
    free_vars,
    map_children,
    smooth,
    subterms,
    tree_size,
)
from langur.frontend import load

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "examples")


def _walk_fv(t):
    match t:
        case Var(x):
            return {x}
        case IfDiffeo(psi, a, b):
            return set(psi.variables) | _walk_fv(a) | _walk_fv(b)
        case ImplicitRoot(eq, x, target, lo, hi):
            return (_walk_fv(eq) - {x}) | _walk_fv(target) | _walk_fv(lo) | _walk_fv(hi)
    out = set()
    for c in children(t):
        out |= _walk_fv(c)
    return out


def _walk_fp(t):
    match t:
        case Param(z):
            return {z}
        case Let(z, bound, body):
            return _walk_fp(bound) | (_walk_fp(body) - {z})
        case IfDiffeo(psi, a, b):
            out = _walk_fp(a) | _walk_fp(b)
            for f in psi.forward:
                out |= _walk_fp(f)
            return out
    out = set()
    for c in children(t):
        out |= _walk_fp(c)
    return out


def _walk_smooth(t):
    if isinstance(t, (IfGe0, IfDiffeo, Call)):
        return False
    return all(_walk_smooth(c) for c in children(t))


def _walk_size(t):
    return 1 + sum(_walk_size(c) for c in children(t))


def _walk_depth(t):
    below = [_walk_depth(c) for c in children(t)]
    if isinstance(t, IfDiffeo):
        below.append(_walk_depth(t.psi.forward[0]) if t.psi.name is None else 1)
    return 1 + max(below, default=0)


def _rules(delta, gamma, t):
    """The diagnostics of Fig. 6's rules applied one by one (an observer forces them)."""
    out = []
    with observe.observing():
        ty.type_term(frozenset(delta), frozenset(gamma), t, out)
    return out


def _check_attributes(t):
    for u in subterms(t):
        assert free_vars(u) == _walk_fv(u)
        assert free_params(u) == _walk_fp(u)
        assert smooth(u) == _walk_smooth(u)
        assert tree_size(u) == _walk_size(u)
        assert depth(u) == _walk_depth(u)


def _example_programs():
    for path in sorted(glob.glob(os.path.join(EXAMPLES, "*.lgr"))):
        loaded = load(path)
        if loaded.program is not None and tree_size(loaded.program.body) < 5000:
            yield loaded


def test_the_kept_attributes_are_the_walks_on_every_example_and_after_unpickling():
    n = 0
    for loaded in _example_programs():
        body = loaded.program.body
        _check_attributes(body)
        _check_attributes(pickle.loads(pickle.dumps(body)))
        n += 1
    assert n >= 8


def test_typing_read_off_the_attributes_agrees_with_the_rules_on_every_example():
    for loaded in _example_programs():
        p = loaded.program
        delta, gamma = frozenset(p.variables), frozenset(loaded.params)
        assert ty.well_typed(delta, gamma, p.body)
        assert _rules(delta, gamma, p.body) == []


# -- ill-typed variants: each premise of Fig. 6 broken somewhere in a generated program ---------

X = Var("x")


def _breakers():
    """Ways to break a subterm ``u``: each gives a term that violates one premise (or, by chance,
    none: the property is an implication)."""
    bad_psi = Diffeo(("x",), (Add(X, Param("a")),), ("u0",), (InverseBranch((Var("x"),)),))  # branch over x, not u0
    return [
        lambda u: Add(u, Var("nowhere")),                          # a variable not in Δ
        lambda u: Mul(u, Param("undeclared")),                     # a parameter not in Γ
        lambda u: IfGe0(Add(X, Const(Fraction(1))), u, u),         # a plain condition over variables
        lambda u: Let("x", Const(Fraction(2)), u),                 # let binds a variable
        lambda u: Let("z", X, u),                                  # let of a term with variables
        lambda u: Let("a", Const(Fraction(1)), Mul(u, Param("a"))),  # fine: a let-bound parameter
        lambda u: Prim("no_such_primitive", u),                    # an unknown primitive
        lambda u: Pow(u, 2.5),                                     # an exponent that is not rational
        lambda u: IfDiffeo(bad_psi, u, Const(Fraction(0))),        # a diffeo's inverse over its variables
        lambda u: IfDiffeo(Diffeo(("x", "x"), (X, X), ("u0", "u1"), ()), u, u),  # repeated variables
        lambda u: u,
    ]


def _replace_at(t, k, f):
    """``t`` with its ``k``-th subterm (pre-order over the tree) replaced by ``f`` of it."""
    count = [0]

    def go(u):
        if count[0] == k:
            count[0] += 1
            return f(u)
        count[0] += 1
        return map_children(u, go)

    return go(t)


@settings(max_examples=40, deadline=None, suppress_health_check=list(HealthCheck))
@given(ls.cores(max_variables=2, light=True, lets=True), st.integers(0, 10_000), st.integers(0, 10))
def test_well_typed_never_says_yes_where_the_rules_report(loaded, where, how):
    p = loaded.program
    delta, gamma = frozenset(p.variables), frozenset(loaded.params)
    assert ty.well_typed(delta, gamma, p.body) and _rules(delta, gamma, p.body) == []
    _check_attributes(p.body)
    size = tree_size(p.body)
    if size > 3000:
        return
    broken = _replace_at(p.body, where % size, _breakers()[how])
    _check_attributes(broken)
    if ty.well_typed(delta, gamma, broken):
        assert _rules(delta, gamma, broken) == []
    else:
        # the attributes say no: the rules say why, and type_term (unobserved) reports the same
        out = []
        ty.type_term(delta, gamma, broken, out)
        assert out == _rules(delta, gamma, broken)
