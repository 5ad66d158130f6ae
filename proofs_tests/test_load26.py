"""Loading at small n, sixth pass (issue 15, branch load26), against independent references.

* ``template.Template._plan``: one walk plans a loop's first copy, its steps made by one function for
  both of its orders (recursive, and with a stack of its own for a deep first copy).  Checked against
  a plan computed here from the definitions alone: which nodes are dependent (an index leaf, a
  conditional on the parameters, or a dependent child — for a completed conditional, its condition
  counts as a child), their post-order, and what each step reads (its children: a dependent one's
  step, a shared one's slot) — on random loop bodies (test_loop_template's generator), on MB1's two
  loops and on a first copy deeper than the recursion's bound (these pass on main too: they guard
  the plan kept); and the stack walk's plan is the recursive walk's, steps included, as soon as it is
  made (on main that walk only marked, and the steps were compiled on first use: ``steps`` was None
  after planning — that test fails there).
* ``affine._solve``: a solved shape keeps the ``c·atom`` parts of its solution itself; they are the
  atoms of every branch completed from it (by identity), shared with shapes whose solutions have the
  same terms, and the solution ``constant + Σ parts`` equals the one solved here by hand from the
  condition's linear form (on main the shape kept the terms, and the parts were looked up in its
  table of branches: the first test fails there; the second guards the sharing kept).
"""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
from test_loop_template import _load, _program, _same_attributes

from langur import core, frontend
from langur.core import Add, Const, IfDiffeo, IfGe0, Mul, Param, Pow, Prim, Var
from langur.syntax import affine, template

MB1 = ("param a = 1\nint ([-1, 1]) (sum i in 1..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x)) + "
       "(sum i in 1..10: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")


# --- template._plan against a plan computed from the definitions ---------------------------------

def _kids(plan: template.Template, u) -> list:
    """``u``'s children, a completed conditional's condition first (what the copies rebuild from)."""
    found = plan.record.completions.get(id(u)) if type(u) is IfDiffeo else None
    return ([found[1]] if found is not None else []) + list(core.children(u))


def _reference(plan: template.Template) -> tuple[dict, list]:
    """Which nodes of the first copy are dependent, and the dependent ones in post-order, left to
    right, each once — by a plain recursive definition (the bodies here are shallow)."""
    dep: dict[int, bool] = {}
    order: list = []

    def go(u) -> bool:
        if id(u) in dep:
            return dep[id(u)]
        kids = [] if type(u) in (Const, Var, Param) else _kids(plan, u)
        results = [go(c) for c in kids]  # (every child walked, left to right)
        d = id(u) in plan.record.leaves if not kids else (type(u) is IfGe0 or any(results))
        dep[id(u)] = d
        if d:
            order.append(u)
        return d

    go(plan.body)
    return dep, order


def _check_plan(plan: template.Template) -> None:
    dep, order = _reference(plan)
    assert plan.dependent == dep
    if not plan.usable:
        return
    assert [id(u) for u in plan.first] == [id(u) for u in order]
    assert len(plan.steps) == len(order)
    step_of = {id(u): i for i, u in enumerate(order)}
    n = len(order)

    def node(slot: int):
        """The first copy's node at a step's slot: a step's own node, or a shared node from the end."""
        return order[slot] if slot >= 0 else plan.start[n + len(plan.shared) + slot]

    assert plan.start[n:] == plan.shared and all(not dep[id(u)] for u in plan.shared)
    for i, (u, step) in enumerate(zip(order, plan.steps)):
        kind = step[0]
        if type(u) in (Const, Var, Param):
            assert kind == "leaf" and step[1] is u.span
        elif type(u) in (Add, Mul):
            assert kind == "binary" and step[1] is type(u) and step[2] == {"shape": u.shape, "span": u.span}
            assert node(step[3]) is u.left and node(step[4]) is u.right
        elif type(u) in (Pow, Prim):
            child = u.base if type(u) is Pow else u.arg
            assert kind == "unary" and node(step[3]) is child
            assert step[4] == (u.exponent if type(u) is Pow else u.op)
            is_index_power = type(u) is Pow and type(child) is Const and id(child) in plan.record.leaves
            assert (step[5] >= 0) == is_index_power
        elif type(u) is IfDiffeo:
            assert kind in ("complete", "conditional")
            if kind == "complete":  # the condition it was completed from, and its branches
                cond = plan.record.completions[id(u)][1]
                assert node(step[2]) is cond and node(step[3]) is u.then and node(step[4]) is u.orelse
            else:
                assert step[1] is u.psi and node(step[3]) is u.then and node(step[4]) is u.orelse
        else:
            assert kind == "other" and step[1] is u
            assert step[2] == {id(c): step_of[id(c)] for c in core.children(u) if dep[id(c)]}
        if kind == "binary":
            assert step[3] < i and step[4] < i  # children before parents
    # every shared node is read by some step, and each once in the list
    assert len({id(u) for u in plan.shared}) == len(plan.shared)


