"""A finite loop's body desugared once and instantiated per value of its index (§9; issue 15).

§9's loop ``sum i in A..B: t`` is unrolled: ``t[A/i] + … + t[B/i]``.  Desugaring each copy from
the surface (and completing each copy's conditions) costs the same every time, although the copies
differ only in the number the index stands for.  :meth:`Desugarer.loop
<langur.syntax.desugar.Desugarer.loop>` therefore desugars the first copy while a :class:`Record`
watches, and builds the others from it by :func:`instantiate`: the ``Const`` leaves the index
became are replaced by the copy's number, every node above them is rebuilt (the rest is shared
with the first copy, as an inlined def body shares its subterms, but for conditionals on the
parameters, which the desugarer may lift out of a condition by their identity), and every condition that
contains them is completed again by the same function the desugarer calls
(``langur.syntax.completion.complete``) — so each copy is the term desugaring it would give.

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
from dataclasses import dataclass, field
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
    map_children,
)

#: Build a loop's copies from its first (False: every copy desugared from the surface, as the
#: tests compare).
ENABLED = True
#: Copies built so far by :meth:`Template.at` (the tests check that they exercised it).
STATS = {"instantiated": 0, "refused": 0}


@dataclass
class Record:
    """What desugaring the first copy of a loop's body showed: the ``Const`` leaves its index became
    (kept alive, so their ids stay theirs), the conditionals it completed (the ``IfDiffeo`` node's id →
    the condition, the variables and the box it was completed over), and whether the body may be
    instantiated at all (:attr:`unsafe`)."""

    index: str
    leaves: dict[int, Const] = field(default_factory=dict)
    completions: dict[int, tuple[IfDiffeo, Term, tuple[str, ...], tuple]] = field(default_factory=dict)
    unsafe: bool = False


class _Refused(Exception):
    """This copy cannot be instantiated (a condition that does not complete again)."""


def _diffeo_terms(psi: Diffeo) -> tuple[Term, ...]:
    return psi.forward + psi.nonzero + tuple(u for b in psi.branches for u in b.components + b.guards)


class Template:
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
        self._mark(body)

    def _mark(self, root: Term) -> None:
        """:attr:`dependent`: whether each distinct node of the first copy is built anew in each copy:
        it has an index leaf below it (in a conditional: in its branches or in the condition it was
        completed from) or a conditional on the parameters; the other nodes are shared by the copies."""
        dep, leaves, completions = self.dependent, self.record.leaves, self.record.completions
        stack: list[tuple[Term, bool]] = [(root, False)]
        while stack:
            u, done = stack.pop()
            key = id(u)
            if key in dep:
                continue
            if type(u) is Const or type(u) is Var or type(u) is Param:
                dep[key] = key in leaves
                continue
            kids = _kids(u, completions)
            if not done:
                stack.append((u, True))
                stack.extend((c, False) for c in kids if id(c) not in dep)
                continue
            # (a conditional on the parameters is copied too: the desugarer lifts such a conditional
            # out of a condition by its identity, `desugar._put`, which must not meet it in two copies)
            dep[key] = type(u) is IfGe0 or any(dep[id(c)] for c in kids)
            if type(u) is IfDiffeo and key not in completions:
                # a Ψ̂ not completed here (there is none while the record is safe): its terms must not
                # mention the index
                if any(self._has_leaf(t) for t in _diffeo_terms(u.psi)):
                    self.usable = False

    def _has_leaf(self, t: Term) -> bool:
        leaves = self.record.leaves
        stack = [t]
        while stack:
            u = stack.pop()
            if id(u) in leaves:
                return True
            stack.extend(_kids(u, {}))
        return False

    def at(self, value: int) -> Term | None:
        """The copy for the index's ``value``: the first copy with its index leaves replaced by
        ``value`` and its conditions over them completed again; None when one does not complete."""
        number = Fraction(value)
        dep, completions = self.dependent, self.record.completions
        memo: dict[int, Term] = {}
        complete, completed = self.complete, self.completed

        def go(u: Term) -> Term:  # (called on nodes with an index leaf below only)
            key = id(u)
            out = memo.get(key)
            if out is not None:
                return out
            tu = type(u)
            if tu is Add or tu is Mul:
                a, b = u.left, u.right
                out = tu(go(a) if dep[id(a)] else a, go(b) if dep[id(b)] else b, span=u.span)
            elif tu is Const:
                out = Const(number, span=u.span)
            elif tu is Pow:
                out = Pow(go(u.base), u.exponent, span=u.span)
            elif tu is Prim:
                out = Prim(u.op, go(u.arg), span=u.span)
            elif tu is IfDiffeo:
                psi, found = u.psi, completions.get(key)
                if found is not None and dep[id(found[1])]:  # its condition has the index: completed again
                    _, cond, variables, box = found
                    cond = go(cond)
                    psi = complete(cond, variables, box)
                    if psi is None:
                        raise _Refused
                    found = (None, cond, variables, box)
                a, b = u.then, u.orelse
                out = IfDiffeo(psi, go(a) if dep[id(a)] else a, go(b) if dep[id(b)] else b, span=u.span)
                if found is not None:
                    completed(out, *found[1:])
            else:
                out = map_children(u, lambda c: go(c) if dep[id(c)] else c)
            memo[key] = out
            return out

        if not dep[id(self.body)]:
            return self.body  # the index does not occur: every copy is the first
        try:
            out = go(self.body)
        except _Refused:
            STATS["refused"] += 1
            return None
        STATS["instantiated"] += 1
        return out


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
