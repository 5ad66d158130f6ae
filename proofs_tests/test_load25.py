"""Loading at small n, fifth pass (issue 15, branch load25), against independent references.

* ``gcpause.kept`` (a load's pause): when the block ends without an exception and the collector was
  on, every tracked object the load made is in the collector's oldest generation (``gc.get_objects``
  by generation), so no young collection traverses them; the collector's state is restored, a
  caller's frozen objects stay frozen, and nothing is moved when the collector was off or the block
  raised.
* ``template.Template._plan``: planning a loop's first copy in one recursive walk gives the steps,
  slots, shared nodes and dependencies that its walk with a stack of its own gives (load26: the two
  walks make their steps by one function; before, the stack walk ``_mark`` and ``_compile``), on random loop bodies (test_loop_template's generator); a first copy deeper than the walk's
  bound takes the stack walk, and its copies are still those desugaring each one gives.
* ``affine.solved_at_ratios``: each Ψ̂ is ``solved_at_ratio``'s (None where a key is None), and
  equal keys share their inverse branches as one by one.
* ``affine._linear`` by class: the linear form of random terms equals a walk over their fields in
  ``Fraction`` arithmetic; ``Program.body`` is computed once and kept.
"""

from __future__ import annotations

import dataclasses
import gc
import pickle
import random
from fractions import Fraction

import pytest
from test_loop_template import _load, _program, _same_attributes

from langur import core, frontend, gcpause
from langur.core import Add, Const, Mul, Param, Pow, Prim, Var
from langur.diagnostics import LangurError
from langur.syntax import affine, template

MB1 = ("param a = 1\nint ([-1, 1]) (sum i in 1..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x)) + "
       "(sum i in 1..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")


def _nodes(t) -> list:
    out, stack, seen = [], [t], set()
    while stack:
        u = stack.pop()
        if id(u) in seen:
            continue
        seen.add(id(u))
        out.append(u)
        stack.extend(core.children(u))
    return out


# --- gcpause.kept -------------------------------------------------------------------------------

def test_a_load_leaves_what_it_made_in_the_oldest_generation():
    assert gc.isenabled()
    frontend.clear_load_cache()
    loaded = frontend.load_text(MB1)
    assert gc.isenabled()
    oldest = {id(o) for o in gc.get_objects(generation=2)}
    nodes = _nodes(loaded.program.body)
    assert len(nodes) > 150
    # every node the load made (and the program) is in generation 2: none waits in a younger one,
    # where the first young collection would traverse it (on main they are in generation 0 or 1)
    assert all(id(u) in oldest for u in nodes)
    assert id(loaded.program) in oldest
    young = {id(o) for g in (0, 1) for o in gc.get_objects(generation=g)}
    assert not any(id(u) in young for u in nodes)


def test_kept_restores_the_collector_and_moves_nothing_when_it_was_off_or_raised():
    gc.disable()
    try:
        with gcpause.kept():
            assert not gc.isenabled()
            made = [[i] for i in range(50)]
        assert not gc.isenabled()  # left off, as it was
        oldest = {id(o) for o in gc.get_objects(generation=2)}
        assert not any(id(x) in oldest for x in made)  # not moved: the collector was off
    finally:
        gc.enable()
    with pytest.raises(LangurError):
        frontend.load_text("int ([0, 1]) x + d(x)\n")  # a syntax error: the block raises
    assert gc.isenabled()
    with pytest.raises(ValueError):
        with gcpause.kept():
            made = [[i] for i in range(50)]
            raise ValueError
    assert gc.isenabled()
    oldest = {id(o) for o in gc.get_objects(generation=2)}
    assert not any(id(x) in oldest for x in made)  # not moved: the block raised
    with gcpause.kept():
        with gcpause.kept():  # nested: the inner block leaves it off, the outer one moves
            assert not gc.isenabled()
        assert not gc.isenabled()
        made = [[i] for i in range(50)]
    assert gc.isenabled()
    oldest = {id(o) for o in gc.get_objects(generation=2)}
    assert all(id(x) in oldest for x in made)


