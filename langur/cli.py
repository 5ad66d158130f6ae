"""The ``langur`` command (the command reference: ``docs/``).

Each subcommand lives in ``langur/commands/<name>.py`` with ``add_arguments(parser)`` and
``run(args) -> int``.  This module parses the command line, sets up the common options, and turns
every :class:`~langur.diagnostics.LangurError` into ``PATH:LINE:COL: error CODE message`` lines and
exit status 1.  Usage errors exit 2, with one line saying what is wrong: every option is validated
here or by its command (counts and seeds in range, parameter values finite) before any work is
done.  Exit statuses are 0, 1 and 2 only (``docs/commands.md``).  A traceback is a bug: an
unexpected exception is reported in one line as an internal error, status 1 (set
``LANGUR_DEBUG=1`` to see the traceback).  Numeric warnings (numpy's "divide by zero", scipy's)
that reach this level are collected and printed as one note, never as raw warning lines.
"""

from __future__ import annotations

import gc
import importlib
import math
import os
import sys
import warnings
from collections import Counter
from typing import TYPE_CHECKING

from . import __version__, gcpause, lazy, progress
from .arguments import Arguments
from .diagnostics import LangurError
from .timebox import run_with_timeout

if TYPE_CHECKING:
    from .modules import Loaded

#: argparse only when a command line is not plain (help, usage errors, …): a plain one is read by
#: :class:`~langur.arguments.Arguments` (issue 15, start-up: argparse with gettext and locale, 16 M
#: instructions of a one-shot ``langur eval``).
argparse = lazy.module("argparse")
cliparser = lazy.module("langur.cliparser")
#: json only for ``--json`` output (start-up: its encoder, decoder and scanner are ≈ 3 M instructions and
#: 46 kB of compiled code a one-shot ``langur eval`` without ``--json`` never calls).
json = lazy.module("json")

COMMANDS = {
    "check": "parse, type-check and lint for transversality",
    "show": "the core term after desugaring, its denotation, and its derivative (--wrt)",
    "eval": "the program's value: exact (symbolic) and Monte Carlo (operational)",
    "deriv": "the derivative: exact, Monte Carlo, standard AD, and the Theorem 8.1 check",
    "plot": "the integrand and its derivative as a picture",
    "render": "a program over a grid of two parameters, as an image (value, derivative, standard AD)",
    "fuzz": "differential testing of the two engines on random programs",
    "reproduce": "the paper's examples and figures, each with its numbers checked",
}


class UsageError(Exception):
    """Bad command line: exit status 2."""


#: Most Monte Carlo samples a command accepts.  Every sample is evaluated in one vectorized numpy
#: pass, so memory grows as samples × the size of the program: 10⁶ samples of the paper's programs
#: take 100–200 MB, 10⁷ about 1–2 GB.  Beyond that, average runs with different seeds.
MAX_SAMPLES = 10_000_000
#: Seeds are non-negative integers below 2⁶⁴ (numpy's SeedSequence, hypothesis).
MAX_SEED = 2**64 - 1


def count(low: int, high: int, what: str = "a count"):
    """An argparse type: an integer in [low, high], refused with one line otherwise."""

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r} is not an integer") from None
        if not low <= n <= high:
            raise argparse.ArgumentTypeError(f"{what} must be between {low:,} and {high:,}, got {n:,}")
        return n

    return parse


def samples(low: int = 2):
    """``--samples N``: at least ``low`` (a standard error needs two samples), at most
    :data:`MAX_SAMPLES` (refused before anything is allocated)."""
    return count(low, MAX_SAMPLES, f"the number of samples (a standard error needs {low} or more; "
                 "memory grows with it)")


seed = count(0, MAX_SEED, "a seed")

#: Longest ``--timeout`` accepted (a day).
MAX_TIMEOUT = 86_400.0
#: The default time budget of ``show``, ``eval`` and ``deriv`` (the whole command) and of
#: ``check`` (each file: a budget that suits a CI job).
DEFAULT_TIMEOUT = {"show": 600.0, "eval": 600.0, "deriv": 600.0, "plot": 600.0, "render": 600.0, "check": 60.0}


def seconds(text: str) -> float:
    """``--timeout SECONDS``: a positive, finite number of seconds, at most a day."""
    try:
        t = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of seconds") from None
    if not (math.isfinite(t) and 0 < t <= MAX_TIMEOUT):
        raise argparse.ArgumentTypeError(f"the time limit must be a positive number of seconds, at most "
                                         f"{MAX_TIMEOUT:g}, got {text}")
    return t


def add_timeout(p: argparse.ArgumentParser, command: str, per: str) -> None:
    default = DEFAULT_TIMEOUT[command]
    p.add_argument("--timeout", type=seconds, default=default, metavar="SECONDS",
                   help=f"time budget {per} (default {default:g}): past it the command stops with a "
                   "message and exit status 1, never a hang")


