"""Transversality of the zero sets of diffeomorphic conditions: the analysis behind ``langur check``.

Paper Def. 7.2 (§7.3.1): a family of submanifolds of ℝⁿ is mutually transverse when, for every
subfamily and every point of their common intersection, their normals there are linearly
independent.  Theorem 8.1 assumes that the zero sets of all diffeomorphic conditions that
*multiply one another* are mutually transverse (LANGUAGE.md §5).  This module

1. **collects** (:func:`collect`) the conditions of a pure core program and which of them multiply:
   the derivative denotation (Fig. 8) multiplies the delta of a condition by the other factors of
   a product, by the jump ``T⟦s⟧ − ⟦r⟧`` of its branches (nesting), and — through the chain rule
   — by ``f'(⟦t⟧)`` for a primitive or a power of a discontinuous ``t``, which jumps on the same
   set (``[x<t]^2``, ``exp([x>=a])``, paper §7.3.2).  Summands never multiply.  ``let`` is seen
   through (its bound value replaces the name), defs are already inlined, and the domain's bounds
   are the product's first factors (§6 sugar, §8.3);
2. **classifies** (:func:`check_program`) every pair and every family of n+1 multiplying
   conditions, deciding with sympy (time-boxed, spot-checked numerically; ``langur.lint.algebra``)
   by restricting one condition to the other's zero set through its inverse branches
   ``x = Ψ̂_b⁻¹(0, u′)``:

   * the restriction vanishes identically for every parameter value: **coincidence** (X301, an
     error: the delta is evaluated on its own jump and the derivative counts it twice), or X308
     when neither zero set moves with the parameters (the deltas have zero weight);
   * it vanishes identically for some parameter values: a **parametric degeneracy** (X304, the
     set is printed).  When both jumps move and lie on the same side they are counted twice in
     directions where the integral *is* differentiable, so the set is always reported; otherwise
     (a jump meeting a fixed zero set such as the domain's bound, or two jumps closing a window)
     the integral merely has a kink there, a null set of parameters Theorem 8.1 excludes, and
     the set is reported only when the parameter values at hand lie in it.  At the values given
     with ``--at`` a degeneracy is an error (X305);
   * otherwise the zero sets may still meet non-transversally at isolated points: **tangency**
     (X302: the restriction and its gradient vanish together) and **more than n zero sets through
     a point of ℝⁿ** (X303).  Both are null sets of each delta's support: Theorem 8.1 no longer
     applies, but the derivative is still likely right (warnings).

Parameter coefficients that stop a condition from being a diffeomorphism (``Diffeo.nonzero``,
``[t*x >= 1]`` at ``t = 0``) are X306 (X305 at ``--at``); primitives applied outside their domain
on the domain of integration are X307 (``langur.lint.domains``); a domain interval that is empty
at the parameter values in force is X314 (``langur.lint.emptydomain``); integrands that are not integrable
on the box (the value, X311, or the derivative denotation in a parameter, X313; X312 when
undecided) come from ``langur.lint.singular``.  ``docs/CODES.md`` documents every code.

Layout: :mod:`langur.lint.collect` (what multiplies), :mod:`langur.lint.classify` (the checker
and its messages) with :mod:`langur.lint.coincidence` (positive-measure failures and parameter
sets) and :mod:`langur.lint.nullsets` (tangencies, too many zero sets through a point), :mod:`langur.lint.geometry` and :mod:`langur.lint.algebra` (sympy, time-boxed),
:mod:`langur.lint.domains` (X307), :mod:`langur.commands._prove` (``--prove``).  This module is the
entry point: :func:`check_loaded` for a front end's ``Loaded``, :func:`check_library` for a module
of defs, :func:`check_program` for a bare core program.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace

from . import failures, timebox
from .core import Call, Param, Program, Var
from .diagnostics import LangurError, Span
from .lint import singular
from .lint.classify import _FAILURES, BUDGET, HERE_CODES, MAX_FAMILIES, Checker
from .lint.collect import MAX_PRODUCTS, Collected, Occurrence, Product, call_sites, collect
from .lint.domains import domain_findings
from .lint.doubleroot import double_root_findings
from .lint.emptydomain import empty_domain_findings
from .lint.findings import Finding
from .lint.geometry import span_key
from .lint.tangent import tangent_findings
from .syntax.inline import inline

__all__ = [
    "BUDGET",
    "HERE_CODES",
    "MAX_FAMILIES",
    "MAX_PRODUCTS",
    "Collected",
    "Finding",
    "Occurrence",
    "Product",
    "call_sites",
    "check_library",
    "check_loaded",
    "check_program",
    "collect",
    "point_of",
]


def check_loaded(
    loaded, *, at: Mapping[str, float] | None = None, sources: Mapping[str, str] | None = None,
    budget: float | None = None,
    only: frozenset[str] | None = None,
) -> list[Finding]:
    """:func:`check_program` on a front end's :class:`~langur.modules.Loaded`, with call sites of
    inlined defs and the domain's intervals located in the user's source (``budget``: CPU seconds
    for the whole analysis, ``only``: the codes asked for, see :func:`check_program`)."""
    if loaded.program is None:
        return []
    sources = dict(sources or {})
    for m in loaded.modules.values():  # (the bytes the load read: a named pipe cannot be read again)
        if m.path not in sources:
            sources[m.path] = m.source.decode("utf-8", errors="replace")
    return check_program(
        loaded.program,
        loaded.params,
        at=at,
        sources=sources,
        domain_spans=_domain_spans(loaded.program),
        sites=call_sites(loaded),
        budget=budget,
        only=only,
    )


def check_library(loaded, *, sources: Mapping[str, str] | None = None) -> list[Finding]:
    """The findings of each ``def`` of a module without a program (a library, e.g. densities.lgr),
    each body analysed as an integrand over its ``var`` arguments, with its ``param`` arguments
    as parameters without values and no domain: what is degenerate for every argument value
    (X301, X302, X303, X304 for two moving jumps, X306) is reported at the def's text."""


    main = loaded.main
    sources = dict(sources or {})
    out: list[Finding] = []
    for d in main.defs.values():
        variables = tuple(n for n, kind in d.args if kind == "var")
        if not variables:
            continue
        args = tuple(Var(n) if kind == "var" else Param(n) for n, kind in d.args)
        unbounded = tuple((Param("__lo"), Param("__hi")) for _ in variables)
        try:
            program = inline(Program(Call(main.name, d.name, args), variables, unbounded), loaded.modules)
        except LangurError:
            continue
        program = replace(program, box=(), span=d.span)
        params = {n: None for n, kind in d.args if kind == "param"}
        out += check_program(program, params, sources=sources)
    return _dedupe(out)


