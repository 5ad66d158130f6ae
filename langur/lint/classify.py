"""Classification of multiplying conditions (paper Def. 7.2, §7.3.1; LANGUAGE.md §5).

:class:`Checker` takes the collection of :mod:`langur.lint.collect` and decides, pair by pair and
family by family, coincidence (X301, X308), parametric degeneracy (X304, X305), tangency and
dependent normals (X302), too many zero sets through a point (X303), degenerate coefficients
(X306), with undecidable questions reported as X310.  ``langur.transversality`` describes the
rules; ``docs/CODES.md`` the codes.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Mapping

import sympy as sp

from ..core import Program
from ..diagnostics import Span
from ..syntax.sympy_bridge import symbol, to_sympy
from . import algebra
from .algebra import Undecided, bad_parameters, describe_point, describe_set, exact, solve_points, vanishes
from .collect import MAX_PRODUCTS, Occurrence, collect
from .findings import Finding
from .geometry import (
    in_box,
    is_linear,
    meets_box,
    moving,
    num,
    orientation,
    params_of,
    restrict,
    span_key,
    xsyms,
)

#: At most this many families of 3 to n+1 conditions are solved for a common point.
MAX_FAMILIES = 400

# ----------------------------------------------------------------------------------------------
# Classification (the collection is langur.lint.collect, the geometry langur.lint.geometry)

#: Seconds the whole analysis of one program may take (beyond: X310, the rest unchecked).
BUDGET = 30.0
_FAILURES = (
    Undecided,
    TypeError,
    ValueError,
    AttributeError,
    ZeroDivisionError,
    NotImplementedError,
    RecursionError,
    KeyError,
    IndexError,
    sp.PolynomialError,
    sp.SympifyError,
)


class Checker:
    def __init__(
        self,
        program: Program,
        declared: Mapping[str, object],
        point: dict[str, object] | None,
        explicit: bool,
        sources: Mapping[str, str],
        domain_spans: Mapping[tuple[int, int], Span] | None = None,
        sites=None,
    ):
        self.program = program
        self.col = collect(program, sites)
        self.domain_spans = dict(domain_spans or {})
        self.variables = program.variables
        self.xs = xsyms(self.variables)
        self.n = len(self.variables)
        self.box = [(to_sympy(lo), to_sympy(hi)) for lo, hi in program.box]
        self.declared = list(declared)
        self.point_values = point
        self.point = {symbol(k): exact(v) for k, v in point.items()} if point is not None else None
        self.explicit = explicit
        self.sources = sources
        self.findings: list[Finding] = []
        self.coincident: set[frozenset[int]] = set()
        self.kinks: dict[int, list] = {}
        self.degenerate_families: list[frozenset[int]] = []

    # -- wording --------------------------------------------------------------------------------

    def text(self, span: Span | None) -> str | None:
        if span is None or span.path not in self.sources:
            return None
        lines = self.sources[span.path].splitlines()
        if not 1 <= span.line <= len(lines):
            return None
        line = lines[span.line - 1]
        end = span.end_col if span.end_line == span.line else len(line) + 1
        frag = line[span.col - 1 : end - 1].strip()
        if span.end_line != span.line:
            frag += " …"
        return frag if len(frag) <= 60 else frag[:57] + "…"

    def anchor(self, occ: Occurrence) -> Span | None:
        """Where a finding about ``occ`` points: the outermost call site for a condition inlined
        from a def (the user's text in the checked file), the domain's interval for a bound, else
        the condition itself."""
        if occ.sites:
            return occ.sites[0]
        if occ.bound_at is not None and occ.bound_at in self.domain_spans:
            return self.domain_spans[occ.bound_at]
        return occ.span

    def label(self, occ: Occurrence) -> str:
        if occ.bound:
            return f"the domain's bound {occ.bound}"
        frag = self.text(occ.span)
        whole = self.text(occ.node_span) or ""
        if frag and frag.startswith(("if ", "ifge0 ")) and " then" in frag:
            frag = frag[: frag.index(" then")]
        if frag and occ.node_span != occ.span and whole.startswith(("ifge0", "if")):
            frag = ("ifge0 " if whole.startswith("ifge0") else "if ") + frag
        text = f"`{frag}`" if frag else f"`{sp.sstr(occ.f)} >= 0`"
        if occ.sites and occ.span is not None:
            text += f" (in a def's body at {self.where(occ.span, occ.sites[0])})"
        return text

    def where(self, span: Span | None, relative_to: Span | None) -> str:
        if span is None:
            return "an unknown place"
        if relative_to is not None and relative_to.path == span.path:
            return f"{span.line}:{span.col}"
        return f"{span.path}:{span.line}:{span.col}"

    def zero_set(self, occ: Occurrence) -> str:
        psi = occ.psi
        if psi.solved_for and len(occ.branches) == 1:
            back = {u: to_sympy(fw) for u, fw in zip(occ.uprime, psi.forward[1:])}
            v = symbol(psi.solved_for)
            if v in occ.branches[0][0]:
                return f"{psi.solved_for} = {sp.sstr(occ.branches[0][0][v].xreplace(back))}"
        return f"{sp.sstr(occ.f)} = 0"

    def param_names(self, *occs: Occurrence) -> tuple[str, ...]:
        names = {s.name for s in params_of(*occs, variables=self.variables)}
        return tuple(n for n in self.declared if n in names) + tuple(sorted(names - set(self.declared)))

    def every(self, names) -> str:
        return f"for every value of {', '.join(names)}" if names else "(no parameter involved)"

    def at_point(self, names=None) -> str:
        names = names if names else self.declared
        return describe_point(self.point_values or {}, names)

    def primary(self, a: Occurrence, b: Occurrence) -> tuple[Occurrence, Occurrence]:
        """The occurrence a finding points at (the user's condition, the later one), and the other."""
        if a.bound and not b.bound:
            return b, a
        if b.bound and not a.bound:
            return a, b
        return (b, a) if span_key(self.anchor(b)) >= span_key(self.anchor(a)) else (a, b)

    def add(self, span, severity, code, message, related=(), params=()):
        related = tuple(r for r in related if r is not None and r != span)
        self.findings.append(Finding(span, severity, code, message, related, tuple(params)))

    # -- the analysis ---------------------------------------------------------------------------

    def run(self) -> list[Finding]:
        col = self.col
        if col.truncated:
            self.add(
                self.program.span,
                "warning",
                "X310",
                f"the integrand has more than {MAX_PRODUCTS} products of conditions: only the first "
                "ones were checked for transversality",
            )
        pairs: set[tuple[int, int]] = set()
        squared: dict[int, Span | None] = {}
        families: set[tuple[int, ...]] = set()
        for p in sorted(col.products, key=lambda p: sorted(p.ids)):
            ids = sorted(p.ids)
            pairs.update(itertools.combinations(ids, 2))
            for i, site in sorted(p.squared, key=lambda s: (s[0], span_key(s[1]))):
                squared.setdefault(i, site)
            # subfamilies of 3 ≤ k ≤ n+1 conditions (k = 2 is the pairs' tangency check)
            for k in range(3, min(self.n + 1, len(ids)) + 1):
                if len(families) >= MAX_FAMILIES:
                    break
                for fam in itertools.combinations(ids, k):
                    families.add(fam)
                    if len(families) >= MAX_FAMILIES:
                        break
        occ = col.occurrences
        steps = [(self.squared, (occ[i], site)) for i, site in sorted(squared.items())]
        steps += [(self.pair, (occ[i], occ[j])) for i, j in sorted(pairs)]
        steps += [(self.report_kinks, ())]
        steps += [
            (self.family, ([occ[i] for i in fam],)) for fam in sorted(families, key=lambda f: (len(f), f))
        ]
        steps += [(self.nonzero, (o,)) for o in occ]
        deadline = time.monotonic() + BUDGET
        for k, (step, args) in enumerate(steps):
            if time.monotonic() > deadline:
                self.add(
                    self.program.span,
                    "warning",
                    "X310",
                    f"the transversality analysis stopped after {BUDGET:g} s with {len(steps) - k} of "
                    f"{len(steps)} checks left: the rest is unchecked",
                )
                break
            try:
                step(*args)
            except _FAILURES as e:  # a sympy failure outside a time-boxed call: say so, go on
                first = args[0][0] if args and isinstance(args[0], list) else (args[0] if args else None)
                second = args[1] if len(args) > 1 and isinstance(args[1], Occurrence) else None
                why = f"{type(e).__name__} in the analysis"
                if isinstance(first, Occurrence):
                    self.undecided(first, second, why)
                else:
                    self.add(self.program.span, "warning", "X310", f"could not finish the analysis ({why})")
        return self.findings

    def undecided(self, a: Occurrence, b: Occurrence | None, why: str):
        p, o = self.primary(a, b) if b is not None else (a, None)
        other = (
            f" and {self.label(o)} at {self.where(self.anchor(o), self.anchor(p))}" if o is not None else ""
        )
        self.add(
            self.anchor(p),
            "warning",
            "X310",
            f"could not decide the transversality of {self.label(p)}{other} ({why}): Theorem 8.1's "
            "assumption is unchecked here",
            (self.anchor(o),) if o is not None else (),
        )

    def squared(self, c: Occurrence, site: Span | None):
        """A condition multiplied by itself through a power or a primitive (paper §7.3.2)."""
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
            "f(0) + (f(1) - f(0))*[c]",
            (site,),
            names,
        )

    def pair(self, a: Occurrence, b: Occurrence):
        c, g = (a, b) if len(a.branches) <= len(b.branches) else (b, a)
        params = params_of(c, g, variables=self.variables)
        names = self.param_names(c, g)
        relations = []
        unsolved = []
        for br in c.branches:
            e = restrict(g.f, br)
            if vanishes(e, c.uprime + tuple(params), br[1]):
                return self.always(c, g, br, names)
            try:
                relations += [(sol, br, e) for sol in bad_parameters(e, c.uprime, params, br[1])]
            except Undecided as u:
                unsolved.append((br, e, str(u)))
        if unsolved:
            self.unsolved(c, g, unsolved, names)
        if relations:
            self.parametric(c, g, relations, names)
        if self.n >= 2 and not (is_linear(c.f, self.xs) and is_linear(g.f, self.xs)):
            self.tangency(c, g, names)

    def unsolved(self, c: Occurrence, g: Occurrence, unsolved, names):
        """The parameter set of a coincidence could not be solved for (a transcendental equation).
        Two moving jumps: the set matters everywhere (X310).  Otherwise only the values in force
        matter (a kink), and those are decided directly."""
        why = unsolved[0][2]
        if moving(c, self.variables) and moving(g, self.variables) and not (c.bound or g.bound):
            return self.undecided(c, g, why)
        if self.point is None:
            return
        hit = any(self.in_set(c, (None, br, e)) for br, e, _ in unsolved)
        if not hit:
            return
        self.coincident.add(frozenset({c.index, g.index}))
        p, o = self.primary(c, g)
        where = self.where(self.anchor(o), self.anchor(p))
        text = (
            f"at {self.at_point(names)} the zero sets of {self.label(p)} and {self.label(o)} at {where} "
            f"coincide (the set of such parameter values could not be solved for: {why}): the integral "
            "has a kink there and its derivative does not exist (Def. 7.2 fails)"
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
        p, o = self.primary(c, g)
        where = self.where(self.anchor(o), self.anchor(p))
        if not (moving(c, self.variables) or moving(g, self.variables)):
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
                "twice (Def. 7.2 fails on a set of positive measure; paper §7.3.1); use the condition once"
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

    def in_set(self, c: Occurrence, rel) -> bool:
        """Is the parameter point in this relation's set, with the common zero set inside the box?"""
        if self.point is None:
            return False
        _, br, e = rel
        guards = br[1]
        try:
            at = e.subs(self.point)
            if not vanishes(at, c.uprime, [gd.subs(self.point) for gd in guards]):
                return False
        except Undecided:
            return False
        return meets_box(c, br, self.box, self.point, self.variables)

    def parametric(self, c: Occurrence, g: Occurrence, relations, names):
        both = moving(c, self.variables) and moving(g, self.variables)
        sides = {orientation(c, g, br, self.variables, fixed=sol) for sol, br, _ in relations}
        hit = any(self.in_set(c, r) for r in relations)
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
        # A jump meeting a fixed zero set (the domain's bound) or closing a window: a kink.
        mover = c if (moving(c, self.variables) and not c.bound) or g.bound else g
        other = g if mover is c else c
        self.kinks.setdefault(mover.index, []).append((other, relations, hit))

    def report_kinks(self):
        occ = self.col.occurrences
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
                "the integral has a kink there and its derivative does not exist (Def. 7.2 fails; "
                "Theorem 8.1 holds only for almost every parameter value)"
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
            if not self._possible_at_point(eqs):
                return
            for sol in solve_points(eqs, xs):
                if self._inside(sol):
                    self.add(
                        self.anchor(p),
                        "warning",
                        "X302",
                        f"the zero sets of {self.label(p)} and {self.label(o)} at {where} are tangent at "
                        f"{self._point_text(sol)} {self.every(names)}: Def. 7.2 fails there, so Theorem 8.1 no "
                        "longer applies; the failure set is a null set of each delta's support, so the "
                        "derivative is still likely right",
                        (self.anchor(o),),
                        names,
                    )
                    return
            if self.explicit and self.point is not None:
                for sol in solve_points([e.subs(self.point) for e in eqs], xs):
                    if self._inside(sol):
                        self.add(
                            self.anchor(p),
                            "warning",
                            "X302",
                            f"at {self.at_point(names)} the zero sets of {self.label(p)} and {self.label(o)} at "
                            f"{where} are tangent at {self._point_text(sol)}: Def. 7.2 fails there, so Theorem "
                            "8.1 no longer applies; the failure set is a null set of each delta's support, so "
                            "the derivative is still likely right",
                            (self.anchor(o),),
                            names,
                        )
                        return
        except Undecided as u:
            self.undecided(c, g, str(u))

    def family(self, fam: list[Occurrence]):
        """Def. 7.2 for a subfamily of k ≥ 3 zero sets: for k = n+1, a common point at all (X303:
        n+1 normals of ℝⁿ are never independent); for k ≤ n, a common point where the k×k minors
        of the Jacobian all vanish (X302: the normals are linearly dependent there)."""
        if any(done <= frozenset(o.index for o in fam) for done in self.degenerate_families):
            return  # contains a subfamily already reported
        if len(fam) <= self.n:
            return self.dependent(fam)
        ids = [o.index for o in fam]
        if any(frozenset(pr) in self.coincident for pr in itertools.combinations(ids, 2)):
            return
        if not any(moving(o, self.variables) for o in fam):
            return
        names = self.param_names(*fam)
        ordered = sorted(fam, key=lambda o: (o.bound is None, span_key(self.anchor(o))))
        p, others = ordered[-1], ordered[:-1]
        listing = ", ".join(
            f"{self.label(o)} at {self.where(self.anchor(o), self.anchor(p))}" for o in others
        )
        eqs = [o.f for o in fam]
        try:
            if not self._possible_at_point(eqs):
                return
            for sol in solve_points(eqs, self.xs):
                if self._inside(sol):
                    self.degenerate_families.append(frozenset(o.index for o in fam))
                    self.add(
                        self.anchor(p),
                        "warning",
                        "X303",
                        f"{len(fam)} zero sets pass through {self._point_text(sol)} in ℝ^{self.n} "
                        f"({self.label(p)}, {listing}) {self.every(names)}: their normals cannot be linearly "
                        "independent, so Def. 7.2 fails there and Theorem 8.1 no longer applies; the failure "
                        "set is null on each delta's support, so the derivative is still likely right",
                        tuple(self.anchor(o) for o in others),
                        names,
                    )
                    return
            if self.explicit and self.point is not None:
                for sol in solve_points([e.subs(self.point) for e in eqs], self.xs):
                    if self._inside(sol):
                        self.degenerate_families.append(frozenset(o.index for o in fam))
                        self.add(
                            self.anchor(p),
                            "warning",
                            "X303",
                            f"at {self.at_point(names)} {len(fam)} zero sets pass through {self._point_text(sol)} "
                            f"in ℝ^{self.n} ({self.label(p)}, {listing}): Def. 7.2 fails there and Theorem 8.1 "
                            "no longer applies; the failure set has measure zero on each delta, so the "
                            "derivative is still likely right",
                            tuple(self.anchor(o) for o in others),
                            names,
                        )
                        return
        except Undecided as u:
            self.undecided(p, others[0], str(u))

    def dependent(self, fam: list[Occurrence]):
        """k ≤ n zero sets of ℝⁿ through a common point with linearly dependent normals."""
        ids = [o.index for o in fam]
        if any(frozenset(pr) in self.coincident for pr in itertools.combinations(ids, 2)):
            return
        if not any(moving(o, self.variables) for o in fam):
            return
        k = len(fam)
        jac = sp.Matrix([[sp.diff(o.f, x) for x in self.xs] for o in fam])
        minors = [
            jac.extract(list(range(k)), list(cols)).det() for cols in itertools.combinations(range(self.n), k)
        ]
        if any(m.is_number and m != 0 for m in minors):  # the normals are independent everywhere
            return
        eqs = [o.f for o in fam] + [m for m in minors if m != 0]  # an identically 0 minor holds everywhere
        names = self.param_names(*fam)
        ordered = sorted(fam, key=lambda o: (o.bound is None, span_key(self.anchor(o))))
        p, others = ordered[-1], ordered[:-1]
        listing = ", ".join(
            f"{self.label(o)} at {self.where(self.anchor(o), self.anchor(p))}" for o in others
        )
        try:
            if not self._possible_at_point(eqs):
                return
            for sol in solve_points(eqs, self.xs):
                if self._inside(sol):
                    self.degenerate_families.append(frozenset(o.index for o in fam))
                    self.add(
                        self.anchor(p),
                        "warning",
                        "X302",
                        f"the normals of {k} zero sets ({self.label(p)}, {listing}) are linearly dependent at "
                        f"{self._point_text(sol)} {self.every(names)}: Def. 7.2 fails there, so Theorem 8.1 no "
                        "longer applies; the failure set is a null set of each delta's support, so the "
                        "derivative is still likely right",
                        tuple(self.anchor(o) for o in others),
                        names,
                    )
                    return
        except Undecided as u:
            self.undecided(p, others[0], str(u))

    def nonzero(self, c: Occurrence):
        """Parameter coefficients that must not vanish for Ψ̂ to be a diffeomorphism (X306/X305)."""
        if c.continuous:  # no delta: a degenerate coefficient changes nothing in the derivative
            return
        for t in c.nonzero:
            params = sorted(t.free_symbols, key=str)
            names = tuple(s.name for s in params)
            try:
                sols = (
                    algebra.timed(lambda t=t, params=params: sp.solve(t, params, dict=True)) if params else []
                )
            except Undecided as u:
                self.undecided(c, None, str(u))
                continue
            sols = [s for s in sols if not any(v.has(sp.I) for v in s.values())]
            the_set = describe_set(sols) if sols else f"{sp.sstr(t)} = 0"
            hit = self.point is not None and num(t.subs(self.point)) == 0
            if hit and self.explicit:
                self.add(
                    self.anchor(c),
                    "error",
                    "X305",
                    f"at {self.at_point(names)} {self.label(c)} is not a diffeomorphism ({sp.sstr(t)} = 0): its "
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
                    f"{self.label(c)} stops being a diffeomorphism when {the_set} (its coefficient "
                    f"{sp.sstr(t)} vanishes): there the derivative is not defined{note}",
                    (),
                    names,
                )
