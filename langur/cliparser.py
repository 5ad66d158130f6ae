"""argparse's parser of the ``langur`` command line (``langur.cli`` builds it): argparse's usage
errors in one line, exit status 2.

Imported when a command line is not plain (help, a usage error, an abbreviated option…): a plain
one is read by :mod:`langur.arguments` without argparse (issue 15, start-up).
"""

from __future__ import annotations

import argparse


class Parser(argparse.ArgumentParser):
    def error(self, message: str):  # argparse's own usage errors: status 2, one line, no traceback
        self.exit(2, f"{self.prog}: error: {message} (see `{self.prog} --help`)\n")
