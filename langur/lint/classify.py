"""Classification of multiplying conditions (paper Def. 7.2, §7.3.1; LANGUAGE.md §5).

:class:`Checker` takes the collection of :mod:`langur.lint.collect` and decides, pair by pair and
family by family, coincidence (X301, X308), parametric degeneracy (X304, X305), tangency and
dependent normals (X302), too many zero sets through a point (X303), degenerate coefficients
(X306), with undecidable questions reported as X310.  ``langur.transversality`` describes the
rules; ``docs/CODES.md`` the codes.

This module holds the checker's state, its wording (labels, anchors, where a finding points),
the order of the analysis (:meth:`Checker.run`, with its time budget) and the per-pair dispatch
(:meth:`Checker.pair`, which looks ``bad_parameters`` up in this module, where the tests replace
it).  The decisions are its two mixins: :mod:`langur.lint.coincidence`
(failures of Def. 7.2 on a set of positive measure and degenerate parameter values: X301, X304,
X305, X306, X308) and :mod:`langur.lint.nullsets` (failures on null sets, §7.3: X302, X303).
"""

from __future__ import annotations

import heapq
import itertools
from collections.abc import Iterator, Mapping

import sympy as sp

from .. import failures
from ..core import Program, TooManyRoots
from ..diagnostics import Span
from ..sympy_bridge import denote, symbol, to_sympy
from ..syntax.printer import print_core
from ..timebox import Clock, Deadline, by_backstop
from .algebra import Undecided, bad_parameters, describe_point, exact, vanishes
from .ancestry import ancestry
from .coincidence import CoincidenceChecks
from .collect import MAX_PRODUCTS, Occurrence, collect
from .findings import Finding, quote
from .geometry import is_linear, moving, params_of, restrict, span_key, xsyms
from .nullsets import NULL_SET_CODES, NullSetChecks

#: At most this many families of 3 to n+1 conditions are solved for a common point.
MAX_FAMILIES = 400

#: Pairs of multiplying conditions listed before the checks start (the product of 10⁴ distinct
#: conditions has 5·10⁷: gigabytes); past this many (counted with repeats) they are made one at a
#: time, in the same order, as the checks reach them within the budget.
LISTED_PAIRS = 200_000

#: The codes that speak only of the parameter values in force (X301: for every value; X305: at the
#: values given with ``--at``): when a caller asks for no other (the ``deriv`` gate, the fuzzer) with
#: values given, the checks skip solving for the *set* of degenerate parameter values — which only
#: X304, X306, X310 and their wording need — wherever the values in force are not in it
#: (:attr:`Checker.here_only`, :meth:`Checker.pass_over`; bench/history/2026-11-29.md#lambert33.
HERE_CODES = frozenset({"X301", "X305"})

