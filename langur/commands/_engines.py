"""Calling the two engines from the CLI, with failures of one engine reported, not fatal."""

from __future__ import annotations

import sys

from .. import failures, progress
from .. import typesys as ty
from ..cli import UsageError
from ..core import Const, IfDiffeo, ImplicitRoot, TooManyRoots, subterms
from ..diagnostics import LangurError

ENGINE_CHOICES = ["both", "exact", "mc"]


def add_engine_arguments(p) -> None:
    """The options eval and deriv share: Monte Carlo sampling and which engines run."""
    p.add_argument("--method", choices=["uniform", "stratified", "qmc"], default="uniform",
                   help="Monte Carlo sampling (default uniform)")
    p.add_argument("--engine", default="both", metavar="NAME",
                   help="which engines to run: both (default), exact or mc; or any other engine — "
                   "standard-ad, module:function, cmd:PROGRAM, an installed plug-in — to compare "
                   "with the exact engine (docs/engines.md)")


def named_engine(args):
    """The engine ``--engine NAME`` names when it is not one of both/exact/mc (None then)."""
    if args.engine in ENGINE_CHOICES:
        return None
    from ..engines import UnknownEngine, resolve  # the engines (and sympy) only when one is named

    try:
        return resolve(args.engine, samples=args.samples, seed=args.seed, method=args.method,
                       timeout=min(float(args.timeout), 600.0))
    except UnknownEngine as e:
        raise UsageError(str(e)) from None


def compare_named(engine, ask, reference) -> tuple[dict, int]:
    """Ask ``engine`` (``ask(engine)`` returns its answer) and compare with the exact engine's
    ``reference`` (an ExactValue/ExactDerivative, or None): the ``engine`` object of the JSON output
    and the exit status (1 when it disagrees or fails)."""
    from ..engines import Answer, Declined, EngineFailure, agree, deviation

    out = {"name": engine.name}
    try:
        with progress.phase(f"engine {engine.name}"):
            answer = ask(engine)
    except EngineFailure as e:
        return {**out, "failure": str(e)}, 1
    out["kind"] = str(engine.kind)
    if isinstance(answer, Declined):
        return {**out, "declined": answer.reason}, 0
    out.update(value=answer.value, error=answer.error)
    if reference is None:
        return out, 0
    ref = Answer(reference.value, reference.error or 0.0)
    ok = agree(engine.kind, ref, answer)
    out.update(agrees=ok, deviation=deviation(engine.kind, ref, answer))
    return out, 0 if ok else 1


def print_named(report: dict, label_width: int) -> None:
    name = report["name"]
    head = f"  {name:<{label_width}}: "
    if "failure" in report:
        print(f"{head}FAILED: {report['failure']}")
    elif "declined" in report:
        print(f"{head}declined: {report['declined']}")
    else:
        unit = {"stochastic": "SE", "bounded": "bounds"}.get(report["kind"], "")
        err = f" ± {report['error']:.3g}" if report["error"] else ""
        verdict = ""
        if "agrees" in report:
            off = report["deviation"]
            how = "equal" if off == 0 else (f"{off:.2g} {unit} off" if unit and off != float("inf") else "differs")
            verdict = f"; {'agrees with' if report['agrees'] else 'DISAGREES with'} exact ({how})"
        print(f"{head}{report['value']:.10g}{err}   ({report['kind']}{verdict})")


class Undefined(str):
    """Why the exact engine says the integral does not exist (divergent, or undefined on part of
    the domain): an answer, printed as such, with exit status 1."""


def say_undefined(kind: str, reason: str) -> None:
    """With ``--json``, why ``exact`` is null: one line on standard error (CLI.md, JSON shapes; the
    text output prints it in its ``exact`` line)."""
    print(f"langur {kind}: no exact value: undefined: {' '.join(reason.split())}", file=sys.stderr)


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
    except TooManyRoots as e:  # moving turning points beyond the split, or not certified (issue 18)
        print(_too_many_roots(kind, "exact", e, program), file=sys.stderr)
        return None, 0
    except api.ExactUnavailable as e:  # no value, in the engine's words (values too large for a float, …)
        print(f"langur {kind}: no exact value: {e.reason}", file=sys.stderr)
        return None, 0
    except LangurError as e:  # a bound of the exact engine's (T234): located, the other engine still runs
        print(f"{e}\nlangur {kind}: no exact value (the error above)", file=sys.stderr)
        return None, 0
    except Exception as e:  # noqa: BLE001 - reported, the other engine still runs
        print(f"langur {kind}: no exact value: {failures.why(e)}", file=sys.stderr)
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
    except TooManyRoots as e:  # a condition split for fewer turning points than it has here (issue 18)
        print(_too_many_roots(kind, "Monte Carlo", e, getattr(loaded, "program", loaded)), file=sys.stderr)
        return None


def _too_many_roots(kind: str, engine: str, e: TooManyRoots, program) -> str:
    """X316 at the condition (where the engine says, else the first condition split at moving
    turning points), else the command's own line."""
    span = e.span or next((t.span for t in subterms(getattr(program, "body", None) or Const(0))
                           if isinstance(t, IfDiffeo) and _moving(t.psi)), None)
    if span is None:
        return f"langur {kind}: no {engine} value: {e}"
    return ty.diag(span, "X316", f"no {engine} value: {e}").format()


def _moving(psi) -> bool:
    """Is ``psi`` split at turning points that move with the parameters (indexed implicit roots)?"""
    return any(isinstance(u, ImplicitRoot) and u.index is not None
               for b in psi.branches for c in b.components for u in subterms(c))
