"""A finite loop's body desugared once and instantiated per value of its index (§9; issue 15).

§9's loop ``sum i in A..B: t`` is unrolled: ``t[A/i] + … + t[B/i]``.  Desugaring each copy from
the surface (and completing each copy's conditions) costs the same every time, although the copies
differ only in the number the index stands for.  :meth:`Desugarer.loop
<langur.syntax.unrolling.Unrolling.loop>` therefore desugars the first copy while a :class:`Record`
watches, and builds the others from it by :func:`instantiate`: the ``Const`` leaves the index
became are replaced by the copy's number, every node above them is rebuilt (the rest is shared
with the first copy, as an inlined def body shares its subterms, but for conditionals on the
parameters, which the desugarer may lift out of a condition by their identity), and every condition that
contains them is completed again by the same function the desugarer calls
(``langur.syntax.completion.complete``) — so each copy is the term desugaring it would give.
The first copy is compiled here into *steps* (:meth:`Template._plan`) that :meth:`Template.at`
runs in one loop (:mod:`langur.syntax.copies`, which builds the copies from them); a node whose children keep the first copy's shape is built by ``core.like`` (its
shape's attributes copied), and a condition that differs from the first's only in constant
summands keeps the first's solved affine shape (``affine.summands``, ``affine.solved_at``): the
completion the desugarer's function would give, for one Fraction addition per summand (issue 15).

That holds when the desugarer's work on the body does not depend on the index's *value* except
through those leaves and the completions.  The desugarer says when it may (:attr:`Record.unsafe`):
the index read as a number (an exponent, an inner loop's bounds), a declared diffeo's application, a
condition split at its kinks (the split compares conditions), a diagnostic, a condition left pending,
or an inner loop with the same index; then every copy is desugared from the surface as before.  A copy
whose condition cannot be completed again is desugared from the surface too (it reports why).
``proofs_tests/test_loop_template.py`` compares instantiated copies with the per-copy desugaring on
random loop bodies.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import field
from fractions import Fraction

from ..core import (
    Add,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    Mul,
    Param,
    Pow,
    Prim,
    Term,
    Var,
    children,
    shape_of,
    shape_with_span,
    small_value,
)
from ..records import FACTORY, record
from . import affine
from .copies import BINARY, COMPLETE, CONDITIONAL, LEAF, OTHER, UNARY, Copies

#: Build a loop's copies from its first (False: every copy desugared from the surface, as the
#: tests compare).
ENABLED = True


@record
class Record:
    """What desugaring the first copy of a loop's body showed: the ``Const`` leaves its index became
    (kept alive, so their ids stay theirs), the conditionals it completed (the ``IfDiffeo`` node's id →
    the condition, the variables and the box it was completed over), and whether the body may be
    instantiated at all (:attr:`unsafe`)."""

    index: str
    leaves: dict[int, Const] = field(default_factory=dict)
    completions: dict[int, tuple[IfDiffeo, Term, tuple[str, ...], tuple]] = field(default_factory=dict)
    unsafe: bool = False

    def __init__(self, index, leaves=FACTORY, completions=FACTORY, unsafe=False):
        self.index = index
        self.leaves = {} if leaves is FACTORY else leaves
        self.completions = {} if completions is FACTORY else completions
        self.unsafe = unsafe


def _diffeo_terms(psi: Diffeo) -> tuple[Term, ...]:
    return psi.forward + psi.nonzero + tuple(u for b in psi.branches for u in b.components + b.guards)


class Template(Copies):
    """The first copy ``body`` of a loop's body with its :class:`Record`; :meth:`at` builds the copy
    for another value of the index (None when it cannot)."""

    def __init__(self, body: Term, record: Record,
                 complete: Callable[[Term, tuple[str, ...], tuple], Diffeo | None],
                 completed: Callable[[IfDiffeo, Term, tuple[str, ...], tuple], None]):
        self.body = body
        self.record = record
        #: ``complete(cond, variables, box)``: the desugarer's completion, None when it fails
        self.complete = complete
        #: ``completed(node, cond, variables, box)``: told of each conditional completed again (an
        #: enclosing loop's record notes it)
        self.completed = completed
        self.dependent: dict[int, bool] = {}
        #: a completed conditional with an index leaf in a term of Ψ̂ that is not its condition (a
        #: Ψ̂ from elsewhere): refuse to instantiate
        self.usable = True
        self.order: list[Term] = []
        #: what :meth:`at` builds (:meth:`_plan`)
        self.shared: list[Term] = []
        self.steps: list[tuple] = []
        self.first: list[Term] = []  # the first copy's node of each step
        self._plan(body)

    def _plan(self, root: Term) -> None:
        """:attr:`dependent`, :attr:`order` and the steps :meth:`at` runs, in one walk of the first
        copy.  A node is dependent — built anew in each copy — when it has an index leaf below it (in
        a conditional: in its branches or in the condition it was completed from) or is a conditional
        on the parameters; the other nodes are shared by the copies.  Each dependent node becomes a
        step (``step``) once its children are walked, children first, left to right (a recursive
        walk's post-order, :attr:`order`): its node is built at its index of a list, and it reads its
        children's slots there — a dependent child's step, a shared child at a negative index
        (:attr:`shared`, in reverse) — so :meth:`at` is one loop, with no recursion and no lookup by
        identity.

        The walk recurses down to :data:`_MARK_DEPTH` levels (the cheapest walk in Python: every loop
        of more than one copy pays it once, issue 15); a deeper first copy (or one met with the
        interpreter's recursion limit near) is walked again with a stack of its own, which makes the
        same steps in the same order (no recursion on a term's depth)."""
        dep, leaves, completions = self.dependent, self.record.leaves, self.record.completions
        own: dict[int, int] = {}  # a dependent node's step
        slot: dict[int, int] = {}  # a shared node's slot
        shared: list[Term] = []
        first: list[Term] = []  # the first copy's node of each step
        steps: list[tuple] = []
        powers: dict[Fraction, int] = {}  # the exponents of the index's powers, each a slot of at()'s

        def ref(c: Term) -> int:
            """A walked child's slot: its step, or (shared) its slot among the shared nodes, from the end."""
            key = id(c)
            if dep[key]:
                return own[key]
            found = slot.get(key)
            if found is None:
                found = slot[key] = -1 - len(shared)
                shared.append(c)
            return found

        def step(u: Term, tu: type, a: int | None = None, b: int | None = None) -> int:
            """The step of the dependent node ``u`` (of class ``tu``), its children walked (``a``,
            ``b``: the first two's steps when the walk has them at hand, else None)."""
            if tu is Add or tu is Mul:
                made = (BINARY, tu, {"shape": u.shape, "span": u.span},
                        ref(u.left) if a is None else a, ref(u.right) if b is None else b)
            elif tu is Pow:
                base = ref(u.base) if a is None else a
                # a power of the index itself (1/i): its value is computed once per copy and exponent
                power = powers.setdefault(u.exponent, len(powers)) if base >= 0 and steps[base][0] is LEAF else -1
                made = (UNARY, tu, shape_with_span(u), base, u.exponent, power)
            elif tu is Prim:
                made = (UNARY, tu, shape_with_span(u), ref(u.arg) if a is None else a, u.op, -1)
            elif tu is IfDiffeo:
                made = self._conditional_step(u, completions.get(id(u)), ref, own)
            elif tu is Const or tu is Var or tu is Param:
                made = (LEAF, u.span)  # (an index leaf)
            else:
                made = (OTHER, u, {id(c): own[id(c)] for c in children(u) if dep[id(c)]})
            key = id(u)
            dep[key] = True
            own[key] = found = len(steps)
            steps.append(made)
            first.append(u)
            return found

        def kept(u: Term, tu: type, kids: tuple) -> bool:
            """Whether the node ``u`` (not a leaf) is copied, its children ``kids`` (:func:`_kids`) walked."""
            if tu is IfDiffeo and id(u) not in completions and any(self._has_leaf(t) for t in _diffeo_terms(u.psi)):
                # a Ψ̂ not completed here (there is none while the record is safe): its terms must
                # not mention the index
                self.usable = False
            # (a conditional on the parameters is copied too: the desugarer lifts such a conditional
            # out of a condition by its identity, `conditionals.put`, which must not meet it in two copies)
            if tu is IfGe0:
                return True
            for c in kids:
                if dep[id(c)]:
                    return True
            return False

        def walk(u: Term, depth: int) -> int | None:
            """``u``'s step when it is dependent, else None."""
            key = id(u)
            d = dep.get(key)
            if d is not None:
                return own[key] if d else None
            tu = type(u)
            if tu is Const or tu is Var or tu is Param:
                if key in leaves:
                    return step(u, tu)
                dep[key] = False
                return None
            if depth > _MARK_DEPTH:
                raise _Deep
            # (the most frequent nodes with their children's steps at hand)
            if tu is Add or tu is Mul:
                a, b = walk(u.left, depth + 1), walk(u.right, depth + 1)
            elif tu is Pow or tu is Prim:
                a, b = walk(u.base if tu is Pow else u.arg, depth + 1), None
            else:
                kids = _kids(u, completions)
                for c in kids:
                    walk(c, depth + 1)
                if kept(u, tu, kids):
                    return step(u, tu)
                a = b = None
            if a is None and b is None:
                dep[key] = False
                return None
            return step(u, tu, a, b)

        try:
            walk(root, 0)
        except (_Deep, RecursionError):  # (deep, or called near the interpreter's limit already)
            for table in (dep, own, slot, powers, shared, first, steps):
                table.clear()
            self.usable = True
            stack: list[Term] = [root]
            while stack:  # (a node whose children are not all walked yet stays under them, made after)
                u = stack[-1]
                if id(u) in dep:
                    stack.pop()
                    continue
                tu = type(u)
                if tu is Const or tu is Var or tu is Param:
                    stack.pop()
                    if id(u) in leaves:
                        step(u, tu)
                    else:
                        dep[id(u)] = False
                    continue
                kids = _kids(u, completions)
                pending = False
                for c in reversed(kids):  # (the leftmost child on top: walked first)
                    if id(c) not in dep:
                        stack.append(c)
                        pending = True
                if pending:
                    continue
                stack.pop()
                if kept(u, tu, kids):
                    step(u, tu)
                else:
                    dep[id(u)] = False
        self.order = first  # (the dependent nodes in post-order)
        self.first, self.steps = first, steps
        self.shared = shared[::-1]
        self.powers = len(powers)
        #: each power's exponent as an int when it is an integer (then computed in integers,
        #: core.index_power_small), else None
        self.exponents = [int(k) if k.denominator == 1 else None for k in powers]
        # what each copy starts from: no node of its own yet, the shared ones at the end (and they
        # have the first copy's shape)
        self.start = [None] * len(steps) + self.shared
        self.start_same = [False] * len(steps) + [True] * len(self.shared)

    def _has_leaf(self, t: Term) -> bool:
        leaves = self.record.leaves
        stack = [t]
        while stack:
            u = stack.pop()
            if id(u) in leaves:
                return True
            stack.extend(_kids(u, {}))
        return False

    def _conditional_step(self, u: IfDiffeo, found: tuple | None, ref: Callable[[Term], int],
                          own: dict[int, int]) -> tuple:
        """A dependent conditional's step (:meth:`_plan`'s): completed again in
        each copy when the condition it was completed from (``found``, the record's) changes with the
        index, else the conditional copied with its Ψ̂ (and ``found``'s condition, variables and box
        for the enclosing loop's record)."""
        if found is not None and self.dependent[id(found[1])]:
            _, cond, variables, box = found
            return (COMPLETE, u.span, ref(cond), ref(u.then), ref(u.orelse), variables, box,
                    self._shifted(cond, variables, own, u.psi), shape_of(u))
        return (CONDITIONAL, u.psi, u.span, ref(u.then), ref(u.orelse), None if found is None else found[1:])

    def _shifted(self, cond: Term, variables: tuple[str, ...], own: dict[int, int], psi: Diffeo):
        """For a condition completed again: its solved shape, the constant term of its solution
        without the changing constant summands (numerator and denominator, in lowest terms), and
        those summands' steps with their factors in it, when :func:`affine.summands` finds them and the first copy's condition completed by
        the affine path (``psi``, which keeps what it solved); else None."""
        dep = self.dependent
        parts = affine.summands(cond, lambda u: dep.get(id(u), False))
        if parts is None or any(id(u) not in own for u, _ in parts):
            return None
        found = affine.solved_by(psi, cond, variables)  # (the first copy's completion solved it)
        if found is None:
            return None
        solved, c0 = found
        for u, factor in parts:  # c0 without the summands: each copy adds its own
            c0 -= small_value(u) if factor == 1 else factor * small_value(u)
        a = solved[1]  # the solution's constant −c₀/a: −(c0 + Σ factor·new)/a = base + Σ (−factor/a)·new
        moves = []
        for u, factor in parts:  # each summand's step, its factor in the solution and whether it is 1 or −1
            f = -factor if a == 1 else -factor / a  # when ±1
            moves.append((own[id(u)], f, -1 if f == -1 else (1 if f == 1 else 0)))
        base = -c0 if a == 1 else -c0 / a
        return solved, base.numerator, base.denominator, tuple(moves)


#: How deep :meth:`Template._plan` recurses before it walks the first copy again with a stack of its own.
_MARK_DEPTH = 200


class _Deep(Exception):
    """A first copy deeper than :data:`_MARK_DEPTH` (:meth:`Template._plan`)."""


def _kids(u: Term, completions: dict) -> tuple[Term, ...]:
    """The children of ``u`` (see ``core.children``), and for a conditional completed while
    recording, the condition it was completed from."""
    tu = type(u)
    if tu is Add or tu is Mul:
        return (u.left, u.right)
    if tu is Pow or tu is Prim:
        return (u.base,) if tu is Pow else (u.arg,)
    if tu is IfDiffeo:
        found = completions.get(id(u))
        return (u.then, u.orelse) if found is None else (found[1], u.then, u.orelse)
    return children(u)


__all__ = ["Record", "Template"]
