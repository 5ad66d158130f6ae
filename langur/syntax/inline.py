"""Inlining def calls: a module's elaborated program (with ``Call`` links) to pure core (§9).

Each ``Call(module, name, args)`` is replaced by the def's body with its arguments substituted
(LANGUAGE.md §6: "the body with arguments substituted"):

* a ``var`` argument's term replaces the argument's variable; a ``param`` argument's term its
  parameter; ``let`` binders of the body are renamed apart from the arguments' parameters and the
  program's variables (no capture);
* a completed condition (``Diffeo.solved_for`` set) is substituted and *re-completed* over all of
  the program's variables with the program's box (``langur.syntax.diffeo.complete``), so that it
  is exactly what desugaring the same condition in the program would give, also when a var
  argument is not a bare variable;
* a declared diffeo's variables must be passed distinct variables of integration (T217): it is
  renamed, its parameters substituted, and extended by the identity to the program's variables.

Afterwards every ``IfDiffeo``'s Diffeo is over exactly ``Program.variables``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from fractions import Fraction

from .. import typesys as ty
from ..core import (
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    Let,
    Param,
    Program,
    Term,
    Var,
    free_params,
    free_vars,
    map_children,
)
from ..diagnostics import Diagnostic, LangurError
from ..modules import ElaboratedModule
from .diffeo import CompletionError, complete, instantiate
from .support import numeric_box

#: Most nodes a program may have once its definitions are inlined (T230): about as many as the
#: largest program that can be written out (E108 allows a million significant characters).
#: Langur links definitions by inlining (§9) and its engines work on the inlined term, so a file
#: of a few lines that doubles a definition n times would cost 2ⁿ: it is refused, located, before
#: any of that is spent.
MAX_INLINED_NODES = 1_000_000
#: Deepest nesting of an inlined program (T230): twice what a written term may have (E105), so
#: that a definition's body may call another's; the recursive semantic functions stay far from
#: the interpreter's limits (``langur.cli`` raises Python's recursion limit for them).
MAX_INLINED_DEPTH = 400


def inline(program: Program, modules: Mapping[str, ElaboratedModule]) -> Program:
    """``program`` with every ``Call`` inlined (recursively); raises LangurError (T207, T217, T221,
    T230)."""
    lookup = lambda m, n: modules[m].defs.get(n) if m in modules else None  # noqa: E731
    too_large = _too_large(program, lookup)
    if too_large:
        raise LangurError([too_large])
    inl = _Inliner(lambda m, n: modules[m].defs[n], program.variables,
                   numeric_box(program.variables, program.box))
    body = inl.expand(program.body, ())
    if inl.errors:
        raise LangurError(inl.errors)
    return replace(program, body=body)


def expand_calls(t: Term, lookup, variables: tuple[str, ...], box) -> tuple[Term, list[Diagnostic]]:
    """``t`` with its calls inlined, in a scope with ``variables`` and numeric ``box``; ``lookup(module,
    name)`` gives the CoreDef (or None: not available yet).  Used for conditions that call defs:
    a condition is completed as a whole, so its calls must be expanded first."""
    inl = _Inliner(lookup, tuple(variables), box)
    return inl.expand(t, ()), inl.errors


class _Inliner:
    def __init__(self, lookup, variables, box):
        self.lookup = lookup
        self.variables = tuple(variables)
        self.box = box
        self.errors: list[Diagnostic] = []

    def expand(self, t: Term, stack: tuple) -> Term:
        match t:
            case Call(module, name, args):
                key = (module, name)
                if key in stack:
                    self.errors.append(ty.reject_recursive(t.span, [f"{m}.{n}" for m, n in stack + (key,)]))
                    return Const(Fraction(0), span=t.span)
                d = self.lookup(module, name)
                if d is None:
                    self.errors.append(ty.reject_condition(t.span, f"it calls `{name}` of module `{module}`; a "
                                                           "condition is completed as a whole, so it may call only "
                                                           "(non-recursive) defs of its own module (a module's "
                                                           "elaborated form depends only on the signatures of "
                                                           "what it imports)"))
                    return Const(Fraction(0), span=t.span)
                args = tuple(self.expand(a, stack) for a in args)
                body = self.instantiate(d, args, t.span)
                return self.expand(body, stack + (key,))
            case IfDiffeo(_, a, b):
                return replace(t, then=self.expand(a, stack), orelse=self.expand(b, stack))
            case _:
                return map_children(t, lambda c: self.expand(c, stack))

    def instantiate(self, d, args: tuple[Term, ...], span) -> Term:
        vmap = {n: a for (n, k), a in zip(d.args, args) if k == "var"}
        pmap = {n: a for (n, k), a in zip(d.args, args) if k == "param"}
        taken = set(self.variables)
        for a in args:
            taken |= free_params(a)
        return _Subst(self, vmap, taken, span, d.name).go(d.body, pmap)


class _Subst:
    def __init__(self, inl: _Inliner, vmap, taken, span, fname):
        self.inl, self.vmap, self.taken, self.span, self.fname = inl, vmap, set(taken), span, fname

    def go(self, t: Term, pmap: dict[str, Term]) -> Term:
        match t:
            case Var(name):
                return self.vmap.get(name, t)
            case Param(name):
                return pmap.get(name, t)
            case Const():
                return t
            case Let(name, bound, body):
                bound = self.go(bound, pmap)
                if name in self.taken:
                    new = _fresh(name, self.taken | _names(body))
                    self.taken.add(new)
                    return replace(t, name=new, bound=bound, body=self.go(body, {**pmap, name: Param(new)}))
                inner = {k: v for k, v in pmap.items() if k != name}
                return replace(t, bound=bound, body=self.go(body, inner))
            case IfDiffeo(psi, a, b):
                a, b = self.go(a, pmap), self.go(b, pmap)
                if psi.name is None:
                    cond = self.go(psi.forward[0], pmap)
                    if not free_vars(cond):
                        return IfGe0(cond, a, b, span=t.span)
                    try:
                        new_psi = complete(cond, self.inl.variables, self.inl.box)
                    except CompletionError as e:
                        self.inl.errors.append(ty.reject_condition(
                            self.span, f"in the body of `{self.fname}` inlined here: {e}"))
                        return Const(Fraction(0), span=t.span)
                    return replace(t, psi=new_psi, then=a, orelse=b)
                names = []
                for x in psi.variables:
                    target = self.vmap.get(x, Var(x))
                    if not isinstance(target, Var) or target.name in names:
                        self.inl.errors.append(ty.reject_diffeo_args(
                            self.span, psi.name, f"in the body of `{self.fname}`, its variable `{x}` is passed a "
                            "term that is not a distinct variable of integration"))
                        return Const(Fraction(0), span=t.span)
                    names.append(target.name)
                keys = tuple(pmap)
                new_psi = instantiate(psi, keys, tuple(names), tuple(pmap[k] for k in keys), self.inl.variables)
                return replace(t, psi=new_psi, then=a, orelse=b)
            case _:
                return map_children(t, lambda c: self.go(c, pmap))


def _too_large(program: Program, lookup) -> Diagnostic | None:
    """T230 when ``program`` would have more than :data:`MAX_INLINED_NODES` nodes, or nest more
    than :data:`MAX_INLINED_DEPTH` levels, once inlined; located at the outermost call that makes
    it so (else the program)."""
    measure = _Size(lookup)
    terms = [program.body] + [b for pair in program.box for b in pair]
    sizes = [measure.of(t, {}) for t in terms]
    total, depth = sum(n for n, _ in sizes), max(d for _, d in sizes)
    if total <= MAX_INLINED_NODES and depth <= MAX_INLINED_DEPTH:
        return None
    culprit, found = None, (total, depth)
    stack = [program.body]
    while stack and culprit is None:
        u = stack.pop()
        if isinstance(u, Call):
            n, d = measure.of(u, {})
            if n > MAX_INLINED_NODES or d > MAX_INLINED_DEPTH:
                culprit, found = u, (n, d)
            continue
        stack.extend(reversed(_children(u)))
    where = culprit.span if culprit is not None and culprit.span is not None else program.span
    what = f"`{culprit.name}(…)`" if culprit is not None else "the program"
    n, d = found
    if n > MAX_INLINED_NODES:
        detail = (f"{what} expands to {_about(n)} nodes when its definitions are inlined (at most "
                  f"{MAX_INLINED_NODES:,}): definitions are inlined (§9), so a definition that calls "
                  "another k times multiplies its size by k")
    else:
        detail = (f"{what} nests {_about(d)} levels deep when its definitions are inlined (at most "
                  f"{MAX_INLINED_DEPTH}): definitions are inlined (§9), so each call adds the depth of "
                  "the definition's body")
    return ty.reject_too_large(where, detail)


def _about(n: float) -> str:
    if n >= 1e300:
        return "more than 10^300"
    if n >= 1e7:
        return f"about {n:.2g}".replace("e+", "e")
    return f"{int(n):,}"


class _Size:
    """The number of nodes and the depth of a term once its calls are inlined, computed without
    inlining: memoized per definition and argument measures (floats: the sizes that matter here
    overflow any bound; they are capped in the memo key), so linear in the definitions' text."""

    CAP = float(MAX_INLINED_NODES + 1)

    def __init__(self, lookup):
        self.lookup = lookup
        self.memo: dict[tuple, tuple[float, float]] = {}
        self.active: set[tuple] = set()

    def of(self, t: Term, env: dict[str, tuple[float, float]]) -> tuple[float, float]:
        """(nodes, depth) of ``t`` inlined, where a name of ``env`` stands for a term of that
        measure."""
        match t:
            case Var(name) | Param(name):
                return env.get(name, (1.0, 1.0))
            case Let(name, bound, body):
                inner = {k: v for k, v in env.items() if k != name}
                return self._node([self.of(bound, env), self.of(body, inner)])
            case IfDiffeo(psi, a, b):
                cond = self.of(psi.forward[0], env) if psi.name is None else (1.0, 1.0)
                return self._node([cond, self.of(a, env), self.of(b, env)])
            case Call(module, name, args):
                measures = tuple(self.of(a, env) for a in args)
                d = self.lookup(module, name)
                key = (module, name, tuple((min(n, self.CAP), min(h, self.CAP)) for n, h in measures))
                if d is None or key in self.active:  # unknown or recursive: reported elsewhere
                    return self._node(list(measures))
                if key not in self.memo:
                    self.active.add(key)
                    self.memo[key] = self.of(d.body, {n: m for (n, _), m in zip(d.args, measures)})
                    self.active.discard(key)
                return self.memo[key]
            case _:
                return self._node([self.of(c, env) for c in _children(t)])

    @staticmethod
    def _node(children: list[tuple[float, float]]) -> tuple[float, float]:
        return 1.0 + sum(n for n, _ in children), 1.0 + max((d for _, d in children), default=0.0)


def _names(t: Term) -> set[str]:
    out = set(free_params(t))
    stack = [t]
    while stack:
        u = stack.pop()
        if isinstance(u, Let):
            out.add(u.name)
        stack.extend(_children(u))
    return out


def _children(u):
    from ..core import children

    return children(u)


def _fresh(name: str, taken: set[str]) -> str:
    k = 1
    while f"{name}_{k}" in taken:
        k += 1
    return f"{name}_{k}"
