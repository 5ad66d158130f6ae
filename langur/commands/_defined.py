"""Does the integral exist?  ``eval``, ``deriv`` and ``show`` ask before running the engines.

**Transversality** (``deriv``): where ``langur check`` reports X301 (Def. 7.2 fails on a set of
positive measure: a jump counted twice) ⦇p⦈ is not the derivative, so ``deriv`` says the
derivative is not defined for the program as written, shows the transverse rewrite of §7.3.2
(``langur.lint.rewrite``) and exits 1; ``deriv --rewrite`` differentiates the rewrite instead.

**At the parameter values** (``deriv``): where ``langur check --at`` reports X305 (the values lie in a
degenerate set: two jumps meet, a jump sits on the domain's end, a condition stops being a
diffeomorphism) the integral has a kink there and ⦇p⦈ is not its derivative (Theorem 8.1 holds for
almost every parameter value, not at these): ``deriv`` reports the derivative as undefined, prints
the finding, still shows the Monte Carlo number marked as not a derivative, and exits 1.

**A completion that degenerates at the values** (``eval``, ``deriv``): a condition completed by
isolating a variable whose coefficient vanishes at the parameter values (a triangle's edge that is
vertical there) is given a completion by another variable when one does not degenerate
(:mod:`langur.lint.recomplete`: same ⟦p⟧, and the same ⦇p⦈ as the program's wherever both are
diffeomorphisms); the command says so in a note (``recompleted`` in JSON).

**Integrability.** The structural analysis of ``langur.lint.singular`` (X311 for ⟦p⟧, X313 for ⦇p⦈ in the
direction asked, X312 when undecided) runs at the parameter values of the command.  A finding at
error severity means the integral does not exist: the command prints it as a diagnostic
(``PATH:LINE:COL: error X311 …``), reports the exact value as undefined instead of running the
exact engine, still prints the Monte Carlo number marked as having no finite variance, and exits
1.  A warning (X312; X314, an empty domain interval: the value is 0) is printed and the engines run; the exact engine's own diagnostics (a
divergent quadrature) can still say undefined.  When the integral exists but its square does not
(``1/sqrt(x)`` on [0, 1]), the Monte Carlo engine is told its estimate has no finite variance.
"""

from __future__ import annotations

import sys
from dataclasses import field
from fractions import Fraction

from .. import lazy
from ..core import IfDiffeo, const, small_value, substitute, subterms
from ..diagnostics import Diagnostic
from ..lint import bounded
from ..lint.findings import Finding
from ..records import record
from ..syntax.printer import print_program

# The analyses (sympy), imported when a program needs them (``langur.lazy``): an integrand that
# ``langur.lint.bounded`` shows bounded on a rational box needs none of them for its value, and a
# program whose conditions ``langur.lint.affineclear`` decides needs none for its derivative (itself
# sympy-free, deferred only because ``eval`` never asks it).
affineclear = lazy.module("langur.lint.affineclear")
emptydomain = lazy.module("langur.lint.emptydomain")
fix = lazy.module("langur.lint.fix")
integrability = lazy.module("langur.symbolic.integrability")
recomplete = lazy.module("langur.lint.recomplete")
rewrite = lazy.module("langur.lint.rewrite")
singular = lazy.module("langur.lint.singular")
transversality = lazy.module("langur.transversality")
onesided = lazy.module("langur.onesided")


@record
class Defined:
    """What the analysis says about one integral the command is about to compute."""

    findings: list[Finding] = field(default_factory=list)
    undefined: str | None = None  # why the integral does not exist
    infinite_variance: str | None = None  # why a Monte Carlo estimate of it has no finite variance
    value_exists: bool = True  # (for a derivative: whether ⟦p⟧ itself is an integral; False: X311)

    def diagnostics(self) -> list[Diagnostic]:
        return [f.diagnostic() for f in self.findings]

    def report(self, as_json: bool) -> None:
        """The findings on standard error (text output; JSON carries them in ``diagnostics``)."""
        if not as_json:
            for d in self.diagnostics():
                print(d.format(), file=sys.stderr)


def _short(f: Finding) -> str:
    """``X311 at 1:14: `1 / x^2` is not integrable on the domain`` (the diagnostic has the rest)."""
    where = f" at {f.span.line}:{f.span.col}" if f.span is not None else ""
    depth, cut = 0, len(f.message)
    for i, ch in enumerate(f.message):  # the first ": " outside parentheses ends the summary
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth == 0 and f.message.startswith(": ", i):
            cut = i
            break
    return f"{f.message[:cut]} ({f.code}{where})"


def _square(res: "singular.Integrability", part: str | None = None) -> str | None:
    b = res.infinite_variance(part)
    if b is None or b.alpha is None:
        return None
    return (f"the integrand's square grows like dist^-{2 * b.alpha:.3g} near a set of codimension {b.codim}, "
            "which is not integrable")


def _may_vanish(psi, params) -> bool:
    """Whether a coefficient in ``psi.nonzero`` may vanish at ``params``: exact rational arithmetic
    when it decides (``core.small_value``), else yes (sympy then decides)."""
    if not psi.nonzero:
        return False
    consts = {k: const(v if isinstance(v, (int, Fraction)) else Fraction(v)) for k, v in params.items()}
    for n in psi.nonzero:
        v = small_value(substitute(n, {}, consts))
        if v is False or (v is not None and v == 0):
            return True
    return False


