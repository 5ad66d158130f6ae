"""§9's finite loop in the desugarer: ``sum i in A..B: t`` unrolled (``t[A/i] + … + t[B/i]``, 0
when B < A; ``prod`` alike, 1), its copies combined into a balanced sum or product.

The bounds, the budget on unrolling (T224, T225) and the balanced combination are
:mod:`langur.syntax.loops`'; the copies after the first are built from it when its desugaring
allows (:mod:`langur.syntax.template`: the first copy is desugared while a record watches, and
:meth:`Unrolling.unsafe` tells the record where the desugaring depends on the index's value).

:class:`Unrolling` holds these methods of :class:`~langur.syntax.desugar.Desugarer` (one class, its
methods in three modules: the sugar table's ``match`` in :mod:`langur.syntax.desugar`, the
conditionals in :mod:`langur.syntax.conditionals`).
"""

from __future__ import annotations

from fractions import Fraction

from .. import typesys as ty
from ..core import Const, Diffeo, IfDiffeo, Term
from . import loops, template
from .completion import complete, diffeo
from .conditionals import join
from .scope import Scope
from .surface import Loop, Name, STerm

#: The index values whose copies are desugared on their own, never built from the template: there the
#: index folds (``x * i`` at i = 1 is ``x``, at i = 0 is ``0``, ``t - i`` at i = −1 is ``t + 1``;
#: ``syntax/folding.py``), at any other value a copy has the first copy's shape.
FOLDING = (-1, 0, 1)


def _next_instantiable(k: int, hi: int) -> bool:
    """Whether a copy after the one at ``k`` (≤ ``hi``) may be built from a template made at ``k``."""
    after = k + 1 if k + 1 not in FOLDING else max(FOLDING) + 1
    return after <= hi


