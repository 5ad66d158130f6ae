"""Finding an engine by name (``--engine NAME``): built-in names, ``module:function``,
``cmd:PROGRAM`` and the ``langur.engines`` entry points of installed packages."""

from __future__ import annotations

import importlib
from importlib.metadata import entry_points

from .builtin import ExactEngine, MonteCarloEngine, StandardAD
from .external import ExternalEngine
from .protocol import Engine

#: The built-in engines and what they build from the command's options.
BUILTIN = {
    "exact": lambda o: ExactEngine(timeout=o.get("timeout", 20.0)),
    "mc": lambda o: MonteCarloEngine(samples=o.get("samples", 20000), seed=o.get("seed", 0),
                                     method=o.get("method", "uniform")),
    "standard-ad": lambda o: StandardAD(samples=o.get("samples", 20000), seed=o.get("seed", 0),
                                        method=o.get("method", "uniform")),
}
ENTRY_POINTS = "langur.engines"


class UnknownEngine(ValueError):
    """No engine of that name (the message says which forms a name may take)."""


def resolve(spec: str, **options) -> Engine:
    """The engine named ``spec``; ``options`` (samples, seed, method, timeout) configure the
    built-in ones and the budget of an external one."""
    if spec in BUILTIN:
        return BUILTIN[spec](options)
    if spec.startswith("cmd:"):
        return ExternalEngine(spec[4:], timeout=options.get("timeout", 60.0))
    if ":" in spec:
        module, _, attr = spec.partition(":")
        try:
            factory = getattr(importlib.import_module(module), attr)
        except (ImportError, AttributeError) as e:
            raise UnknownEngine(f"--engine {spec}: cannot import {attr} from {module} ({e})") from None
        return _checked(factory(), spec)
    found = [ep for ep in entry_points(group=ENTRY_POINTS) if ep.name == spec]
    if found:
        return _checked(found[0].load()(), spec)
    raise UnknownEngine(f"--engine {spec}: no such engine (built in: {', '.join(BUILTIN)}; or module:function, "
                        f"cmd:PROGRAM, or a name registered under the entry points {ENTRY_POINTS!r})")


def _checked(engine, spec: str) -> Engine:
    if not isinstance(engine, Engine):
        raise UnknownEngine(f"--engine {spec}: {engine!r} is not an engine (it needs name, kind, value and derivative)")
    return engine
