"""What the command line calls for the exact (symbolic) engine (CLI.md, JSON shapes).

* :func:`exact_eval` → the ``exact`` object of ``langur eval --json``;
* :func:`exact_deriv` → the ``exact`` object of ``langur deriv --json`` plus ``standard_ad`` (the
  regular part alone, the paper's Dˢ) and ``theorem_8_1`` (the check of Theorem 8.1);
* :func:`show_denotation` (``langur show``): ⟦p⟧ as the integral of its (Piecewise) integrand over
  the box, and its closed form when the integrator finds one at the given parameters;
* :func:`show_derivative` (``langur show --wrt``): ⦇p⦈ = ∫ f + Σ ∫ δ(Φ)·h — the regular part f as a
  sum of Iverson products, then each delta term ``δ(Φ)·h`` with its condition Φ, its factor h and
  the inverse branches of its diffeomorphism (the change of variables that integrates it).

Parameter values may be floats or Fractions; exact decimals are used as sympy Rationals (``0.5``
is 1/2).  When neither a closed form nor quadrature works, :class:`ExactUnavailable` is raised with
a one-line reason (the CLI then prints ``"exact": null`` and the reason on standard error);
:class:`ExactUndefined`, its subclass, when the integral does not exist (divergent, or undefined
on part of the domain).
"""

from __future__ import annotations

import time
from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from . import failures
from .core import Program
from .ddenote import ddenote, ddenote_program
from .denote import denote, denote_program, undefined_where
from .symbolic.decompose import Ctx
from .symbolic.integrate import for_reading
from .symbolic.nounits import units_unloaded
from .symbolic.pieces import Method, accuracy, accuracy_of
from .symbolic.quadrature import UndefinedIntegral, printable
from .symbolic.readable import Readable, readable
from .symbolic.text import (
    delta_text,
    derivative_result_text,
    expr_text,
    pieces_text,
    product_text,
    psi_text,
    shared_sstr,
)
from .symbolic.walks import size
from .sympy_bridge import at_symbols, exact_number, symbol
from .theorem import TheoremCheck, check_theorem_8_1
from .timebox import budget, run_with_timeout


class ExactUnavailable(Exception):
    """The symbolic engine cannot evaluate this program (the message says why, on one line;
    ``reason`` is the engine's own words)."""

    def __init__(self, message: str, reason: str):
        super().__init__(message)
        self.reason = reason


class ExactUndefined(ExactUnavailable):
    """The integral does not exist (it diverges, or its integrand is undefined on part of the
    domain): an answer about the program, not a failure of the engine."""


#: Operation count beyond which a closed form is printed without sorting its terms.
LARGE_TEXT_OPS = 2000
#: Size (tree nodes) beyond which a closed form is not printed at all (megabytes of text, a minute
#: of sympy's printer: the stylization kernel's quadratic shader, §10.3.1); a note says so.
UNPRINTED_OPS = 100_000


def _expr_text(e: sp.Expr | None) -> str | None:
    """The closed form as text; a rational of more than about 1,200 digits (Python refuses to
    print more than 4300) is written as a 30-digit float, and the text says so.  None when no
    text is wanted (:func:`~langur.symbolic.integrate.untidied`: ``langur fuzz`` compares values)."""
    if e is None or not for_reading():
        return None
    if size(e, UNPRINTED_OPS) >= UNPRINTED_OPS:
        return None
    shown = printable(e)
    # a large closed form (thousands of operations) printed in sympy's canonical term order costs
    # seconds of sorting; printed as it is built instead
    order = "none" if size(shown, LARGE_TEXT_OPS) >= LARGE_TEXT_OPS else None
    return shared_sstr(shown, order=order) + ("   [numbers of more than 1,200 digits rounded to 30 digits in this text]"
                             if shown != e else "")


def _guard(fn, *args, **kwargs):
    try:
        return fn(*args, **kwargs)
    except UndefinedIntegral as e:
        raise ExactUndefined(f"undefined: {e.reason}", e.reason) from e
    except (NotImplementedError, TypeError, ValueError, ZeroDivisionError, ArithmeticError, TimeoutError) as e:
        reason = failures.why(e)
        raise ExactUnavailable(f"symbolic engine: {reason}", reason) from e


