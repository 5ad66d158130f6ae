"""``langur deriv FILE --wrt NAME``: ⦇p⦈ exact and by Monte Carlo, standard AD, and Theorem 8.1."""

from __future__ import annotations

import math
import sys
from dataclasses import replace

from .. import progress
from ..cli import add_common, add_timeout
from . import _common as c
from . import _defined
from ._engines import (
    Undefined,
    add_engine_arguments,
    compare_named,
    named_engine,
    print_mc_notes,
    print_named,
    run_exact,
    run_mc,
    say_undefined,
)


def add_arguments(p):
    p.add_argument("file", metavar="FILE", help="a .lgr file with a program (- reads standard input)")
    p.add_argument("--wrt", metavar="NAME", help="differentiate with respect to this parameter")
    p.add_argument("--dir", action="append", metavar="NAME=VALUE",
                   help="a direction γ' instead of --wrt (repeatable, or comma-separated)")
    add_common(p, mc=True)
    add_timeout(p, "deriv", "for the whole command, in seconds")
    add_engine_arguments(p)
    p.add_argument("--rewrite", action="store_true",
                   help="differentiate the transverse rewrite (paper §7.3.2) of a program that is not "
                        "transverse (X301), which has no derivative as written")
    p.add_argument("--no-theorem", action="store_true",
                   help="skip the Theorem 8.1 check (it re-evaluates ⦇p⦈ at nearby parameters when the "
                        "closed form cannot be differentiated symbolically)")


def run(args) -> int:
    loaded = c.load(args)
    program = c.require_program(loaded, args.file)
    params = c.param_values(args, loaded)
    direction = c.direction(args, loaded)
    status = 0
    exact = mc = theorem = named = None
    standard_ad = None
    engine = named_engine(args)
    gate = _defined.transversal(loaded, args.file, params)  # X301: is ⦇p⦈ the derivative at all? X305: here?
    rewrite = gate.shown if gate.findings else None
    if gate.findings and not args.rewrite:
        return _not_transverse(args, gate, params, direction, loaded.program, engine)
    target = loaded
    if gate.findings:  # --rewrite: differentiate the transverse program instead
        program = target = gate.rewritten
    program, recompleted = _defined.completed_here(program, params)  # a completion degenerate here
    if recompleted:
        target = program
    with progress.phase("integrability analysis"):
        defined = _defined.derivative(program, params, direction, loaded.texts())  # X311 / X313
    here = bool(gate.here) and not gate.findings  # X305: ⦇p⦈ is not defined at these parameter values
    sides = None  # … is ⟦p⟧ differentiable there all the same?
    if here:
        defined.findings = gate.here + defined.findings
        if defined.undefined is None and args.engine in ("both", "exact"):
            with progress.phase("one-sided derivatives of ⟦p⟧"):
                sides = _defined.onesided.one_sided(program, params, direction)
    elif defined.undefined is not None and defined.value_exists and args.engine in ("both", "exact"):
        # X313: ⦇p⦈ is not an integral, but ⟦p⟧ is (∫₀¹ |x − a|^(-1/2) dx = 2√a + 2√(1 − a)): it may
        # still be differentiable, which Theorem 8.1 cannot say and ⟦p⟧'s closed form can
        with progress.phase("one-sided derivatives of ⟦p⟧"):
            sides = _defined.onesided.one_sided(program, params, direction)
    defined.report(args.json)
    integral_undefined = defined.undefined  # X311/X313: the integral itself does not exist
    if integral_undefined is not None and sides is not None:
        integral_undefined += "; " + sides.text("⦇p⦈ is not an integral (Theorem 8.1 needs one)")
    undefined = integral_undefined or gate.undefined_here(sides)
    if undefined is not None:
        status = 1
    elif args.engine in ("both", "exact") or engine is not None:
        result, status = run_exact("deriv", program, params, direction, theorem=not args.no_theorem)
        if isinstance(result, Undefined):
            undefined, result = str(result), None
        if result is not None:
            exact, theorem = result, result.theorem_8_1
            standard_ad = {"value": result.standard_ad, "stderr": 0.0, "source": "exact"}
    if engine is not None:  # another engine, compared with the exact one (docs/engines.md)
        named, bad = _ask(engine, program, params, direction, exact)
        status = max(status, bad)
    if args.engine in ("both", "mc"):
        mc = run_mc("deriv", target, params, args, direction,
                    infinite_variance=defined.infinite_variance or (integral_undefined and "the derivative does not exist"))
        if mc is not None and here and integral_undefined is None and not math.isnan(mc.value):
            mc = replace(mc, notes=("⦇p⦈'s estimate, which is not the derivative at these parameter values (X305)",
                                    *mc.notes))
        if mc is None and args.engine == "mc":
            status = 1
        if mc is not None:
            standard_ad = {**mc.standard_ad.to_json(), "source": "mc"}
    if undefined is None and exact is None and mc is None and named is None:  # no engine asked for gave a number
        status = 1
    if args.json:
        if undefined is not None:
            say_undefined("deriv", undefined)
        c.dump_json({"params": params, "direction": direction, "exact": exact.to_json() if exact else None,
                     "mc": mc.to_json(standard_ad=False) if mc is not None else None,
                     "standard_ad": standard_ad, "theorem_8_1": theorem.to_json() if theorem else None,
                     "undefined": undefined, "one_sided": sides.to_json() if sides is not None else None,
                     "diagnostics": [d.to_json() for d in defined.diagnostics()], "rewrite": rewrite,
                     "recompleted": list(recompleted),
                     **({"engine": named} if named is not None else {})})
        return status
    print(f"{args.file}: {_what(direction)} at {c.fmt_params(params)}")
    if rewrite is not None:
        print("  (of the transverse rewrite, paper §7.3.2; the program as written has no derivative: X301)")
        print("    " + rewrite.rstrip("\n").replace("\n", "\n    "))
    for note in recompleted:
        print(f"  note        : {note}")
    if undefined is not None:
        print(f"  exact       : undefined: {undefined}")
    if exact is not None:
        print(f"  exact       : {c.fmt(exact.value)} = regular {c.fmt(exact.regular)}"
              f" + boundary {c.fmt(exact.boundary)}   ({exact.how()}{': ' + exact.expr if exact.expr else ''})")
        for note in exact.notes:
            print(f"                note: {c.readable_note(note)}")
    if mc is not None:
        d = None if c.scientific(mc.value, mc.stderr) else c.mc_decimals(mc.stderr)
        print(f"  MC          : {c.fmt_mc(mc.value, mc.stderr)} ± {c.fmt_se(mc.stderr, mc.value)} = regular "
              f"{c.fmt_mc(mc.regular.value, mc.stderr, d)} + boundary {c.fmt_mc(mc.boundary.value, mc.stderr, d)}   "
              f"({mc.samples} samples, {mc.method}, seed {mc.seed})")
        print_mc_notes(mc, "                ")
    if exact is not None and mc is not None:
        print("  agree       : " + c.agreement(exact.value, exact.error, mc.value, mc.stderr, mc.all_zero))
    if standard_ad is not None:
        print(f"  standard AD : {c.fmt_mc(standard_ad['value'], standard_ad['stderr'])} ± "
              f"{c.fmt_se(standard_ad['stderr'], standard_ad['value'])}"
              "   (deltas dropped: what PyTorch or JAX compute on the discretized integral)")
    if named is not None:
        print_named(named, 12)
    if theorem is not None:
        verdict = {True: "holds", False: "FAILS", None: "inconclusive"}[theorem.holds]
        how = "; ".join(filter(None, [theorem.compared(),
                                      "run `langur check` for transversality" if theorem.holds is False else ""]))
        print(f"  Theorem 8.1 : {verdict}: {theorem.left_side()}, ⦇p⦈ = {c.fmt(theorem.derivative_denotation)}"
              + (f"   ({how})" if how else ""))
        if theorem.reason() is not None:
            print(f"                note: {theorem.reason()}")
    return status


