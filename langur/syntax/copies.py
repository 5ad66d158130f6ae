"""A finite loop's copies built from the steps of its first (§9's ``sum i in A..B: t`` unrolled;
issue 15): :meth:`Copies.at` builds one copy for a value of the index, :meth:`Copies.at_all` all the
others at once, both by running the steps :mod:`langur.syntax.template` compiled from the first
copy (one loop, no recursion, no lookup by identity).

A node whose children keep the first copy's shape is built by ``core.like`` (its shape's attributes
copied); a condition that differs from the first's only in constant summands keeps the first's
solved affine shape (``affine.solved_at_ratio``), its constant term added up in integers
(:func:`moved`); any other condition is completed again by the desugarer's function.  Each copy is
the term desugaring it would give (``proofs_tests/test_loop_template.py``).
"""

from __future__ import annotations

import functools
from fractions import Fraction
from math import gcd

from ..core import (
    IfDiffeo,
    Pow,
    Prim,
    Term,
    index_const,
    index_power_small,
    like,
    like_binary,
    like_binary_many,
    like_leaf,
    like_power,
    map_children,
    same_shape,
    small_power,
    small_value,
)
from . import affine

#: ``core.index_power_small``, each (index, exponent) computed once per load: a module's loops often
#: run over the same indices (MB1's two sums; each copy's ``1/i`` is a ``Fraction`` made in Python,
#: issue 15).  An ``lru_cache`` of a ``langur.syntax`` module, so emptied with the front end's memos.
index_power = functools.lru_cache(maxsize=1024)(index_power_small)

#: Copies built so far by :meth:`Template.at`, refused, and conditions completed again by adding up
#: their constant term alone (the tests check that they exercised each).
STATS = {"instantiated": 0, "refused": 0, "shifted": 0}

#: The kinds of step of :attr:`Template.steps <langur.syntax.template.Template.steps>`.
BINARY, LEAF, UNARY, COMPLETE, CONDITIONAL, OTHER = (
    "binary", "leaf", "unary", "complete", "conditional", "other")


class Copies:
    """Building a loop's copies from the steps of its first (a part of
    :class:`~langur.syntax.template.Template`, which compiles them: :attr:`body`, :attr:`dependent`, :attr:`steps`, :attr:`first`,
    :attr:`shared`, :attr:`start`, :attr:`start_same`, :attr:`powers`, :attr:`exponents`, the
    desugarer's ``complete`` and ``completed``)."""

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
            if k is BINARY:
                _, cls, shape, a, b = step
                if same[a] and same[b]:
                    vals[i] = like_binary(cls, shape, vals[a], vals[b])
                    same[i] = True
                else:
                    vals[i] = cls(vals[a], vals[b], span=shape["span"])
            elif k is LEAF:
                vals[i] = leaf = index_const(value, step[1]) if leaf is None else like_leaf(leaf, step[1])
                same[i] = True
            elif k is UNARY:
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
                                                         else index_power(value, e))
                        vals[i] = like_power(shape, vals[a], small)
                    else:
                        vals[i] = like(cls, shape, (vals[a],), shape["span"])
                    same[i] = True
                elif cls is Pow:
                    vals[i] = Pow(vals[a], arg, span=shape["span"])
                else:
                    vals[i] = Prim(arg, vals[a], span=shape["span"])
            elif k is COMPLETE:
                _, span, c, a, b, variables, box, shifted, shape = step
                cond = vals[c]
                psi = None
                if shifted is not None:  # the same shape: the constant term moved by the summands' change
                    solved, num, den, parts = shifted
                    for j, factor, sign in parts:
                        new = small_value(vals[j])
                        if new is None or new is False:
                            break
                        num, den = moved(num, den, new, factor, sign)
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
            elif k is CONDITIONAL:
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
            if k is BINARY:
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
            elif k is LEAF:
                span = step[1]
                if leaves is None:
                    cols[i] = leaves = [index_const(v, span) for v in values]
                else:
                    cols[i] = [like_leaf(leaf, span) for leaf in leaves]
                same[i] = True
            elif k is UNARY:
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
                            else [index_power(v, e) for v in values])
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
            elif k is COMPLETE:
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
                            num, den = moved(num, den, new, factor, sign)
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
            elif k is CONDITIONAL:
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


def moved(num: int, den: int, new: Fraction, factor: Fraction, sign: int) -> tuple[int, int]:
    """``num / den + factor·new`` (``sign``: 1 when ``factor`` is 1, −1 when it is −1, else 0) as
    a numerator and a positive denominator, not reduced: a condition's constant term in a loop's
    copy, added up in integers (``Fraction``'s operators are Python code that reduces at every
    step, issue 15)."""
    if sign == 0:
        new = factor * new
    p, q = new.numerator, new.denominator
    return (num * q - p * den if sign < 0 else num * q + p * den), den * q



__all__ = ["BINARY", "COMPLETE", "CONDITIONAL", "LEAF", "OTHER", "STATS", "UNARY", "Copies", "index_power", "moved"]
