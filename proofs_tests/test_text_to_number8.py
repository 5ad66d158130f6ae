"""A loop's copies built step by step for all of them at once, tenth pass (issue 15, branch front8):
``Template.at_all`` against ``Template.at`` copy by copy, and ``core.like_binary_many`` against
``core.like_binary`` pair by pair — equal terms, every kept attribute the same, the same
conditionals told to an enclosing loop — and a range with a copy that does not complete gives None
(the desugarer then builds the copies one by one and reports it, as before); the first copy's
completion keeps its solved shape for the template (``affine.solved_by``).
"""

from __future__ import annotations

import random
from fractions import Fraction

import pytest

from langur import core
from langur.core import attributes
from langur.diagnostics import LangurError
from langur.frontend import clear_load_cache, core_term_from_text, load_text
from langur.syntax import affine, template


def _same(s: core.Term, t: core.Term) -> None:
    """``s`` and ``t`` equal, with the same kept attributes at every node (and diffeo summaries)."""
    assert s == t
    stack = [(s, t)]
    while stack:
        a, b = stack.pop()
        assert type(a) is type(b)
        assert core.kept_attributes(a) == core.kept_attributes(b), (a, b)
        assert a.span == b.span
        if type(a) is core.IfDiffeo:
            assert a.psi == b.psi
            assert attributes._diffeo_summary(a.psi) == attributes._diffeo_summary(b.psi)
        stack.extend(zip(core.children(a), core.children(b)))


def _templates(text: str) -> list[template.Template]:
    """The templates a load of ``text`` makes (one per loop whose copies are instantiated)."""
    made: list[template.Template] = []
    init = template.Template.__init__

    def watch(self, *args):
        init(self, *args)
        made.append(self)

    template.Template.__init__ = watch
    clear_load_cache()
    try:
        load_text(text, "t.lgr")
    except LangurError:
        pass
    finally:
        template.Template.__init__ = init
    return made


_BODIES = [
    "[x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x)",            # microbenchmark 1's body
    "[a - x - i/3 >= 0] * (x*i + i^-2)",                      # a negated summand, a power of i
    "[2*(x + i/5) + 1 <= a] * exp(x/i)",                      # a constant factor, a primitive
    "[x + (i - 2)*a >= 0] * (x + 1)",                         # a coefficient solved again per copy
    "[x + y/(i + 3) >= 1/2] * y",                             # a variable's coefficient moves
    "[y - x^2 >= i/8] * (x + y)",                             # not affine: completed again
    "[a - 1/2 >= 0] * (x + i) + [x - i/7 >= 0] * y",          # a conditional on the parameters
    "[x - 1/i >= 0] * (sum j in 1..3: [y - j/i >= 0] * (x + j))",  # an inner loop
]


def _collector(notes: list):
    return lambda *note: notes.append(note)


@pytest.mark.parametrize("body", _BODIES)
def test_at_all_is_at_copy_by_copy(body):
    text = f"param a = 0.5\nint ([0, 1], [0, 1]) (sum i in 1..6: {body}) d(x, y)\n"
    made = _templates(text)
    assert made, "no template made"
    for plan in made:
        notes: list = []
        plan.completed = _collector(notes)
        built = plan.at_all(range(2, 7))
        by_all = notes[:]
        notes.clear()
        one = [plan.at(k) for k in range(2, 7)]
        assert built is not None and None not in one
        assert len(built) == len(one) == 5
        for s, t in zip(built, one):
            _same(s, t)
        # the conditionals completed again, told in the same order with equal conditions and boxes
        assert [(type(n[0]), n[1], n[2], n[3]) for n in by_all] == [(type(n[0]), n[1], n[2], n[3]) for n in notes]
        for a, b in zip(by_all, notes):
            _same(a[0], b[0])


def test_at_all_refuses_a_range_with_a_copy_that_does_not_complete():
    # i = 0: `0 * x - 1 >= 0` has no variable to isolate
    (plan,) = _templates("int ([0, 2]) (sum i in -2..2: [i*x - 1 >= 0] * x) d(x)\n")
    assert plan.at_all(range(-1, 3)) is None
    assert plan.at_all(range(1, 3)) is not None
    assert plan.at(0) is None


