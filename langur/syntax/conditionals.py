"""Conditionals of the desugarer: ``ifge0`` and the comparisons, on the parameters or over the
variables (§5.2 and Fig. 6, conditional and diffeomorphic conditional; Ψ̂ a C¹ diffeomorphism,
Def. 3.4).

A condition that is variable-free becomes ``IfGe0``.  A condition over variables becomes
``IfDiffeo``: a declared diffeo application is instantiated (``langur.syntax.diffeo.instantiate``,
:meth:`Conditionals.diffeo_app`); any other condition is completed automatically
(``langur.syntax.diffeo.complete``) over *all* of Δ.  In a program body a declared diffeo is
extended by the identity to all the program's variables; in a ``def`` body it stays over its
application's variables (the inliner renames and extends it at each call site).
A condition over variables that calls defs of its own module is completed with those calls
expanded (it is completed as a whole); calling an imported def there is a T207 (the module's
elaborated form would depend on the imported body, not just its signature).  A condition with
kinks (``abs``, ``min``, ``max`` over the variables) is split at them (at most :data:`MAX_PIECES`
pieces in all; :mod:`langur.syntax.kinks`).  While a program's box is not known yet (no domain,
§8.3) a condition that needs it waits (:meth:`Conditionals.complete_pending`).

:class:`Conditionals` holds these methods of :class:`~langur.syntax.desugar.Desugarer` (one class,
its methods in three modules: the sugar table's ``match`` in :mod:`langur.syntax.desugar`, the §9
loops in :mod:`langur.syntax.unrolling`).
"""

from __future__ import annotations

from dataclasses import replace
from fractions import Fraction

from .. import typesys as ty
from ..core import (
    Add,
    Call,
    Const,
    Diffeo,
    IfDiffeo,
    IfGe0,
    Mul,
    Term,
    free_vars,
    map_children,
    smooth,
    subterms,
    tree_size,
)
from ..diagnostics import Span
from . import kinks
from .completion import complete, complete_or_split, diffeo, sign_chain
from .folding import minus, plus, times
from .inline import expand_calls
from .scope import Scope
from .surface import DiffeoApp, Iverson, Name, STerm

#: The conditions of a module split at their kinks (abs/min/max over the variables) have at most
#: this many pieces in all (nested kinks double them at each level: the bound keeps the work bounded).
MAX_PIECES = 128
#: A condition with kinks is split only when written out as a tree it has at most this many nodes
#: (the cube [max(max(abs(x), abs(y)), abs(z)) <= a] has 867; four nested abs over 10000).
MAX_SPLIT_SIZE = 1000


class TooManyPieces(Exception):
    """More than :data:`MAX_PIECES` pieces of conditions split at their kinks."""


def put(t: Term, old: Term, new: Term) -> Term:
    """``t`` with the subterm ``old`` (by identity) replaced by ``new``."""
    if t is old:
        return new
    return map_children(t, lambda c: put(c, old, new))


def decided(t: Term, cond: Term, holds: bool) -> Term:
    """``t`` where ``cond ≥ 0`` is known to hold (or not): each conditional over the variables on
    ``cond`` replaced by its then-branch (else-branch), which it takes there."""
    t = map_children(t, lambda c: decided(c, cond, holds))
    if isinstance(t, IfDiffeo) and t.psi.condition == cond:
        return t.then if holds else t.orelse
    if type(t) is Add:  # (a branch put in may be 0 or 1: [max(x, 0) >= a] where x < 0 is [0 - a >= 0], i.e. -a)
        return plus(t.left, t.right, t.span)
    if type(t) is Mul:
        return times(t.left, t.right, t.span)
    return t


