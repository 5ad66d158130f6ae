"""Deferred imports for start-up: the one place where a module is imported on first use.

The Monte Carlo path (``langur eval FILE --engine mc`` on a program whose conditions are affine)
needs neither sympy nor scipy, which take most of a one-shot process's start-up (issue 15).  The
modules on that path name a heavy module they need only sometimes (the sympy solver of nonlinear
conditions, the integrability analysis of ``langur.lint.singular``) through :func:`module`; it is
imported when an attribute is first read, then it is an ordinary module.  This is not a way around
an import cycle: every use says which fast path makes the import unnecessary.
"""

from __future__ import annotations

import importlib
from types import ModuleType


class LazyModule:
    """Stands for the module ``name`` until an attribute is read, then imports it."""

    def __init__(self, name: str):
        self._name = name
        self._module: ModuleType | None = None

    def __getattr__(self, attr: str):
        if attr.startswith("__"):
            raise AttributeError(attr)
        if self._module is None:
            self._module = importlib.import_module(self._name)
        return getattr(self._module, attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._name}>"


def module(name: str) -> LazyModule:
    """The module ``name`` (absolute), imported when first used."""
    return LazyModule(name)
