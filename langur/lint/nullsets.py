"""Failures of Def. 7.2 on null sets: tangency, dependent normals, too many zero sets through a
point (paper Def. 7.2, §7.3; LANGUAGE.md §5).

Def. 7.2 asks that, wherever k zero sets of ℝⁿ meet, their normals are linearly independent.
Where this fails only at isolated points (a null set of each delta's support), Theorem 8.1 no
longer applies but the derivative is still likely right, so these are warnings:

* two zero sets tangent at a common point (X302: every 2×2 minor of [∇f; ∇g] vanishes);
* 3 ≤ k ≤ n zero sets through a common point with linearly dependent normals (X302);
* n+1 zero sets of ℝⁿ through a common point (X303: n+1 normals are never independent).

:class:`NullSetChecks` is mixed into :class:`langur.lint.classify.Checker`, which supplies the
state (``xs``, ``n``, ``box``, ``point``, ``explicit``, ``coincident``, ``degenerate_families``)
and the wording (``label``, ``anchor``, ``where``, ``every``, ``at_point``, ``primary``, ``add``,
``undecided``).
"""

from __future__ import annotations

import itertools
from collections.abc import Callable, Mapping

import sympy as sp

from .algebra import Undecided, solve_points
from .ancestry import in_force
from .collect import Occurrence
from .geometry import in_box, moving, num, span_key

#: The codes these checks report (``check_program``'s ``only`` leaves them out when it asks for neither).
NULL_SET_CODES = frozenset({"X302", "X303"})

#: Words a family's finding is built from: (the common point, the members, the parameter names).
Message = Callable[[str, str, tuple[str, ...]], str]


