"""``langur eval FILE``: the program's value, exact (symbolic, §6/§8) and Monte Carlo (operational, §9)."""

from __future__ import annotations

import sys

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
    add_common(p, mc=True)
    add_timeout(p, "eval", "for the whole command, in seconds")
    add_engine_arguments(p)


def run(args) -> int:
    loaded = c.load(args)
    program = c.require_program(loaded, args.file)
    params = c.param_values(args, loaded)
    status = 0
    exact = mc = named = None
    engine = named_engine(args)
    program, recompleted = _defined.completed_here(program, params)  # a completion degenerate here
    target = program if recompleted else loaded
    with progress.phase("integrability analysis"):
        defined = _defined.value(program, params, loaded.texts())  # X311: does ⟦p⟧ exist?
    defined.report(args.json)
    undefined = defined.undefined
    if undefined is not None:
        status = 1
    elif args.engine in ("both", "exact") or engine is not None:
        exact, status = run_exact("eval", program, params)
        if isinstance(exact, Undefined):
            undefined, exact = str(exact), None
    if engine is not None:  # another engine, compared with the exact one (docs/engines.md)
        floats = {k: float(v) for k, v in params.items()}
        named, bad = compare_named(engine, lambda e: e.value(program, floats), exact)
        status = max(status, bad)
    if args.engine in ("both", "mc"):
        mc = run_mc("eval", target, params, args,
                    infinite_variance=defined.infinite_variance or (undefined and "the integral does not exist"))
        if mc is None and args.engine == "mc":
            status = 1
    if undefined is None and exact is None and mc is None and named is None:  # no engine asked for gave a number
        status = 1
    if args.json:
        if undefined is not None:
            say_undefined("eval", undefined)
        c.dump_json({"params": params, "exact": exact.to_json() if exact is not None else None,
                     "mc": mc.to_json() if mc is not None else None, "undefined": undefined,
                     **({"engine": named} if named is not None else {}), "recompleted": list(recompleted),
                     "diagnostics": [d.to_json() for d in defined.diagnostics()]})
        return status
    print(f"{args.file}: value at {c.fmt_params(params)}")
    for note in recompleted:
        print(f"  note  : {note}")
    if undefined is not None:
        print(f"  exact : undefined: {undefined}")
    if exact is not None:
        print(f"  exact : {c.fmt(exact.value)}   ({exact.how()}{': ' + exact.expr if exact.expr else ''})")
        for note in exact.notes:
            print(f"          note: {c.readable_note(note)}")
    if mc is not None:
        print(f"  MC    : {c.fmt_mc(mc.value, mc.stderr)} ± {c.fmt_se(mc.stderr, mc.value)}   "
              f"({mc.samples} samples, {mc.method}, seed {mc.seed})")
        print_mc_notes(mc, "          ")
    if exact is not None and mc is not None:
        print("  agree : " + c.agreement(exact.value, exact.error, mc.value, mc.stderr, mc.all_zero))
    if named is not None:
        print_named(named, 6)
    sys.stdout.flush()
    return status
