"""``langur show FILE``: the core term after desugaring (§4), its denotation ⟦p⟧ (Fig. 7, 12), and
with ``--wrt``/``--dir`` its derivative ⦇p⦈ in the normal form of Theorem 7.1.

Closed forms are shown in readable cases (``langur.symbolic.readable``; ``--raw`` for the engine's
own form).  ``--latex`` prints one complete LaTeX document, ``--latex-fragment`` its body."""

from __future__ import annotations

from .. import exact, progress, steps
from ..cli import UsageError, add_common, add_timeout
from ..core import tree_size
from ..syntax import printer
from . import _common as c
from . import _defined


def add_arguments(p):
    p.add_argument("file", metavar="FILE", help="a .lgr file (- reads standard input)")
    p.add_argument("--wrt", metavar="NAME", help="also show the derivative in this parameter")
    p.add_argument("--dir", action="append", metavar="NAME=VALUE", help="a direction γ' instead of --wrt")
    p.add_argument("--latex", action="store_true", help="one complete LaTeX document (pdflatex)")
    p.add_argument("--latex-fragment", action="store_true", help="LaTeX without the preamble, to paste")
    p.add_argument("--raw", action="store_true", help="closed forms as the engine found them (no cases)")
    p.add_argument("--steps", action="store_true",
                   help="with --wrt/--dir: the derivation of ⦇t⦈ rule by rule (Fig. 8) and the sifting of each delta")
    p.add_argument("--typing", action="store_true", help="the typing derivation (Fig. 6, 11)")
    p.add_argument("--core", action="store_true", help="only the core term (no semantics)")
    add_common(p)
    add_timeout(p, "show", "for the whole command, in seconds")


#: Largest inlined program printed as text (nodes written out as a tree).
PRINT_LIMIT = 100_000


def _core_text(loaded) -> str:
    lines = []
    main = loaded.main
    for name, d in main.defs.items():
        args = ", ".join(f"{a}: {k}" for a, k in d.args)
        lines.append(f"def {name}({args}) = {printer.print_core(d.body)}")
    for psi in main.diffeos.values():
        lines.append(printer.print_diffeo(psi))
    if loaded.program is not None:
        nodes = tree_size(loaded.program.body)
        if nodes > PRINT_LIMIT:  # shared after inlining: written out it would not fit anywhere
            lines.append(f"int … d({', '.join(loaded.program.variables)})   (the inlined integrand has {nodes:,} "
                         f"nodes written out, more than {PRINT_LIMIT:,}: not printed; its definitions are above)")
        else:
            lines.append(printer.print_program(loaded.program, defaults=loaded.params))
    return "\n".join(lines) if lines else "(empty module)"


PREAMBLE = ("\\documentclass{article}\n\\usepackage{amsmath}\n\\usepackage{amssymb}\n"
            "\\allowdisplaybreaks\n\\begin{document}\n")


def _ascii(s: str) -> str:
    """The core term for ``verbatim`` under pdflatex: the few non-ASCII characters spelled out."""
    return "".join({"…": "...", "γ": "gamma", "′": "'"}.get(ch, ch if ord(ch) < 128 else "?") for ch in s)


def _math_block(body: str) -> str:
    """Lines of LaTeX math joined by ``\\\\`` as one ``gather*`` display."""
    return "\\begin{gather*}\n" + body + "\n\\end{gather*}\n"


def latex_document(sections: list[tuple[str, str]], fragment: bool = False) -> str:
    """``sections``: (heading as LaTeX, body as LaTeX) in order; a complete document unless ``fragment``."""
    body = "".join(f"\\section*{{{head}}}\n{text}" for head, text in sections)
    return body if fragment else PREAMBLE + body + "\\end{document}\n"