@dataclass(frozen=True)
class ExactValue:
    """⟦p⟧ at the parameters: ``expr`` the closed form as text (None: quadrature only, or no text
    wanted: ``integrate.untidied``), ``error``
    quadrature's estimate of |value − ⟦p⟧| (None for a closed form), ``proved`` a bound on it that
    interval enclosures prove (None: none proved; :mod:`langur.symbolic.quadrature.enclosed`)."""

    value: float
    expr: str | None
    method: Method
    error: float | None
    notes: list[str]
    #: closed forms discarded because their quadrature cross-check failed (an engine bug)
    inconsistent: tuple[str, ...] = ()
    proved: float | None = None

    @classmethod
    def of(cls, r) -> ExactValue:
        """From an exact-engine result (an Integral or a DerivativeResult)."""
        text = _expr_text(r.expr)
        notes = list(r.notes)
        if text is None and r.expr is not None and for_reading():
            notes.append(f"closed form of more than {UNPRINTED_OPS:,} nodes: not printed")
        return cls(float(r.value), text, r.method,
                   None if r.method == Method.CLOSED_FORM else float(r.error), notes, r.inconsistent,
                   None if r.method == Method.CLOSED_FORM or r.proved is None else float(r.proved))

    def how(self) -> str:
        """How the value was obtained, for the text output."""
        if self.method == Method.CLOSED_FORM:
            return "closed form"
        return accuracy(self.error, self.proved)

    def to_json(self) -> dict:
        """The ``exact`` object of ``langur eval --json`` (CLI.md)."""
        out = {"value": self.value, "expr": self.expr, "method": self.method}
        if self.error is not None:
            out["error"] = self.error
        out["notes"] = list(self.notes)
        return out


@dataclass(frozen=True)
class ExactDerivative(ExactValue):
    """⦇p⦈(γ, γ') = ``regular`` + ``boundary`` (Theorem 7.1's split); ``standard_ad`` is the regular
    part alone (the paper's Dˢ); ``theorem_8_1`` the check of Theorem 8.1 (None when not asked
    for or not computable)."""

    regular: float = 0.0
    boundary: float = 0.0
    standard_ad: float = 0.0
    theorem_8_1: TheoremCheck | None = None

    def to_json(self) -> dict:
        """The ``exact`` object of ``langur deriv --json`` (CLI.md), without ``standard_ad`` and
        ``theorem_8_1``, which the command reports beside it."""
        out = super().to_json()
        return {"value": out.pop("value"), "regular": self.regular, "boundary": self.boundary, **out}


#: The CPU seconds of sympy work one call of :func:`exact_eval` or :func:`exact_deriv` may spend (issue 15:
#: one time budget per call): a derivative's regular and boundary parts and its Theorem 8.1 check draw on
#: it together, and what is not done by its end is quadrature (said by the notes; the check, by
#: :data:`CHECK_STOPPED`).  Before, each integral had 20 s of its own: a lambert pixel's exact derivative
#: took ≈ 60 CPU s (bench/history/2026-11-29.md#budget33.  None: no bound beyond each integral's own.
CALL_SECONDS = 20.0


def exact_eval(program: Program, params: Mapping[str, float | object], *,
               seconds: float | None = CALL_SECONDS) -> ExactValue:
    """⟦p⟧ at ``params``, the sympy work within ``seconds`` CPU seconds (:data:`CALL_SECONDS`)."""
    with budget(seconds):
        return ExactValue.of(_guard(denote_program, program, dict(params)))


#: The note of a derivative whose Theorem 8.1 check ran out of the CPU seconds it was given.
CHECK_STOPPED = "Theorem 8.1 check stopped: its CPU budget was spent"


def exact_deriv(program: Program, params: Mapping[str, float | object], direction: Mapping[str, float | object],
                *, check: bool = True, check_seconds: float | None = None,
                seconds: float | None = CALL_SECONDS) -> ExactDerivative:
    """⦇p⦈ at ``params`` in the direction γ' = ``direction`` (``--wrt a`` is ``{"a": 1}``), with the
    check of Theorem 8.1 unless ``check`` is false; ``check_seconds``: the CPU seconds the check may
    take (None: no limit), past which it is left out with the note :data:`CHECK_STOPPED` (the
    derivative itself is never cut short: past ``seconds`` its symbolic work gives way to quadrature).
    ``seconds`` (:data:`CALL_SECONDS`): the one CPU budget of the whole call, derivative and check;
    the check gets what the derivative left of it (or ``check_seconds``, if less)."""
    with budget(seconds):
        return _exact_deriv(program, params, direction, check, check_seconds,
                            None if seconds is None else time.process_time() + seconds)


