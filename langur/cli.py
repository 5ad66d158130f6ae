"""The ``langur`` command (the command reference: ``docs/``).

Each subcommand lives in ``langur/commands/<name>.py`` with ``add_arguments(parser)`` and
``run(args) -> int``.  This module parses the command line, sets up the common options, and turns
every :class:`~langur.diagnostics.LangurError` into ``PATH:LINE:COL: error CODE message`` lines and
exit status 1.  Usage errors exit 2.  A traceback is a bug: unexpected exceptions are reported as
an internal error (set ``LANGUR_DEBUG=1`` to see the traceback).
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import sys

from .diagnostics import LangurError

COMMANDS = {
    "check": "parse, type-check and lint for transversality",
    "show": "the core term after desugaring, its denotation, and its derivative (--wrt)",
    "eval": "the program's value: exact (symbolic) and Monte Carlo (operational)",
    "deriv": "the derivative: exact, Monte Carlo, standard AD, and the Theorem 8.1 check",
    "plot": "the integrand and its derivative as a picture",
    "fuzz": "differential testing of the two engines on random programs",
    "reproduce": "the paper's examples and figures, each with its numbers checked",
}


class UsageError(Exception):
    """Bad command line: exit status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own usage errors: status 2, no traceback
        self.print_usage(sys.stderr)
        self.exit(2, f"{self.prog}: error: {message}\n")


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
                out[name.strip()] = float(num)
            except ValueError:
                raise UsageError(f"{what} {name.strip()}: {num!r} is not a number") from None
    return out


def parse_modules(values: list[str] | None) -> dict[str, str]:
    out: dict[str, str] = {}
    for value in values or []:
        name, eq, path = value.partition("=")
        if not eq or not name or not path:
            raise UsageError(f"--module expects NAME=PATH, got {value!r}")
        out[name] = path
    return out


def add_common(p: argparse.ArgumentParser, *, params=True, mc=False) -> None:
    p.add_argument("--json", action="store_true", help="one JSON object on standard output")
    p.add_argument("--module", action="append", metavar="NAME=PATH",
                   help="resolve `from NAME import …` to PATH (swap a shader)")
    if params:
        p.add_argument("--at", action="append", metavar="NAME=VALUE",
                       help="parameter values (repeatable, or comma-separated)")
    if mc:
        p.add_argument("--samples", type=int, default=10000, help="Monte Carlo samples (default 10000)")
        p.add_argument("--seed", type=int, default=0, help="random seed (same seed, same numbers)")


def build_parser() -> argparse.ArgumentParser:
    from . import __version__

    parser = _Parser(prog="langur", description="Langur: differentiating integrals with parametric discontinuities.")
    parser.add_argument("--version", action="version", version=f"langur {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name, help_ in COMMANDS.items():
        p = sub.add_parser(name, help=help_, description=help_)
        mod = importlib.import_module(f"langur.commands.{name}")
        mod.add_arguments(p)
        p.set_defaults(_run=mod.run)
    return parser


def print_diagnostics(err: LangurError, as_json: bool) -> None:
    if as_json:
        print(json.dumps({"diagnostics": [d.to_json() for d in err.diagnostics]}))
    for d in err.diagnostics:
        print(d.format(), file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help(sys.stderr)
        return 2
    try:
        return int(args._run(args) or 0)
    except UsageError as e:
        print(f"langur {args.command}: error: {e}", file=sys.stderr)
        return 2
    except LangurError as e:
        print_diagnostics(e, getattr(args, "json", False))
        return 1
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        return 0
    except Exception as e:  # a bug, reported without a traceback unless asked for
        if os.environ.get("LANGUR_DEBUG"):
            raise
        print(f"langur {args.command}: internal error: {type(e).__name__}: {e} "
              "(this is a bug; LANGUR_DEBUG=1 shows the traceback)", file=sys.stderr)
        return 3


if __name__ == "__main__":
    sys.exit(main())
