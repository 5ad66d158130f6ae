"""Random well-typed, transverse Langur programs as `.lgr` text (the generator behind
``langur fuzz``; see :mod:`langur.fuzz` for what is generated and why): the public strategies of
:mod:`langur.strategies`, printed, plus the campaign's settings (agreement rule, lint discards,
where hypothesis keeps its files).
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass

from .. import lazy
from . import bundle

#: The public strategies (they import hypothesis: loaded when generating, not at start-up).
strategies = lazy.module("langur.strategies")

SIGMA = 5.0          # standard errors allowed (false alarm ≈ 6e-7 per comparison under normality)
ABS_SLACK = 1e-9
REL_SLACK = 1e-9
LINT_DISCARD = ("X301", "X305")


class MissingHypothesis(RuntimeError):
    """``hypothesis`` (a dependency of Langur, which ``langur fuzz`` draws programs with) is missing."""


def _hypothesis():
    try:
        import hypothesis
        from hypothesis import strategies as st
    except ImportError:  # pragma: no cover - depends on the environment
        raise MissingHypothesis("`langur fuzz` needs hypothesis, a dependency of Langur missing from "
                                "this environment: pip install hypothesis (or pip install -e .)") from None
    return hypothesis, st


def default_storage() -> str:
    """Where a campaign lets hypothesis keep its files (its cache of source constants; campaigns
    keep no example database): ``$HYPOTHESIS_STORAGE_DIRECTORY`` when set, else the user's cache
    folder (``$XDG_CACHE_HOME/langur/hypothesis``, ``~/.cache/langur/hypothesis``), never the
    current folder."""
    where = os.environ.get("HYPOTHESIS_STORAGE_DIRECTORY")
    if where:
        return where
    cache = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return os.path.join(cache, "langur", "hypothesis")


@contextlib.contextmanager
def hypothesis_home(directory: str | None):
    """Hypothesis's storage folder is ``directory`` (``default_storage()`` when None) while the
    block runs, and what it was before afterwards."""
    _hypothesis()
    from hypothesis import configuration

    before = getattr(configuration, "__hypothesis_home_directory", None)
    configuration.set_hypothesis_home_dir(directory or default_storage())
    try:
        yield
    finally:
        configuration.set_hypothesis_home_dir(before)


# ---------------------------------------------------------------------------------------------
# Program generator
# ---------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class FuzzProgram:
    """A generated program: its ``.lgr`` text (with modules, a :mod:`.bundle` of their files) and
    the parameter defaults it declares."""

    text: str
    params: tuple[tuple[str, str], ...]

    def __str__(self) -> str:
        return self.text


#: Zero sets a ``deep`` program may have (three nested split brackets register six or more).
DEEP_CONDS = 7
#: How many variables a campaign's programs have at most (1 to 3); light programs: 2.
MAX_VARIABLES, MAX_VARIABLES_LIGHT = 3, 2


def programs(max_summands: int = 3, max_factors: int = 3, max_conds: int = 4, max_params: int = 3,
             light: bool = False, kinks: bool = False, max_variables: int | None = None,
             turning: bool = False, wide: bool = False, poles: bool = False, huge: bool = False,
             deep: bool = False):
    """A hypothesis strategy of :class:`FuzzProgram` (well-typed, transverse at the defaults):
    :func:`langur.strategies.programs`, printed (with ``wide``, a program with modules as a
    :mod:`.bundle`).

    ``max_conds`` bounds the number of zero sets per program and ``max_params`` the parameters
    (each one is a derivative to compute): both bound the exact engine's work.  ``light`` keeps
    to polynomials, exp, sin, cos and sqrt (sympy integrates atan, log and fractional powers over
    regions slowly: the fast property tests use it).  ``kinks`` adds conditions with ``abs``,
    ``min`` or ``max`` inside, ``turning`` conditions in one variable with no closed-form inverse
    (``v^3 - v``, ``exp(v) + v``: implicit roots); ``max_variables`` (1 to 3) bounds the dimension (default 3, and 2
    for light programs: the exact engine's three-dimensional regions are its slowest); ``wide``
    the constructs the default draw never makes (:mod:`langur.strategies.wide`: loops, ``&``/``|``/
    ``not``, a ``let`` in a factor, guarded partial primitives, atan2's cut, more primitives, boxes
    with both ends moving, programs without a domain; :mod:`langur.strategies.variants`: negative
    parameter defaults, programs without parameters, a def called with other parameter terms, a
    def whose ``let`` takes other values there, modules; :mod:`langur.strategies.lexical`: comments,
    CRLF, numbers spelled otherwise, ≤/≥, extra parentheses); ``poles``: moving poles, products of
    moving factors, such conditions nested, folding edge cases (:mod:`langur.strategies.poles`);
    ``huge``: a third of the programs over a huge box (up to ±10¹⁰, decaying weights); ``deep``:
    products of moving lines over two variables, split conditions nested three deep, such a condition
    in a def called at two parameter terms (:mod:`langur.strategies.deep`; ``max_conds`` raised to
    :data:`DEEP_CONDS`: a nested split registers more zero sets)."""
    _hypothesis()
    if max_variables is None:
        max_variables = MAX_VARIABLES_LIGHT if light else MAX_VARIABLES
    if deep:
        max_conds = max(max_conds, DEEP_CONDS)
    return strategies.programs(max_summands=max_summands, max_factors=max_factors, max_conds=max_conds,
                               max_params=max_params, light=light, kinks=kinks, max_variables=max_variables,
                               turning=turning, wide=wide, modules=wide, poles=poles,
                               huge=huge, deep=deep).map(_fuzz_program)


def _fuzz_program(g) -> FuzzProgram:
    files = g.files()
    main = files.pop("main.lgr")
    return FuzzProgram(bundle.join(main, files), g.defaults)
