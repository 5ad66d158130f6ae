"""Text and LaTeX rendering of ⟦p⟧ and of ⦇p⦈ in the normal form of Theorem 7.1 (``langur show``).

* :func:`show_denotation`: ⟦p⟧ as the integral of its (Piecewise) integrand over the box, and its
  closed form when the integrator finds one at the given parameters;
* :func:`show_derivative`: ⦇p⦈ = ∫ f + Σ ∫ δ(Φ)·h — the regular part f as a sum of Iverson
  products, then each delta term ``δ(Φ)·h`` with its condition Φ, its factor h and the inverse
  branches of its diffeomorphism (the change of variables that integrates it).

Strings use sympy's ``sstr`` (text) and ``latex``.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import sympy as sp

from .decompose import exact_number, symbol
from .pieces import Condition, DeltaPiece, Method, Piece, Psi


def _e(e: sp.Expr, latex: bool) -> str:
    return sp.latex(e) if latex else sp.sstr(e)


def condition_text(c: Condition, latex: bool = False) -> str:
    return f"[{_e(c.expr, latex)} \\geq 0]" if latex else f"[{_e(c.expr, latex)} >= 0]"


def _factor(weight: sp.Expr, latex: bool) -> str:
    s = _e(weight, latex)
    if isinstance(weight, sp.Add):
        return f"\\left({s}\\right)" if latex else f"({s})"
    return s


def product_text(conditions: Sequence[Condition], weight: sp.Expr, latex: bool = False,
                 lead: str = "") -> str:
    """``c·lead·[Φ1 >= 0]·[Φ2 >= 0]·(g)`` with the rational coefficient c of the weight in front."""
    dot = " \\cdot " if latex else "·"
    coeff, rest = sp.sympify(weight).as_coeff_Mul()
    parts = ([lead] if lead else []) + [condition_text(c, latex) for c in conditions]
    if rest != 1 or not parts:
        parts.append(_factor(rest, latex))
    text = dot.join(parts)
    if coeff == 1:
        return text
    if coeff == -1:
        return "-" + text
    return _e(coeff, latex) + dot + text


def pieces_text(pieces: Sequence[Piece], latex: bool = False) -> str:
    if not pieces:
        return "0"
    return " + ".join(product_text(p.conditions, p.weight, latex) for p in pieces)


def psi_text(psi: Psi, latex: bool = False) -> list[str]:
    """Ψ̂ and its inverse branches, e.g. ``Ψ̂(x) = (theta - x); x = theta - u0``."""
    ins = ", ".join(_e(u, latex) for u in psi.inputs)
    vs = ", ".join(_e(v, latex) for v in psi.variables)
    fwd = ", ".join(_e(f, latex) for f in psi.forward)
    head = (f"\\hat\\Psi({vs}) = ({fwd})" if latex else f"Psi({vs}) = ({fwd})")
    lines = [head]
    for i, b in enumerate(psi.branches):
        inv = ", ".join(f"{_e(v, latex)} = {_e(e, latex)}" for v, e in b.inverse)
        guard = ""
        if b.guards:
            sep = " \\wedge " if latex else " and "
            ge = " \\geq 0" if latex else " >= 0"
            guard = (" \\text{ where } " if latex else " where ") + sep.join(_e(g, latex) + ge for g in b.guards)
        label = f"\\text{{branch {i + 1} in }} ({ins})" if latex else f"inverse branch {i + 1} in ({ins})"
        lines.append(f"{label}: {inv}{guard}")
    return lines


def delta_text(d: DeltaPiece, latex: bool = False) -> str:
    phi = _e(d.psi.forward[0], latex)
    lead = f"\\delta\\left({phi}\\right)" if latex else f"δ({phi})"
    return product_text(d.conditions, d.weight, latex, lead=lead)


def normal_form_text(nf, latex: bool = False) -> str:
    """⦇t⦈ = f + Σ δ(Φ)·h on one line."""
    parts = [pieces_text(nf.regular, latex)] if nf.regular else []
    parts += [delta_text(d, latex) for d in nf.deltas]
    return " + ".join(parts) if parts else "0"


def derivative_result_text(res, latex: bool = False) -> str:
    value = f"{res.value:.12g}" + ("" if res.method == Method.CLOSED_FORM else f" ± {res.error:.2g}")
    if res.expr is not None:
        body = _e(res.expr, latex)
        return f"{body} = {value}" if not latex else f"{body} \\approx {value}"
    return value


def _box_text(program, latex: bool) -> str:
    from ..denote import denote

    parts = []
    for x, (lo, hi) in zip(program.variables, program.box):
        lo_s, hi_s = _e(denote(lo), latex), _e(denote(hi), latex)
        parts.append(f"{x} \\in [{lo_s}, {hi_s}]" if latex else f"{x} in [{lo_s}, {hi_s}]")
    return ", ".join(parts)


def _evaluated(fn, *args, undefined: list[str] | None = None):
    """``(fn(*args), None)``, or ``(None, reason)`` when the integral does not exist (then the
    reason is also appended to ``undefined``) or the engine cannot evaluate it."""
    from .quadrature import UndefinedIntegral

    try:
        return fn(*args), None
    except UndefinedIntegral as e:
        if undefined is not None:
            undefined.append(e.reason)
        return None, f"undefined: {e.reason}"
    except (NotImplementedError, TypeError, ValueError, ZeroDivisionError, ArithmeticError, TimeoutError) as e:
        return None, f"no exact value: {str(e).splitlines()[0] if str(e) else type(e).__name__}"


def show_denotation(program, latex: bool = False, params: Mapping[str, object] | None = None, *,
                    undefined: list[str] | None = None, known_undefined: str | None = None) -> str:
    """⟦p⟧ = ∫ ⟦t⟧ d(x⃗) over the box, then its closed form at ``params`` when found.  When the
    integral does not exist the value line says so, and the reason is appended to ``undefined``;
    ``known_undefined`` (a reason found before) skips the evaluation."""
    at = params
    from ..denote import denote, denote_program

    integrand = _e(denote(program.body), latex)
    xs = ", ".join(program.variables)
    if latex:
        lines = [f"[\\![p]\\!] = \\int_{{{_box_text(program, True)}}} {integrand} \\, d({xs})"]
    else:
        lines = [f"⟦p⟧ = int_{{{_box_text(program, False)}}} {integrand} d({xs})"]
    if at is not None:
        r, why = (None, f"undefined: {known_undefined}") if known_undefined else \
            _evaluated(denote_program, program, at, undefined=undefined)
        if r is None:
            lines.append(("  " if not latex else "") + f"value at {_at_text(at)}: {why}")
            return ("\\\\\n" if latex else "\n").join(lines)
        if r.expr is not None and r.method == Method.CLOSED_FORM:
            lines.append("= " + _e(r.expr, latex))
        lines.append(("  " if not latex else "") + f"value at {_at_text(at)}: {r.value:.12g}"
                     + ("" if r.method == Method.CLOSED_FORM else f" ± {r.error:.2g} (quadrature)"))
        lines += [f"  note: {n}" for n in r.notes] if not latex else []
    return ("\\\\\n" if latex else "\n").join(lines)


def _at_text(at: Mapping[str, object]) -> str:
    return ", ".join(f"{k} = {v}" for k, v in at.items()) or "(no parameters)"


def show_derivative(program, direction: Mapping[str, object], latex: bool = False,
                    params: Mapping[str, object] | None = None, *, undefined: list[str] | None = None,
                    known_undefined: str | None = None) -> str:
    """⦇p⦈ in the normal form of Theorem 7.1: regular part, then each delta term with its Ψ̂.

    With ``params``, variable-free conditionals are decided there and the value is appended (or
    why there is none; a reason the integral does not exist is also appended to ``undefined``).
    """
    at = params
    from ..ddenote import ddenote, ddenote_program

    nf = ddenote(program.body, direction, at=at, variables=tuple(program.variables))
    xs = ", ".join(program.variables)
    nl = "\\\\\n" if latex else "\n"
    gp = ", ".join(f"{_e(symbol(k), latex)}' = {_e(exact_number(v), latex)}" for k, v in direction.items())
    lines = []
    if latex:
        lines.append(f"(\\!|p|\\!) = \\int f \\, d({xs}) + \\sum_k \\int \\delta(\\Phi_k)\\, h_k \\, d({xs})"
                     f" \\quad ({gp})")
        lines.append(f"f = {pieces_text(nf.regular, True)}")
    else:
        lines.append(f"⦇p⦈ = ∫ f d({xs}) + Σ_k ∫ δ(Φ_k)·h_k d({xs})   with γ': {gp}")
        lines.append(f"regular part f = {pieces_text(nf.regular)}")
    if not nf.deltas:
        lines.append("no delta terms" if not latex else "\\text{no delta terms}")
    for k, d in enumerate(nf.deltas, 1):
        if latex:
            lines.append(f"\\text{{delta term {k}: }} {delta_text(d, True)}")
        else:
            lines.append(f"delta term {k}: {delta_text(d)}")
            lines.append(f"    Φ = {_e(d.psi.forward[0], False)};  h = {product_text(d.conditions, d.weight)}")
        lines += [("    " if not latex else "\\quad ") + s for s in psi_text(d.psi, latex)]
    if at is not None:
        res, why = (None, f"undefined: {known_undefined}") if known_undefined else \
            _evaluated(ddenote_program, program, at, direction, undefined=undefined)
        if res is None:
            lines.append(f"value at {_at_text(at)}: {why}" if not latex else f"\\text{{{why}}}")
            return nl.join(lines)
        tail = (f"value at {_at_text(at)}: {derivative_result_text(res, latex)}"
                f"  (regular {res.regular.value:.12g}, boundary {res.boundary.value:.12g})")
        lines.append(tail if not latex else f"\\text{{{_at_text(at)}: }} {derivative_result_text(res, True)}")
    return nl.join(lines)