class _Watched:
    """The templates a load builds (``template.Template`` wrapped)."""

    def __init__(self, monkeypatch):
        self.built: list[template.Template] = []
        real = template.Template
        built = self.built

        class Watched(real):
            def __init__(self, *args):
                super().__init__(*args)
                built.append(self)

        monkeypatch.setattr(template, "Template", Watched)


@pytest.mark.parametrize("seed", range(3))
def test_the_plan_is_the_one_the_definitions_give(seed, monkeypatch):
    watched = _Watched(monkeypatch)
    r = random.Random(2600 + seed)
    planned = 0
    for _ in range(30):
        watched.built.clear()
        _load(_program(r), True)
        for plan in watched.built:
            _check_plan(plan)
            planned += 1
    assert planned >= 12  # (fewer since fold31: a loop of copies at 0 and 1 only, e.g. 0..1, 1..2, has no template)
    frontend.clear_load_cache()
    watched.built.clear()
    frontend.load_text(MB1)
    assert len(watched.built) == 2
    for plan in watched.built:
        _check_plan(plan)
        # (14 and 10 since fold31: the condition's `- 0` is gone, one dependent node and one shared constant fewer)
        assert len(plan.steps) == 14 and len(plan.shared) == 10


def test_a_deep_first_copy_is_planned_by_the_stack_walk_with_its_steps(monkeypatch):
    watched = _Watched(monkeypatch)
    deep = "i/2"
    for _ in range(150):  # (each `x - …` two levels of the core: 300, past the recursion's bound of 200)
        deep = f"(x - {deep})"
    text = f"param a = 0.5\nint ([0, 1]) (sum i in 1..3: [x + i/4 >= a] * {deep}) d(x)\n"
    new, new_errors = _load(text, True)
    assert new_errors == [] and len(watched.built) == 1
    plan = watched.built[0]
    assert core.depth(plan.body) > template._MARK_DEPTH
    # the stack walk's plan (its steps compiled by the time the load ends, on main too)
    assert plan.steps is not None and len(plan.steps) == len(plan.first) > 300
    dep, order = plan.dependent, plan.first
    # post-order, children first: every dependent node's dependent children come before it
    index = {id(u): i for i, u in enumerate(order)}
    for i, u in enumerate(order):
        for c in _kids(plan, u):
            if dep[id(c)]:
                assert index[id(c)] < i
    old, old_errors = _load(text, False)
    assert old_errors == []
    _same_attributes(new.program.body, old.program.body)
    assert core.tree_size(new.program.body) == core.tree_size(old.program.body)


def test_both_walks_give_one_plan(monkeypatch):
    watched = _Watched(monkeypatch)
    r = random.Random(2650)
    for _ in range(20):
        watched.built.clear()
        _load(_program(r), True)
        for plan in list(watched.built):
            bound = template._MARK_DEPTH
            template._MARK_DEPTH = -1  # every node deeper: the stack walk at once
            try:
                other = template.Template(plan.body, plan.record, plan.complete, plan.completed)
            finally:
                template._MARK_DEPTH = bound
            assert other.dependent == plan.dependent and other.usable == plan.usable
            if plan.usable:
                assert other.steps == plan.steps
                assert [id(u) for u in other.shared] == [id(u) for u in plan.shared]
                assert [id(u) for u in other.first] == [id(u) for u in plan.first]


# --- affine: a solved shape keeps its parts -------------------------------------------------------

def _solution_by_hand(cond, variables: tuple[str, ...]) -> tuple[str, dict, Fraction]:
    """The variable solved for (the last one with a nonzero coefficient) and its solution
    ``x_v = (u0 − c₀ − Σ c·atom)/a`` as coefficients by atom name and a constant, from the linear
    form computed here by a walk over the fields."""
    def lin(t):
        if type(t) is Var:
            return {t.name: Fraction(1)}, Fraction(0)
        if type(t) is Param:
            return {t.name: Fraction(1)}, Fraction(0)
        if type(t) is Const:
            return {}, t.value
        if type(t) is Add:
            (fa, ca), (fb, cb) = lin(t.left), lin(t.right)
            out = dict(fa)
            for k, v in fb.items():
                out[k] = out.get(k, 0) + v
            return {k: v for k, v in out.items() if v}, ca + cb
        if type(t) is Mul:
            (fa, ca), (fb, cb) = lin(t.left), lin(t.right)
            assert not (fa and fb)
            f, c, k = (fb, cb, ca) if not fa else (fa, ca, cb)
            return {n: k * v for n, v in f.items() if k * v}, k * c
        raise AssertionError(t)

    form, c0 = lin(cond)
    v = [x for x in variables if x in form][-1]
    a = form[v]
    sol = {n: -c / a for n, c in form.items() if n != v}
    sol["u0"] = 1 / a
    return v, sol, -c0 / a