def _exact_deriv(program, params, direction, check: bool, check_seconds: float | None,
                 end: float | None) -> ExactDerivative:
    """:func:`exact_deriv` within its budget, which ends at ``end`` (``time.process_time``; None: never)."""
    params, direction = dict(params), dict(direction)
    res = _guard(ddenote_program, program, params, direction)
    base = ExactValue.of(res)
    notes, theorem = base.notes, None

    def checked():
        # ⟦p⟧ near the point is all the check needs (it localizes ⟦p⟧'s closed form there)
        with units_unloaded():  # sympy's simplify without its import of physical units
            denotation = denote_program(program, params, near=True)
            return check_theorem_8_1(program, params, direction, denotation=denotation, derivative=res)

    if check:
        start = time.process_time()
        if end is not None:
            check_seconds = max(0.0, min(end - start, check_seconds if check_seconds is not None else end - start))
        try:
            theorem = run_with_timeout(checked, check_seconds, cpu=True)
        except TimeoutError as e:  # this limit's, or one inside the check that it did not catch
            spent = check_seconds is not None and time.process_time() - start >= check_seconds - 1e-3
            notes.append(CHECK_STOPPED if spent else f"Theorem 8.1 check not computed: {e}")
        except Exception as e:  # noqa: BLE001 - the check is a report, not a reason to lose the derivative
            notes.append(f"Theorem 8.1 check not computed: {failures.why(e)}")
    return ExactDerivative(base.value, base.expr, base.method, base.error, notes, base.inconsistent, base.proved,
                           regular=float(res.regular.value),
                           boundary=float(res.boundary.value), standard_ad=float(res.standard_ad),
                           theorem_8_1=theorem)


def readable_of(expr: sp.Expr | None, at: Mapping[str, object] | None, parts=()) -> Readable | None:
    """The closed form ``expr`` of ⟦p⟧ or ⦇p⦈ in readable cases (langur.symbolic.readable), valid on
    the intersection of the cells of ``parts`` (the Integrals it was summed from); None when no
    case split was found (then the engine's form is shown)."""
    if expr is None:
        return None
    cell = tuple(rel for r in parts for rel in r.cell)
    everywhere = all(r.everywhere for r in parts)
    generic = any(r.generic for r in parts)
    try:
        return readable(expr, at_symbols(at) if at is not None else None, cell=cell,
                        everywhere=everywhere, generic=generic)
    except Exception:  # noqa: BLE001 - presentation only: the engine's form is always there to show
        return None


def _closed_form_lines(expr, rd: Readable | None, latex: bool, lead: str) -> list[str]:
    """``lead = expr`` (the engine's form) or, when readable, the cases (text: one per line)."""
    if rd is None:
        return [f"{lead} = {expr_text(expr, latex)}"]
    body = rd.text(latex)
    if latex:
        return [f"{lead} = {body}"]
    head = f"{lead} = " + (f"piecewise in {rd.parameter}:" if rd.parameter is not None and len(rd.cases) > 1
                           else "" if rd.complete else "near the evaluation point:")
    if "\n" not in body and rd.complete and len(rd.cases) == 1:
        return [f"{lead} = {body}"]
    return [head.rstrip()] + ["    " + line for line in body.splitlines()]


def _box_text(program, latex: bool) -> str:
    parts = []
    for x, (lo, hi) in zip(program.variables, program.box):
        lo_s, hi_s = expr_text(denote(lo), latex), expr_text(denote(hi), latex)
        parts.append(f"{x} \\in [{lo_s}, {hi_s}]" if latex else f"{x} in [{lo_s}, {hi_s}]")
    return ", ".join(parts)


def _evaluated(fn, *args, undefined: list[str] | None = None):
    """``(fn(*args), None)``, or ``(None, reason)`` when the integral does not exist (then the
    reason is also appended to ``undefined``) or the engine cannot evaluate it."""
    try:
        return _guard(fn, *args), None
    except ExactUndefined as e:
        if undefined is not None:
            undefined.append(e.reason)
        return None, str(e)
    except ExactUnavailable as e:
        return None, f"no exact value: {e.reason}"