def test_a_callers_frozen_objects_stay_frozen():
    frontend.clear_load_cache()
    keep = [[i] for i in range(100)]
    gc.freeze()
    try:
        assert gc.get_freeze_count() >= len(keep)
        loaded = frontend.load_text(MB1)
        assert gc.isenabled()
        tracked = {id(o) for g in range(3) for o in gc.get_objects(generation=g)}
        assert not any(id(x) in tracked for x in keep)  # still in the permanent generation
        assert gc.get_freeze_count() >= len(keep)
        # (and the load moved nothing: its objects are where allocation put them, not in the oldest)
        oldest = {id(o) for o in gc.get_objects(generation=2)}
        assert id(loaded.program) not in oldest
    finally:
        gc.unfreeze()


# --- template._plan -----------------------------------------------------------------------------

def _by_stack_walk(plan: template.Template) -> template.Template:
    """The same first copy planned by the walk with a stack of its own."""
    bound = template._MARK_DEPTH
    template._MARK_DEPTH = -1  # (every node is deeper: _plan falls back at once)
    try:
        return template.Template(plan.body, plan.record, plan.complete, plan.completed)
    finally:
        template._MARK_DEPTH = bound


def _same_plan(a: template.Template, b: template.Template) -> None:
    assert a.dependent == b.dependent
    assert a.usable == b.usable
    if not a.dependent[id(a.body)] or not a.usable:
        return
    assert a.steps == b.steps
    assert [id(u) for u in a.first] == [id(u) for u in b.first]
    assert [id(u) for u in a.shared] == [id(u) for u in b.shared]
    assert (a.powers, a.exponents) == (b.powers, b.exponents)
    assert [id(u) for u in a.start] == [id(u) for u in b.start] and a.start_same == b.start_same


@pytest.mark.parametrize("seed", range(3))
def test_one_walk_plans_as_the_stack_walk_and_compile_do(seed, monkeypatch):
    built: list[template.Template] = []
    real = template.Template

    class Watched(real):
        def __init__(self, *args):
            super().__init__(*args)
            built.append(self)

    monkeypatch.setattr(template, "Template", Watched)
    r = random.Random(100 + seed)
    for _ in range(30):
        built.clear()
        _load(_program(r), True)
        for plan in list(built):
            _same_plan(plan, _by_stack_walk(plan))
    frontend.clear_load_cache()
    built.clear()
    frontend.load_text(MB1)
    assert len(built) == 2
    for plan in list(built):
        _same_plan(plan, _by_stack_walk(plan))
        # (14 and 10 since fold31: the condition's `- 0` is gone, one dependent node and one shared constant fewer)
        assert len(plan.steps) == 14 and len(plan.shared) == 10


def test_a_first_copy_deeper_than_the_walk_takes_the_stack_walk(monkeypatch):
    deep = "i/2"
    for _ in range(150):  # (the parser's bound is 200 levels) each `x - …` two levels of the core: 300
        deep = f"(x - {deep})"
    text = f"param a = 0.5\nint ([0, 1]) (sum i in 1..3: [x + i/4 >= a] * {deep}) d(x)\n"
    marked = []

    class Deep(template._Deep):  # (what the recursive walk raises past _MARK_DEPTH, caught by _plan)
        def __init__(self, *args):
            marked.append(1)
            super().__init__(*args)

    monkeypatch.setattr(template, "_Deep", Deep)
    new, new_errors = _load(text, True)
    assert marked  # the stack walk was taken
    old, old_errors = _load(text, False)
    assert new_errors == old_errors == []
    _same_tree(new.program.body, old.program.body)  # (== and the printer recurse on the depth)
    _same_attributes(new.program.body, old.program.body)


def _same_tree(s, t) -> None:
    """``s == t`` without recursion: the same class and fields at every node, Ψ̂ included."""
    stack = [(s, t)]
    while stack:
        a, b = stack.pop()
        assert type(a) is type(b)
        kids_a, kids_b = core.children(a), core.children(b)
        assert len(kids_a) == len(kids_b)
        for f in dataclasses.fields(a):
            x, y = getattr(a, f.name), getattr(b, f.name)
            if f.compare and not any(x is k for k in kids_a):
                assert x == y, (f.name, x, y)
        stack.extend(zip(kids_a, kids_b))


# --- affine.solved_at_ratios ----------------------------------------------------------------------

