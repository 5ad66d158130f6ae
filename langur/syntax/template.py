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
The first copy is compiled into *steps* (:meth:`Template._plan`) that :meth:`Template.at` runs
in one loop; a node whose children keep the first copy's shape is built by ``core.like`` (its
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

import functools
from collections.abc import Callable
from dataclasses import field
from fractions import Fraction
from math import gcd

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
    index_const,
    index_power_small,
    like,
    like_binary,
    like_binary_many,
    like_leaf,
    like_power,
    map_children,
    same_shape,
    shape_of,
    shape_with_span,
    small_power,
    small_value,
)
from ..records import FACTORY, record
from . import affine

#: ``core.index_power_small``, each (index, exponent) computed once per load: a module's loops often
#: run over the same indices (MB1's two sums; each copy's ``1/i`` is a ``Fraction`` made in Python,
#: issue 15).  An ``lru_cache`` of a ``langur.syntax`` module, so emptied with the front end's memos.
_index_power = functools.lru_cache(maxsize=1024)(index_power_small)

#: Build a loop's copies from its first (False: every copy desugared from the surface, as the
#: tests compare).
ENABLED = True
#: Copies built so far by :meth:`Template.at`, refused, and conditions completed again by adding up
#: their constant term alone (the tests check that they exercised each).
STATS = {"instantiated": 0, "refused": 0, "shifted": 0}


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
                made = (_BINARY, tu, {"shape": u.shape, "span": u.span},
                        ref(u.left) if a is None else a, ref(u.right) if b is None else b)
            elif tu is Pow:
                base = ref(u.base) if a is None else a
                # a power of the index itself (1/i): its value is computed once per copy and exponent
                power = powers.setdefault(u.exponent, len(powers)) if base >= 0 and steps[base][0] is _LEAF else -1
                made = (_UNARY, tu, shape_with_span(u), base, u.exponent, power)
            elif tu is Prim:
                made = (_UNARY, tu, shape_with_span(u), ref(u.arg) if a is None else a, u.op, -1)
            elif tu is IfDiffeo:
                made = self._conditional_step(u, completions.get(id(u)), ref, own)
            elif tu is Const or tu is Var or tu is Param:
                made = (_LEAF, u.span)  # (an index leaf)
            else:
                made = (_OTHER, u, {id(c): own[id(c)] for c in children(u) if dep[id(c)]})
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
            return (_COMPLETE, u.span, ref(cond), ref(u.then), ref(u.orelse), variables, box,
                    self._shifted(cond, variables, own, u.psi), shape_of(u))
        return (_CONDITIONAL, u.psi, u.span, ref(u.then), ref(u.orelse), None if found is None else found[1:])

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

    def at(self, value: int) -> Term | None:
        """The copy for the index's ``value``: the first copy with its index leaves replaced by
        ``value`` and its conditions over them completed again; None when one does not complete."""
        if not self.dependent[id(self.body)]:
            return self.body  # the index does not occur: every copy is the first
        steps, first = self.steps, self.first
        n = len(steps)
        vals = self.start[:]  # (each step's node at its index, shared nodes from the end)
        # same[i]: vals[i] has the shape of the first copy's node (core.same_shape), so a node above it
        # is built by core.like, which keeps the attributes of that shape and computes the others
        same = self.start_same[:]
        powers = [None] * self.powers  # the small value of each power of the index, once computed
        leaf = None  # the copy's first index leaf: the others are built from it
        complete, completed = self.complete, self.completed
        for i, step in enumerate(steps):
            k = step[0]
            if k is _BINARY:
                _, cls, shape, a, b = step
                if same[a] and same[b]:
                    vals[i] = like_binary(cls, shape, vals[a], vals[b])
                    same[i] = True
                else:
                    vals[i] = cls(vals[a], vals[b], span=shape["span"])
            elif k is _LEAF:
                vals[i] = leaf = index_const(value, step[1]) if leaf is None else like_leaf(leaf, step[1])
                same[i] = True
            elif k is _UNARY:
                _, cls, shape, a, arg, power = step
                if same[a]:
                    if cls is Pow:
                        if power < 0:
                            small = small_power(vals[a].small, arg)
                        else:
                            small = powers[power]
                            if small is None:
                                e = self.exponents[power]
                                small = powers[power] = (small_power(vals[a].small, arg) if e is None
                                                         else _index_power(value, e))
                        vals[i] = like_power(shape, vals[a], small)
                    else:
                        vals[i] = like(cls, shape, (vals[a],), shape["span"])
                    same[i] = True
                elif cls is Pow:
                    vals[i] = Pow(vals[a], arg, span=shape["span"])
                else:
                    vals[i] = Prim(arg, vals[a], span=shape["span"])
            elif k is _COMPLETE:
                _, span, c, a, b, variables, box, shifted, shape = step
                cond = vals[c]
                psi = None
                if shifted is not None:  # the same shape: the constant term moved by the summands' change
                    solved, num, den, parts = shifted
                    for j, factor, sign in parts:
                        new = small_value(vals[j])
                        if new is None or new is False:
                            break
                        num, den = _moved(num, den, new, factor, sign)
                    else:
                        g = gcd(num, den)
                        psi = affine.solved_at_ratio(cond, variables, solved, num // g, den // g)
                        STATS["shifted"] += 1
                        if same[c] and same[a] and same[b]:
                            # Ψ̂ of the first's shape (affine.completed of a condition of its shape): so is the node
                            out = vals[i] = like(IfDiffeo, shape, (psi, vals[a], vals[b]), span)
                            completed(out, cond, variables, box)
                            same[i] = True
                            continue
                if psi is None:
                    psi = complete(cond, variables, box)
                    if psi is None:
                        STATS["refused"] += 1
                        return None
                out = vals[i] = IfDiffeo(psi, vals[a], vals[b], span=span)
                completed(out, cond, variables, box)
                same[i] = same_shape(out, first[i])
            elif k is _CONDITIONAL:
                _, psi, span, a, b, found = step
                out = vals[i] = IfDiffeo(psi, vals[a], vals[b], span=span)
                if found is not None:
                    completed(out, *found)
                same[i] = same_shape(out, first[i])
            else:
                kids = step[2]
                out = vals[i] = map_children(step[1], lambda c, kids=kids: vals[kids[id(c)]] if id(c) in kids else c)
                same[i] = same_shape(out, step[1])
        STATS["instantiated"] += 1
        return vals[n - 1]


    def at_all(self, values: range) -> list[Term] | None:
        """The copies for the index's ``values`` (each :meth:`at`'s), built step by step for all of
        them at once: each step's kind, shape and slots are read once for every copy, and a node whose
        children keep the first copy's shape is built in one loop over the copies (issue 15).  None
        when a copy's condition does not complete (the caller then builds the copies one by one, as
        :meth:`at` does, which reports it); the conditionals completed are told (``completed``) once
        all are built, copy by copy in the order :meth:`at` would."""
        if not self.dependent[id(self.body)]:
            return [self.body] * len(values)
        steps, first = self.steps, self.first
        m = len(values)
        n = len(steps)
        # cols[i]: step i's node in each copy (a list), or a shared node (from the end, one for all)
        cols: list = [None] * n + self.shared
        # same[i]: cols[i]'s nodes all have the first copy's shape (True), or a list per copy
        same: list = [False] * n + [True] * len(self.shared)
        powers: dict[int, list] = {}  # the small value of each power of the index, per copy
        leaves = None  # the copies' first index leaves: the others are built from them
        notes: list[list] = [[] for _ in values]  # the conditionals completed, per copy
        shifted_count = 0
        for i, step in enumerate(steps):
            k = step[0]
            if k is _BINARY:
                _, cls, shape, a, b = step
                xs, ys = cols[a], cols[b]
                if type(xs) is not list:
                    xs = [xs] * m
                if type(ys) is not list:
                    ys = [ys] * m
                sa, sb = same[a], same[b]
                if sa is True and sb is True:
                    cols[i], same[i] = like_binary_many(cls, shape, xs, ys), True
                else:
                    sa = [sa] * m if type(sa) is bool else sa
                    sb = [sb] * m if type(sb) is bool else sb
                    out, flags = [], []
                    for x, y, p, q in zip(xs, ys, sa, sb):
                        if p and q:
                            out.append(like_binary(cls, shape, x, y))
                            flags.append(True)
                        else:
                            out.append(cls(x, y, span=shape["span"]))
                            flags.append(False)
                    cols[i], same[i] = out, flags
            elif k is _LEAF:
                span = step[1]
                if leaves is None:
                    cols[i] = leaves = [index_const(v, span) for v in values]
                else:
                    cols[i] = [like_leaf(leaf, span) for leaf in leaves]
                same[i] = True
            elif k is _UNARY:
                _, cls, shape, a, arg, power = step
                xs = cols[a]
                if type(xs) is not list:
                    xs = [xs] * m
                sa = same[a]
                sa = [sa] * m if type(sa) is bool else sa
                if cls is Pow and power >= 0:
                    smalls = powers.get(power)
                    if smalls is None:
                        e = self.exponents[power]
                        smalls = powers[power] = (
                            [small_power(x.small, arg) for x in xs] if e is None
                            else [_index_power(v, e) for v in values])
                else:
                    smalls = None
                if smalls is not None and same[a] is True:  # (the index's powers, 1/i: one call a copy)
                    cols[i], same[i] = [like_power(shape, x, small) for x, small in zip(xs, smalls)], True
                    continue
                if smalls is None:
                    smalls = [None] * m
                out, flags = [], []
                for x, p, small in zip(xs, sa, smalls):
                    if p:
                        if cls is Pow:
                            out.append(like_power(shape, x, small_power(x.small, arg) if power < 0 else small))
                        else:
                            out.append(like(cls, shape, (x,), shape["span"]))
                    elif cls is Pow:
                        out.append(Pow(x, arg, span=shape["span"]))
                    else:
                        out.append(Prim(arg, x, span=shape["span"]))
                    flags.append(bool(p))
                cols[i], same[i] = out, (True if all(flags) else flags)
            elif k is _COMPLETE:
                _, span, c, a, b, variables, box, shifted, shape = step
                conds, xs, ys = (col if type(col) is list else [col] * m for col in (cols[c], cols[a], cols[b]))
                sc, sa, sb = (s if type(s) is list else [s] * m for s in (same[c], same[a], same[b]))
                out, flags = [], []
                if shifted is not None:
                    # each copy's constant term in integers (the copies whose summands all have a small
                    # value), then their Ψ̂ built in one loop
                    solved, num0, den0, parts = shifted
                    keys: list = []
                    for j in range(m):
                        num, den = num0, den0
                        for jj, factor, sign in parts:
                            col = cols[jj]
                            new = (col[j] if type(col) is list else col).small  # (core.small_value)
                            if new is None or new is False:
                                keys.append(None)
                                break
                            num, den = _moved(num, den, new, factor, sign)
                        else:
                            g = gcd(num, den)
                            keys.append((num // g, den // g))
                    psis = affine.solved_at_ratios(conds, variables, solved, keys)
                else:
                    psis = [None] * m
                for j in range(m):
                    cond = conds[j]
                    psi = psis[j]
                    if psi is not None:
                        shifted_count += 1
                        if sc[j] and sa[j] and sb[j]:
                            node = like(IfDiffeo, shape, (psi, xs[j], ys[j]), span)
                            notes[j].append((node, cond, variables, box))
                            out.append(node)
                            flags.append(True)
                            continue
                    else:
                        psi = self.complete(cond, variables, box)
                        if psi is None:
                            return None
                    node = IfDiffeo(psi, xs[j], ys[j], span=span)
                    notes[j].append((node, cond, variables, box))
                    out.append(node)
                    flags.append(same_shape(node, first[i]))
                cols[i], same[i] = out, (True if all(flags) else flags)
            elif k is _CONDITIONAL:
                _, psi, span, a, b, found = step
                xs, ys = (col if type(col) is list else [col] * m for col in (cols[a], cols[b]))
                out, flags = [], []
                for j in range(m):
                    node = IfDiffeo(psi, xs[j], ys[j], span=span)
                    if found is not None:
                        notes[j].append((node, *found))
                    out.append(node)
                    flags.append(same_shape(node, first[i]))
                cols[i], same[i] = out, (True if all(flags) else flags)
            else:
                kids, u = step[2], step[1]
                out, flags = [], []
                for j in range(m):
                    # (the copy's own children by the first copy's children's ids; the rest shared)
                    own = {key: (col[j] if type(col) is list else col)
                           for key, col in ((key, cols[slot]) for key, slot in kids.items())}
                    node = map_children(u, lambda c, own=own: own.get(id(c), c))
                    out.append(node)
                    flags.append(same_shape(node, u))
                cols[i], same[i] = out, (True if all(flags) else flags)
        completed = self.completed
        for copy in notes:
            for note in copy:
                completed(*note)
        STATS["instantiated"] += m
        STATS["shifted"] += shifted_count
        return cols[n - 1]


def _moved(num: int, den: int, new: Fraction, factor: Fraction, sign: int) -> tuple[int, int]:
    """``num / den + factor·new`` (``sign``: 1 when ``factor`` is 1, −1 when it is −1, else 0) as
    a numerator and a positive denominator, not reduced: a condition's constant term in a loop's
    copy, added up in integers (``Fraction``'s operators are Python code that reduces at every
    step, issue 15)."""
    if sign == 0:
        new = factor * new
    p, q = new.numerator, new.denominator
    return (num * q - p * den if sign < 0 else num * q + p * den), den * q


#: How deep :meth:`Template._plan` recurses before it walks the first copy again with a stack of its own.
_MARK_DEPTH = 200


class _Deep(Exception):
    """A first copy deeper than :data:`_MARK_DEPTH` (:meth:`Template._plan`)."""


# the kinds of step of Template.steps
_BINARY, _LEAF, _UNARY, _COMPLETE, _CONDITIONAL, _OTHER = (
    "binary", "leaf", "unary", "complete", "conditional", "other")


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
