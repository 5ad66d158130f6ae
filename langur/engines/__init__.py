"""Engines: anything that answers ⟦p⟧ and ⦇p⦈ for a core program, to be tested against the exact
engine (``langur eval/deriv/fuzz --engine NAME``; ``docs/engines.md``).

An engine has a ``name``, declares its :class:`Kind` — exact, deterministic with an error bound,
or stochastic with a standard error — and answers ``value(program, params)`` and
``derivative(program, params, direction)`` with an :class:`Answer` (the number and its error: 0,
a bound, or a standard error, as its kind says) or a :class:`Declined` (a program it does not
support: counted apart, never a disagreement).  A crash, a hang past its budget or a malformed
answer raises :class:`EngineFailure`, reported with the program that caused it.

Engines are named (:func:`resolve`): the built-in ``exact``, ``mc`` and ``standard-ad``
(:mod:`.builtin`); ``module:function`` (a Python callable returning an engine, imported from the
installed packages); ``cmd:PROGRAM`` (any program speaking one JSON request and one JSON answer
per line, :mod:`.external`); or a name registered by another package under the entry-point group
``langur.engines``.  :func:`agree` is the rule a comparison uses.
"""

from __future__ import annotations

from .protocol import (
    ABS_SLACK,
    REL_SLACK,
    SIGMA,
    Answer,
    Declined,
    Engine,
    EngineFailure,
    Kind,
    agree,
    deviation,
    tolerance,
)
from .registry import BUILTIN, UnknownEngine, resolve

__all__ = ["ABS_SLACK", "Answer", "BUILTIN", "Declined", "Engine", "EngineFailure", "Kind", "REL_SLACK", "SIGMA",
           "UnknownEngine", "agree", "deviation", "resolve", "tolerance"]
