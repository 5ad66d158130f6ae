"""Hypothesis strategies of well-typed Langur programs, for anyone's test suite (issue 13).

Like ``hypothesis-jsonschema`` for JSON Schema, this package turns the language (LANGUAGE.md
§4–§6) into generators::

    from hypothesis import given
    from langur import strategies as ls

    @given(ls.programs(max_variables=2))
    def test_my_engine(g):           # g: ls.Generated
        loaded = g.load()            # the front end: the core program, type-checked
        ...                          # g.text is the `.lgr` source, g.module its surface AST

Public API::

    programs(*, min_variables=1, max_variables=3, max_summands=3, max_factors=3, max_conds=4,
             max_params=3, light=False, kinks=True, turning=False, lets=True, defs=True,
             modules=False, generic=True, wide=False, poles=False, huge=False, deep=False) -> strategy of Generated
    texts(**shape) -> strategy of str          # the printed main module
    cores(**shape) -> strategy of Loaded       # through the front end (langur.frontend)
    Generated(module, params, libraries): .text, .files(), .load(directory=None)
    render(module) -> str                      # `.lgr` text; parses back to the same AST

Programs are drawn *type-directed*: variables only where a variable may stand, parameter terms
(parameters and ``let`` names) where a parameter is expected, primitives only inside their
domains on every box, conditions only in the forms the front end completes to diffeomorphisms
(§5): affine with literal or parameter coefficients, two-root quadratics, monotone primitives
(``exp``, ``sqrt``, ``log``, ``atan``, ``tanh``), graphs ``y − g(x)``, circles and balls,
declared diffeomorphisms (a shear, a rotation, a cubic graph), conditions with ``abs``/``min``/
``max`` inside (split at their kinks by the front end), with ``turning=True`` conditions in one
variable with no closed-form inverse (implicit roots), windows, nested conditionals and
conditionals on parameters alone; boxes with constant or parametric bounds; ``let`` of a
parameter term; a factor moved into a ``def`` (``modules=True``: into an imported module).  Each
program is generic at its parameter defaults (:func:`langur.strategies.terms.generic`), so both
engines' derivatives exist there (§5, Theorem 8.1).  Everything is built with ``st.composite``
from small choices whose first option is the simplest, so hypothesis shrinks a failing program to
one variable, one parameter and one factor when the failure allows it.

``hypothesis`` is a dependency of Langur (``langur fuzz`` needs it); importing this package in an
environment without it raises :class:`ImportError` saying how to install it.  Nothing else in Langur imports this package at
start-up (``langur fuzz`` does when it generates).
"""

from __future__ import annotations

try:
    import hypothesis  # noqa: F401
except ImportError as e:  # pragma: no cover - depends on the environment
    raise ImportError("langur.strategies needs hypothesis, a dependency of Langur missing from this "
                      "environment: pip install hypothesis (or pip install -e . in the clone)") from e

from .programs import GENERIC, PARAMS, VARIABLES, Generated, cores, programs, render, texts

__all__ = ["GENERIC", "PARAMS", "VARIABLES", "Generated", "cores", "programs", "render", "texts"]