def _read_solution(t) -> tuple[dict, Fraction]:
    """``constant + Σ c·atom`` read back (the branch's solution)."""
    out: dict = {}
    constant = Fraction(0)
    stack = [t]
    while stack:
        u = stack.pop()
        if type(u) is Add:
            stack += [u.left, u.right]
        elif type(u) is Const:
            constant += u.value
        elif type(u) in (Var, Param):
            out[u.name] = out.get(u.name, 0) + 1
        else:
            assert type(u) is Mul and type(u.left) is Const
            out[u.right.name] = out.get(u.right.name, 0) + u.left.value
    return out, constant


def test_a_solved_shape_keeps_its_parts_and_branches_are_built_of_them():
    r = random.Random(26)
    x, y, a, b = Var("x"), Var("y"), Param("a"), Param("b")
    for _ in range(60):
        affine._solve.cache_clear()
        affine._atoms.cache_clear()
        terms = [Mul(Const(Fraction(r.choice([-3, -2, -1, 1, 2, 5]), r.choice([1, 2, 3]))), u)
                 for u in r.sample([x, y, a, b], r.randint(1, 4))]
        if not any(free for t in terms for free in core.free_vars(t)):
            terms.append(x)
        cond = Add(terms[0], Const(Fraction(r.randint(-9, 9), r.randint(1, 4))))
        for t in terms[1:]:
            cond = Add(cond, t)
        variables = ("x", "y")
        found = affine.solve(cond, variables)
        assert found is not None
        solved, c0 = found
        parts = solved[4]
        psi = affine.complete(cond, variables)
        solution = psi.branches[0].components[variables.index(psi.solved_for)]
        # the branch's solution is built of the shape's parts, by identity
        assert [id(u) for u in _atoms_of(psi, variables)] == [id(u) for u in parts]
        # and it is the solution solved by hand
        v, coeffs, constant = _solution_by_hand(cond, variables)
        assert psi.solved_for == v
        inputs = psi.inputs
        got, got_constant = _read_solution(solution)
        renamed = {"u0": inputs[0], **{z: inputs[1] for z in variables if z != v}}
        assert got == {renamed.get(n, n): c for n, c in coeffs.items()}
        assert got_constant == constant
        # another constant of the same shape: the same parts
        again = affine.solved_at(cond, variables, solved, constant + 7)
        assert all(any(p is q for q in parts) for p in _atoms_of(again, variables))


def _atoms_of(psi, variables) -> list:
    sol = psi.branches[0].components[variables.index(psi.solved_for)]
    out, stack = [], [sol]
    while stack:
        u = stack.pop()
        if type(u) is Add:
            stack += [u.right, u.left]
        elif type(u) is not Const:
            out.append(u)
    return out


def test_shapes_whose_solutions_have_the_same_terms_share_their_atoms():
    affine._solve.cache_clear()
    affine._atoms.cache_clear()
    x, a, b = Var("x"), Param("a"), Param("b")
    one = core.sub(x, a)  # x − a over (x,)
    two = Add(core.sub(x, a), core.sub(b, b))  # the same solution, another shape (b cancels: its params differ)
    p, q = affine.complete(one, ("x",)), affine.complete(two, ("x",))
    assert affine.solve(one, ("x",))[0] is not affine.solve(two, ("x",))[0]  # two solved shapes
    assert p.branches[0].components[0] == q.branches[0].components[0]
    assert [id(u) for u in _atoms_of(p, ("x",))] == [id(u) for u in _atoms_of(q, ("x",))]


def test_mb1_loads_as_the_copies_desugared_one_by_one():
    for n_text in (MB1, MB1.replace("1..10", "10..10"), MB1.replace("1..10", "10..19")):
        new, new_errors = _load(n_text, True)
        old, old_errors = _load(n_text, False)
        assert new_errors == old_errors == []
        assert new.program == old.program
        _same_attributes(new.program.body, old.program.body)
