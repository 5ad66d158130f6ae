"""``langur plot FILE --wrt NAME -o OUT.png``: the integrand and its derivative as pictures (CLI.md).

One variable: the four panels of paper Fig. 1 (matplotlib).  Two variables: the surfaces of
Fig. 9 — the integrand, the derivative with its delta ridge, standard AD — with pyvista
(``--kind surfaces``, the default), the same seen from above with the ridge coloured by its weight
(``--kind flat``), or Monte Carlo estimates against samples (``--kind convergence``); ``--kind
all`` writes the three, named after OUT.  The pictures are drawn by the ``viz`` package (the
``plot`` extra: ``pip install -e '.[plot]'``), from the engines' own numbers.
"""

from __future__ import annotations

import importlib
import os
import sys

from .. import progress
from ..cli import UsageError, add_common, add_timeout, seed
from . import _common as c
from ._outputs import inputs_of, picture_file, writing

KINDS = ("auto", "curves", "surfaces", "flat", "convergence", "all")
GREEK = {"alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "theta": "θ", "mu": "μ", "sigma": "σ",
         "lambda": "λ", "phi": "φ", "tau": "τ", "omega": "ω"}


def add_arguments(p):
    p.add_argument("file", metavar="FILE", help="a .lgr file with a program of one or two variables")
    p.add_argument("--wrt", metavar="NAME", help="differentiate with respect to this parameter")
    p.add_argument("--dir", action="append", metavar="NAME=VALUE", help="a direction γ' instead of --wrt")
    p.add_argument("-o", "--out", metavar="OUT.png", help="where to write the picture (default: FILE's name "
                   "with .png, in the current folder)")
    p.add_argument("--kind", choices=KINDS, default="auto",
                   help="curves (one variable), surfaces, flat or convergence (two variables), or all; "
                   "default: curves or surfaces")
    add_common(p, mc=False)
    p.add_argument("--seed", type=seed, default=0, metavar="S",
                   help="seed of the convergence plot, a non-negative integer")
    add_timeout(p, "plot", "for the whole command, in seconds")


def _viz():
    """The optional ``viz`` package (matplotlib, pyvista): a usage error when not installed."""
    try:
        return importlib.import_module("viz.geometry")
    except ImportError as e:
        raise UsageError(f"langur plot needs the plot extra ({e.name or e}): pip install -e '.[plot]'") from None


def _name(x: str) -> str:
    return GREEK.get(x, x)


def _outputs(args, kind: str, inputs: list[str]) -> list[tuple[str, str]]:
    """The pictures to write, each checked before any work (:func:`~langur.commands._outputs.output_file`)."""
    base = args.out or os.path.splitext(os.path.basename(args.file))[0] + ".png"
    stem, ext = os.path.splitext(base)  # a name without extension gets .png, as the drawing libraries add it
    if kind != "all":
        outs = [(kind, stem + (ext or ".png"))]
    else:
        outs = [(k, f"{stem}_{k}{ext or '.png'}") for k in ("surfaces", "flat", "convergence")]
    return [(k, picture_file(out, inputs, "-o", f"-o {out}: refusing to write a picture over a program"))
            for k, out in outs]


def run(args) -> int:
    loaded = c.load(args)
    program = c.require_program(loaded, args.file)
    n = len(program.variables)
    if n > 2:
        raise UsageError(f"{args.file}: langur plot draws programs of one or two variables; this one has {n} "
                         f"({', '.join(program.variables)})")
    params = {k: float(v) for k, v in c.param_values(args, loaded).items()}
    direction = c.direction(args, loaded)
    kind = args.kind if args.kind != "auto" else ("curves" if n == 1 else "surfaces")
    if (kind == "curves") != (n == 1):
        raise UsageError(f"--kind {kind} is for {'one' if kind == 'curves' else 'two'}-variable programs; "
                         f"{args.file} has {n}")
    outputs = _outputs(args, kind, inputs_of(args, loaded))
    geometry = _viz()
    wrt = ", ".join(_name(k) for k, v in direction.items() if v) or "γ'"
    where = ", ".join(f"{_name(k)} = {v:g}" for k, v in params.items()) or "no parameters"
    title = f"{args.file} at {where}"
    with progress.phase("exact engine (sympy)"):
        s = geometry.scene(program, params, direction)
    written = []
    for k, out in outputs:
        with progress.phase(f"drawing {k}"), writing(out, "-o"):
            if k == "curves":
                importlib.import_module("viz.curves").save(s, out, title, wrt)
            elif k == "surfaces":
                importlib.import_module("viz.surfaces").render(s, out, title, wrt)
            elif k == "flat":
                importlib.import_module("viz.flat").flat(s, out, title, wrt)
            else:
                importlib.import_module("viz.flat").convergence(s, loaded, out, f"{title}: Monte Carlo", wrt,
                                                                seed=args.seed)
        written.append(out)
    if args.json:
        c.dump_json({"written": written, "value": s.value, "derivative": s.derivative,
                     "standard_ad": s.standard_ad, "boundary": s.boundary})
    else:
        for out in written:
            print(out)
    sys.stdout.flush()
    return 0
