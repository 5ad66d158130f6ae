"""Plumbing shared by the subcommands: loading FILE, parameter values, directions, JSON output."""

from __future__ import annotations

import math
import os
import sys
from fractions import Fraction

# numpy before the front end, three imports deep rather than six (issue 15, one-shot start-up): numpy's
# own import nests some sixty Python frames, and begun under the front end's chain of imports
# (frontend → typesys → primitives) its typing stubs ran where CPython's frame stack needs a second
# 16 kB chunk, mapped and unmapped again some two hundred times (≈ 400 page faults of a one-shot
# ``langur eval``).  Every command that loads a program needs numpy.
import numpy  # noqa: F401

from .. import frontend, lazy, progress
from ..cli import UsageError, parse_assignments, parse_modules, refuse_unimported_modules
from ..source import read_file, read_source

#: json only for ``--json`` output (as in :mod:`langur.cli`).
json = lazy.module("json")


def load(args, path: str | None = None):
    """Load FILE (``-`` is standard input) with the ``--module`` overrides; LangurError propagates."""

    path = path if path is not None else args.file
    modules = parse_modules(getattr(args, "module", None))
    if path == "-":
        path, data = "<stdin>", read_source(sys.stdin.buffer, "<stdin>")
    elif not os.path.lexists(path):
        raise UsageError(f"{path}: no such file")
    elif os.path.isdir(path):
        raise UsageError(f"{path}: is a directory")
    else:
        try:
            data = read_file(path)  # (a named pipe: waited for within the command's --timeout)
        except OSError as e:  # as for a missing file: status 2 (langur check reports it as E109)
            raise UsageError(f"{path}: cannot read this file ({e.strerror or type(e).__name__})") from None
    with progress.phase("reading and type-checking"):
        loaded = frontend.load_bytes(data, path, modules=modules)
    refuse_unimported_modules(modules, [(path, loaded)])
    return loaded


def require_program(loaded, path: str):
    if loaded.program is None:
        raise UsageError(f"{path}: the module has no program (`int … d(…)`) to evaluate")
    return loaded.program


def param_values(args, loaded) -> dict[str, Fraction | float]:
    """Defaults overridden by ``--at``; unknown or missing parameters are usage errors."""
    at = parse_assignments(getattr(args, "at", None), "--at")
    unknown = sorted(set(at) - set(loaded.params))
    if unknown:
        declared = ", ".join(loaded.params) or "none"
        raise UsageError(f"--at {unknown[0]}: no such parameter (declared: {declared})")
    exact = {k: Fraction(str(v)) if math.isfinite(v) else v for k, v in at.items()}  # 0.1 stays 1/10
    try:
        return loaded.param_values(exact)
    except KeyError as e:
        name = e.args[0]
        raise UsageError(f"parameter {name} has no default: give it with --at {name}=VALUE") from None


def direction(args, loaded) -> dict[str, float]:
    """``--wrt NAME`` is the unit vector e_NAME; ``--dir a=1,b=0.5`` an arbitrary γ'."""
    wrt = getattr(args, "wrt", None)
    dirs = getattr(args, "dir", None)
    if wrt and dirs:
        raise UsageError("give either --wrt NAME or --dir NAME=VALUE,…, not both")
    if wrt:
        if wrt not in loaded.params:
            declared = ", ".join(loaded.params) or "none"
            raise UsageError(f"--wrt {wrt}: no such parameter (declared: {declared})")
        return {name: (1.0 if name == wrt else 0.0) for name in loaded.params}
    if dirs:
        d = parse_assignments(dirs, "--dir")
        unknown = sorted(set(d) - set(loaded.params))
        if unknown:
            raise UsageError(f"--dir {unknown[0]}: no such parameter")
        return {name: d.get(name, 0.0) for name in loaded.params}
    if len(loaded.params) == 1:
        (only,) = loaded.params
        return {only: 1.0}
    raise UsageError("which derivative? give --wrt NAME or --dir NAME=VALUE,…")