def show_denotation(program, latex: bool = False, params: Mapping[str, object] | None = None, *,
                    undefined: list[str] | None = None, known_undefined: str | None = None,
                    raw: bool = False) -> str:
    """⟦p⟧ = ∫ ⟦t⟧ d(x⃗) over the box, then its closed form at ``params`` when found.  When the
    integral does not exist the value line says so, and the reason is appended to ``undefined``;
    ``known_undefined`` (a reason found before) skips the evaluation.  The closed form is shown in
    readable cases (:func:`readable_of`) unless ``raw`` (then as the engine found it).
    With ``latex`` every line is LaTeX math (joined by ``\\\\``)."""
    at = params
    integrand = expr_text(denote(program.body), latex)
    xs = ", ".join(program.variables)
    if latex:
        lines = [f"[\\![p]\\!] = \\int_{{{_box_text(program, True)}}} {integrand} \\, d({xs})"]
    else:
        lines = [f"⟦p⟧ = int_{{{_box_text(program, False)}}} {integrand} d({xs})"]
    lines += _undefined_lines(program, at, latex, "  ")
    if at is not None:
        r, why = (None, f"undefined: {known_undefined}") if known_undefined else \
            _evaluated(denote_program, program, at, undefined=undefined)
        if r is None:
            lines.append(f"\\text{{at }} {_at_latex(at)}:\\ \\text{{{latex_text(why)}}}" if latex
                         else f"  value at {_at_text(at)}: {why}")
            return ("\\\\\n" if latex else "\n").join(lines)
        if r.expr is not None and r.method == Method.CLOSED_FORM:
            rd = None if raw else readable_of(r.expr, at, (r,))
            lines += _closed_form_lines(r.expr, rd, latex, "[\\![p]\\!]" if latex else "⟦p⟧")
        if latex:
            how = "" if r.method == Method.CLOSED_FORM else f" \\pm {r.error:.2g} \\text{{ (quadrature)}}"
            lines.append(f"\\text{{at }} {_at_latex(at)}:\\ [\\![p]\\!] = {r.value:.12g}{how}")
            lines += [f"\\text{{note: {latex_text(n)}}}" for n in r.notes]
        else:
            lines.append(f"  value at {_at_text(at)}: {r.value:.12g}{accuracy_of(r)}")
            lines += [f"  note: {n}" for n in r.notes]
    return ("\\\\\n" if latex else "\n").join(lines)


def _undefined_lines(program, at: Mapping[str, object] | None, latex: bool, lead: str, what: str = "") -> list[str]:
    """Where ⟦t⟧ is undefined although the text of ⟦t⟧ or ⦇t⦈ above reads as a number there (a
    primitive outside its domain times a bracket's 0, sympy's ``log(x) − log(x)`` = 0:
    :func:`~langur.denote.undefined_where`), as one line after ``lead``; none when it is defined."""
    if at is None or any(v is None for v in at.values()):
        return []
    try:
        bad = undefined_where(program, Ctx(at=at_symbols(at), variables=tuple(program.variables)))
    except Exception:  # noqa: BLE001 - presentation only: the value line says what the engine found
        return []
    if bad is None:
        return []
    text = (f"⟦t⟧ is undefined on a set of positive measure{what}: `{bad.what}` is evaluated outside its "
            f"domain ({bad.why}), e.g. at {bad.at}")
    return [f"\\text{{{latex_text(text)}}}" if latex else lead + text]


def _at_text(at: Mapping[str, object]) -> str:
    return ", ".join(f"{k} = {v}" for k, v in at.items()) or "(no parameters)"


def _at_latex(at: Mapping[str, object]) -> str:
    return ", ".join(f"{expr_text(symbol(k), True)} = {expr_text(exact_number(v), True)}" for k, v in at.items()) \
        or "\\text{(no parameters)}"


#: Non-ASCII characters of the engine's notes and reasons, as LaTeX text-mode ASCII.
_TEXT_MAP = {"⟦": "[[", "⟧": "]]", "⦇": "(|", "⦈": "|)", "≤": "<=", "≥": ">=", "≠": "!=", "±": "+/-",
             "…": "...", "—": "--", "–": "-", "·": "*", "γ": "gamma", "θ": "theta", "δ": "delta",
             "Φ": "Phi", "Ψ": "Psi", "̂": "", "∫": "int", "Σ": "sum", "×": "x", "→": "->", "′": "'",
             "²": "^2", "ρ": "rho", "≈": "~", "∞": "inf"}


