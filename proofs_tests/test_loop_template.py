"""A loop's copies built from its first (``langur/syntax/template.py``, issue 15) are the copies
desugaring each one gives (§9: ``sum i in A..B: t`` is ``t[A/i] + … + t[B/i]``).

Random loop bodies — the index in sums, products, quotients, conditions (completed affine or by
sympy), primitives, lets, exponents and inner loops' bounds, with kinks and with copies whose
condition cannot be completed — are loaded twice, with the instantiation on and off (then every
copy is desugared from the surface, the path before it existed): the core programs must be equal,
print the same, give the same diagnostics and the same seeded Monte Carlo numbers.  The counters
check that the instantiation was taken (and refused) on a good share of them, so the comparison is
not vacuous.
"""

from __future__ import annotations

import random

import pytest

from langur import core, operational
from langur.core import attributes
from langur.diagnostics import LangurError
from langur.frontend import clear_load_cache, load_text
from langur.syntax import copies, template
from langur.syntax.printer import print_program


def _atom(r: random.Random, names: list[str]) -> str:
    return r.choice(names + ["1", "2", "1/2", "3/4"])


def _term(r: random.Random, names: list[str], depth: int) -> str:
    """A random real-valued surface term over ``names`` (variables, parameters, indices)."""
    if depth == 0 or r.random() < 0.25:
        return _atom(r, names)
    k = r.randrange(9)
    a = _term(r, names, depth - 1)
    if k == 0:
        return f"({a} + {_term(r, names, depth - 1)})"
    if k == 1:
        return f"({a} - {_term(r, names, depth - 1)})"
    if k == 2:
        return f"({a} * {_term(r, names, depth - 1)})"
    if k == 3:
        return f"({a} / ({_atom(r, names)} + 2))"
    if k == 4:
        return f"sin({a})"
    if k == 5:
        return f"({a})^{r.choice(['2', '3', 'i'] if 'i' in names else ['2', '3'])}"
    if k == 6:
        return f"[{_cond(r, names)}]"
    if k == 7:
        return f"(let z = {_atom(r, [n for n in names if n not in ('x', 'y')])} * a in ({a}) * z)"
    return f"(if {_cond(r, names)} then {a} else {_term(r, names, depth - 1)})"


def _cond(r: random.Random, names: list[str]) -> str:
    """A comparison over the variables: affine in them mostly (the direct completion), sometimes a
    graph (sympy), a kink (abs: split) or a coefficient that is the index (0 for one copy)."""
    idx = [n for n in names if n in ("i", "j")] or ["1"]
    k = r.randrange(6)
    op = r.choice([">=", "<=", ">", "<"])
    if k <= 2:
        return f"x + {r.choice(['', 'y + '])}{_atom(r, names)}/{r.choice(['2', '3', '(i + 1)' if 'i' in names else '5'])} {op} a"
    if k == 3:
        return f"y - x^2 {op} {r.choice(idx)}/4"
    if k == 4:
        return f"abs(x - {r.choice(idx)}/3) {op} a"
    return f"{r.choice(idx)} * x - 1 {op} 0"


def _program(r: random.Random) -> str:
    names = ["x", "y", "a", "b", "i"]
    body = _term(r, names, 3)
    if r.random() < 0.3:  # an inner loop: bounds with or without the outer index
        hi = r.choice(["2", "i", "i + 1"])
        body = f"{body} + (sum j in 1..{hi}: {_term(r, names + ['j'], 2)})"
    if r.random() < 0.2:  # the loop inside a condition, with a conditional on the parameters in its body
        body = (f"(if a >= {r.choice(['0.2', '0.7'])} then x else {r.choice(['2*x', 'x + y'])}) + "
                f"{r.choice(['i', '1/(i + 1)', 'b*i'])} * {r.choice(['y', 'a', '1/2'])}")
        lo, hi = r.choice([0, 1]), r.choice([2, 3])
        return (f"param a = 0.5\nparam b = 0.25\nint ([0, 1], [0, 1]) [(sum i in {lo}..{hi}: {body}) >= 1] "
                f"* (1 + b) d(x, y)\n")
    lo = r.choice([0, 1, 2])
    hi = lo + r.choice([1, 2, 3, 5])
    op = r.choice(["sum", "sum", "prod"])
    return f"param a = 0.5\nparam b = 0.25\nint ([0, 1], [0, 1]) ({op} i in {lo}..{hi}: {body}) * (1 + b) d(x, y)\n"




def _same_attributes(s: core.Term, t: core.Term) -> None:
    """``s`` and ``t`` (equal terms) carry the same kept attributes at every node (``core.like``
    builds a copy's nodes from the first copy's shape: they must be those the constructors give),
    and their diffeos the same summary."""
    stack = [(s, t)]
    seen = set()
    while stack:
        a, b = stack.pop()
        if (id(a), id(b)) in seen:
            continue
        seen.add((id(a), id(b)))
        assert core.kept_attributes(a) == core.kept_attributes(b), (a, b)
        if type(a) is core.IfDiffeo:
            assert attributes._diffeo_summary(a.psi) == attributes._diffeo_summary(b.psi)
        stack.extend(zip(core.children(a), core.children(b)))


def _load(text: str, enabled: bool):
    template.ENABLED = enabled
    clear_load_cache()
    try:
        loaded = load_text(text, "t.lgr")
    except LangurError as e:
        return None, [d.format() for d in e.diagnostics]
    finally:
        template.ENABLED = True
    return loaded, []