class Conditionals:
    """The desugarer's conditionals (a part of :class:`~langur.syntax.desugar.Desugarer`)."""

    def if_chain(self, chain: Iverson, then: Term, orelse: Term, sc: Scope, span) -> Term:
        """``if t0 op0 t1 op1 t2 … then s else r``: one conditional per comparison, nested."""
        core = [self.term(u, sc) for u in chain.terms]
        out = then
        for i in reversed(range(len(chain.ops))):
            out = self.conditional(compare(core[i], chain.ops[i], core[i + 1]), out, orelse, sc, span,
                                   join(chain.terms[i], chain.terms[i + 1]), built=True)
        return out

    def conditional(self, cond: Term, then: Term, orelse: Term, sc: Scope, span, cond_span=None,
                    built: bool = False) -> Term:
        """``ifge0 cond then … else …``: IfGe0 when ``cond`` is variable-free, else the completed
        IfDiffeo (Fig. 6, conditional / diffeomorphic conditional).  ``built``: ``cond`` is a
        difference the desugarer wrote (a comparison's ``t − s``, min/max's), not a term of the
        source: its completion Ψ takes no span of its own, so a finding on it is located at the
        conditional (the bracket ``[`` or the ``if``), as before fold31 — where ``t − 0`` folds to
        ``t`` the condition *is* the operand ``t``, whose span would move the finding onto it."""
        cond = kinks.cancelled(cond) if self.splitting else cond  # a kink split's flat piece
        if not free_vars(cond):
            return IfGe0(cond, then, orelse, span)
        if smooth(cond):  # no conditional and no call inside: completed as it is
            self.count_piece()
            return self.completed(cond, then, orelse, sc, span, cond_span, built)
        inner = next((u for u in subterms(cond) if isinstance(u, IfGe0) and not free_vars(u.cond)), None)
        if inner is not None:
            # a conditional on the parameters inside a condition over variables ([x < min(t, s)],
            # a bound `if c < 0 then a else b`): constant in the variables, it is lifted out —
            # ifge0 c' then (the condition with its then-branch) else (… with its else-branch)
            return IfGe0(inner.cond,
                         self.conditional(put(cond, inner, inner.then), then, orelse, sc, span, cond_span, built),
                         self.conditional(put(cond, inner, inner.orelse), then, orelse, sc, span, cond_span, built),
                         span=span)
        kink = next((u for u in subterms(cond) if isinstance(u, IfDiffeo)), None)
        if kink is not None and tree_size(cond) > MAX_SPLIT_SIZE:
            # nested kinks (abs(abs(…) − c)) double the written-out condition at each level
            return self.fail(ty.reject_condition(cond_span or cond.span or span, (
                f"with its kinks (abs, min, max over the variables) written out it has more than {MAX_SPLIT_SIZE} "
                "nodes: write it as a product or sum of simpler conditions ([max(A, B) <= s] is "
                "[A <= s & B <= s], [min(A, B) <= s] is [A <= s | B <= s]: brackets that compare a min, max "
                "or abs with a term are rewritten so by themselves)")), span)
        if kink is not None:
            self.unsafe()  # the split compares conditions
            # a conditional over the variables inside a condition (abs, min, max: [abs(x - a) <= 0.2])
            # splits the condition at the kink: ifge0 ⌊Ψ_k⌋ then (the condition with the kink's
            # then-branch) else (… with its else-branch), each branch completed on its own.  The
            # split's delta has weight (then − else) at the kink, which is 0 for a continuous
            # abs/min/max (both branches agree there): the split adds no derivative
            # (every conditional on the kink's condition in it takes the same branch: no repeated split)
            # (at most MAX_PIECES pieces in all the module's conditions: each split doubles them)
            c = kink.psi.condition
            top, self.splitting = not self.splitting, True
            self.sides.append((c, True))  # which piece: for the messages of a piece refused (T207)
            try:
                yes = self.conditional(decided(cond, c, True), then, orelse, sc, span, cond_span, built)
                self.sides[-1] = (c, False)
                no = self.conditional(decided(cond, c, False), then, orelse, sc, span, cond_span, built)
                return IfDiffeo(kink.psi, yes, no, span=span)
            except TooManyPieces:
                if not top:
                    raise
                return self.fail(ty.reject_condition(cond_span or cond.span or span, (
                    f"split at their kinks (abs, min, max over the variables) the conditions have more than "
                    f"{MAX_PIECES} pieces in all: write this one as a product or sum of simpler conditions")), span)
            finally:
                self.sides.pop()
                if top:
                    self.splitting = False
        self.count_piece()
        if any(isinstance(u, Call) for u in subterms(cond)):
            self.unsafe()
            # a condition is completed as a whole: expand the defs it calls first
            cond, errs = expand_calls(cond, lambda m, n: self.env.bodies.get((m, n)), sc.variables, sc.box)
            if errs:
                self.errors.extend(errs)
                return Const(Fraction(0), span=span)
        return self.completed(cond, then, orelse, sc, span, cond_span, built)

    def count_piece(self) -> None:
        """One more piece of a condition split at its kinks (at most MAX_PIECES in all)."""
        if self.splitting:
            self.pieces += 1
            if self.pieces > MAX_PIECES:
                raise TooManyPieces

    def completed(self, cond: Term, then: Term, orelse: Term, sc: Scope, span, cond_span, built=False) -> Term:
        """``ifge0 ⌊Ψ⌋ then … else …`` with Ψ the completion of ``cond`` over the variables (a
        pending one while the program's box is not known yet)."""
        try:
            psi = complete_or_split(cond, sc.variables, sc.box)
        except diffeo.CompletionError as e:
            why = kinks.on_piece(str(e), self.sides)
            if not sc.in_program and "bounded" in why:
                why += "; inside a def or diffeo the variables' domain is unknown: write this condition in the program"
            diagnostic = ty.reject_condition(cond_span or cond.span or span, why)
            if self.pending is None:
                return self.fail(diagnostic, span)
            psi = Diffeo(sc.variables, (cond,), (), (), span=None if built else cond.span)  # completed by complete_pending
            self.pending.append((psi, diagnostic))
            self.unsafe()
            return IfDiffeo(psi, then, orelse, span=span)
        if isinstance(psi, tuple):
            return self.signs(psi, then, orelse, sc, span, cond_span, built)
        if built and psi.span is not None:
            psi = replace(psi, span=None)  # (a built difference has no text of its own: ``conditional``)
        node = IfDiffeo(psi, then, orelse, span)
        if self.records:
            self.note_completion(node, cond, sc.variables, sc.box)
        return node

    def signs(self, split, then: Term, orelse: Term, sc: Scope, span, cond_span, built=False) -> Term:
        """A condition that changes sign where its completion does not reach, as the signs of its
        factors (:func:`langur.syntax.completion.sign_chain`), each factor a conditional of its own."""
        self.unsafe()  # the factors are read off the condition's value (sympy factors it)
        return sign_chain(split, then, orelse, lambda f, s, r: self.conditional(f, s, r, sc, span, cond_span, built), span)

    def complete_pending(self, t: Term, variables: tuple[str, ...], box) -> Term:
        """``t`` with the conditions left pending completed over the program's ``box`` (a periodic
        condition needs its argument's range); those that still fail are reported (T207)."""
        pending, self.pending = dict((id(psi), d) for psi, d in self.pending or ()), None
        if not pending:
            return t

        def go(u: Term) -> Term:
            u = map_children(u, go)
            if not (isinstance(u, IfDiffeo) and id(u.psi) in pending):
                return u
            if box:
                try:
                    return replace(u, psi=replace(complete(u.psi.forward[0], variables, box), span=u.psi.span))
                except diffeo.CompletionError as e:
                    return self.fail(ty.reject_condition(pending[id(u.psi)].span, str(e)), u.span)
            return self.fail(pending[id(u.psi)], u.span)

        return go(t)

    def diffeo_app(self, app: DiffeoApp, sc: Scope) -> Diffeo | None:
        self.unsafe()  # a declared Ψ instantiated with its arguments' values
        where = app.name_span or app.span
        if app.name in self.env.poisoned:
            return None
        if app.name not in self.env.diffeos:
            detail = ": it is a def, not a diffeo" if app.name in self.env.defs else ": no diffeo of that name in scope"
            self.errors.append(ty.reject_unknown_function(where, app.name, detail))
            return None
        sig = self.env.diffeos[app.name]
        n, m = len(sig.diffeo.variables), len(sig.params)
        if len(app.variables) != n or len(app.params) != m:
            self.errors.append(ty.diag(where, "T203", f"diffeo `{app.name}` takes {n} variable(s) and {m} "
                                       f"parameter(s), got {len(app.variables)} and {len(app.params)}"))
            return None
        names: list[str] = []
        for v in app.variables:
            if not (isinstance(v, Name) and v.name in sc.variables):
                self.errors.append(ty.reject_diffeo_args(getattr(v, "span", where), app.name,
                                                         "this argument is not a variable of integration"))
                return None
            if v.name in names:
                self.errors.append(ty.reject_diffeo_args(v.span, app.name, f"`{v.name}` is passed twice"))
                return None
            names.append(v.name)
        params = []
        for p, pname in zip(app.params, sig.params):
            t = self.term(p, replace(sc, where=f"parameter `{pname}` of diffeo `{app.name}`"))
            used = free_vars(t)
            if used:
                self.errors.append(ty.reject_param_arg_with_variables(getattr(p, "span", where), app.name, pname, used))
                return None
            params.append(t)
        psi = diffeo.instantiate(sig.diffeo, sig.params, tuple(names), tuple(params),
                                 sc.variables if sc.in_program else None)
        return replace(psi, span=app.span)



def join(a: STerm, b: STerm) -> Span | None:
    """The span from the start of ``a`` to the end of ``b`` (a comparison's source text)."""
    sa, sb = getattr(a, "span", None), getattr(b, "span", None)
    if sa is None or sb is None:
        return sa or sb
    return Span(sa.path, sa.line, sa.col, sb.end_line, sb.end_col)


def compare(left: Term, op: str, right: Term) -> Term:
    """The condition of ``[left op right]``: ``left − right`` for ≥ and >, ``right − left`` for ≤ and <
    (``t − 0`` is ``t``, ``0 − t`` is ``−t``: :func:`~langur.syntax.folding.minus`)."""
    if op in (">=", ">", "≥"):
        return minus(left, right)
    if op in ("<=", "<", "≤"):
        return minus(right, left)
    raise ValueError(f"unknown comparison {op}")



__all__ = ["MAX_PIECES", "MAX_SPLIT_SIZE", "Conditionals", "TooManyPieces", "compare", "decided", "join", "put"]
