"""sympy's ``simplify`` without the import of ``sympy.physics.units`` (issue 15).

Every call of :func:`sympy.simplify` (ours, and the ones inside ``solve``, ``equals``, a
relation's simplification) runs ``from sympy.physics.units import Quantity`` only to ask whether the
expression holds a physical quantity.  The first such import in a process costs about 0.15 CPU s
(the SI unit system it builds), paid by the first partial derivative of nearly every example.

No ``Quantity`` can exist while ``sympy.physics.units`` has not been imported (the class is
defined in a module of that package, and importing any of its modules imports the package).  So,
within :func:`units_unloaded` and only while the package is not imported, ``sys.modules`` holds a
placeholder for it (and for ``sympy.physics``) whose ``Quantity`` (``Unit``, the same class, for
``solve``'s ``checksol``) is a class nothing is an instance of: ``expr.has(Quantity)``
is False, as it would be with the real class, and simplify returns the same expression.  Any
other name asked of the placeholder (or ``Quantity`` outside the blocks, through a reference kept to
it) imports the real package and drops the placeholder, so code that really wants units gets them;
the placeholders are removed when the last block exits.  (Code run inside a block that wrote
``import sympy.physics.units`` and then reached the package as ``sympy.physics.units`` would not
find the attribute; nothing the exact engine calls does that — ``from … import`` and
``import … as`` work.)
"""

from __future__ import annotations

import importlib
import sys
import threading
import types
from collections.abc import Iterator
from contextlib import contextmanager

PARENT, NAME = "sympy.physics", "sympy.physics.units"
#: What sympy asks of the package: simplify's ``Quantity``, ``checksol``'s ``Unit`` (the same class).
ASKED = ("Quantity", "Unit")


class _NoQuantity:
    """Stands for ``sympy.physics.units.Quantity`` while that package is not imported: no
    expression can hold an instance of either."""


class _Placeholder(types.ModuleType):
    """``sys.modules[NAME]`` (and ``[PARENT]``) within :func:`units_unloaded` while the real
    packages are not imported."""

    def __getattr__(self, name: str):
        if self.__name__ == NAME and name in ASKED and _depth > 0 and sys.modules.get(NAME) is self:
            return _NoQuantity  # within a block, the real package not imported: no Quantity exists
        if name.startswith("__"):
            raise AttributeError(name)
        return getattr(_real(self.__name__), name)


_lock = threading.RLock()
_depth = 0
_placeholders = {name: _Placeholder(name, __doc__) for name in (PARENT, NAME)}


def _drop() -> None:
    for name, module in _placeholders.items():
        if sys.modules.get(name) is module:
            del sys.modules[name]


def _real(name: str) -> types.ModuleType:
    """The real package: the placeholders dropped from ``sys.modules``, then imported."""
    with _lock:
        _drop()
    return importlib.import_module(name)


@contextmanager
def units_unloaded() -> Iterator[None]:
    """Within the block, sympy's simplify does not import ``sympy.physics.units`` (module doc);
    blocks nest, and may run in several threads at once."""
    global _depth
    with _lock:
        if _depth == 0 and NAME not in sys.modules and PARENT not in sys.modules:
            # (importing ``sympy.physics`` imports its ``units``: neither is, or both are, imported)
            sys.modules.update(_placeholders)
        _depth += 1
    try:
        yield
    finally:
        with _lock:
            _depth -= 1
            if _depth == 0:
                _drop()
