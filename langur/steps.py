"""Derivations as the semantics computes them (``langur show --steps`` / ``--typing``, issue 14).

* :func:`derivative_steps`: ⦇t⦈ rule by rule (Fig. 8), recorded by :mod:`langur.observe` while
  :func:`langur.ddenote.ddenote` runs — each step is the rule a case of its one ``match`` applied,
  the subterm, and the part of the normal form (Theorem 7.1) it produced;
* :func:`sifting`: each delta term of that normal form integrated through the change of variables
  u = Ψ̂(x) of its inverse branches (Jacobian |det DΨ̂⁻¹|), δ(u₀) sifting u₀ = 0, down to its number
  (the integrator's own value for that term);
* :func:`typing_steps`: the typing derivation (Fig. 6, 11) recorded while ``typesys.type_program``
  checks the program.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import sympy as sp

from . import observe, typesys
from .core import Program
from .ddenote import NormalForm, ddenote
from .denote import program_box
from .exact import latex_text, readable_of
from .symbolic.decompose import Ctx, decided_cell
from .symbolic.pieces import Method, accuracy_of
from .symbolic.text import expr_text, normal_form_text, product_text
from .sympy_bridge import at_symbols, symbols
from .syntax import printer

#: Longest subterm or result written on a step line (the rest is elided with "…").
WIDTH = 90
#: Most steps written out (a program inlined from many definitions has one per node).
MAX_STEPS = 600

_LATEX = {"⦇": "(\\!|", "⦈": "|\\!)", "⟦": "[\\![", "⟧": "]\\!]", "γ": "\\gamma ", "Γ": "\\Gamma ",
          "Δ": "\\Delta ", "⊢": "\\vdash ", "≥": "\\geq ", "∈": "\\in ", "↦": "\\mapsto ", "π₀": "\\pi_0 ",
          "Ψ̂": "\\hat\\Psi ", "δ": "\\delta ", "⟹": "\\Rightarrow ", "·": "\\cdot ", "−": "-", "∘": "\\circ ",
          "…": "\\ldots ", "x1": "x_1", "xn": "x_n", "D_γ": "D_\\gamma "}


def _short(s: str) -> str:
    s = " ".join(s.split())
    return s if len(s) <= WIDTH else s[:WIDTH - 1] + "…"


def _rule_latex(rule: str) -> str:
    """``Fig. 8, sum: ⦇t + s⦈ = …`` as ``\\text{Fig. 8, sum: } (\\!|t + s|\\!) = …``."""
    name, _, eq = rule.partition(": ")
    for k in sorted(_LATEX, key=len, reverse=True):
        eq = eq.replace(k, _LATEX[k])
    eq = eq.replace("ifge0", "\\mathrm{ifge0}\\ ").replace("then", "\\ \\mathrm{then}\\ ") \
        .replace("else", "\\ \\mathrm{else}\\ ").replace("let ", "\\mathrm{let}\\ ").replace(" in ", "\\ \\mathrm{in}\\ ") \
        .replace("int ", "\\textstyle\\int ").replace("real", "\\mathrm{real}")
    return f"\\text{{{latex_text(name)}: }} {eq}"


def _term_text(t) -> str:
    if isinstance(t, Program):
        return _short(printer.print_program(t))
    return _short(printer.print_core(t))


#: Rules of plain arithmetic: a typing subtree made of them only is written as one line.
_ARITHMETIC = ("Fig. 6, constant", "Fig. 6, variable", "Fig. 6, sum / product", "Fig. 6, parameter")


def _collapsible(steps: list[observe.Step], i: int) -> int:
    """How many steps after ``steps[i]`` are its subtree, when that subtree is not worth spelling
    out: a derivative of 0 (no parameter moves anything in it), or typing by arithmetic only."""
    s = steps[i]
    end = i + 1
    while end < len(steps) and steps[end].depth > s.depth:
        end += 1
    sub = steps[i:end]
    zero = isinstance(s.result, NormalForm) and not s.result.regular and not s.result.deltas
    plain = all(x.rule.startswith(_ARITHMETIC) for x in sub) and s.result is None
    return end - i - 1 if (zero or plain) and end > i + 1 else 0


def steps_text(steps: list[observe.Step], latex: bool = False, full: bool = False) -> list[str]:
    """One line per step, indented by depth: the rule, the subterm, and what it produced.  Unless
    ``full``, a subtree whose derivative is 0, or typed by arithmetic rules only, is one line."""
    lines: list[str] = []
    i = 0
    while i < len(steps):
        if len(lines) >= MAX_STEPS:
            more = f"… {len(steps) - i} more steps not written out (more than {MAX_STEPS} lines)"
            lines.append(f"\\text{{{latex_text(more)}}}" if latex else more)
            break
        s = steps[i]
        skip = 0 if full else _collapsible(steps, i)
        i += 1 + skip
        if skip:
            what = "⦇·⦈ = 0 throughout" if s.result is not None else "constant, variable, parameter, sum, product"
            s = observe.Step(f"{s.rule}   [+{skip} steps below: {what}]", s.term, s.depth, s.result)
        result = ""
        if isinstance(s.result, NormalForm):
            result = normal_form_text(s.result, latex)
            if not latex:
                result = _short(result)
        if latex:
            lines.append(f"\\hspace{{{s.depth}em}} {_rule_latex(s.rule)} \\quad \\text{{on }} "
                         f"\\texttt{{{latex_text(_term_text(s.term))}}}"
                         + (f" \\quad \\leadsto {result}" if result and len(result) < 400 else ""))
        else:
            lines.append("  " * s.depth + f"{s.rule}\n" + "  " * s.depth + f"    on  {_term_text(s.term)}"
                         + (f"\n{'  ' * s.depth}    ⟶  {result}" if result else ""))
    return lines


def derivative_steps(program: Program, direction: Mapping[str, object],
                     at: Mapping[str, object] | None) -> tuple[list[observe.Step], NormalForm]:
    """The rules of Fig. 8 that build ⦇t⦈ for the program's integrand, in the order they apply,
    and the resulting Theorem 7.1 normal form."""
    with observe.observing() as steps:
        nf = ddenote(program.body, direction, at=at, variables=tuple(program.variables))
    return list(steps), nf


def typing_steps(program: Program, params) -> tuple[list[observe.Step], list]:
    """The typing derivation ·;Γ ⊢ int t d(x⃗) (Fig. 11, Fig. 6) and its diagnostics."""
    with observe.observing() as steps:
        found = typesys.type_program(program, frozenset(params))
    return list(steps), found


def _jacobian(branch, inputs) -> sp.Expr:
    xs = [e for _, e in branch.inverse]
    return sp.simplify(sp.Abs(sp.Matrix(xs).jacobian(sp.Matrix(inputs)).det()))


def delta_integrals(program: Program, nf: NormalForm, at: Mapping[str, object]) -> list:
    """The integral of each delta term of ``nf`` alone, by the integrator (its Integral)."""
    from .symbolic.integrate import integrate_delta_pieces  # scipy: only when integrating

    point = at_symbols(at)
    ctx = Ctx(at=point, variables=tuple(program.variables))
    variables, box = symbols(program.variables), program_box(program, ctx)
    cell = decided_cell(program.body, ctx)
    return [integrate_delta_pieces([d], variables, box, point, cell=cell) for d in nf.deltas]


def sifting(program: Program, nf: NormalForm, at: Mapping[str, object], latex: bool = False) -> list[str]:
    """Each delta term ∫ δ(Φ)·h of ``nf`` through the change of variables u = Ψ̂(x): per inverse
    branch the substitution x = Ψ̂⁻¹(u), its Jacobian, δ(u₀) setting u₀ = 0, and the term's value
    as the integrator computes it."""
    integrals = delta_integrals(program, nf, at)
    where = ", ".join(f"{k} = {v}" for k, v in at.items()) or "(no parameters)"
    e = lambda x: expr_text(x, latex)  # noqa: E731
    lines: list[str] = []
    if not nf.deltas:
        return ["\\text{no delta terms: nothing to sift}" if latex else "no delta terms: nothing to sift"]
    for k, d in enumerate(nf.deltas, 1):
        psi = d.psi
        ins = ", ".join(e(u) for u in psi.inputs)
        xs = ", ".join(e(v) for v in psi.variables)
        if latex:
            lines.append(f"\\text{{delta term {k}: }} u = \\hat\\Psi({xs}) = ({', '.join(e(f) for f in psi.forward)})")
        else:
            lines.append(f"delta term {k}: change of variables ({ins}) = Psi({xs}) = "
                         f"({', '.join(e(f) for f in psi.forward)})")
        for i, b in enumerate(psi.branches, 1):
            sub = dict(b.inverse)
            on_zero = {psi.inputs[0]: 0}
            jac = _jacobian(b, psi.inputs)
            conds = tuple(type(c)(sp.expand(c.expr.xreplace(sub).xreplace(on_zero)), None, c.origin, c.strict)
                          for c in d.conditions)
            weight = sp.expand(d.weight.xreplace(sub).xreplace(on_zero) * jac.xreplace(on_zero))
            rest = ", ".join(e(u) for u in psi.inputs[1:])
            inv = ", ".join(f"{e(v)} = {e(x)}" for v, x in b.inverse)
            guard = (" where " + " and ".join(f"{e(g)} >= 0" for g in b.guards)) if b.guards and not latex else ""
            sifted = product_text(conds, weight, latex)
            if latex:
                lines.append(f"\\quad \\text{{branch {i}: }} {inv} \\quad |\\det D\\hat\\Psi^{{-1}}| = {e(jac)}")
                lines.append(f"\\quad \\delta({e(psi.inputs[0])}) \\text{{ sifts }} {e(psi.inputs[0])} = 0:\\ "
                             + (f"\\int {sifted} \\, d({rest})" if rest else sifted))
            else:
                lines.append(f"    inverse branch {i}: {inv}{guard}")
                lines.append(f"    Jacobian |det D(Psi^-1)| = {e(jac)}")
                lines.append(f"    δ({e(psi.inputs[0])}) sifts {e(psi.inputs[0])} = 0:  "
                             + (f"∫ {sifted} d({rest})" if rest else sifted))
        r = integrals[k - 1]
        value = f"{r.value:.12g}" + (("" if r.method == Method.CLOSED_FORM else f" ± {r.error:.2g} (quadrature)") if latex
                                     else accuracy_of(r))
        rd = readable_of(r.expr, at, (r,)) if r.expr is not None and r.method == Method.CLOSED_FORM else None
        closed = r.expr is not None and r.method == Method.CLOSED_FORM
        if latex:
            shown = (rd.text(True) if rd else e(r.expr)) + " = " if closed else ""
            lines.append(f"\\quad = {shown}{value}")
            continue
        if rd is not None and (len(rd.cases) > 1 or not rd.complete):
            lines.append("    = " + "\n      ".join(rd.text().splitlines()))
        elif closed:
            lines.append(f"    = {rd.text() if rd else e(r.expr)}")
        lines.append(f"    value of delta term {k} at {where}: {value}")
    return lines


@dataclass(frozen=True)
class Derivation:
    """``show --steps`` as a value for the Python API: the rules (Fig. 8), the normal form they
    produced (Theorem 7.1) and the sifting of its deltas; prints as text, renders as LaTeX in a
    notebook (``_repr_latex_``)."""

    steps: tuple[observe.Step, ...]
    normal_form: NormalForm
    sifting_text: tuple[str, ...]
    sifting_latex: tuple[str, ...]

    def __str__(self) -> str:
        return "\n".join([*steps_text(list(self.steps)), "normal form (Theorem 7.1): " + str(self.normal_form),
                          *self.sifting_text])

    def _repr_latex_(self) -> str:
        rows = [*steps_text(list(self.steps), latex=True),
                "\\text{normal form (Theorem 7.1): } " + normal_form_text(self.normal_form, latex=True),
                *self.sifting_latex]
        return "$\\begin{array}{l}\n" + " \\\\\n".join(rows) + "\n\\end{array}$"


def derivation(program: Program, direction: Mapping[str, object], at: Mapping[str, object]) -> Derivation:
    """The derivation of ⦇t⦈ for ``program`` at ``at`` in the direction ``direction``, sifted."""
    trace, nf = derivative_steps(program, direction, at)
    return Derivation(tuple(trace), nf, tuple(sifting(program, nf, at)), tuple(sifting(program, nf, at, latex=True)))