def parse_assignments(values: list[str] | None, what: str) -> dict[str, float]:
    """``--at a=-1,b=4 --at c=2`` → ``{"a": -1.0, "b": 4.0, "c": 2.0}``."""
    out: dict[str, float] = {}
    for value in values or []:
        for part in value.split(","):
            part = part.strip()
            if not part:
                continue
            name, eq, num = part.partition("=")
            if not eq or not name.strip():
                raise UsageError(f"{what} expects NAME=VALUE, got {part!r}")
            try:
                value = float(num)
            except ValueError:
                raise UsageError(f"{what} {name.strip()}: {num!r} is not a number") from None
            if not math.isfinite(value):
                why = "out of range" if num.strip().lower().lstrip("+-") not in ("inf", "infinity", "nan") else \
                    "not a finite number"
                raise UsageError(f"{what} {name.strip()}={num.strip()}: {why} (parameter values and directions "
                                 "are finite real numbers)")
            out[name.strip()] = value
    return out


def parse_modules(values: list[str] | None) -> dict[str, str]:
    """``--module NAME=PATH`` options as ``{NAME: PATH}``; a usage error when one is not of that
    form or PATH is not a file (missing, or a directory, a device such as /dev/zero, a pipe)."""
    out: dict[str, str] = {}
    for value in values or []:
        name, eq, path = value.partition("=")
        if not eq or not name or not path:
            raise UsageError(f"--module expects NAME=PATH, got {value!r}")
        if not os.path.isfile(path):
            raise UsageError(f"--module {value}: " + ("not a regular file" if os.path.exists(path) else "no such file"))
        out[name] = path
    return out


def refuse_unimported_modules(modules: dict[str, str], loaded: list[tuple[str, Loaded]]) -> None:
    """A usage error for the first ``--module NAME=PATH`` that none of the FILEs imports (it would be
    silently ignored); ``loaded``: each FILE's path and :class:`~langur.modules.Loaded`.  With several
    FILEs (``langur check``) a module may be meant for some of them only: refused only when no FILE
    imports it."""
    for name, mpath in modules.items():
        if all(ld.modules.get(name) in (None, ld.main) for _, ld in loaded):
            imported = ", ".join(dict.fromkeys(n for _, ld in loaded for n, m in ld.modules.items()
                                               if m is not ld.main)) or "none"
            paths = ", ".join(path for path, _ in loaded)
            raise UsageError(f"--module {name}={mpath}: {paths} " + (
                f"imports no module {name} (it imports: {imported})" if len(loaded) == 1
                else f"import no module {name} (they import: {imported})"))