def completed_here(program, params) -> tuple[object, tuple[str, ...]]:
    """``program`` with each completion that degenerates at ``params`` replaced by one that does not
    (:mod:`langur.lint.recomplete`), and a note per replacement.  A program none of whose
    completions divides by a parameter coefficient that may vanish at ``params`` is returned as it
    is, without sympy."""
    if not any(isinstance(u, IfDiffeo) and _may_vanish(u.psi, params) for u in subterms(program.integrand)):
        return program, ()
    changed, done = recomplete.at_values(program, params)
    return changed, tuple(r.note() for r in done)


@record
class Transversal:
    """X301 findings of the program (none: ⦇p⦈ is the derivative) and its rewrite."""

    findings: list[Finding] = field(default_factory=list)
    rewritten: object = None  # the rewritten core Program
    shown: str = ""  # the rewrite as a diff of the file (or the whole program)
    here: list[Finding] = field(default_factory=list)  # X305 at the parameter values asked

    def undefined_here(self, sides: "onesided.OneSided | None" = None) -> str | None:
        """Why ⦇p⦈ is not the derivative at the parameter values (X305), or None; with ``sides``
        (:mod:`langur.onesided`), whether ⟦p⟧ has a derivative there all the same."""
        if not self.here:
            return None
        why = _short(self.here[0])
        if sides is None:
            return f"⦇p⦈ is not defined at these parameter values: {why}"
        return f"{sides.text()}: {why}"

    def reason(self) -> str:
        f = self.findings[0]
        where = f" at {f.span.line}:{f.span.col}" if f.span is not None else ""
        return ("the program is not transverse (X301" + where + "): Def. 7.2 fails on a set of positive "
                "measure, ⦇p⦈ counts a jump twice and is not the derivative (paper §7.3)")


def transversal(loaded, path: str | None, at=None) -> Transversal:
    """X301: is ⦇p⦈ the derivative of this program?  With the rewrite when it is not.  With ``at``,
    also X305: is it the derivative at those parameter values?  (Messages quote, and the rewrite
    patches, the text the load read — :meth:`~langur.modules.Loaded.texts` —, never the file read
    again: a named pipe has nothing more to give, a blocking ``open`` of one waited for a writer
    for the command's whole --timeout, bench/history/2026-11-29.md#hostile33.)"""

    if at is not None and loaded.program is not None and \
            affineclear.nothing_to_find(loaded.program, {k: float(v) for k, v in at.items()}):
        return Transversal()  # affine conditions: the analysis would find nothing (no sympy)
    sources = loaded.texts()
    checked = transversality.check_loaded(loaded, at=None if at is None else {k: float(v) for k, v in at.items()},
                           sources=sources, only=transversality.HERE_CODES)
    found = [f for f in checked if f.code == "X301"]
    here = [f for f in checked if f.code == "X305"]
    if not found:
        return Transversal(here=here)
    out = Transversal(found, rewrite.transverse(loaded.program).program, here=here)
    text = sources.get(path or "") if path != "-" else None  # (standard input: no file to rewrite)
    try:
        fixed = fix.fix(text, path, loaded) if text is not None else None
    except fix.FixError:
        fixed = None
    out.shown = fixed.diff(fix.target(path, False)) if fixed is not None else \
        print_program(out.rewritten, loaded.params) + "\n"
    return out


def value(program, params, sources: dict[str, str]) -> Defined:
    """Is ⟦p⟧ an integral at ``params``?  (``sources``: the texts that messages quote,
    :meth:`~langur.modules.Loaded.texts`.)"""
    point = dict(params)
    if bounded.nothing_to_find(program, point):  # a bounded integrand: no finding, finite variance
        return Defined()
    res = singular.value_integrability(program, point)
    out = Defined(emptydomain.empty_domain_findings(program, point) +
                  singular.findings_of(res, program, point, sources, "X311"))
    if res.verdict is integrability.Verdict.DIVERGENT:
        out.undefined = _short(out.findings[0])
        out.infinite_variance = "the integral itself does not exist"
    else:
        out.infinite_variance = _square(res)
    return out


def derivative(program, params, direction, sources: dict[str, str]) -> Defined:
    """Is ⦇p⦈ in the direction γ' an integral at ``params`` (and is ⟦p⟧)?"""
    out = value(program, params, sources)
    if out.undefined is not None:
        out.undefined = "⟦p⟧ does not exist, so neither does its derivative: " + out.undefined
        out.value_exists = False
        return out
    point = dict(params)
    if affineclear.derivative_bounded(program, point):  # bounded integrand and derivative: no X313
        return out
    res = singular.derivative_integrability(program, point, direction)
    found = singular.findings_of(res, program, point, sources, "X313")
    out.findings += found
    if res.verdict is integrability.Verdict.DIVERGENT:
        out.undefined = _short(found[0])
        out.infinite_variance = "the derivative denotation is not an integral"
    else:
        out.infinite_variance = _square(res, "the regular part")
    return out
