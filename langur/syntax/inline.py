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
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    Let,
    Mul,
    Param,
    Pow,
    Program,
    Term,
    Var,
    children,
    depth,
    free_params,
    free_vars,
    has_calls,
    map_children,
    substitute,
    subterms,
)
from ..diagnostics import Diagnostic, LangurError
from ..modules import ElaboratedModule
from .completion import complete, complete_or_split, diffeo, sign_chain
from .folding import plus, power, times
from .support import numeric_box

#: Deepest nesting of an inlined program (T230): twice what a written term may have (E105), so
#: that a definition's body may call another's; the recursive semantic functions stay far from
#: the interpreter's limits (``langur.cli`` raises Python's recursion limit for them).
#:
#: A call of a definition with the same arguments as an earlier one is the same shared subterm (a
#: DAG), and the passes that walk the inlined program are memoized per distinct node
#: (``langur.core.shared``); the one engine that walks it path by path (Monte Carlo) bounds its
#: tree's size itself.
MAX_INLINED_DEPTH = 400

#: Most nodes the copies of definitions' bodies may have in all (T230): each call with *new*
#: arguments is a copy, so a loop of calls at distinct arguments multiplies a body's size by its
#: copies — three lines (``def f(y: var) = sum j in 1..2000: y*j`` called as ``sum i in 1..2000:
#: f(x + i)``) wrote out 4·10⁶ nodes, 65 CPU s and 1.9 GB before anything was evaluated
#: (bench/history/2026-11-29.md#hostile33.  Counted as the copies are made, so refused at the call that
#: passes it, having built at most this much: as many nodes as loops may write out (T225), so
#: that a loop of calls costs what the same loop with the body written in it would.
MAX_INLINED_NODES = 500_000


