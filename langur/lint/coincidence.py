"""Coincident zero sets and parameter-dependent degeneracy (paper Def. 7.2, §7.3.1, §7.3.2).

Failures of Def. 7.2 on a set of positive measure of a delta's support, and the parameter values
where a zero set degenerates:

* a condition multiplied by itself through a power or a primitive (X301, or X308 when its zero set
  does not move; §7.3.2);
* two conditions with the same zero set for every parameter value (X301, X308);
* two conditions whose zero sets coincide for some parameter values (X304; X305 at ``--at``
  values inside that set), and a jump lying on a fixed zero set, e.g. the domain's bound, where
  the integral has a kink (X304/X305);
* parameter coefficients whose vanishing stops a condition from being a diffeomorphism (X306;
  X305 at ``--at``).

:class:`CoincidenceChecks` is mixed into :class:`langur.lint.classify.Checker`, which supplies the
state (``variables``, ``box``, ``point``, ``explicit``, ``coincident``, ``kinks``, ``col``) and the
wording (``label``, ``anchor``, ``where``, ``zero_set``, ``every``, ``at_point``, ``primary``,
``add``, ``undecided``).
"""

from __future__ import annotations

import itertools
import math

import sympy as sp

from ..core import IfDiffeo, Term, free_vars, map_children
from ..diagnostics import Span
from ..sympy_bridge import denote
from ..syntax.support import numeric_box
from . import algebra, recomplete
from .algebra import Undecided, describe_set, vanishes
from .ancestry import in_force
from .collect import Occurrence
from .geometry import moving, num, orientation, params_of, zero_set_points


def _negative(f: sp.Expr, point, at: dict) -> bool:
    v = num(f.subs(point).subs(at))
    return v is not None and v < -1e-9


def _forced(t: Term, choice: dict[int, bool]) -> Term:
    """``t`` with each conditional whose ``id`` is in ``choice`` replaced by its then (True) or
    else (False) branch; a shared subterm is rebuilt once."""
    memo: dict[int, Term] = {}

    def go(u: Term) -> Term:
        if id(u) not in memo:
            if isinstance(u, IfDiffeo) and id(u) in choice:
                memo[id(u)] = go(u.then if choice[id(u)] else u.orelse)
            else:
                memo[id(u)] = map_children(u, go)
        return memo[id(u)]

    return go(t)


def _common_zeros(system: list, params: list) -> list[dict]:
    """The common zeros of ``system`` (products of factors) as solution dicts: ``sympy.solve`` of a
    product system misses components (``k·ny = k·nx = 0`` gives only ``nx = ny = 0``, not ``k = 0``),
    so each smallest choice of one factor per product is solved (:func:`~langur.lint.algebra.solve_by_factors`;
    sympy's ``solve`` of each choice of factors when they are not polynomials with rational
    coefficients), and solutions inside another dropped."""
    if len(system) == 1:
        return sp.solve(system[0], params, dict=True)
    found = algebra.solve_by_factors(system, params)
    if found is None:
        factors = [[f for f, _ in sp.factor_list(e)[1]] or [e] for e in system]
        if math.prod(len(f) for f in factors) > 64:
            return sp.solve(system, params, dict=True)
        found = []
        for choice in itertools.product(*factors):
            for s in sp.solve(list(choice), params, dict=True):
                if s not in found:
                    found.append(s)

    def inside(a: dict, b: dict) -> bool:  # the solutions a describes all satisfy b
        return a is not b and all(sp.simplify((k - v).subs(a)) == 0 for k, v in b.items())

    return [a for a in found if not any(inside(a, b) for b in found)]