#: CPU seconds the whole analysis of one program may take (beyond: X310, the rest unchecked); CPU
#: time, as every limit of the checker, so that its findings do not change with the machine's load.
BUDGET = 30.0
_FAILURES = (
    Undecided,
    TooManyRoots,  # a condition split for fewer turning points than it has at the point (sin(100000·x))
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


def _merged_pairs(products) -> Iterator[tuple[int, int]]:
    """The distinct pairs of conditions multiplying in one of ``products``, in increasing order
    (``sorted`` of their set), made one at a time: each product's pairs come in increasing order,
    merged, repeats skipped."""
    last = None
    for pair in heapq.merge(*(itertools.combinations(sorted(p.ids), 2) for p in products)):
        if pair != last:
            last = pair
            yield pair


def _same_math(o: Occurrence):
    """What a check reads of an occurrence, apart from where it is written."""
    return (o.psi, o.f, o.bound, o.bound_at, o.continuous, o.nonzero)


class Checker(CoincidenceChecks, NullSetChecks):
    """The transversality analysis of one program: :meth:`run` returns its findings."""

    def __init__(
        self,
        program: Program,
        declared: Mapping[str, object],
        point: dict[str, object] | None,
        explicit: bool,
        sources: Mapping[str, str],
        domain_spans: Mapping[tuple[int, int], Span] | None = None,
        sites=None,
        budget: float | None = None,
        only: frozenset[str] | None = None,
    ):
        #: CPU seconds the analysis may take: :data:`BUDGET`, or less when the caller says so
        #: (``check_program``'s ``budget``, which also bounds the analysis with ``timebox.budget``).
        self.budget = BUDGET if budget is None else min(BUDGET, budget)
        #: the codes asked for (None: all): the null-set checks (tangency, families: X302, X303
        #: only, :data:`NULL_SET_CODES`) are left out when neither is (``check_program``'s ``only``)
        self.null_sets = only is None or bool(NULL_SET_CODES & only)
        #: only X301/X305 asked for, at values given with ``--at``: parameter sets are solved for
        #: only when the values lie in them (:data:`HERE_CODES`)
        self.here_only = only is not None and only <= HERE_CODES and explicit and point is not None
        self.program = program
        self.col = collect(program, sites, point)
        self.ancestry = ancestry(program.body, self.col.occurrences)
        self.domain_spans = dict(domain_spans or {})
        self.variables = program.variables
        self.xs = xsyms(self.variables)
        self.n = len(self.variables)
        self.box = [(denote(lo), denote(hi)) for lo, hi in program.box]  # a bound may be piecewise in the parameters
        self.declared = list(declared)
        self.point_values = point
        self.point = {symbol(k): exact(v) for k, v in point.items()} if point is not None else None
        self.explicit = explicit
        self.sources = sources
        self.findings: list[Finding] = []
        self.coincident: set[frozenset[int]] = set()
        self.kinks: dict[int, list] = {}
        self.degenerate_families: list[frozenset[int]] = []
        self._split_parts: frozenset[int] | None = None
        #: pairs whose parameter sets were not solved for (:meth:`pass_over`), and the order in
        #: which the pairs were checked (:meth:`report_kinks` solves the first when it needs them)
        self.passed_over: list[tuple] = []
        self.pair_order: dict[tuple[int, int], int] = {}
        self.solve_all = False

    # -- wording --------------------------------------------------------------------------------

    def text(self, span: Span | None) -> str | None:
        return quote(span, self.sources, multiline=True)

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
        if frag and occ.index in self.split_parts():  # (what the finding is about: the part, not the whole)
            text = f"the part `{print_core(occ.psi.forward[0])} >= 0` of {text}"
        if occ.sites and occ.span is not None:
            text += f" (in a def's body at {self.where(occ.span, occ.sites[0])})"
        return text

    def split_parts(self) -> frozenset[int]:
        """The occurrences that are parts of a condition written once and split into several
        conditionals — the signs of its factors (``syntax/poles.py``), the pieces of a kinked one
        (``syntax/kinks.py``): nested one in another's branch, from the same text (the condition's
        span and call sites).  Their findings name the part as well as the written condition."""
        if self._split_parts is None:
            occ, parts = self.col.occurrences, set()
            for o in occ:
                for path in self.ancestry.get(o.index) or ():
                    for i, _ in path:
                        if o.span is not None and (occ[i].span, occ[i].sites) == (o.span, o.sites):
                            parts |= {i, o.index}
            self._split_parts = frozenset(parts)
        return self._split_parts

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
        products = sorted(col.products, key=lambda p: sorted(p.ids))
        most = sum(len(p.ids) * (len(p.ids) - 1) // 2 for p in products)  # pairs, with repeats
        for p in products:
            ids = sorted(p.ids)
            if most <= LISTED_PAIRS:
                pairs.update(itertools.combinations(ids, 2))
            for i, site in sorted(p.squared, key=lambda s: (s[0], span_key(s[1]))):
                squared.setdefault(i, site)
            # subfamilies of 3 ≤ k ≤ n+1 conditions (k = 2 is the pairs' tangency check)
            for k in range(3, min(self.n + 1, len(ids)) + 1) if self.null_sets else ():
                if len(families) >= MAX_FAMILIES:
                    break
                for fam in itertools.combinations(ids, k):
                    families.add(fam)
                    if len(families) >= MAX_FAMILIES:
                        break
        occ = col.occurrences
        key = [_same_math(o) for o in occ]
        steps = [(self.squared, (occ[i], site), ("squared", key[i])) for i, site in sorted(squared.items())]
        listed = sorted(pairs) if most <= LISTED_PAIRS else None
        rest = [(self.report_kinks, (), None)]
        rest += [
            (self.family, ([occ[i] for i in fam],), ("family", *(key[i] for i in fam)))
            for fam in sorted(families, key=lambda f: (len(f), f))
        ]
        rest += [(self.nonzero, (o,), ("nonzero", key[i])) for i, o in enumerate(occ)]
        # the pairs in increasing order, listed, or made one at a time as the checks reach them
        count = len(steps) + len(listed) + len(rest) if listed is not None else None
        steps = itertools.chain(steps, ((self.pair, (occ[i], occ[j]), ("pair", key[i], key[j]))
                                        for i, j in (listed if listed is not None else _merged_pairs(products))), rest)
        # A check whose conditions are, mathematically, ones already checked without a finding
        # (5000 copies of [x <= a] in one sum) is not repeated; one that found something is, so
        # that each copy is reported where it is written.
        clean: set = set()
        clock = Deadline(BUDGET)  # within an enclosing timebox.budget (check_program's ``budget``)
        for k, (step, args, same) in enumerate(steps):
            if same is not None and same in clean:
                continue
            before = self._state()
            stopped = clock.stopped_by()
            if stopped is not None:
                left = (f"{count - k} of {count} checks left" if count is not None else
                        f"{k} checks done of at most {len(squared) + most + len(rest)}")
                how = (f"was stopped {by_backstop(self.budget)}" if stopped is Clock.BACKSTOP
                       else f"stopped after {self.budget:g} CPU s (its budget)")
                self.add(
                    self.program.span,
                    "warning",
                    "X310",
                    f"the transversality analysis {how} with {left}: the rest is unchecked",
                )
                break
            try:
                step(*args)
            except _FAILURES as e:  # a sympy failure outside a time-boxed call: say so, go on
                first = args[0][0] if args and isinstance(args[0], list) else (args[0] if args else None)
                second = args[1] if len(args) > 1 and isinstance(args[1], Occurrence) else None
                why = failures.why(e)
                if isinstance(first, Occurrence):
                    self.undecided(first, second, why)
                else:
                    self.add(self.program.span, "warning", "X310", f"could not finish the analysis ({why})")
            if same is not None and self._state() == before:
                clean.add(same)
        return self.findings

    def _state(self) -> tuple[int, ...]:
        return (len(self.findings), len(self.coincident), len(self.degenerate_families),
                sum(map(len, self.kinks.values())), len(self.passed_over))

    def pass_over(self, c: Occurrence, g: Occurrence) -> bool:
        """May the pair's parameter set go unsolved when the values in force are not in it?  Yes
        when only X301/X305 are asked for (:attr:`here_only`), and whenever the pair cannot be two
        moving jumps (:meth:`parametric`'s X304, :meth:`unsolved`'s X310): a jump meeting the
        domain's bound or a fixed zero set is a kink, reported only at values in its set."""
        if self.solve_all:
            return False
        both = moving(c, self.variables) and moving(g, self.variables) and not (c.bound or g.bound)
        return self.here_only or not both

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

    def pair(self, a: Occurrence, b: Occurrence):
        """Def. 7.2 for two multiplying conditions: the same zero set for every parameter value
        (:meth:`always`), for some values (:meth:`parameter_sets`), or a tangent meeting
        (:meth:`tangency`)."""
        c, g = (a, b) if len(a.branches) <= len(b.branches) else (b, a)
        params = params_of(c, g, variables=self.variables)
        names = self.param_names(c, g)
        self.pair_order.setdefault((c.index, g.index), len(self.pair_order))
        restricted = [(br, restrict(g.f, br)) for br in c.branches]
        for br, e in restricted:
            if vanishes(e, c.uprime + tuple(params), br[1]):
                if not self.meet_in_force(c, g, br):
                    return  # the common zero set lies where one of them is not in force (a piece)
                return self.always(c, g, br, names)
        self.parameter_sets(c, g, restricted, params, names)
        if self.null_sets and self.n >= 2 and not (is_linear(c.f, self.xs) and is_linear(g.f, self.xs)):
            self.tangency(c, g, names)

    def parameter_sets(self, c: Occurrence, g: Occurrence, restricted, params, names):
        """The parameter values where the zero sets coincide (:meth:`parametric`, :meth:`unsolved`):
        solved for only when a finding can come of them (:meth:`pass_over`; else remembered in
        :attr:`passed_over`, for :meth:`report_kinks`)."""
        if self.pass_over(c, g) and not any(self.vanishes_here(c, br, e) for br, e in restricted):
            self.passed_over.append((c, g, restricted, params, names))
            return
        relations = []
        unsolved = []
        for br, e in restricted:
            try:
                relations += [(sol, br, e) for sol in bad_parameters(e, c.uprime, params, br[1])]
            except Undecided as u:
                unsolved.append((br, e, str(u)))
        if unsolved:
            self.unsolved(c, g, unsolved, names)
        if relations:
            self.parametric(c, g, relations, names)
