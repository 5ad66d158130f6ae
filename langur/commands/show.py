"""`langur show` (CLI.md).  Not yet implemented."""

from ..cli import UsageError


def add_arguments(p):
    p.add_argument("files", nargs="*")


def run(args):
    raise UsageError("`langur show` is not implemented yet")
