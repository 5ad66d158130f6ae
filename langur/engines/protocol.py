"""The engine protocol: what an engine answers and how an answer is compared (see the package
docstring and ``docs/engines.md``)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from enum import StrEnum
from typing import Protocol, runtime_checkable

from ..core import Program

#: Standard errors a stochastic answer may be off, and the absolute and relative slack of every
#: comparison (false alarms ≈ 6e-7 per comparison of a normal estimate).
SIGMA, ABS_SLACK, REL_SLACK = 5.0, 1e-9, 1e-9


class Kind(StrEnum):
    """What an engine's error means."""

    EXACT = "exact"  # the number is exact up to rounding (error: a bound when it integrated numerically)
    BOUNDED = "bounded"  # deterministic, |answer − truth| ≤ error
    STOCHASTIC = "stochastic"  # an unbiased estimate with its standard error


@dataclass(frozen=True)
class Answer:
    value: float
    error: float = 0.0
    notes: tuple[str, ...] = ()


@dataclass(frozen=True)
class Declined:
    """The engine does not support this program (why, in its words)."""

    reason: str


class EngineFailure(RuntimeError):
    """An engine crashed, hung past its budget or answered something malformed."""


@runtime_checkable
class Engine(Protocol):
    name: str
    kind: Kind

    def value(self, program: Program, params: Mapping[str, float]) -> Answer | Declined: ...

    def derivative(self, program: Program, params: Mapping[str, float],
                   direction: Mapping[str, float]) -> Answer | Declined: ...


def tolerance(kind: Kind, reference: Answer, answer: Answer) -> float:
    """How far ``answer`` (of an engine of ``kind``) may be from the exact engine's ``reference``."""
    size = max(abs(reference.value), abs(answer.value))
    spread = SIGMA * answer.error if kind is Kind.STOCHASTIC else answer.error
    return spread + reference.error + ABS_SLACK + REL_SLACK * size


def agree(kind: Kind, reference: Answer, answer: Answer) -> bool:
    """Does ``answer`` agree with the exact engine's ``reference``?  NaN (no integral) agrees only
    with NaN."""
    if math.isnan(reference.value) and math.isnan(answer.value):
        return True  # both say the integral does not exist
    vals = (reference.value, reference.error, answer.value, answer.error)
    if any(not isinstance(v, (int, float)) or math.isnan(v) for v in vals):
        return False
    if math.isinf(reference.value) or math.isinf(answer.value):
        return reference.value == answer.value
    return abs(answer.value - reference.value) <= tolerance(kind, reference, answer)


def deviation(kind: Kind, reference: Answer, answer: Answer) -> float:
    """``|answer − reference|`` in the engine's error units (standard errors, bounds); inf when
    its error is 0 and the numbers differ beyond rounding."""
    d = abs(answer.value - reference.value)
    if d <= ABS_SLACK + REL_SLACK * max(abs(reference.value), abs(answer.value)) + reference.error:
        return 0.0
    return d / answer.error if answer.error > 0 else math.inf