def inline(program: Program, modules: Mapping[str, ElaboratedModule]) -> Program:
    """``program`` with every ``Call`` inlined (recursively), a call with the same arguments as an
    earlier one shared; raises LangurError (T207, T217, T221, T230: too deep, or too many nodes
    copied)."""
    bounds = [b for pair in program.box for b in pair]
    body = program.body
    if not has_calls(body) and not any(has_calls(b) for b in bounds) and \
            max([depth(body), *map(depth, bounds)]) <= MAX_INLINED_DEPTH:
        return program  # no call, not too deep (_too_large's measure without a call is the depth): as it is
    lookup = lambda m, n: modules[m].defs.get(n) if m in modules else None  # noqa: E731
    try:
        too_large = _too_large(program, lookup)
        if too_large:
            raise LangurError([too_large])
        if not has_calls(program.integrand):
            return program  # nothing to inline (no inliner, no numeric box: issue 15)
        inl = _Inliner(lambda m, n: modules[m].defs[n], program.variables,
                       numeric_box(program.variables, program.box))
        integrand = inl.expand(program.integrand, ())  # the domain's bounds call nothing
    except RecursionError:  # calls through thousands of definitions that each add no depth
        raise LangurError([ty.reject_too_large(program.span, "its calls go through too many definitions, "
                                               "one inside the next, to be inlined")]) from None
    if inl.errors:
        raise LangurError(inl.errors)
    return replace(program, integrand=integrand)


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
        self.calls: dict[tuple, Term] = {}
        #: Nodes of the bodies copied so far (at most :data:`MAX_INLINED_NODES`), and each
        #: definition's body's distinct nodes.
        self.copied = 0
        self.sizes: dict[tuple[str, str], int] = {}
        #: Parameters that the calls expanded so far bring with them (their modules' params, free
        #: in an inlined body but not in the call's arguments): a caller's ``let`` of one of these
        #: names must not capture them.
        self.brought: set[str] = set()
        self.params_of: dict[tuple[str, str], frozenset[str]] = {}
        #: By node identity: a shared subterm is expanded once — (the term, kept alive so that its
        #: id stays its own; its expansion; the parameters its calls bring)
        self.done: dict[tuple, tuple] = {}

    def expand(self, t: Term, stack: tuple) -> Term:
        """``t`` with its calls inlined; a subterm shared before inlining (a let-bound vector's
        components, substituted where it is used) stays shared, expanded once; a subterm without
        calls is itself."""
        if not has_calls(t):
            return t
        key = (id(t), stack)
        hit = self.done.get(key)
        if hit is None:
            outer, self.brought = self.brought, set()
            hit = self.done[key] = (t, self._expand(t, stack), frozenset(self.brought))
            self.brought = outer
        self.brought |= hit[2]
        return hit[1]

    def _expand(self, t: Term, stack: tuple) -> Term:
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
                shared = (module, name, args)  # the same call twice is one shared subterm (§9)
                if shared not in self.calls:
                    if self.copied > MAX_INLINED_NODES:  # (refused already: no more copies)
                        return Const(Fraction(0), span=t.span)
                    self.copied += self.size(key, d.body)
                    if self.copied > MAX_INLINED_NODES:
                        self.errors.append(ty.reject_too_large(t.span, (
                            f"`{name}(…)` here makes the copies of definitions' bodies more than "
                            f"{MAX_INLINED_NODES:,} nodes in all: definitions are inlined (§9), and each call "
                            f"with new arguments is a copy of the body ({self.size(key, d.body):,} nodes for "
                            f"`{name}`; {len(self.calls) + 1:,} copies so far)")))
                        return Const(Fraction(0), span=t.span)
                    body = self.instantiate(d, args, t.span)
                    self.calls[shared] = self.expand(body, stack + (key,))
                self.brought |= self.module_params(module, name)
                return self.calls[shared]
            case Let():
                return self.expand_let(t, stack)
            case _:
                return _rebuilt(t, lambda c: self.expand(c, stack))

    def size(self, key: tuple[str, str], body: Term) -> int:
        """The distinct nodes of a definition's body (a copy has at most as many new ones)."""
        if key not in self.sizes:
            self.sizes[key] = sum(1 for _ in subterms(body))
        return self.sizes[key]

    def module_params(self, module: str, name: str, active: frozenset = frozenset()) -> frozenset[str]:
        """The parameters a call of ``module.name`` reads besides its arguments: its module's
        params free in its body, and those of the defs it calls (memoized per def)."""
        key = (module, name)
        if key not in self.params_of:
            d = self.lookup(module, name)
            if d is None or key in active:
                return frozenset()
            out = free_params(d.body) - {n for n, k in d.args if k == "param"}
            for u in subterms(d.body):
                if isinstance(u, Call):
                    out |= self.module_params(u.module, u.name, active | {key})
            self.params_of[key] = out
        return self.params_of[key]

    def expand_let(self, t: Let, stack: tuple) -> Term:
        """``let x = s in r`` with the calls of ``s`` and ``r`` expanded.  When a call in ``r``
        brings a module parameter named ``x`` (the callee reads the program's ``x``, not this
        binder), the binder is renamed apart first, so that inlining does not capture it."""
        bound = self.expand(t.bound, stack)
        outer, self.brought = self.brought, set()
        body = self.expand(t.body, stack)
        name = t.name
        if name in self.brought:
            name = _fresh(t.name, self.brought | _names(t.body) | set(self.variables))
            renamed = substitute(t.body, params={t.name: Param(name)})
            body = self.expand(renamed, stack)
        self.brought |= outer
        if name == t.name and bound is t.bound and body is t.body:
            return t
        return replace(t, name=name, bound=bound, body=body)

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
                        new_psi = complete_or_split(cond, self.inl.variables, self.inl.box)
                        if isinstance(new_psi, tuple):  # a pole or factor that moves once inlined (syntax.poles)
                            return sign_chain(new_psi, a, b, lambda f, s, r: IfDiffeo(
                                complete(f, self.inl.variables, self.inl.box), s, r, span=t.span), t.span)
                    except diffeo.CompletionError as e:
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
                new_psi = diffeo.instantiate(psi, keys, tuple(names), tuple(pmap[k] for k in keys), self.inl.variables)
                return replace(t, psi=new_psi, then=a, orelse=b)
            case _:
                return _rebuilt(t, lambda c: self.go(c, pmap))


