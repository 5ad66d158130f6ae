"""Elaborated modules: the front end's output, per module, for separate compilation (§9).

``langur.frontend.load`` parses a file, follows its imports, desugars and type-checks each module
once, and returns a :class:`Loaded`: every module's elaborated form (its defs and program with calls
into other modules left as :class:`langur.core.Call` links) and the main program fully inlined into
the pure core language.  A module's elaborated form depends only on its own text and the
*signatures* of what it imports, so it can be compiled and cached on its own.
"""

from __future__ import annotations

from dataclasses import field
from fractions import Fraction

from .core import Diffeo, Program, Term
from .diagnostics import Span
from .records import FACTORY, frozen, record


@frozen
class CoreDef:
    """``def name(args) = body`` after desugaring.

    ``args`` are ``(name, kind)`` with kind ``"var"`` or ``"param"``; in ``body`` a var argument is
    ``Var(name)`` and a param argument ``Param(name)``.  ``body`` may contain ``Call`` nodes.
    """

    module: str
    name: str
    args: tuple[tuple[str, str], ...]
    body: Term
    span: Span | None = field(default=None, compare=False, repr=False)


@record
class ElaboratedModule:
    """One module elaborated (desugared and typed): its params, diffeos and defs, what it imports,
    and its program with calls left as links."""

    name: str  # the module's name: its file stem, or the NAME of --module NAME=PATH
    path: str
    source: bytes  # the file's bytes: the module's identity in the load and link caches, compared as they are
    params: dict[str, Fraction | None]  # declared params with their defaults (None: no default)
    diffeos: dict[str, Diffeo]  # declared (and checked) diffeos, in the declaration's own names
    defs: dict[str, CoreDef]
    imports: dict[str, tuple[str, str]]  # local name -> (module name, name there)
    program: Program | None  # elaborated: calls left as Call nodes
    # each declared diffeo's parameter names in declaration order (a Diffeo value does not keep it)
    diffeo_params: dict[str, tuple[str, ...]] = field(default_factory=dict)

    def __init__(self, name, path, source, params, diffeos, defs, imports, program, diffeo_params=FACTORY):
        self.name, self.path, self.source, self.params = name, path, source, params
        self.diffeos, self.defs, self.imports, self.program = diffeos, defs, imports, program
        self.diffeo_params = {} if diffeo_params is FACTORY else diffeo_params


@record
class Loaded:
    """What a load gives: the main module, every module reached, the main program inlined, and its
    parameters."""

    main: ElaboratedModule
    modules: dict[str, ElaboratedModule]  # every module reached, the main one included
    program: Program | None  # the main program, fully inlined: pure core, no Call nodes
    params: dict[str, Fraction | None]  # the program's parameters with defaults, declaration order

    def __init__(self, main, modules, program, params):
        self.main, self.modules, self.program, self.params = main, modules, program, params

    def files(self) -> dict[str, bytes]:
        """The bytes of every imported module's file, by path, as this load read them: what a load of
        a rewrite of this program is given (``frontend.load_text(…, files=)``) instead of reading
        them again."""
        return {m.path: m.source for m in self.modules.values() if m is not self.main}

    def texts(self) -> dict[str, str]:
        """Every module's text (the main one's included) by path, as this load read it: what
        messages quote (a file is not opened again: a named pipe has nothing more to give, and a
        file changed since would be quoted wrong)."""
        return {m.path: m.source.decode("utf-8", errors="replace") for m in self.modules.values()}

    def param_values(self, overrides: dict[str, float] | None = None) -> dict[str, Fraction | float]:
        """Defaults overridden by ``overrides``; raises ``KeyError`` naming a missing value."""
        out: dict[str, Fraction | float] = {}
        overrides = overrides or {}
        for name, default in self.params.items():
            if name in overrides:
                out[name] = overrides[name]
            elif default is not None:
                out[name] = default
            else:
                raise KeyError(name)
        return out