def _domain_spans(program: Program) -> dict[tuple[int, int], Span]:
    """``(variable index, 0 lower / 1 upper) → span`` of the declared domain's bounds."""
    out = {}
    for i, iv in enumerate(program.domain):
        for k, end in enumerate((iv.lo, iv.hi)):
            span = end.span or iv.span
            if span is not None:
                out[(i, k)] = span
    return out


def point_of(declared: Mapping[str, object], at: Mapping[str, float] | None) -> dict[str, object] | None:
    """The parameter values in force: defaults overridden by ``at``; None when one has no value."""
    at = dict(at or {})
    point: dict[str, object] = {}
    for name, default in declared.items():
        if name in at:
            point[name] = at[name]
        elif default is not None:
            point[name] = default
        else:
            return None
    point.update({k: v for k, v in at.items() if k not in point})
    return point


def check_program(
    program: Program,
    declared: Mapping[str, object] | None = None,
    *,
    at: Mapping[str, float] | None = None,
    sources: Mapping[str, str] | None = None,
    domain_spans: Mapping[tuple[int, int], Span] | None = None,
    sites: list | None = None,
    budget: float | None = None,
    only: frozenset[str] | None = None,
) -> list[Finding]:
    """The transversality findings of ``program`` (see the module docstring).

    ``declared``: the program's parameters with their defaults (None: no default), in declaration
    order; ``at``: values given on the command line (``--at``), which make degeneracies at that
    point errors; ``sources``: file texts by path, to quote the user's conditions in messages;
    ``domain_spans``: ``(variable index, 0 lower / 1 upper) → span`` of the domain's bounds;
    ``sites``: :func:`call_sites` of the program; ``budget``: CPU seconds the whole analysis may
    take (a fuzz unit's share of its time limit; None: each analysis's own limits, the checker's
    :data:`BUDGET`).  CPU seconds, as every limit of the linter, so that the findings do not change
    with the machine's load; what the budget leaves unchecked is said in an X310 warning.
    ``only``: the codes the caller acts on (``langur fuzz`` discards a program on X301 or X305):
    the analyses that cannot report any of them are not run (:data:`ANALYSES_CODES`), so the
    findings of other codes are those of the analyses that ran (X310 included); None: every
    analysis.
    """
    if budget is None:
        return _analysed(program, declared, at, sources, domain_spans, sites, None, only=only)
    state: dict = {}
    with timebox.budget(budget):
        try:  # the checks stop themselves at the budget; this bounds code between two checks too
            return timebox.run_with_timeout(
                lambda: _analysed(program, declared, at, sources, domain_spans, sites, budget, state, only),
                budget + OVERRUN, cpu=True)
        except TimeoutError as e:
            found, clock = list(state.get("findings", ())), timebox.stopped_by(e)
    return _dedupe(found + [_stopped(program, budget, "it ran past it", clock)])


