"""The workbench's own engines behind the protocol: the exact engine (the reference), the Monte
Carlo engine (§9) and standard AD (the Monte Carlo engine's regular part alone: every delta
dropped, what PyTorch or JAX compute on the discretized integral — the simplest wrong engine)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

from .. import exact as api
from .. import operational
from ..core import Program
from ..timebox import run_with_timeout
from .protocol import Answer, Declined, Kind


@dataclass
class ExactEngine:
    """⟦p⟧ and ⦇p⦈ by the symbolic engine (closed form, else quadrature with its bound)."""

    timeout: float = 20.0
    name: str = "exact"
    kind: Kind = Kind.EXACT

    def value(self, program: Program, params: Mapping[str, float]) -> Answer | Declined:
        return self._run(lambda: api.exact_eval(program, dict(params)))

    def derivative(self, program: Program, params, direction) -> Answer | Declined:
        return self._run(lambda: api.exact_deriv(program, dict(params), dict(direction), check=False))

    def _run(self, fn) -> Answer | Declined:
        try:
            r = run_with_timeout(fn, self.timeout)
        except api.ExactUndefined as e:  # the integral does not exist: an answer, NaN with the reason
            return Answer(math.nan, 0.0, (str(e),))
        except api.ExactUnavailable as e:
            return Declined(str(e))
        except TimeoutError:
            return Declined(f"the exact engine took longer than {self.timeout:g} s")
        return Answer(r.value, r.error or 0.0, tuple(r.notes))


@dataclass
class MonteCarloEngine:
    """The operational engine: unbiased estimates with their standard errors."""

    samples: int = 20000
    seed: int = 0
    method: str = "uniform"
    name: str = "mc"
    kind: Kind = Kind.STOCHASTIC

    def value(self, program: Program, params: Mapping[str, float]) -> Answer | Declined:
        r = operational.estimate_value(program, dict(params), samples=self.samples, seed=self.seed, method=self.method)
        return Answer(r.value, r.stderr, tuple(r.notes))

    def derivative(self, program: Program, params, direction) -> Answer | Declined:
        r = operational.estimate_derivative(program, dict(params), dict(direction), samples=self.samples,
                                            seed=self.seed, method=self.method)
        return Answer(r.value, r.stderr, tuple(r.notes))


@dataclass
class StandardAD(MonteCarloEngine):
    """Standard AD of the Monte Carlo estimator: the derivative's regular part only (deltas dropped)."""

    name: str = "standard-ad"

    def derivative(self, program: Program, params, direction) -> Answer | Declined:
        r = operational.estimate_derivative(program, dict(params), dict(direction), samples=self.samples,
                                            seed=self.seed, method=self.method)
        return Answer(r.standard_ad.value, r.standard_ad.stderr)
