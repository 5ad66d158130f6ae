"""An optional observer of the semantic functions' rules: ``langur show --steps`` / ``--typing``.

The derivation of ⦇t⦈ (Fig. 8) and the typing derivation (Fig. 6, 11) are byproducts of the one
semantics: each case of ``ddenote.ddenote_subterm`` and ``typesys.type_term`` calls :func:`rule` with the name
of its rule and the term it applies to; a recursive pass decorated with :func:`nested` records the
depth and, for a case that returns one, the result.  Nothing is recorded (and almost nothing done)
unless a caller opened :func:`observing`.

A caller may also count the rules by wrapping the semantic functions themselves (a campaign's rule
coverage, ``langur.fuzz.coverage``); it says so by opening :func:`counted`.  Either way the rules
are :func:`watched`, and a pass that would skip applications it made before (the point-free memos
of ⟦t⟧'s pieces and ⦇p⦈'s normal form, typing read off the attributes kept on terms) stands aside:
the observer sees the same applications as without it.
"""

from __future__ import annotations

import functools
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import field

from .records import record

_STATE: dict = {"steps": None, "depth": 0, "counting": 0}


@record
class Step:
    """One rule applied: ``rule`` (e.g. ``"Fig. 8, product"``) to ``term`` at nesting ``depth``;
    ``result`` what the case returned (when it returns something)."""

    rule: str
    term: object
    depth: int
    result: object = None
    context: dict = field(default_factory=dict)


def rule(name: str, term, **context) -> None:
    """Tell the observer, if any, that rule ``name`` applies to ``term``."""
    steps = _STATE["steps"]
    if steps is not None:
        steps.append(Step(name, term, _STATE["depth"], None, context))


def active() -> bool:
    """Whether an observer is recording the rules into a list (:func:`observing`)."""
    return _STATE["steps"] is not None


def watched() -> bool:
    """Whether the rules are observed at all: recorded (:func:`observing`) or counted by wrappers
    of the semantic functions (:func:`counted`).  A pass that skips work it has done before must
    not then."""
    return _STATE["steps"] is not None or _STATE["counting"] > 0


def nested(fn):
    """Record the depth of the recursion of ``fn`` and the result of each rule it applies."""

    @functools.wraps(fn)
    def wrapper(*args):
        steps = _STATE["steps"]
        if steps is None:
            return fn(*args)
        first = len(steps)
        _STATE["depth"] += 1
        try:
            result = fn(*args)
        finally:
            _STATE["depth"] -= 1
        if len(steps) > first:
            steps[first].result = result
        return result

    return wrapper


@contextmanager
def observing() -> Iterator[list[Step]]:
    """Record the rules applied inside the ``with`` block into the list it yields."""
    saved = dict(_STATE)
    _STATE.update(steps=[], depth=0)
    try:
        yield _STATE["steps"]
    finally:
        _STATE.update(saved)


@contextmanager
def counted() -> Iterator[None]:
    """Say that the rules are counted inside the ``with`` block by wrappers of the semantic
    functions (:func:`watched` is true there; blocks nest)."""
    _STATE["counting"] += 1
    try:
        yield
    finally:
        _STATE["counting"] -= 1