def jsonable(v):
    """JSON numbers, with NaN and infinities as the strings "nan", "inf", "-inf" (CLI.md)."""
    if isinstance(v, dict):
        return {str(k): jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [jsonable(x) for x in v]
    if isinstance(v, bool) or v is None or isinstance(v, str):
        return v
    if isinstance(v, (int, Fraction)):
        return float(v) if isinstance(v, Fraction) else v
    try:
        f = float(v)
    except (TypeError, ValueError):
        return str(v)
    if math.isnan(f):
        return "nan"
    if math.isinf(f):
        return "inf" if f > 0 else "-inf"
    return f


def dump_json(obj) -> None:
    print(json.dumps(jsonable(obj)))


def fmt(v, digits: int = 10) -> str:
    try:
        f = float(v)
    except (TypeError, ValueError):
        return str(v)
    if math.isnan(f) or math.isinf(f):
        return str(f)
    return f"{f:.{digits}g}"


#: The longest note the text output prints whole (a note can hold an inverse branch or det DΨ̂⁻¹ of
#: thousands of characters: the lambert shader's, bench/history/2026-11-29.md#budget33.
NOTE_CHARS = 400
#: How much of a longer note's end is kept (where it says what was decided: "taken as +", "(heuristic)").
NOTE_TAIL = 80


def readable_note(note: str) -> str:
    """``note`` as the text output prints it: whole up to :data:`NOTE_CHARS` characters, else its
    beginning and its last :data:`NOTE_TAIL` characters around how much was left out and where the
    whole note is (``--json``, whose ``notes`` are never shortened)."""
    if len(note) <= NOTE_CHARS:
        return note
    head = NOTE_CHARS - NOTE_TAIL
    return (f"{note[:head]} … [{len(note) - head - NOTE_TAIL} characters left out; the whole note: --json] … "
            f"{note[-NOTE_TAIL:]}")


def fmt_params(values: dict) -> str:
    return ", ".join(f"{k} = {fmt(v)}" for k, v in values.items()) or "no parameters"


def mc_decimals(stderr) -> int | None:
    """Decimal places that show a Monte Carlo estimate to its precision: its standard error to two
    significant digits (None when the error is 0 or not finite: then the value is exact or unknown)."""
    try:
        se = float(stderr)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(se) or se <= 0:
        return None
    return max(0, 1 - math.floor(math.log10(se)))


#: Beyond these, an estimate and its standard error are written in scientific notation (a value of
#: 3·10⁻⁷³ with ~70 zeros, or 20 digits of which the last 15 are noise, say less in more space).
FIXED_DECIMALS, FIXED_DIGITS = 8, 10


def scientific(value: float, stderr: float) -> bool:
    """Whether :func:`fmt_mc` writes ``value ± stderr`` in scientific notation."""
    d = mc_decimals(stderr)
    return d is not None and math.isfinite(value) and (d > FIXED_DECIMALS or abs(value) >= 10.0 ** FIXED_DIGITS)


def fmt_mc(value, stderr, decimals: int | None = None) -> str:
    """``value`` rounded to the place of its standard error's second significant digit
    (``3.992 ± 0.031``, not ``3.992450112 ± 0.0305``); in scientific notation when that place is
    far from the decimal point (``2.91e-73 ± 2.4e-74``)."""
    d = mc_decimals(stderr) if decimals is None else decimals
    if d is None:
        return fmt(value)
    try:
        f = float(value)
    except (TypeError, ValueError):
        return str(value)
    if decimals is None and scientific(f, float(stderr)):
        digits = math.floor(math.log10(abs(f))) - math.floor(math.log10(float(stderr))) + 1 if f else 0
        return f"{f:.{max(0, digits)}e}"
    return f"{f:.{d}f}" if math.isfinite(f) else str(f)


def fmt_se(stderr, value=None) -> str:
    """The standard error to two significant digits, written like :func:`fmt_mc` writes ``value``."""
    d = mc_decimals(stderr)
    if d is None:
        return fmt(stderr, 3)
    if value is not None and scientific(float(value), float(stderr)):
        return f"{float(stderr):.1e}"
    return f"{float(stderr):.{d}f}"


#: Engines agree when the Monte Carlo estimate is within this many standard errors of the exact value.
AGREE_SE = 5.0


def agreement(exact_value, exact_error, mc_value, mc_stderr, all_zero: bool = False) -> str:
    """One line: do the exact and Monte Carlo engines agree, and by how many standard errors;
    ``all_zero``: every Monte Carlo sample was 0 (its standard error 0 bounds nothing, so an
    agreement is no evidence: bench/history/2026-11-29.md#exact32."""
    diff = abs(float(exact_value) - float(mc_value))
    slack = float(exact_error or 0.0) + 1e-12 * (1 + abs(float(exact_value)))
    se = float(mc_stderr)
    if not math.isfinite(diff) or not math.isfinite(se):
        which = [w for w, v in (("exact value", exact_value), ("Monte Carlo value", mc_value))
                 if not math.isfinite(float(v))] or ["Monte Carlo standard error"]
        return f"engines not compared (the {' and the '.join(which)} {'is' if len(which) == 1 else 'are'} not finite)"
    if se <= 0:
        ok = diff <= slack
        why = (f"every MC sample was 0: {'consistent, not evidence' if ok else 'MC saw none of the mass'};"
               if all_zero else "MC SE = 0,")  # (an SE of 0 from all-zero samples bounds nothing)
        return (f"engines {'agree' if ok else 'DISAGREE'}: |exact − MC| = {diff:.2g} "
                f"({why[:-1]}{why[-1] + ' exact ± ' + format(float(exact_error), '.2g') if exact_error else ''})")
    k = max(0.0, diff - slack) / se
    ok = k <= AGREE_SE
    return (f"engines {'agree' if ok else 'DISAGREE'}: |exact − MC| = {diff / se:.1f} SE"
            + ("" if ok else f" (more than {AGREE_SE:g})")
            + (f"; exact ± {float(exact_error):.2g}" if exact_error else ""))