def test_a_loop_with_a_copy_that_does_not_complete_reports_it_once():
    # (i = 2: (2 - 2)*x - 1 has no variable to isolate; since fold31 a copy `0*x - 1` at i = 0 folds to the
    # variable-free [-1 >= 0], which loads: the copy that does not complete is at i = 2 here)
    text = "int ([0, 2]) (sum i in -2..4: [(i - 2)*x - 1 >= 0] * x) d(x)\n"
    errors = []
    for enabled in (True, False):
        template.ENABLED = enabled
        clear_load_cache()
        try:
            load_text(text, "t.lgr")
            errors.append([])
        except LangurError as e:
            errors.append([d.format() for d in e.diagnostics])
        finally:
            template.ENABLED = True
    assert errors[0] == errors[1] and len(errors[0]) == 1 and "T207" in errors[0][0]
    assert errors[0][0].startswith("t.lgr:1:")


def test_like_binary_many_is_like_binary():
    r = random.Random(3)
    leaves = [core.Var("x"), core.Param("a"), core.Const(Fraction(0)), core.Const(Fraction(1)),
              core.Const(Fraction(-3, 7)), core.Const(Fraction(2) ** 300), core.Const("pi"),
              core.Const(Fraction(1, 2 ** 300))]
    for cls in (core.Add, core.Mul):
        first = cls(core.Const(Fraction(2)), core.Const(Fraction(5)), span=None)
        shape = core.shape_with_span(first)
        lefts = [r.choice(leaves[2:]) for _ in range(40)]
        rights = [r.choice(leaves[2:]) for _ in range(40)]
        for s, a, b in zip(core.like_binary_many(cls, shape, lefts, rights), lefts, rights):
            _same(s, core.like_binary(cls, shape, a, b))
            _same(s, cls(a, b))
        first = cls(core.Var("x"), core.Const(Fraction(2)))
        shape = core.shape_with_span(first)
        rights = [r.choice(leaves[2:]) for _ in range(40)]
        for s, b in zip(core.like_binary_many(cls, shape, [leaves[0]] * 40, rights), rights):
            _same(s, cls(leaves[0], b))
        # children over a variable whose constants are not all small (no small value, `_small_all` false)
        psi = affine.complete(core.Add(core.Var("x"), core.Const(Fraction(-1))), ("x",))
        lefts = [core.IfDiffeo(psi, core.Const(Fraction(k, 2 ** 300)), core.Const(Fraction(0))) for k in (1, 3)]
        lefts += [core.IfDiffeo(psi, core.Const(Fraction(k)), core.Const(Fraction(0))) for k in (1, 3)]
        shape = core.shape_with_span(cls(lefts[0], core.Var("x")))
        built = core.like_binary_many(cls, shape, lefts, [core.Var("x")] * 4)
        assert [s.small_all for s in built] == [False, False, True, True]
        for s, a in zip(built, lefts):
            _same(s, cls(a, core.Var("x")))


@pytest.mark.parametrize("text", ["x + 1/7 + a - 1", "2*x - y + 3*a - 1/5", "-x + 2*y - 1/3", "x/3 - a"])
def test_a_completion_keeps_what_it_solved(text):
    # the template reads the first copy's solved shape off its Ψ̂ (affine.solved_by) instead of
    # solving the condition again: the same shape and constant term as solving it
    cond = core_term_from_text(text, params=("a",), variables=("x", "y"))
    for variables in (("x", "y"), ("y", "x")):
        psi = affine.complete(cond, variables)
        expected = affine.solve(cond, variables)
        assert affine.solved_by(psi, cond, variables) == expected
        # another condition of that value, or other variables: solved again, not read off psi
        other = core_term_from_text(text, params=("a",), variables=("x", "y"))
        assert affine.solved_by(psi, other, variables) == affine.solve(other, variables)
        swapped = variables[::-1]
        assert affine.solved_by(psi, cond, swapped) == affine.solve(cond, swapped)
    avoiding = affine.complete(cond, ("x", "y"), frozenset({"x"}))  # (None when only x occurs)
    assert avoiding is None or core.kept_solved(avoiding) is None