def _too_large(program: Program, lookup) -> Diagnostic | None:
    """T230 when ``program`` would nest more than :data:`MAX_INLINED_DEPTH` levels once inlined,
    located at the outermost call that makes it so (else the program); computed from the
    definitions without inlining, linear in their text."""
    measure = _Depth(lookup)
    depth = max(measure.of(t, {}) for t in [program.body] + [b for pair in program.box for b in pair])
    if depth <= MAX_INLINED_DEPTH:
        return None
    culprit, found = None, depth
    stack, seen = [program.body], set()
    while stack and culprit is None:
        u = stack.pop()
        if id(u) in seen:  # a shared subterm is searched once
            continue
        seen.add(id(u))
        if isinstance(u, Call):
            d = measure.of(u, {})
            if d > MAX_INLINED_DEPTH:
                culprit, found = u, d
            continue
        stack.extend(reversed(_children(u)))
    where = culprit.span if culprit is not None and culprit.span is not None else program.span
    what = f"`{culprit.name}(…)`" if culprit is not None else "the program"
    how = ("definitions are inlined (§9), so each call adds the depth of the definition's body" if culprit else
           "definitions are inlined (§9) and let-bound vectors substituted, so each call or use adds the depth of "
           "what it stands for")
    return ty.reject_too_large(where, f"{what} nests {found:,} levels deep when its definitions are inlined "
                               f"(at most {MAX_INLINED_DEPTH}): {how}")


class _Depth:
    """The depth of a term once its calls are inlined, computed without inlining: memoized per
    definition and argument depths, so linear in the definitions' text."""

    def __init__(self, lookup):
        self.lookup = lookup
        self.memo: dict[tuple, int] = {}
        self.active: set[tuple] = set()
        self.nodes: dict = {}  # by node identity and env: a shared subterm is measured once

    def of(self, t: Term, env: dict[str, int]) -> int:
        """Depth of ``t`` inlined, where a name of ``env`` stands for a term that deep.  A term that
        shares subterms (a let-bound vector's components are substituted where it is used: a DAG
        even before inlining) is measured in time linear in its distinct nodes.  A term known to
        call nothing, where no name stands for anything, has its own depth (:func:`langur.core.depth`,
        kept on its nodes)."""
        if not env and not has_calls(t):
            return depth(t)
        key = (id(t), tuple(env.items())) if env else id(t)
        k = self.nodes.get(key)
        if k is None:
            k = self.nodes[key] = self._of(t, env)
        return k

    def _of(self, t: Term, env: dict[str, int]) -> int:
        match t:
            case Var(name) | Param(name):
                return env.get(name, 1)
            case Let(name, bound, body):
                inner = {k: v for k, v in env.items() if k != name}
                return 1 + max(self.of(bound, env), self.of(body, inner))
            case IfDiffeo(psi, a, b):
                cond = self.of(psi.forward[0], env) if psi.name is None else 1
                return 1 + max(cond, self.of(a, env), self.of(b, env))
            case Call(module, name, args):
                depths = tuple(min(self.of(a, env), MAX_INLINED_DEPTH + 1) for a in args)
                d = self.lookup(module, name)
                key = (module, name, depths)
                if d is None or key in self.active:  # unknown or recursive: reported elsewhere
                    return 1 + max(depths, default=0)
                if key not in self.memo:
                    self.active.add(key)
                    self.memo[key] = self.of(d.body, {n: k for (n, _), k in zip(d.args, depths)})
                    self.active.discard(key)
                return self.memo[key]
            case _:
                return 1 + max((self.of(c, env) for c in _children(t)), default=0)


def _rebuilt(t: Term, f) -> Term:
    """``map_children(t, f)`` (sums, products and powers folded), but ``t`` itself when ``f`` changes no
    child: what inlining leaves alone stays the same node, so that the passes that keep their results on nodes (typing, the
    range check, the depth) do not redo the scene after a shader swap."""
    old = children(t)
    new = tuple(f(c) for c in old)
    if all(n is o for n, o in zip(new, old)):
        return t
    # (a sum, product or power whose child changed: its 0s and 1s folded, a param argument 1 or 0
    # in `k * x + c` gives x: syntax/folding.py)
    if type(t) is Add:
        return plus(new[0], new[1], t.span)
    if type(t) is Mul:
        return times(new[0], new[1], t.span)
    if type(t) is Pow:
        return power(new[0], t.exponent, t.span)
    it = iter(new)
    return map_children(t, lambda _: next(it))


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
    return children(u)


def _fresh(name: str, taken: set[str]) -> str:
    k = 1
    while f"{name}_{k}" in taken:
        k += 1
    return f"{name}_{k}"