class NullSetChecks:
    """Measure-zero failures of Def. 7.2 (X302, X303)."""

    def _point_text(self, sol: Mapping[sp.Symbol, sp.Expr]) -> str:
        xs = [x for x in self.xs if x in sol]
        free = [x.name for x in self.xs if x not in sol]
        text = f"({', '.join(x.name for x in xs)}) = ({', '.join(sp.sstr(sol[x]) for x in xs)})"
        return text + (f" (any {', '.join(free)})" if free else "")

    def _inside(self, xsol: Mapping[sp.Symbol, sp.Expr], guards=(), sub=None) -> bool:
        if self.point is None:
            return True
        for gd in guards:
            v = num(gd.subs(sub or {}).subs(self.point))
            if v is not None and v < -1e-9:
                return False
        return in_box(xsol, self.box, self.point, self.variables)

    def _possible_at_point(self, eqs) -> bool:
        """A cheap filter: with the parameter values known, a common point inside the box must
        exist at those values (solved with numbers) for anything to be reported."""
        if self.point is None:
            return True
        return any(self._inside(sol) for sol in solve_points([e.subs(self.point) for e in eqs], self.xs))

    def _in_force(self, fam: list[Occurrence], sol) -> bool:
        """Are all of ``fam`` in force at ``sol`` (no enclosing conditional selects the other
        branch there, ``langur.lint.ancestry``)?  A meeting point where one of them is not is no
        meeting of the program's zero sets: the kink split's pieces end at their kinks."""
        return all(in_force(o, sol, self.point, self.col.occurrences, self.ancestry) for o in fam)

    def _witness(self, eqs, retry_at_point: bool, fam: list[Occurrence] = ()):
        """A common solution of ``eqs`` inside the box where every member of ``fam`` is in force,
        as ``(solution, False)`` when it holds with the parameters left symbolic; failing that, with
        ``retry_at_point`` and ``--at`` values, ``(solution, True)`` for a solution at those values;
        else None.  Raises Undecided."""
        if not self._possible_at_point(eqs):
            return None
        for sol in solve_points(eqs, self.xs):
            if self._inside(sol) and self._in_force(fam, sol):
                return sol, False
        if retry_at_point and self.explicit and self.point is not None:
            for sol in solve_points([e.subs(self.point) for e in eqs], self.xs):
                if self._inside(sol) and self._in_force(fam, sol):
                    return sol, True
        return None

    def tangency(self, c: Occurrence, g: Occurrence, names):
        """Tangency: a common zero of both conditions where their normals are linearly dependent
        (every 2×2 minor of the Jacobian [∇f; ∇g] vanishes)."""
        p, o = self.primary(c, g)
        where = self.where(self.anchor(o), self.anchor(p))
        xs = self.xs
        df = [sp.diff(c.f, x) for x in xs]
        dg = [sp.diff(g.f, x) for x in xs]
        eqs = [c.f, g.f] + [
            df[i] * dg[j] - df[j] * dg[i] for i, j in itertools.combinations(range(self.n), 2)
        ]
        try:
            found = self._witness(eqs, retry_at_point=True, fam=[c, g])
            if found is None:
                return
            sol, fixed = found
            if not fixed:
                message = (
                    f"the zero sets of {self.label(p)} and {self.label(o)} at {where} are tangent at "
                    f"{self._point_text(sol)} {self.every(names)}: Def. 7.2 fails there, so Theorem 8.1 no "
                    "longer applies; the failure set is a null set of each delta's support, so the "
                    "derivative is still likely right"
                )
            else:
                message = (
                    f"at {self.at_point(names)} the zero sets of {self.label(p)} and {self.label(o)} at "
                    f"{where} are tangent at {self._point_text(sol)}: Def. 7.2 fails there, so Theorem "
                    "8.1 no longer applies; the failure set is a null set of each delta's support, so "
                    "the derivative is still likely right"
                )
            self.add(self.anchor(p), "warning", "X302", message, (self.anchor(o),), names)
        except Undecided as u:
            self.undecided(c, g, str(u))

    def family(self, fam: list[Occurrence]):
        """Def. 7.2 for a subfamily of k ≥ 3 zero sets: for k = n+1, a common point at all (X303:
        n+1 normals of ℝⁿ are never independent); for k ≤ n, a common point where the k×k minors
        of the Jacobian all vanish (X302: the normals are linearly dependent there)."""
        ids = [o.index for o in fam]
        if any(done <= frozenset(ids) for done in self.degenerate_families):
            return  # contains a subfamily already reported
        if any(frozenset(pr) in self.coincident for pr in itertools.combinations(ids, 2)):
            return  # a coincident pair is reported as such (X301/X304/X305)
        if not any(moving(o, self.variables) for o in fam):
            return  # nothing moves: no delta carries weight
        if any(o.continuous for o in fam):
            # a kink split's own zero set (abs, min, max) is no jump: its branches agree there, so
            # its delta has zero weight and other zero sets meeting on it meet no discontinuity of
            # the program as written (a piece ending on it is checked pair by pair: X301/X304/X305)
            return
        if len(fam) <= self.n:
            return self.dependent(fam)
        return self.too_many(fam)

    def dependent(self, fam: list[Occurrence]):
        """k ≤ n zero sets of ℝⁿ through a common point with linearly dependent normals (X302)."""
        k = len(fam)
        # Only the variables the family's functions contain: a minor with a column of another
        # variable (all 0) is identically 0, which says nothing below; all n columns made C(n, k)
        # determinants per family — 10,660 for 3 conditions in 41 variables (bench/history/2026-11-29.md#hostile32.
        xs = [x for x in self.xs if any(x in o.f.free_symbols for o in fam)]
        jac = sp.Matrix([[sp.diff(o.f, x) for x in xs] for o in fam])
        minors = [
            jac.extract(list(range(k)), list(cols)).det() for cols in itertools.combinations(range(len(xs)), k)
        ]
        if any(m.is_number and m != 0 for m in minors):  # the normals are independent everywhere
            return
        eqs = [o.f for o in fam] + [m for m in minors if m != 0]  # an identically 0 minor holds everywhere
        self._report_family(
            fam,
            eqs,
            "X302",
            lambda point, members, names: (
                f"the normals of {k} zero sets ({members}) are linearly dependent at "
                f"{point} {self.every(names)}: Def. 7.2 fails there, so Theorem 8.1 no "
                "longer applies; the failure set is a null set of each delta's support, so the "
                "derivative is still likely right"
            ),
        )

    def too_many(self, fam: list[Occurrence]):
        """n+1 zero sets of ℝⁿ through a common point: their normals cannot be independent (X303)."""
        k = len(fam)
        self._report_family(
            fam,
            [o.f for o in fam],
            "X303",
            lambda point, members, names: (
                f"{k} zero sets pass through {point} in ℝ^{self.n} "
                f"({members}) {self.every(names)}: their normals cannot be linearly "
                "independent, so Def. 7.2 fails there and Theorem 8.1 no longer applies; the failure "
                "set is null on each delta's support, so the derivative is still likely right"
            ),
            message_at_point=lambda point, members, names: (
                f"at {self.at_point(names)} {k} zero sets pass through {point} "
                f"in ℝ^{self.n} ({members}): Def. 7.2 fails there and Theorem 8.1 "
                "no longer applies; the failure set has measure zero on each delta, so the "
                "derivative is still likely right"
            ),
        )

    def _report_family(
        self, fam: list[Occurrence], eqs, code: str, message: Message, message_at_point: Message | None = None
    ):
        """The part the family checks share: look for a common point of ``eqs`` inside the box
        (with ``message_at_point``, also at the ``--at`` values); if there is one, record the family as
        degenerate (its superfamilies are not reported again) and add one warning pointing at the
        last member, the others related.  ``message`` / ``message_at_point`` word it from the point, the
        members (``label at where, …``) and the parameter names."""
        names = self.param_names(*fam)
        ordered = sorted(fam, key=lambda o: (o.bound is None, span_key(self.anchor(o))))
        p, others = ordered[-1], ordered[:-1]
        members = ", ".join(
            [self.label(p)]
            + [f"{self.label(o)} at {self.where(self.anchor(o), self.anchor(p))}" for o in others]
        )
        try:
            found = self._witness(eqs, retry_at_point=message_at_point is not None, fam=fam)
            if found is None:
                return
            sol, fixed = found
            self.degenerate_families.append(frozenset(o.index for o in fam))
            words = message_at_point if fixed else message
            self.add(
                self.anchor(p),
                "warning",
                code,
                words(self._point_text(sol), members, names),
                tuple(self.anchor(o) for o in others),
                names,
            )
        except Undecided as u:
            self.undecided(p, others[0], str(u))