@pytest.mark.parametrize("seed", range(4))
def test_instantiated_copies_are_the_desugared_copies(seed):
    r = random.Random(seed)
    before = dict(copies.STATS)
    loaded_ok = 0
    for _ in range(40):
        text = _program(r)
        new, new_errors = _load(text, True)
        old, old_errors = _load(text, False)
        assert new_errors == old_errors, text
        if old is None:
            assert new is None, text
            continue
        loaded_ok += 1
        assert new.program == old.program, text
        _same_attributes(new.program.body, old.program.body)
        assert print_program(new.program) == print_program(old.program), text
        if loaded_ok % 4 == 0:  # the Monte Carlo numbers (a DAG where copies share subterms: same numbers)
            at, d = new.param_values({}), {"a": 1.0}
            x = operational.estimate_derivative(new, at, d, samples=200, seed=seed)
            y = operational.estimate_derivative(old, at, d, samples=200, seed=seed)
            assert (x.value, x.regular, x.boundary) == (y.value, y.regular, y.boundary), text
    assert loaded_ok >= 10
    # the new path was taken (the copies at i = 0 and 1 are desugared on their own since fold31: there
    # the index folds, x * 1 is x)
    assert copies.STATS["instantiated"] - before["instantiated"] >= 20


@pytest.mark.parametrize("cond, shifted", [
    ("x + 1/i - a >= 0", 2),            # the index in a constant summand
    ("a - x - i/3 >= 0", 2),            # under a negation: the summand's factor is -1
    ("2*(x + i/5) + 1 <= a", 2),        # under a constant factor
    ("x + (i - 2)*a >= 0", 0),          # a coefficient of a parameter: solved again per copy
    ("x + y/(i + 1) >= 1/2", 0),        # a coefficient of a variable: solved again per copy
    ("y - x^2 >= i/8", 0),              # not affine (sympy): completed again per copy
])
def test_conditions_of_one_shape_move_their_constant_term_only(cond, shifted):
    # a copy's condition that differs from the first's in constant summands only is completed by
    # adding up its constant term (affine.summands); the others by the completion itself: either
    # way the copies are those desugaring each one gives
    text = f"param a = 0.5\nint ([0, 1], [0, 1]) (sum i in 1..4: [{cond}] * (x + i)) d(x, y)\n"
    before = dict(copies.STATS)
    new, new_errors = _load(text, True)
    old, old_errors = _load(text, False)
    assert new_errors == old_errors == []
    assert new.program == old.program
    _same_attributes(new.program.body, old.program.body)
    assert print_program(new.program) == print_program(old.program)
    assert copies.STATS["instantiated"] - before["instantiated"] == 2  # i = 3, 4 (i = 1 folds: on its own, fold31)
    assert copies.STATS["shifted"] - before["shifted"] == shifted
    at, d = new.param_values({}), {"a": 1.0}
    assert (operational.estimate_derivative(new, at, d, samples=50, seed=1).value
            == operational.estimate_derivative(old, at, d, samples=50, seed=1).value)


def test_a_copy_that_does_not_complete_is_desugared_and_refused():
    # i = 3: `(3 - 3) * x - 1 >= 0` has no variable to isolate; the copies i = 2, 4 complete (the
    # template is made at i = 2: copies at i = 0 and 1 are desugared on their own since fold31)
    text = "int ([0, 2]) (sum i in 2..4: [(i - 3)*x - 1 >= 0] * x) d(x)\n"
    refused = copies.STATS["refused"]
    new, new_errors = _load(text, True)
    old, old_errors = _load(text, False)
    assert new is None and old is None
    assert new_errors == old_errors and "T207" in new_errors[0]
    assert copies.STATS["refused"] == refused + 1


def test_microbenchmark_one_is_instantiated():
    # §10.3.2's microbenchmark 1 at n = 49: the copies but the first of each loop are instantiated
    n = 49
    text = (f"param a = 1\nint ([-1, 1]) (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x))"
            f" + (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")
    count, shifted = copies.STATS["instantiated"], copies.STATS["shifted"]
    new, _ = _load(text, True)
    assert copies.STATS["instantiated"] == count + 2 * (n - 1)
    assert copies.STATS["shifted"] == shifted + 2 * (n - 1)  # each copy's condition: its constant term
    old, _ = _load(text, False)
    assert new.program == old.program
    _same_attributes(new.program.body, old.program.body)
    at, d = new.param_values({}), {"a": 1.0}
    assert (operational.estimate_derivative(new, at, d, samples=10, seed=0).value
            == operational.estimate_derivative(old, at, d, samples=10, seed=0).value)


def test_a_conditional_on_the_parameters_is_copied():
    # the loop's sum inside a condition: the desugarer lifts each `if a >= 0.2 …` out of the condition
    # by its identity (conditionals.put); copies sharing it would lift them all at once (another term)
    text = ("param a = 0.5\nint ([0, 2]) [(sum i in 1..3: (if a >= 0.2 then x else 2*x) + i/4) >= 1]"
            " + (sum i in 1..3: [min(x, a + i/5) >= 0.4]) d(x)\n")
    new, _ = _load(text, True)
    old, _ = _load(text, False)
    assert new.program == old.program
    assert print_program(new.program) == print_program(old.program)