class Unrolling:
    """The desugarer's §9 loops (a part of :class:`~langur.syntax.desugar.Desugarer`)."""

    def loop(self, st: Loop, sc: Scope) -> Term:
        """§9's finite loop, unrolled: one copy of the body per value of the index, combined into a
        balanced sum or product (:mod:`langur.syntax.loops`; T224 for a bound that is not an integer
        constant, T225 past the bound on unrolling)."""
        if self.budget.exhausted:
            return Const(Fraction(0), span=st.span)
        self.unsafe(st.lo, st.hi, sc=sc)  # an enclosing index as a number
        try:
            lo, hi = loops.bounds(st.lo, st.hi, sc.consts)
        except loops.BoundError as e:
            return self.fail(ty.reject_loop_bound(e.span, e.why), st.span)
        except loops.TooLarge:
            self.budget.exhausted = True
            return self.fail(ty.reject_loop_too_large(join(st.lo, st.hi), f"a bound has more than {loops.MAX_BITS} "
                                                      "bits"), st.span)
        where = st.name_span or st.span
        if st.index in sc.variables:
            return self.fail(ty.reject_var_param_clash(where, st.index, "a loop's index has the name of a variable"),
                             st.span)
        if st.index == "pi":
            return self.fail(ty.reject_duplicate(where, "name (reserved constant)", "pi"), st.span)
        refused = self.budget.charge(max(0, hi - lo + 1), loops.size(st.body))
        if refused:
            return self.fail(ty.reject_loop_too_large(join(st.lo, st.hi), refused), st.span)
        before = len(self.errors)
        copies: list[Term] = []
        plan: template.Template | None = None
        watched = False  # whether a copy was desugared while a record watched (at most one)
        try_all = False  # whether to build the rest of this run of copies at once
        charged = (0, 0)  # what desugaring the first copy took of the budget: each instantiated copy takes it too
        k = lo
        while k <= hi:
            if k in FOLDING:
                # the index at −1, 0 or 1 folds (x·0, x·1, t − 0, t − (−1): syntax/folding.py), so the copy may not have the
                # template's shape: desugared on its own (and the copies after it form a new run)
                copies.append(self.term(st.body, sc.with_index(st.index, k)))
                if self.budget.exhausted:
                    break
                try_all = plan is not None
                k += 1
                continue
            end = min(hi, min(FOLDING) - 1) if k < 0 else hi  # the last copy of this run (no folding index in it)
            if plan is not None and try_all:
                # every other copy of the run at once when they all fit the budget and all complete (else
                # one by one, below: a copy that does not complete is desugared, and reports why)
                try_all = False
                rest = end - k + 1
                if self.budget.again(charged[0] * rest, charged[1] * rest):
                    built = plan.at_all(range(k, end + 1))
                    if built is not None:
                        copies += built
                        k = end + 1
                        continue
                    self.budget.copies -= charged[0] * rest
                    self.budget.nodes -= charged[1] * rest
            if plan is not None:
                if self.budget.again(*charged):
                    copy = plan.at(k)
                    if copy is not None:
                        copies.append(copy)
                        k += 1
                        continue
                    self.budget.copies -= charged[0]
                    self.budget.nodes -= charged[1]
                else:
                    plan = None  # past the bound: desugared (and refused) as before
            if not watched and template.ENABLED and _next_instantiable(k, hi):
                # the first copy, watched: the others are built from it when its desugaring allows
                watched = True
                first, plan, charged = self.first_copy(st, sc, k)
                copies.append(first)
                try_all = plan is not None
            else:
                copies.append(self.term(st.body, sc.with_index(st.index, k)))
            if self.budget.exhausted:
                break
            k += 1
        self.errors[before:] = loops.once(self.errors[before:])  # the copies' diagnostics are the body's
        if self.budget.exhausted:
            return Const(Fraction(0), span=st.span)
        return loops.balanced(copies, st.op, st.span)

    def first_copy(self, st: Loop, sc: Scope, k: int) -> tuple[Term, template.Template | None, tuple[int, int]]:
        """The first copy of a loop's body (index ``k``), desugared while a record watches; the
        template of the others when its desugaring allows (:mod:`langur.syntax.template`), and
        what it took of the budget."""
        record = template.Record(st.index)
        outer = self.records.get(st.index)
        if outer is not None:
            outer.unsafe = True  # an inner loop with the same index: the outer index is not watched here
        self.records[st.index] = record
        errors, pending, pieces = len(self.errors), len(self.pending or ()), self.pieces
        copies, nodes = self.budget.copies, self.budget.nodes
        try:
            body = self.term(st.body, sc.with_index(st.index, k))
        finally:
            if outer is None:
                del self.records[st.index]
            else:
                self.records[st.index] = outer
        charged = (self.budget.copies - copies, self.budget.nodes - nodes)
        if (record.unsafe or len(self.errors) > errors or len(self.pending or ()) != pending
                or self.pieces != pieces or self.budget.exhausted):
            return body, None, charged
        plan = template.Template(body, record, self.complete_again, self.note_completion)
        return body, (plan if plan.usable else None), charged

    def complete_again(self, cond: Term, variables: tuple[str, ...], box) -> Diffeo | None:
        """A copy's condition completed as :meth:`completed` would; None when it is not."""
        try:
            return complete(cond, variables, box)
        except diffeo.CompletionError:
            return None

    def note_completion(self, node: IfDiffeo, cond: Term, variables: tuple[str, ...], box) -> None:
        """Tell the loops being watched that ``node`` completes ``cond`` over ``variables``."""
        for watched in self.records.values():
            watched.completions[id(node)] = (node, cond, variables, box)

    def unsafe(self, *sts: STerm, sc: Scope | None = None) -> None:
        """The desugaring depends on the value of a watched loop index: on every watched one (no
        ``sts``), or on those the surface terms ``sts`` mention (read as numbers)."""
        if not self.records:
            return
        if not sts:
            for record in self.records.values():
                record.unsafe = True
            return
        for st in sts:
            stack = [st]
            while stack:
                u = stack.pop()
                if isinstance(u, Name) and u.name in self.records and (sc is None or u.name in sc.consts):
                    self.records[u.name].unsafe = True
                stack.extend(loops.children(u))


__all__ = ["Unrolling"]
