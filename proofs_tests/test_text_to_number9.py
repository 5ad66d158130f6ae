"""A loop's first copy walked once, its body's size counted with fewer steps, eleventh pass (issue 15,
branch front9): ``Template._mark`` now also records the dependent nodes in a recursive walk's
post-order (``Template.order``), which ``Template._compile`` turns into steps without a walk of its
own — checked here against that recursive walk written out, and the copies built from it against
the copies desugared one by one; ``loops.size`` (names, numbers, operators and negations handled
first) against the count by ``loops.children`` at every surface node of every example program and of loops
over the bodies of ``test_text_to_number8``;
``core.shape_with_span`` against ``shape_of`` with the span.
"""

from __future__ import annotations

import os
import sys
from fractions import Fraction
from pathlib import Path

import pytest
from test_text_to_number8 import _BODIES, _same, _templates

from langur import core
from langur.diagnostics import Span
from langur.frontend import clear_load_cache, load_text
from langur.syntax import loops, template
from langur.syntax.parser import parse_bytes

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = sorted((ROOT / "examples").rglob("*.lgr"))


def _reference_size(st) -> int:
    """The number of surface nodes of ``st``: one plus its children's (``loops.children``)."""
    return 1 + sum(_reference_size(c) for c in loops.children(st))


def _surface_nodes(root):
    stack = [root]
    while stack:
        u = stack.pop()
        if loops._is_node(u):
            yield u
            stack.extend(loops.children(u))
        elif isinstance(u, (tuple, list)):
            stack.extend(u)


def test_size_is_the_count_of_children_at_every_node_of_the_examples():
    assert len(EXAMPLES) > 20
    checked, classes = 0, set()
    limit = sys.getrecursionlimit()
    sys.setrecursionlimit(max(limit, 20_000))
    try:
        loop_texts = [f"param a = 0.5\nint ([0, 1], [0, 1]) (sum i in 1..6: {body}) - (prod k in 0..2: -x + k) d(x, y)\n"
                      for body in _BODIES]
        for path in EXAMPLES + loop_texts:
            data = path.encode() if isinstance(path, str) else path.read_bytes()
            try:
                mod = parse_bytes(data, str(path))
            except Exception:  # (an example of a syntax error)
                continue
            for item in list(mod.items) + ([mod.program] if mod.program is not None else []):
                for u in _surface_nodes(item):
                    if type(u).__name__ in ("ProgramS", "DefDecl", "DiffeoDecl", "ParamItem", "ImportItem"):
                        continue
                    assert loops.size(u) == _reference_size(u), (path, u)
                    checked += 1
                    classes.add(type(u).__name__)
    finally:
        sys.setrecursionlimit(limit)
    assert checked > 1000
    assert {"Name", "Num", "BinOp", "Neg", "Apply", "Iverson", "Loop"} <= classes


def _recursive_post_order(plan: template.Template) -> list:
    """The dependent nodes of ``plan``'s first copy in a recursive walk's post-order, left to right,
    each once (the walk ``_compile`` made before ``_mark`` recorded it)."""
    dep, completions = plan.dependent, plan.record.completions
    seen: set[int] = set()
    out: list = []

    def go(u):
        if id(u) in seen:
            return
        seen.add(id(u))
        for c in template._kids(u, completions):
            if dep[id(c)]:
                go(c)
        out.append(u)

    go(plan.body)
    return out


@pytest.mark.parametrize("body", _BODIES)
def test_order_is_the_recursive_post_order_and_the_copies_are_desugared_ones(body):
    text = f"param a = 0.5\nint ([0, 1], [0, 1]) (sum i in 1..6: {body}) d(x, y)\n"
    made = [plan for plan in _templates(text) if plan.usable]
    assert made, "no template made"
    for plan in made:
        if not plan.dependent[id(plan.body)]:
            continue
        expected = _recursive_post_order(plan)
        assert [id(u) for u in plan.order] == [id(u) for u in expected]
        assert all(plan.dependent[id(u)] for u in plan.order)
    # the whole load with the template on and off: the same program, every attribute
    clear_load_cache()
    on = load_text(text, "t.lgr").program.body
    template.ENABLED = False
    try:
        clear_load_cache()
        off = load_text(text, "t.lgr").program.body
    finally:
        template.ENABLED = True
        clear_load_cache()
    _same(on, off)


def test_a_shared_dependent_node_is_ordered_once_where_the_walk_first_meets_it():
    # `let` shares one bound (with the index in it) between two uses: a DAG
    text = ("param a = 0.5\nint ([0, 1]) (sum i in 1..4: let b = a + 1/i in "
            "[x - b >= 0] * (b + x) + b * x) d(x)\n")
    made = [plan for plan in _templates(text) if plan.usable]
    for plan in made:
        if plan.dependent[id(plan.body)]:
            order = [id(u) for u in plan.order]
            assert len(order) == len(set(order))
            assert order == [id(u) for u in _recursive_post_order(plan)]


def test_shape_with_span_is_shape_of_with_the_span():
    x, a = core.Var("x"), core.Param("a")
    span = Span("p", 1, 2, 1, 9)
    for t in (core.Add(x, core.Const(Fraction(1, 3)), span=span), core.Mul(a, x, span=span),
              core.Pow(x, Fraction(-2), span=span), core.Prim("exp", x, span=span), core.Add(x, a)):
        expected = dict(core.shape_of(t), span=t.span)
        assert core.shape_with_span(t) == expected
        assert list(core.shape_with_span(t)) == list(expected)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(pytest.main([os.path.abspath(__file__), "-q"]))