class CoincidenceChecks:
    """Positive-measure failures of Def. 7.2 and degenerate parameter values (X301, X304–X306, X308)."""

    def squared(self, c: Occurrence, site: Span | None):
        """A condition multiplied by itself through a power or a primitive (paper §7.3.2)."""
        if c.continuous:
            return  # a kink split (abs, min, max): no delta, so nothing is counted twice
        names = self.param_names(c)
        self.coincident.add(frozenset({c.index}))
        what = self.text(site) if site is not None else None
        how = f"`{what}`" if what else "a power or a primitive"
        if not moving(c, self.variables):
            self.add(
                self.anchor(c),
                "warning",
                "X308",
                f"{self.label(c)} is multiplied by itself through {how}, but its zero set {self.zero_set(c)} does "
                "not move with the parameters: its delta has zero weight and the derivative is unaffected",
                (site,),
                names,
            )
            return
        self.add(
            self.anchor(c),
            "error",
            "X301",
            f"{self.label(c)} is multiplied by itself through {how} at {self.where(site, self.anchor(c))}: the chain "
            f"rule multiplies its delta by a function that jumps on the same zero set {self.zero_set(c)}, "
            f"{self.every(names)}, so the derivative is wrong (Def. 7.2 fails on a set of positive "
            "measure; paper §7.3.2); rewrite it without the power, e.g. [c]^k as [c] and f([c]) as "
            "f(0) + (f(1) - f(0))*[c] (`langur check --fix` writes the rewrite)",
            (site,),
            names,
        )

    def unsolved(self, c: Occurrence, g: Occurrence, unsolved, names):
        """The parameter set of a coincidence could not be solved for (a transcendental equation).
        Two moving jumps: the set matters everywhere (X310).  Otherwise only the values in force
        matter (a kink), and those are decided directly."""
        why = unsolved[0][2]
        if moving(c, self.variables) and moving(g, self.variables) and not (c.bound or g.bound):
            return self.undecided(c, g, why)
        if self.point is None:
            return
        hit = any(self.in_set(c, (None, br, e), g) for br, e, _ in unsolved)
        if not hit:
            return
        self.coincident.add(frozenset({c.index, g.index}))
        p, o = self.primary(c, g)
        where = self.where(self.anchor(o), self.anchor(p))
        text = (
            f"at {self.at_point(names)} the zero sets of {self.label(p)} and {self.label(o)} at {where} "
            f"coincide (the set of such parameter values could not be solved for: {why}): ⦇p⦈ is not "
            "defined there and the integral may have a kink (Def. 7.2 fails; `langur deriv` decides whether "
            "its derivative exists)"
        )
        if self.explicit:
            self.add(self.anchor(p), "error", "X305", text, (self.anchor(o),), names)
        else:
            self.add(
                self.anchor(p),
                "warning",
                "X304",
                text.replace("at ", "at the default values ", 1),
                (self.anchor(o),),
                names,
            )

    def always(self, c: Occurrence, g: Occurrence, br, names):
        self.coincident.add(frozenset({c.index, g.index}))
        if c.continuous and g.continuous:
            return  # two kink splits on one zero set: neither has a delta to count twice
        p, o = self.primary(c, g)
        where = self.where(self.anchor(o), self.anchor(p))
        if not (moving(c, self.variables) or moving(g, self.variables)):
            if c.continuous or g.continuous:
                return  # a kink on a fixed zero set ([abs(x) <= a] on [0, 1]): no delta on either side
            self.add(
                self.anchor(p),
                "warning",
                "X308",
                f"{self.label(p)} and {self.label(o)} at {where} have the same zero set {self.zero_set(c)}, but it "
                "does not move with the parameters: the deltas have zero weight and the derivative is "
                "unaffected (the product is redundant; Def. 7.2 fails formally)",
                (self.anchor(o),),
                names,
            )
            return
        side = orientation(c, g, br, self.variables)
        if side < 0:
            why = (
                "they are ≥ 0 on opposite sides of it, so their product vanishes almost everywhere and the "
                "derivative denotation has no meaning there (Def. 7.2 fails on a set of positive measure; "
                "paper §7.3.1)"
            )
        else:
            why = (
                "the delta of one is evaluated on the jump of the other, so the derivative counts the jump "
                "twice (Def. 7.2 fails on a set of positive measure; paper §7.3.1); use the condition once "
                "(`langur check --fix` writes the rewrite)"
            )
        self.add(
            self.anchor(p),
            "error",
            "X301",
            f"{self.label(p)} and {self.label(o)} at {where} multiply and have the same zero set "
            f"{self.zero_set(c)} {self.every(names)}: {why}",
            (self.anchor(o),),
            names,
        )

    def meet_in_force(self, c: Occurrence, g: Occurrence, br) -> bool:
        """Is the common zero set of c and g (through c's branch ``br``) in the box, at the
        parameter values in force, somewhere both are in force?  Only nested conditions (a kink
        split's pieces) can fail this; without parameter values it is assumed, and so it is for a
        zero set of dimension ≥ 1 (its points would be sampled: a short stretch where both are in
        force could be missed, and a missed X301 is worse than a redundant one)."""
        if self.point is None or c.uprime or not (self.nested(c) or self.nested(g)):
            return True
        return any(self._in_force([c, g], pt)
                   for pt in zero_set_points(c, br, self.box, self.point, self.variables))

    def in_set(self, c: Occurrence, rel, g: Occurrence | None = None) -> bool:
        """Is the parameter point in this relation's set, with the common zero set inside the box
        at a point where c (and g) are in force?"""
        if self.point is None:
            return False
        _, br, e = rel
        if not self.vanishes_here(c, br, e):
            return False
        # the meeting must be where both are in force (a kink split's piece ends at its kink)
        return any(self._in_force([c] + ([g] if g is not None else []), pt)
                   for pt in zero_set_points(c, br, self.box, self.point, self.variables))

    def vanishes_here(self, c: Occurrence, br, e: sp.Expr) -> bool:
        """Does the restriction ``e`` of a condition to c's zero set (through c's branch ``br``)
        vanish identically at the parameter values in force?  (False when undecided, or without values.)"""
        if self.point is None:
            return False
        try:
            return vanishes(e.subs(self.point), c.uprime, [gd.subs(self.point) for gd in br[1]])
        except Undecided:
            return False

    def nested(self, o: Occurrence) -> bool:
        """Is o written in a branch of another conditional (a kink split's piece)?"""
        return any(path for path in self.ancestry.get(o.index) or ())

    def possible(self, c: Occurrence, g: Occurrence, rel) -> bool:
        """Can the relation's parameter values make c and g meet where both are in force?  Decided
        only for nested conditions in one variable when the relation fixes every parameter (``a =
        -13/10``): then their meeting point is computed there; otherwise assumed."""
        sol, br, _ = rel
        if c.uprime or not (self.nested(c) or self.nested(g)):
            return True
        point = {**(self.point or {}), **{k: v for k, v in sol.items() if getattr(v, "is_number", False)}}
        if any(s not in point for s in params_of(c, g, variables=self.variables)):
            return True
        return any(all(in_force(o, pt, point, self.col.occurrences, self.ancestry) for o in (c, g))
                   for pt in zero_set_points(c, br, self.box, point, self.variables))

    def parametric(self, c: Occurrence, g: Occurrence, relations, names):
        if c.continuous and g.continuous:
            return  # two kinks (abs(x - a) + abs(x + a) at a = 0): neither has a delta to count twice
        # only parameter values where the zero sets meet where both are in force (a kink split's
        # pieces end at their kinks: [abs(x) - a >= 0]'s piece x - a never reaches x = -1)
        relations = [r for r in relations if self.possible(c, g, r)]
        if not relations:
            return
        # a kink (no delta) meeting a jump is where roots merge at the kink: a kink of the integral
        both = moving(c, self.variables) and moving(g, self.variables) and not (c.continuous or g.continuous)
        sides = {orientation(c, g, br, self.variables, fixed=sol) for sol, br, _ in relations}
        hit = any(self.in_set(c, r, g) for r in relations)
        if hit:  # coincident at the values in force: families through them say nothing more
            self.coincident.add(frozenset({c.index, g.index}))
        the_set = describe_set([sol for sol, _, _ in relations])
        p, o = self.primary(c, g)
        where = self.where(self.anchor(o), self.anchor(p))
        if both and 1 in sides and not (c.bound or g.bound):
            if hit and self.explicit:
                self.add(
                    self.anchor(p),
                    "error",
                    "X305",
                    f"at {self.at_point(names)} the zero sets of {self.label(p)} and {self.label(o)} at {where} "
                    f"coincide (they do when {the_set}): the derivative counts the jump twice here "
                    "(Def. 7.2 fails; paper §7.3.1)",
                    (self.anchor(o),),
                    names,
                )
            else:
                note = f"; the default values {self.at_point(names)} lie in this set" if hit else ""
                self.add(
                    self.anchor(p),
                    "warning",
                    "X304",
                    f"{self.label(p)} and {self.label(o)} at {where} have coincident zero sets when {the_set}: "
                    f"there the derivative counts the jump twice (Def. 7.2 fails; paper §7.3.1){note}",
                    (self.anchor(o),),
                    names,
                )
            return
        # A jump meeting a fixed zero set (the domain's bound) or closing a window: a kink — unless
        # every product they meet in is 0 around the meeting place (another factor vanishes there)
        if hit and self.zero_around(c, g):
            return
        # the one whose jump moves: a piece rather than a kink (no delta) or the domain's bound
        mover = c if (moving(c, self.variables) and not c.bound and not c.continuous) or g.bound or g.continuous else g
        other = g if mover is c else c
        self.kinks.setdefault(mover.index, []).append((other, relations, hit))

    def zero_around(self, c: Occurrence, g: Occurrence) -> bool:
        """Does the meeting of c's and g's zero sets make no kink at the parameter values in force?

        The integral's derivative jumps, where the two zero sets cross over, by the integral over
        the meeting place of the integrand's mixed difference in the two conditions,
        ⟦t⟧(c, g) − ⟦t⟧(c, ¬g) − ⟦t⟧(¬c, g) + ⟦t⟧(¬c, ¬g).  No kink when it is 0 all along c's
        zero set in the box: either each product where c and g multiply has another condition
        negative there (``[x + k > 0]·[x > 0]`` at k = 1: the jump sits on the bound x = −1, where
        ``[x > 0]`` is 0), or the integrand's weight vanishes there (``sqrt(x - theta)`` over
        ``[theta, v]`` at theta = v: the integral (2/3)(v − θ)^(3/2) is C¹)."""
        prods = [p for p in self.col.products if c.index in p.ids and g.index in p.ids]
        if self.point is None or not prods:
            return False
        pts = [pt for br in c.branches for pt in zero_set_points(c, br, self.box, self.point, self.variables)]
        if not pts or any(not pt for pt in pts):
            return False
        return self.others_negative(c, g, prods, pts) or self.weight_vanishes(c, g, pts)

    def weight_vanishes(self, c: Occurrence, g: Occurrence, pts) -> bool:
        """The mixed difference of the integrand in c and g (see :meth:`zero_around`) is 0 at
        each of ``pts`` (points of c's zero set), evaluated exactly at the parameter values."""
        if c.node is None or g.node is None:
            return False
        body = self.program.body
        sides = []
        for a, b, sign in ((True, True, 1), (True, False, -1), (False, True, -1), (False, False, 1)):
            sides.append((sign, denote(_forced(body, {id(c.node): a, id(g.node): b})).subs(self.point)))
        for pt in pts:
            values = [(sign, num(e.subs(pt))) for sign, e in sides]
            if any(v is None for _, v in values):
                return False
            mixed = sum(sign * v for sign, v in values)
            if abs(mixed) > 1e-9 * max(1.0, *(abs(v) for _, v in values)):
                return False
        return True

    def others_negative(self, c: Occurrence, g: Occurrence, prods, pts) -> bool:
        """Each product where c and g multiply has another condition on its zero side at all
        ``pts``: negative for a factor or a conditional c and g are in the then-branch of, positive
        for one they are in the else-branch of (a kink split's piece, ``langur.lint.ancestry``)."""
        occ = self.col.occurrences
        for p in prods:
            others = [occ[i] for i in p.ids - {c.index, g.index}]
            if not any(all(self._off(h, c, g, pt) for pt in pts) for h in others):
                return False
        return True

    def _off(self, h: Occurrence, c: Occurrence, g: Occurrence, pt) -> bool:
        """Is h strictly on the side that does not select c and g at ``pt``?"""
        sides = {side for o in (c, g) for path in (self.ancestry.get(o.index) or ())
                 for i, side in path if i == h.index}
        if sides == {-1}:  # c or g is in h's else-branch: h selects it where h < 0
            return _negative(-h.f, self.point, pt)
        return not sides - {1} and _negative(h.f, self.point, pt)

    def report_kinks(self):
        occ = self.col.occurrences
        movers = {i for i, entries in self.kinks.items() if any(hit for _, _, hit in entries)}
        again = [args for args in self.passed_over if {args[0].index, args[1].index} & movers]
        if again:  # a kink's finding names every set its jump lies on: those of the pairs passed over too
            self.passed_over, self.solve_all = [], True
            for args in again:
                self.parameter_sets(*args)
            order = self.pair_order  # (in the order the pairs were checked, as if none was passed over)
            for i in movers:
                self.kinks[i].sort(key=lambda e, i=i: min(order.get((i, e[0].index), math.inf),
                                                          order.get((e[0].index, i), math.inf)))
        for i, entries in sorted(self.kinks.items()):
            if not any(hit for _, _, hit in entries):
                continue
            c = occ[i]
            sols = [sol for _, rels, _ in entries for sol, _, _ in rels]
            names = self.param_names(c, *(o for o, _, _ in entries))
            shown = [e for e in entries if e[2]] if self.explicit else entries
            parts = [
                f"{self.label(o)} at {self.where(self.anchor(o), self.anchor(c))}"
                + ("" if self.explicit else f" when {describe_set([s for s, _, _ in rels])}")
                for o, rels, _ in shown
            ]
            the_set = describe_set(sols)
            related = tuple(self.anchor(o) for o, _, _ in shown)
            consequence = (
                "⦇p⦈ is not defined there and the integral may have a kink (Def. 7.2 fails; Theorem 8.1 "
                "holds only for almost every parameter value; `langur deriv` decides whether its derivative exists)"
            )
            if self.explicit:
                self.add(
                    self.anchor(c),
                    "error",
                    "X305",
                    f"at {self.at_point(names)} the jump of {self.label(c)} lies on {'; '.join(parts)}: "
                    f"{consequence} (degenerate when {the_set})",
                    related,
                    names,
                )
            else:
                self.add(
                    self.anchor(c),
                    "warning",
                    "X304",
                    f"the jump of {self.label(c)} lies on {'; '.join(parts)}, i.e. when {the_set}; the "
                    f"default values {self.at_point(names)} lie in this set: {consequence}",
                    related,
                    names,
                )

    def nonzero(self, c: Occurrence):
        """Parameter coefficients that must not vanish for Ψ̂ to be a diffeomorphism (X306/X305).
        Where the completion's coefficient vanishes but a completion solved for another variable
        does not degenerate (:mod:`langur.lint.recomplete`), the engines use that one: what is
        reported is where every completion degenerates."""
        if c.continuous:  # no delta: a degenerate coefficient changes nothing in the derivative
            return
        if self.here_only and not (any(num(t.subs(self.point)) == 0 for t in c.nonzero)
                                   or recomplete.vanishing(c.psi, self.point)):
            return  # X305 only, and no coefficient vanishes at the values in force (``hit`` below)
        closed = c.psi.solved_for is not None and free_vars(c.psi.condition) <= set(c.psi.variables)
        chain = None
        if closed and c.nonzero:
            box = numeric_box(self.program.variables, self.program.box)
            chain = recomplete.degenerate_set(c.psi, box)
            if not chain:
                return  # a completion by another variable never degenerates
            if len(chain) == 1:
                chain = None  # no other completion: each coefficient on its own, as below
        if chain is None:
            for t in c.nonzero:
                hit = self.point is not None and num(t.subs(self.point)) == 0
                self.degenerate(c, [t], f"{sp.sstr(t)} = 0", f"its coefficient {sp.sstr(t)} vanishes", hit)
            return
        hit = (self.point is not None and bool(recomplete.vanishing(c.psi, self.point))
               and recomplete.alternative(c.psi, self.point, box) is None)
        self.degenerate(c, chain, f"{sp.sstr(chain[0])} = 0 and so are the other completions' coefficients",
                        f"its completion divides by {sp.sstr(chain[0])}, and every completion by another "
                        "variable degenerates there too", hit)

    def degenerate(self, c: Occurrence, system: list, vanish: str, why: str, hit: bool):
        """X306 for the parameter values where ``system`` vanishes (or X305 with ``--at`` values
        among them, ``hit``)."""
        params = sorted(set().union(*(e.free_symbols for e in system)), key=str)
        names = tuple(s.name for s in params)
        try:
            sols = algebra.timed(lambda: _common_zeros(system, params)) if params else []
        except Undecided as u:
            self.undecided(c, None, str(u))
            return
        sols = [s for s in sols if not any(v.has(sp.I) for v in s.values())]
        the_set = describe_set(sols) if sols else vanish
        if hit and self.explicit:
            self.add(
                self.anchor(c),
                "error",
                "X305",
                f"at {self.at_point(names)} {self.label(c)} is not a diffeomorphism ({vanish}): its "
                "zero set degenerates and the derivative is not defined here",
                (),
                names,
            )
        elif sols or hit:
            note = f"; the default values {self.at_point(names)} lie in this set" if hit else ""
            self.add(
                self.anchor(c),
                "warning",
                "X306",
                f"{self.label(c)} stops being a diffeomorphism when {the_set} ({why}): "
                f"there the derivative is not defined{note}",
                (),
                names,
            )