def run(args) -> int:
    loaded = c.load(args)
    core = _core_text(loaded)
    out: dict = {"core": core}
    program = loaded.program
    want_deriv = bool(args.wrt or args.dir)
    latex = args.latex or args.latex_fragment
    undefined: list[str] = []  # why an integral shown does not exist (then the exit status is 1)
    if program is not None and not args.core:
        params = c.param_values(args, loaded)
        direction = c.direction(args, loaded) if want_deriv else None
        with progress.phase("integrability analysis"):
            defined = (_defined.derivative(program, params, direction, loaded.texts()) if want_deriv
                       else _defined.value(program, params, loaded.texts()))  # X311 / X313
        defined.report(args.json)
        out["diagnostics"] = [d.to_json() for d in defined.diagnostics()]
        value_undefined = next((f for f in defined.findings if f.code == "X311" and f.severity == "error"), None)
        if defined.undefined:
            undefined.append(defined.undefined)
        with progress.phase("denotation ⟦p⟧"):
            out["denotation"] = exact.show_denotation(
                program, latex=latex, params=params, undefined=undefined,
                known_undefined=defined.undefined if value_undefined else None, raw=args.raw)
        if want_deriv:
            with progress.phase("derivative ⦇p⦈"):
                out["derivative"] = exact.show_derivative(program, direction, latex=latex, params=params,
                                                            undefined=undefined, known_undefined=defined.undefined,
                                                            raw=args.raw)
        if args.steps and want_deriv:
            with progress.phase("derivation steps"):
                trace, nf = steps.derivative_steps(program, direction, params)
                out["steps"] = steps.steps_text(trace, latex)
                out["sifting"] = steps.sifting(program, nf, params, latex) if not undefined else \
                    ["(not sifted: the integral does not exist)"]
    elif want_deriv and program is None:
        c.require_program(loaded, args.file)
    if args.steps and not want_deriv:
        raise UsageError("--steps shows the derivation of the derivative: give --wrt NAME or --dir NAME=VALUE")
    if args.typing:
        program_for_typing = c.require_program(loaded, args.file)
        trace, found = steps.typing_steps(program_for_typing, loaded.params)
        out["typing"] = steps.steps_text(trace, latex) + [
            ("\\text{well typed}" if latex else "well typed") if not found
            else f"{len(found)} rule(s) violated: " + "; ".join(d.code for d in found)]
    status = 1 if undefined else 0
    if args.json:
        c.dump_json(out)
        return status
    if latex:
        sections = [("Core term", "\\begin{verbatim}\n" + _ascii(core) + "\n\\end{verbatim}\n")]
        if "denotation" in out:
            sections.append(("Denotation $[\\![p]\\!]$ (Fig.~7, 12)", _math_block(out["denotation"])))
        if "typing" in out:
            sections.append(("Typing derivation (Fig.~6, 11)", _math_block("\\\\\n".join(out["typing"]))))
        if "steps" in out:
            sections.append(("Derivation of $(\\!|t|\\!)$ rule by rule (Fig.~8)", _math_block("\\\\\n".join(out["steps"]))))
        if "derivative" in out:
            sections.append(("Derivative $(\\!|p|\\!)$ (Theorem~7.1 normal form)", _math_block(out["derivative"])))
        if "sifting" in out:
            sections.append(("Sifting each delta through $\\hat\\Psi^{-1}$", _math_block("\\\\\n".join(out["sifting"]))))
        print(latex_document(sections, fragment=args.latex_fragment), end="")
        return status
    print("core:")
    print("  " + core.replace("\n", "\n  "))
    if "denotation" in out:
        print("denotation ⟦p⟧:")
        print("  " + out["denotation"].replace("\n", "\n  "))
    if "typing" in out:
        print("typing derivation (Fig. 6, 11):")
        print("  " + "\n".join(out["typing"]).replace("\n", "\n  "))
    if "steps" in out:
        print("derivation of ⦇t⦈ rule by rule (Fig. 8):")
        print("  " + "\n".join(out["steps"]).replace("\n", "\n  "))
    if "derivative" in out:
        print("derivative ⦇p⦈ (Theorem 7.1 normal form):")
        print("  " + out["derivative"].replace("\n", "\n  "))
    if "sifting" in out:
        print("sifting each delta through Ψ̂⁻¹ (change of variables u = Ψ̂(x)):")
        print("  " + "\n".join(out["sifting"]).replace("\n", "\n  "))
    return status
