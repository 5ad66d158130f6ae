"""Calling the two engines from the CLI, with failures of one engine reported, not fatal."""

from __future__ import annotations

import sys

from .. import progress
from .. import typesys as ty

ENGINE_CHOICES = ["both", "exact", "mc"]


def add_engine_arguments(p) -> None:
    """The options eval and deriv share: Monte Carlo sampling and which engines run."""
    p.add_argument("--method", choices=["uniform", "stratified", "qmc"], default="uniform",
                   help="Monte Carlo sampling (default uniform)")
    p.add_argument("--engine", choices=ENGINE_CHOICES, default="both",
                   help="which engines to run (default both)")


class Undefined(str):
    """Why the exact engine says the integral does not exist (divergent, or undefined on part of
    the domain): an answer, printed as such, with exit status 1."""


def run_exact(kind: str, program, params, direction=None, *, theorem: bool = True):
    """The symbolic reference's answer as CLI.md's ``exact`` object, or ``(None, status)``, or
    ``(Undefined(reason), 1)`` when the integral does not exist.

    ``exact`` is null, with a one-line reason on standard error, only where neither the closed
    form nor quadrature works.  A closed form that disagrees with its quadrature cross-check is
    never returned: the engine reports the quadrature, with a note saying so.
    """
    from .. import exact as api

    try:
        with progress.phase("exact engine (sympy)"):
            if kind == "eval":
                return api.exact_eval(program, params), 0
            return api.exact_deriv(program, params, direction, check=theorem), 0
    except api.ExactUndefined as e:
        return Undefined(str(e).removeprefix("undefined: ")), 1
    except Exception as e:  # noqa: BLE001 - reported, the other engine still runs
        print(f"langur {kind}: no exact value: {type(e).__name__}: {e}", file=sys.stderr)
        return None, 0


def print_mc_notes(mc, indent: str) -> None:
    """The Monte Carlo result's notes (no finite variance, a heavy tail, non-finite samples)."""
    for note in mc.notes:
        print(f"{indent}note: {note}")


def run_mc(kind: str, loaded, params, args, direction=None, *, infinite_variance: str | None = None):
    from .. import operational

    values = {k: float(v) for k, v in params.items()}
    kw = dict(samples=args.samples, seed=args.seed, method=args.method, infinite_variance=infinite_variance)
    try:
        with progress.phase(f"Monte Carlo engine ({args.samples:,} samples)"):
            if kind == "eval":
                return operational.estimate_value(loaded, values, **kw)
            return operational.estimate_derivative(loaded, values, {k: float(v) for k, v in direction.items()},
                                                   **kw)
    except operational.TooLarge as e:  # located, and the exact engine's answer still stands
        print(ty.reject_too_large(e.span, str(e)).format(), file=sys.stderr)
        return None
