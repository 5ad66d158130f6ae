"""X311, X312, X313: integrals that do not exist (undefined is an answer).

⟦int t d(x⃗)⟧ = ∫ ⟦t⟧ (Fig. 12) exists only when ⟦t⟧ is integrable on the box, and the paper's
results assume it (Prop. 7.1 and Theorem 7.1: "if ⟦t⟧ is locally integrable").  ⦇p⦈ = ∫ ⦇t⦈
(Fig. 8, Theorem 7.1) exists only when the regular part f of ⦇t⦈ is integrable and every delta
term's weight h is integrable on its zero set; the derivative can fail to exist where the value
exists: ``log(abs(x - a))`` is integrable, its ⦇·⦈ in ``a`` is ``-1/(x - a)``, which is not
(its principal value is not an integral), and ``if x >= a then 1 / sqrt(x - a) else 0`` puts
δ(x − a) on a weight that is infinite there.

This module decomposes the integrand at the parameter values in force into simply decomposable
pieces (Def. 6.2; ``langur.symbolic.decompose``, and ``langur.ddenote`` for ⦇t⦈'s normal form)
and asks the exact engine's :mod:`langur.symbolic.integrability` where each piece's weight blows up
on its region and whether it is integrable there (the order of the singularity against the
codimension of the set it sits on), after asking the exact engine (``langur.symbolic.definedness``, through
``langur.denote.undefined_where``) whether a primitive is applied outside its domain on a set of
positive measure of where it is evaluated: the box cut by the conditions of the conditionals
enclosing it, not by a bracket factor beside it (``[x >= 0] * log(x)`` on [−1, 1] is undefined,
LANGUAGE.md §1, §3; a piece's weight ``0 · log(x)`` is 0 to sympy and cannot show it).  Delta terms are pulled back to their
zero set through the inverse branch ``x = Ψ̂_b⁻¹(0, u′)`` (LANGUAGE.md §4) when Ψ̂ was completed
by solving for one variable (then u′ are the other variables and their box is the box's); in one
variable the weight is evaluated at the root.  The Jacobian ``|det DΨ̂_b⁻¹|`` is left out (its folds, ``1/sqrt`` at the rim of a
disk, are integrable).

Findings (``docs/CODES.md``): X311 (error) the value does not exist; X313 (error) the derivative
denotation in a parameter does not exist although the value does; X312 (warning) a singularity
whose integrability the analysis cannot decide.  The same analysis tells the Monte Carlo engine
when its estimate has no finite variance (∫ w² = ∞: ``1/sqrt(x)`` on [0, 1]).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import sympy as sp

from .. import failures
from ..core import Pow, Prim, Program, Term, subterms
from ..ddenote import ddenote
from ..denote import denote, program_box, undefined_where
from ..diagnostics import Span
from ..precise import real_value
from ..primitives import REGISTRY, Domain
from ..symbolic.decompose import Ctx, decompose
from ..symbolic.definedness import Undefined
from ..symbolic.integrability import Blowup, Verdict, delta_blowups, piece_blowups
from ..sympy_bridge import at_symbols, symbols
from ..timebox import Deadline
from .bounded import bounded
from .findings import Finding, quote

#: CPU seconds for the whole analysis of one integral (beyond: nothing is claimed).
TIME_LIMIT = 15.0


@dataclass
class Integrability:
    """The verdict on one integral (the value, or the derivative in one direction)."""

    what: str  # "⟦p⟧", "⦇p⦈ in a"
    blowups: list[tuple[Blowup, str]] = field(default_factory=list)  # (blow-up, which part)
    note: str | None = None  # why the analysis could not run

    @property
    def verdict(self) -> Verdict:
        vs = {b.verdict for b, _ in self.blowups}
        for v in (Verdict.DIVERGENT, Verdict.UNDECIDED):
            if v in vs:
                return v
        return Verdict.INTEGRABLE

    @property
    def divergent(self) -> list[tuple[Blowup, str]]:
        return [(b, part) for b, part in self.blowups if b.verdict is Verdict.DIVERGENT]

    def infinite_variance(self, part: str | None = None) -> Blowup | None:
        """A blow-up that makes ∫ w² infinite (in ``part`` only, when given)."""
        for b, p in self.blowups:
            if (part is None or p == part) and b.square is Verdict.DIVERGENT:
                return b
        return None


# ----------------------------------------------------------------------------------------------
# The analysis


def _point(point: Mapping[str, object]) -> dict[sp.Symbol, sp.Expr]:
    return at_symbols({k: v for k, v in point.items() if v is not None})


def _box(program: Program, ctx: Ctx, at: dict) -> list[tuple[sp.Expr, sp.Expr]]:
    return [(sp.sympify(lo).xreplace(at), sp.sympify(hi).xreplace(at)) for lo, hi in program_box(program, ctx)]


def _pieces(pieces, xs, box, at, part: str, out: Integrability) -> None:
    for _, found in piece_blowups(pieces, xs, box, at):  # (the exact engine's analysis, piece by piece)
        out.blowups += [(b, part) for b in found]


def _delta_pieces(deltas, xs, box, at, out: Integrability) -> None:
    """Each delta term's weight on its zero set (the exact engine's analysis, module docstring)."""
    for _, _, found in delta_blowups(deltas, xs, box, at):
        out.blowups += [(b, "a delta term") for b in found]


@dataclass(frozen=True)
class Outside(Blowup):
    """The integrand undefined on a set of positive measure (shape "undefined"): ``application``,
    the subterm evaluated outside its domain there (``base`` is its argument)."""

    application: Term | None = None


def _undefined(bad: Undefined) -> Outside:
    """The exact engine's witness (:func:`~langur.denote.undefined_where`: an application evaluated
    outside its domain on a set of positive measure of the box, where Fig. 7 evaluates it) as a
    divergence at its point; the pieces' weights cannot show it when a bracket factor's 0
    multiplies the application away (sympy's ``0·log(x)`` is 0)."""
    return Outside(bad.argument, tuple(p for _, p in bad.point), "undefined", None, None, None,
                   Verdict.DIVERGENT, Verdict.DIVERGENT, application=bad.application)


def _guarded(what: str, fn) -> Integrability:
    out = Integrability(what)
    clock = Deadline(TIME_LIMIT)  # within the whole analysis's budget, when it has one
    cut = clock.remaining() < 0.99 * TIME_LIMIT  # an enclosing budget has less left than this limit
    try:
        clock.run(lambda: fn(out))
    except TimeoutError:
        out.note = (f"the analysis of {what} ran out of the analysis's CPU budget" if cut else
                    f"the analysis of {what} took longer than {TIME_LIMIT:g} CPU s")
    except Exception as e:  # noqa: BLE001 - the analysis never stops a command; it claims nothing then
        out.note = f"the analysis of {what} could not run: {failures.why(e)}"
    return out


def value_integrability(program: Program, point: Mapping[str, object]) -> Integrability:
    """Is ⟦p⟧'s integrand integrable on the box at ``point``?"""
    at = _point(point)
    xs = symbols(program.variables)

    def run(out: Integrability) -> None:
        if bounded(program.body):
            return  # a bounded integrand: nothing blows up, nothing is undefined (langur.lint.bounded)
        ctx = Ctx(at=at, variables=tuple(program.variables))
        bad = undefined_where(program, ctx)
        if bad is not None:
            out.blowups.append((_undefined(bad), "the integrand"))
            return
        _pieces(decompose(program.body, ctx), xs, _box(program, ctx, at), at, "the integrand", out)

    return _guarded("⟦p⟧", run)


def derivative_integrability(program: Program, point: Mapping[str, object],
                             direction: Mapping[str, object]) -> Integrability:
    """Is ⦇p⦈ in the direction γ' = ``direction`` an integral at ``point`` (module docstring)?"""

    at = _point(point)
    xs = symbols(program.variables)
    moving = [k for k, v in direction.items() if v]
    what = f"⦇p⦈ in {moving[0]}" if len(moving) == 1 else "⦇p⦈"

    def run(out: Integrability) -> None:
        ctx = Ctx(at=at, variables=tuple(program.variables))
        box = _box(program, ctx, at)
        nf = ddenote(program.body, direction, at=point, variables=tuple(program.variables))
        _pieces(nf.regular, xs, box, at, "the regular part", out)
        _delta_pieces(nf.deltas, xs, box, at, out)

    return _guarded(what, run)


# ----------------------------------------------------------------------------------------------
# Findings


def _edge(domain: Domain, e: sp.Expr) -> sp.Expr:
    """A quantity that vanishes where ``e`` reaches the edge of a primitive's domain and is
    negative outside it: cos(e) at tan's poles, (e − lo)·(hi − e) at finite ends."""
    if domain.poles:
        return sp.cos(e)
    out = sp.Integer(1)
    if math.isfinite(domain.lo):
        out *= e - sp.nsimplify(domain.lo)
    if math.isfinite(domain.hi):
        out *= sp.nsimplify(domain.hi) - e
    return out


def _culprit(program: Program, b: Blowup, at: dict, sources: Mapping[str, str]) -> tuple[Span | None, str]:
    """The subterm of the user's text that is singular at the blow-up point: a division or
    negative power whose base vanishes there, a ``tan`` at a pole, a ``log``, ``sqrt`` or
    fractional power of something vanishing there (what ⦇·⦈ differentiates into a pole); for an
    integrand undefined on a set of positive measure, the application evaluated outside its
    domain there; else the program."""

    if isinstance(b, Outside):
        t = b.application
        if t is None or t.span is None:
            return program.span, "the integrand"
        text = quote(t.span, sources)
        return t.span, f"`{text}`" if text else "a division"
    xs = symbols(program.variables)
    for t in subterms(program.body):
        base = None
        if isinstance(t, Pow) and (t.exponent < 0 or t.exponent.denominator != 1):
            base = t.base
        elif isinstance(t, Prim) and not REGISTRY[t.op].domain.everywhere:
            base = t.arg
        if base is None or t.span is None:
            continue
        try:
            e = denote(base).xreplace(at)
        except (TypeError, KeyError):
            continue
        if isinstance(t, Prim):
            e = _edge(REGISTRY[t.op].domain, e)
        if b.point and len(b.point) == len(xs):
            v = real_value(e.xreplace(dict(zip(xs, b.point))))
            for eps in (sp.Float("1e-30", 50), sp.Float("-1e-30", 50)):
                if math.isnan(v):  # 0·∞ at the point itself (x·log x): look right next to it
                    v = real_value(e.xreplace({x: c + eps for x, c in zip(xs, b.point)}))
                    v = v if abs(v) < 1e-20 else math.nan
            if not (math.isfinite(v) and abs(v) < 1e-25):
                continue
        text = quote(t.span, sources)
        return t.span, f"`{text}`" if text else "a division"
    return program.span, "the integrand"


def _where(b: Blowup, program: Program) -> str:
    names = list(program.variables)
    if b.shape == "zero set":
        what = "not defined (0/0, or outside a primitive's domain)" if b.alpha is not None and \
            math.isnan(b.alpha) else "infinite"
        return (f"at {names[0]} = {', '.join(_fmt(v) for v in b.point)}, on the zero set of its condition, "
                f"where its weight {sp.sstr(b.base)} is {what}")
    pt = ", ".join(_fmt(v) for v in b.point)
    at = f"({', '.join(names)}) = ({pt})" if len(names) > 1 else f"{names[0]} = {pt}" if b.point else "?"
    if b.shape == "crossing":
        return f"on the zero set of {sp.sstr(b.base)}, which crosses the domain (e.g. at {at})"
    if b.shape == "face":
        face = " and ".join(f"{names[i]} = {_fmt(v)}" for i, v in b.face)
        kind = "face" if b.codim == 1 else "edge" if b.codim == len(names) - 1 and len(names) > 2 else "corner" \
            if b.codim == len(names) else "face"
        return f"on the {kind} {face} of the domain (e.g. at {at})"
    if b.shape == "undefined":
        return f"undefined on a set of positive measure (e.g. at {at}: a logarithm, root or fractional power " \
               "of a negative number, or another primitive outside its domain)"
    if b.shape == "condition":
        return f"on the boundary {sp.sstr(b.base)} = 0 of the region (e.g. at {at})"
    if b.shape == "point" and len(names) == 1:
        return f"at {at}" + (", an end of the domain" if b.face or _at_end(b, program) else "")
    if b.shape == "point":
        return f"at the point {at}"
    return f"where {sp.sstr(b.base)} = 0 on the domain" + (f" (e.g. at {at})" if b.point else "")


def _at_end(b: Blowup, program: Program) -> bool:
    try:
        ends = [real_value(denote(e)) for e in program.box[0]]
    except (TypeError, KeyError, IndexError):
        return False
    return any(abs(real_value(b.point[0]) - e) < 1e-12 for e in ends if math.isfinite(e))


def _fmt(v) -> str:
    f = real_value(v)
    return f"{f:.6g}" if math.isfinite(f) else sp.sstr(v)


def _order(b: Blowup) -> str:
    if b.alpha is None or not math.isfinite(b.alpha):
        return "and the delta's sifting property evaluates it there"
    return (f"like dist^-{b.alpha:.3g} near a set of codimension {b.codim}, and a singularity of order α "
            f"is integrable only when α is below the codimension of the set it sits on")


def findings(program: Program, declared: Mapping[str, object], point: Mapping[str, object] | None,
             sources: Mapping[str, str], *, derivatives: bool = True) -> list[Finding]:
    """X311/X312 for ⟦p⟧ and, with ``derivatives``, X313/X312 for ⦇p⦈ in each parameter, at the
    parameter values in force (nothing when a parameter has no value)."""
    if point is None or any(v is None for v in point.values()):
        return []
    out: list[Finding] = []
    value = value_integrability(program, point)
    out += findings_of(value, program, point, sources, "X311")
    if value.verdict is Verdict.DIVERGENT or not derivatives:
        return out
    for name in declared:
        d = derivative_integrability(program, point, {k: (1 if k == name else 0) for k in declared})
        out += findings_of(d, program, point, sources, "X313")
    return out


def findings_of(res: Integrability, program: Program, point, sources, code: str) -> list[Finding]:
    """One finding per integral: its first divergence (X311/X313), else its first undecided
    singularity (X312)."""
    at = _point(point)
    vals = ", ".join(f"{k} = {float(v):g}" for k, v in point.items())
    at_text = f" at {vals}" if vals else ""
    pick = res.divergent[:1] or [(b, p) for b, p in res.blowups if b.verdict is Verdict.UNDECIDED][:1]
    out = []
    for b, part in pick:
        span, what = _culprit(program, b, at, sources)
        where = _where(b, program)
        if b.verdict is Verdict.DIVERGENT:
            if code == "X311" and b.shape == "undefined":
                msg = (f"{what} is {where.replace('positive measure', 'positive measure of the domain', 1)}"
                       f"{at_text}: the integral of an integrand undefined there does not exist (LANGUAGE.md §1; "
                       "⟦p⟧ is undefined)")
            elif code == "X311":
                msg = (f"{what} is not integrable on the domain{at_text}: it blows up {where}, "
                       f"{_order(b)}: the integral does not exist (⟦p⟧ is undefined, it diverges)")
            else:
                msg = (f"{res.what} is not an integral{at_text}: the derivative of {what} ({part}) blows up {where}, "
                       f"{_order(b)}: "
                       "the derivative denotation is undefined (paper Theorem 7.1 needs it locally "
                       "integrable), although the value ⟦p⟧ exists")
            out.append(Finding(span, "error", code, msg, (), tuple(point)))
        else:
            why = ("a logarithm and a power of the same order meet there" if b.logarithmic else
                   "the growth is not the same power in every direction, or the singular set is not "
                   "one it can describe")
            out.append(Finding(span, "warning", "X312",
                               f"{what} blows up {where}{at_text} and the analysis cannot decide whether "
                               f"{res.what if code == 'X313' else 'the integral'} exists ({why}); the "
                               "engines' answers rely on their own diagnostics", (), tuple(point)))
    if res.note is not None and not res.divergent:
        # the analysis stopped (its CPU limit, a failure): what it did not reach is unchecked, said so
        out.append(Finding(program.span, "warning", "X312",
                           f"{res.note}{at_text}: whether {res.what if code == 'X313' else 'the integral'} exists "
                           "is unchecked; the engines' answers rely on their own diagnostics", (), tuple(point)))
    return out
