"""Differential testing of the two engines (CLI.md, ``langur fuzz``).

The exact symbolic reference (:mod:`langur.exact`, sympy) and the operational Monte Carlo
engine (:mod:`langur.operational`, numpy) implement ⟦p⟧ and ⦇p⦈ (LANGUAGE.md §3–§4) independently.
This module generates random well-typed, *transverse* programs as ``.lgr`` text (so the front end
is exercised too), loads them with :func:`langur.frontend.load_text` (a program with modules, ``--wide``:
its files written to a folder the campaign owns, :mod:`langur.fuzz.bundle`), and compares the engines.

Public API::

    programs(max_summands=3, max_factors=3, max_conds=4, max_params=3, light=False, kinks=False,
             max_variables=None)   # None: 3, or 2 for light programs
        -> hypothesis strategy of FuzzProgram
    compare_text(text, *, samples=20000, seed=0, timeout=20.0, lint=True, method="uniform")
        -> ProgramResult
    run_fuzz(examples=50, seed=0, samples=20000, timeout=20.0, keep=None, lint=True,
             progress=None, method="uniform") -> FuzzSummary

``hypothesis`` (a dependency of Langur) is imported lazily, when generating, and :class:`MissingHypothesis`
is raised (with ``pip install hypothesis`` advice) when it is absent.

Generated programs (transverse by construction, LANGUAGE.md §5) are those of the public strategies
:func:`langur.strategies.programs` (one to three variables, see docs/strategies.md), printed; at
the defaults no two zero sets coincide, none coincides with a face of the box, and none passes
through a corner of the box.  Optionally (``lint``) the
program is also run through :func:`langur.transversality.check_loaded` and discarded on any
X301/X305 finding at the defaults (a cross-test of the linter: such a finding on these programs
is counted).  X304 ("coincident for *some* parameter values", reported for any two moving jumps
of one variable on the same side, e.g. ``[x >= a]·[x >= b]``) is recorded but not discarded: the
defaults are generic, so the program is transverse where it is evaluated.  Only the analyses
that can report X301 or X305 run in a unit (``check_loaded``'s ``only``); a unit that fails is
linted again with all of them, so that its findings (tangencies, integrability, …) are complete.
A failing program is
shrunk and written with both engines' numbers by :mod:`langur.fuzz.counterexamples` (``--out``).

Comparison (per program, value and the derivative in each parameter): agree iff
``|mc − exact| ≤ 5·stderr + 1e-9 + exact error bound + 1e-9·max(|mc|, |exact|)`` (the relative term
covers one-variable deltas, which the Monte Carlo engine evaluates exactly, standard error 0); a
Monte Carlo estimate outside it is made again with ten times the samples from another seed, which
must disagree too (:func:`langur.fuzz.compare._recheck`: replicate-based standard errors can
understate the error of a discontinuous integrand).
Compared separately: value, derivative, its regular part and its boundary (delta) part, standard
AD = regular in each engine, and Theorem 8.1's check must hold (these programs are transverse).
An exact engine that takes longer than ``timeout`` seconds on a program is a ``timeout``, not a
failure; one that cannot evaluate (``ExactUnavailable``) is ``exact_unavailable``; any other
exception of the exact engine (e.g. a closed form that disagrees with its own quadrature) is an
``exact_error`` and counts as a failure.  The exact engine runs in a forked child process killed
at the time limit (a SIGALRM-based limit can be lost when it fires inside a gc callback).
"""

from . import campaign, cluster, compare, pool
from .campaign import FuzzSummary, generated, run_fuzz
from .compare import ProgramResult, Row, agree, compare_engine, compare_text
from .generate import FuzzProgram, MissingHypothesis, programs

__all__ = ["FuzzProgram", "FuzzSummary", "MissingHypothesis", "ProgramResult", "Row", "agree", "campaign", "cluster",
           "compare", "compare_engine", "compare_text", "generated", "pool", "programs", "run_fuzz"]