def add_common(p: argparse.ArgumentParser, *, params=True, mc=False) -> None:
    p.add_argument("--json", action="store_true", help="one JSON object on standard output")
    p.add_argument("--module", action="append", metavar="NAME=PATH",
                   help="resolve `from NAME import …` to PATH (swap a shader)")
    if params:
        p.add_argument("--at", action="append", metavar="NAME=VALUE",
                       help="parameter values (repeatable, or comma-separated)")
    if mc:
        p.add_argument("--samples", type=samples(), default=10000, metavar="N",
                       help=f"Monte Carlo samples, 2 to {MAX_SAMPLES:,} (default 10000)")
        p.add_argument("--seed", type=seed, default=0, metavar="S",
                       help="random seed, a non-negative integer (same seed, same numbers)")


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """The parser; with ``argv``, only the command it names is imported and given its arguments
    (start-up: ``langur eval`` does not import the modules of ``check``, ``fuzz``, ``reproduce`` …;
    the others keep their one-line help).  When the command is ``argv``'s first word, nothing
    before it can ask for the list of commands (``langur --help eval`` can), and the other
    commands' parsers are not made at all (start-up: each is an ``ArgumentParser`` whose help
    strings go through ``gettext``'s search for translations)."""
    chosen = _command_of(argv)
    alone = chosen is not None and argv[0] == chosen
    parser = cliparser.Parser(prog="langur", description="Langur: differentiating integrals with parametric "
                              "discontinuities.")
    parser.add_argument("--version", action="version", version=f"langur {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=cliparser.Parser)
    for name, help_ in COMMANDS.items():
        if alone and name != chosen:
            continue
        p = sub.add_parser(name, help=help_, description=help_)
        if chosen is None or name == chosen:
            mod = importlib.import_module(f"langur.commands.{name}")
            mod.add_arguments(p)
            p.set_defaults(_run=mod.run)
    return parser


#: The options of the command line's parser itself (argparse matches every word against them too).
TOP_OPTIONS = ("-h", "--help", "--version")


def read_plain(argv: list[str]):
    """``argv``'s attributes as ``build_parser(argv).parse_args(argv)`` gives them, read without
    argparse when the command is ``argv``'s first word and the rest is plain
    (:mod:`langur.arguments`); None otherwise."""
    chosen = _command_of(argv)
    if chosen is None or argv[0] != chosen:
        return None
    mod = importlib.import_module(f"langur.commands.{chosen}")
    arguments = Arguments()
    mod.add_arguments(arguments)
    arguments.set_defaults(_run=mod.run)
    return arguments.parse(argv[1:], {"command": chosen}, TOP_OPTIONS)


def _command_of(argv: list[str] | None) -> str | None:
    """The command ``argv`` names (its first word not an option), if it is one of :data:`COMMANDS`."""
    if argv is None:
        return None
    first = next((a for a in argv if not a.startswith("-")), None)
    return first if first in COMMANDS else None


def print_diagnostics(err: LangurError, as_json: bool) -> None:
    if as_json:
        print(json.dumps({"diagnostics": [d.to_json() for d in err.diagnostics]}))
    for d in err.diagnostics:
        print(d.format(), file=sys.stderr)


#: The recursive semantic functions follow the term: up to ``MAX_INLINED_DEPTH`` levels (T230), a
#: few Python frames each.
RECURSION_LIMIT = 20_000


#: The status of a command whose standard output was closed before it finished (``langur check … |
#: head``): 1, the contract's status for an answer not given (CLI.md: 0, 1 or 2 only), never 0 — its
#: findings were not all read, and ``set -o pipefail`` must see it; nothing is printed (as ``cat`` or
#: ``grep`` print nothing when a closed pipe stops them).
BROKEN_PIPE = 1


def main(argv: list[str] | None = None) -> int:
    own_process = argv is None  # (the console script, python -m langur: not a caller's process)
    try:
        return _main(sys.argv[1:] if argv is None else list(argv), own_process)
    except BrokenPipeError:  # from the command or from printing its diagnostics
        if own_process:  # the interpreter's last flush of standard output would fail again (Python's
            # documented recipe, "Note on SIGPIPE" in the signal module's docs): it goes to /dev/null
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return BROKEN_PIPE


def _main(argv: list[str], own_process: bool) -> int:
    sys.setrecursionlimit(max(sys.getrecursionlimit(), RECURSION_LIMIT))
    with gcpause.paused():  # the command's modules imported without cyclic collections (issue 15, start-up)
        args = read_plain(argv)
        parser = build_parser(argv) if args is None else None
        if own_process:  # what the imports built lives as long as the process: no collection scans it again
            gc.freeze()
    if args is None:
        args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help(sys.stderr)
        return 2
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")  # numpy's RuntimeWarnings, scipy's IntegrationWarnings, …
            for quiet in (DeprecationWarning, PendingDeprecationWarning, FutureWarning):
                warnings.simplefilter("ignore", quiet)  # about libraries' APIs, not the user's numbers
            try:
                if args.command in ("show", "eval", "deriv", "render", "plot"):  # one budget for the whole command
                    progress.enable(args.command, None if not getattr(args, "json", False) else False)
                    return int(run_with_timeout(lambda: args._run(args), args.timeout) or 0)
                return int(args._run(args) or 0)
            except TimeoutError:
                if not hasattr(args, "timeout"):
                    raise
                hint = ", fewer --samples or one --engine" if args.command in ("eval", "deriv") else ""
                print(f"langur {args.command}: error: stopped after {args.timeout:g} s (--timeout {args.timeout:g}): "
                      f"the computation did not finish in time (a larger --timeout{hint} may help)", file=sys.stderr)
                return 1
            finally:
                _note_warnings(args.command, caught)
    except UsageError as e:
        print(f"langur {args.command}: error: {e}", file=sys.stderr)
        return 2
    except LangurError as e:
        print_diagnostics(e, getattr(args, "json", False))
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        raise  # (main's: standard output closed is not a bug)
    except MemoryError:
        print(f"langur {args.command}: error: out of memory (fewer --samples, or a smaller program)",
              file=sys.stderr)
        return 1
    except Exception as e:  # a bug, reported without a traceback unless asked for
        if os.environ.get("LANGUR_DEBUG"):
            raise
        print(f"langur {args.command}: internal error: {type(e).__name__}: {e} "
              "(this is a bug; LANGUR_DEBUG=1 shows the traceback)", file=sys.stderr)
        return 1


def _note_warnings(command: str, caught: list[warnings.WarningMessage]) -> None:
    """Warnings no engine turned into a note of its own: one line, each message counted once."""
    if not caught:
        return
    counts = Counter(f"{w.category.__name__}: {str(w.message).strip()}" for w in caught)
    shown = "; ".join(f"{m}" + (f" (×{n})" if n > 1 else "") for m, n in counts.most_common(3))
    more = f"; and {len(counts) - 3} other kind(s)" if len(counts) > 3 else ""
    print(f"langur {command}: note: warnings while computing: {shown}{more}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())