def test_psis_built_in_one_loop_are_those_built_one_by_one():
    x, a = Var("x"), Param("a")
    conds = [core.sub(Add(Add(x, Const(Fraction(1, k))), a), Const(Fraction(1))) for k in range(1, 8)]
    found = affine.solve(conds[0], ("x",))
    assert found is not None
    solved, _ = found
    keys = []
    for k in range(1, 8):  # −(1/k − 1) over the coefficient 1, in lowest terms; one key None
        c = -(Fraction(1, k) - 1)
        keys.append(None if k == 4 else (c.numerator, c.denominator))
    keys.append(keys[1])  # a repeated constant: the same branches
    conds.append(conds[1])
    many = affine.solved_at_ratios(conds, ("x",), solved, keys)
    assert many[3] is None
    for cond, key, psi in zip(conds, keys, many):
        if key is None:
            continue
        one = affine.solved_at_ratio(cond, ("x",), solved, *key)
        assert psi == one and psi.branches is one.branches  # the shape's table: one branch per constant
        assert psi.forward[0] is cond and psi.span is cond.span
        reference = affine.complete(cond, ("x",))  # the completion itself
        assert psi == reference
    assert many[-1].branches is many[1].branches


# --- affine._linear, Program.body -----------------------------------------------------------------

def _reference_linear(t):
    """The affine form of ``t`` by its fields, in Fraction arithmetic (None when not affine)."""
    if isinstance(t, Const):
        return ({}, t.value) if isinstance(t.value, Fraction) else None
    if isinstance(t, Var):
        return {("v", t.name): Fraction(1)}, Fraction(0)
    if isinstance(t, Param):
        return {("p", t.name): Fraction(1)}, Fraction(0)
    if isinstance(t, Add):
        la, lb = _reference_linear(t.left), _reference_linear(t.right)
        if la is None or lb is None:
            return None
        coeffs = dict(la[0])
        for k, c in lb[0].items():
            coeffs[k] = coeffs.get(k, 0) + c
        return {k: c for k, c in coeffs.items() if c}, la[1] + lb[1]
    if isinstance(t, Mul):
        la, lb = _reference_linear(t.left), _reference_linear(t.right)
        if la is None or lb is None or (la[0] and lb[0]):
            return None
        c, form = (la[1], lb) if not la[0] else (lb[1], la)
        return {k: c * v for k, v in form[0].items() if c * v}, c * form[1]
    if isinstance(t, Pow):
        lb = _reference_linear(t.base)
        if lb is None:
            return None
        if t.exponent == 1:
            return lb
        if lb[0] or t.exponent.denominator != 1 or abs(t.exponent) > affine.MAX_EXPONENT or (
                t.exponent < 0 and lb[1] == 0):
            return None
        return {}, lb[1] ** int(t.exponent)
    return None


def _random_term(r: random.Random, depth: int):
    if depth == 0 or r.random() < 0.3:
        return r.choice([Var("x"), Var("y"), Param("a"), Const(Fraction(r.randint(-3, 3), r.randint(1, 4))),
                         Const("pi")])
    k = r.randrange(5)
    a = _random_term(r, depth - 1)
    if k == 0:
        return Add(a, _random_term(r, depth - 1))
    if k == 1:
        return Mul(a, _random_term(r, depth - 1))
    if k == 2:
        return Pow(a, r.choice([Fraction(1), Fraction(2), Fraction(-1), Fraction(1, 2)]))
    if k == 3:
        return Prim("sin", a)
    return core.neg(a)


def test_linear_forms_by_class_are_those_of_a_walk_over_the_fields():
    r = random.Random(25)
    affine_count = 0
    for _ in range(500):
        t = _random_term(r, 4)
        got, want = affine.linear(t), _reference_linear(t)
        if want is None:
            assert got is None, t
            continue
        affine_count += 1
        assert got is not None, t
        assert ({k: v for k, v in got[0].items() if v}, got[1]) == want, t
    assert affine_count > 100


def test_a_programs_body_is_computed_once_and_kept():
    frontend.clear_load_cache()
    p = frontend.load_text("int ([0, 1], [0, 2]) x * y d(x, y)\n").program
    assert "body" not in vars(p) or p.body is vars(p)["body"]
    body = p.body
    assert p.body is body and vars(p)["body"] is body  # kept in the instance, read again as it is
    lower, upper = p.domain[0].lower, p.domain[0].upper
    assert body == core.product([lower, upper, p.domain[1].lower, p.domain[1].upper, p.integrand])
    copy = pickle.loads(pickle.dumps(p))
    assert copy == p and copy.body == body
    assert type(p).body.__doc__.startswith("``[x1")  # the property's documentation kept