def _ask(engine, program, params, direction, reference):
    """The named engine's derivative of ``program``, compared with ``reference`` (docs/engines.md)."""
    floats = {k: float(v) for k, v in params.items()}
    dirs = {k: float(v) for k, v in direction.items()}
    return compare_named(engine, lambda e: e.derivative(program, floats, dirs), reference)


def _what(direction) -> str:
    wrt = [k for k, v in direction.items() if v]
    if len(wrt) == 1 and direction[wrt[0]] == 1:
        return f"d/d{wrt[0]}"
    return "derivative in direction " + ", ".join(f"{k}'={c.fmt(v)}" for k, v in direction.items() if v)


def _not_transverse(args, gate, params, direction, program, engine) -> int:
    """X301: no number is presented as ⦇p⦈; the rewrite is shown (Def. 7.2, §7.3).  A named engine
    (``--engine``) is still asked about the program as written, and compared with the derivative of
    ⟦p⟧, which the transverse rewrite has too (same ⟦p⟧): an engine that counts the jump twice, or
    drops it (Teg's 0 for d/dt ∫₀¹[x<t]²), disagrees."""
    named = reference = None
    if engine is not None:
        reference, _ = run_exact("deriv", gate.rewritten, params, direction, theorem=False)
        if isinstance(reference, Undefined):
            reference = None
        named, _ = _ask(engine, program, params, direction, reference)
    if args.json:
        say_undefined("deriv", gate.reason())
        c.dump_json({"params": params, "direction": direction, "exact": None, "mc": None, "standard_ad": None,
                     "theorem_8_1": None, "undefined": gate.reason(), "rewrite": gate.shown,
                     "diagnostics": [f.diagnostic().to_json() for f in gate.findings],
                     **({"engine": named, "rewrite_derivative": reference.value if reference else None}
                        if named is not None else {})})
        return 1
    for f in gate.findings:
        print(f.diagnostic().format(), file=sys.stderr)
    print(f"{args.file}: {_what(direction)} at {c.fmt_params(params)}")
    print(f"  exact       : not defined: {gate.reason()}")
    print("  rewrite     : the transverse program of paper §7.3.2 (same value ⟦p⟧); "
          "`langur deriv --rewrite` differentiates it, `langur check --fix` writes it:")
    print("    " + gate.shown.rstrip("\n").replace("\n", "\n    "))
    if named is not None:
        if reference is not None:
            print(f"  D⟦p⟧        : {c.fmt(reference.value)}   (the rewrite's ⦇p⦈: it has the same ⟦p⟧; "
                  f"{named['name']} is asked about the program as written)")
        print_named(named, 12)
    return 1