#: CPU seconds an analysis with a ``budget`` may run past it (code between two checks) before it is
#: stopped where it is, keeping what it has found.
OVERRUN = 1.0


def _stopped(program: Program, budget: float, rest: str, clock: timebox.Clock | None = None) -> Finding:
    """X310: the analysis stopped by its budget (``clock``: which limit; the wall-clock backstop is said)."""
    how = (f"was stopped {timebox.by_backstop(budget)}" if clock is timebox.Clock.BACKSTOP
           else f"stopped after {budget:g} CPU s (its budget)")
    return Finding(program.span, "warning", "X310", f"the transversality analysis {how}: {rest}; the rest is unchecked")


#: The codes each analysis after the checker's can report (``check_program``'s ``only`` skips an
#: analysis none of whose codes is asked for); the checker's null-set steps: :data:`~langur.lint.nullsets.NULL_SET_CODES`.
ANALYSES_CODES = {
    "the domains of primitives": frozenset({"X307"}),
    "double roots": frozenset({"X315"}),
    "turning points": frozenset({"X305", "X306"}),
    "empty domains": frozenset({"X314"}),
    "integrability": frozenset({"X311", "X312", "X313"}),
}


def _analysed(program, declared, at, sources, domain_spans, sites, budget, state=None, only=None) -> list[Finding]:
    """:func:`check_program`'s analyses one after the other (those that can report one of ``only``'s
    codes; None: all); ``state["findings"]``: what they have found so far (kept when the budget
    stops them)."""
    declared = dict(declared or {})
    at = dict(at or {})
    point = point_of(declared, at)
    state = {} if state is None else state
    try:
        checker = Checker(program, declared, point, bool(at), dict(sources or {}), domain_spans, sites, budget, only)
    except _FAILURES as e:  # the conditions could not be read as sympy expressions
        return [
            Finding(
                program.span,
                "warning",
                "X310",
                f"could not analyse the conditions ({failures.why(e)}): transversality is unchecked",
            )
        ]
    state["findings"] = findings = checker.findings
    findings = checker.run()
    state["findings"] = findings
    after = [
        ("the domains of primitives", lambda: domain_findings(program, point, sources or {})),
        ("double roots", lambda: double_root_findings(program)),
        ("turning points", lambda: tangent_findings(program, point, bool(at))),
        ("empty domains", lambda: empty_domain_findings(program, point, domain_spans)),
        ("integrability", lambda: singular.findings(program, declared, point, sources or {})),
    ]
    if only is not None:
        after = [(what, analysis) for what, analysis in after if ANALYSES_CODES[what] & only]
    for k, (_what, analysis) in enumerate(after):
        clock = timebox.Deadline(budget).stopped_by() if budget is not None else None
        if clock is not None:
            skipped = ", ".join(w for w, _ in after[k:])
            findings.append(_stopped(program, budget, f"{skipped} not analysed", clock))
            break
        findings += analysis()
        state["findings"] = findings
    return _dedupe(findings)


def _dedupe(findings: list[Finding]) -> list[Finding]:
    seen = set()
    out = []
    for f in findings:
        key = (f.code, span_key(f.span), f.message)
        if key not in seen:
            seen.add(key)
            out.append(f)
    out.sort(key=lambda f: (span_key(f.span), f.code))
    return out