def latex_text(s: str) -> str:
    """``s`` safe inside ``\\text{…}`` for pdflatex: special characters escaped, non-ASCII spelled out."""
    s = "".join(_TEXT_MAP.get(ch, ch if ord(ch) < 128 else "?") for ch in s)
    out = []
    for ch in s:
        if ch in "&%$#_{}":
            out.append("\\" + ch)
        elif ch == "\\":
            out.append("\\textbackslash{}")
        elif ch == "^":
            out.append("\\^{}")
        elif ch == "~":
            out.append("\\~{}")
        elif ch in "<>|":
            out.append(f"\\ensuremath{{{ch}}}")
        else:
            out.append(ch)
    return "".join(out)


def show_derivative(program, direction: Mapping[str, object], latex: bool = False,
                    params: Mapping[str, object] | None = None, *, undefined: list[str] | None = None,
                    known_undefined: str | None = None, raw: bool = False) -> str:
    """⦇p⦈ in the normal form of Theorem 7.1: regular part, then each delta term with its Ψ̂.

    With ``params``, variable-free conditionals are decided there and the value is appended (or
    why there is none; a reason the integral does not exist is also appended to ``undefined``).
    """
    at = params
    nf = ddenote(program.body, direction, at=at, variables=tuple(program.variables))
    xs = ", ".join(program.variables)
    nl = "\\\\\n" if latex else "\n"
    gp = ", ".join(f"{expr_text(symbol(k), latex)}' = {expr_text(exact_number(v), latex)}" for k, v in direction.items())
    lines = []
    if latex:
        lines.append(f"(\\!|p|\\!) = \\int f \\, d({xs}) + \\sum_k \\int \\delta(\\Phi_k)\\, h_k \\, d({xs})"
                     f" \\quad ({gp})")
        lines.append(f"f = {pieces_text(nf.regular, True)}")
    else:
        lines.append(f"⦇p⦈ = ∫ f d({xs}) + Σ_k ∫ δ(Φ_k)·h_k d({xs})   with γ': {gp}")
        lines.append(f"regular part f = {pieces_text(nf.regular)}")
    lines += _undefined_lines(program, at, latex, "", " (so is ⦇t⦈, whatever f reads there)")
    if not nf.deltas:
        lines.append("no delta terms" if not latex else "\\text{no delta terms}")
    for k, d in enumerate(nf.deltas, 1):
        if latex:
            lines.append(f"\\text{{delta term {k}: }} {delta_text(d, True)}")
        else:
            lines.append(f"delta term {k}: {delta_text(d)}")
            lines.append(f"    Φ = {expr_text(d.psi.forward[0], False)};  h = {product_text(d.conditions, d.weight)}")
        lines += [("    " if not latex else "\\quad ") + s for s in psi_text(d.psi, latex)]
    if at is not None:
        res, why = (None, f"undefined: {known_undefined}") if known_undefined else \
            _evaluated(ddenote_program, program, at, direction, undefined=undefined)
        if res is None:
            lines.append(f"value at {_at_text(at)}: {why}" if not latex
                         else f"\\text{{at }} {_at_latex(at)}:\\ \\text{{{latex_text(why)}}}")
            return nl.join(lines)
        rd = None if raw or res.expr is None else readable_of(res.expr, at, (res.regular, res.boundary))
        split = f"(regular {res.regular.value:.12g}, boundary {res.boundary.value:.12g})"
        if rd is None:
            tail = f"value at {_at_text(at)}: {derivative_result_text(res, latex)}  {split}"
            lines.append(tail if not latex else
                         f"\\text{{at }} {_at_latex(at)}:\\ {derivative_result_text(res, True)}")
        else:
            lines += _closed_form_lines(res.expr, rd, latex, "(\\!|p|\\!)" if latex else "⦇p⦈")
            value = f"{res.value:.12g}" + ("" if res.method == Method.CLOSED_FORM else f" ± {res.error:.2g}")
            lines.append(f"\\text{{at }} {_at_latex(at)}:\\ (\\!|p|\\!) = {value}" if latex
                         else f"value at {_at_text(at)}: {res.value:.12g}{accuracy_of(res)}  {split}")
    return nl.join(lines)
