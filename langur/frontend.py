"""The front end: `.lgr` text to elaborated modules and the main program in pure core (§4, §9).

Public API::

    load(path, modules: dict[str, str] | None = None) -> Loaded
    load_text(text, path="<string>", modules=None) -> Loaded
    load_bytes(data, path="<bytes>", modules=None) -> Loaded
    core_term_from_text(text, variables=(), params=(), path="<string>", box=None, diffeos=None) -> Term

``load*`` parse the main module (``langur.syntax.parser``), follow its imports, elaborate each
module once (``langur.syntax.elaborate``: desugaring and typing, LANGUAGE.md §2 and §6), inline the
main program's calls (``langur.syntax.inline``) and type the result again on the core
(``langur.typesys.type_program``, Fig. 6 and Fig. 11).  Bad input raises
:class:`~langur.diagnostics.LangurError` carrying every error found (at least the first, located).

Modules.  ``from m import f`` finds ``m.lgr`` in the directory of the importing file; ``modules``
(the CLI's ``--module m=PATH``) overrides by name.  A module's name is its file's stem, or the
NAME it was given in ``modules``; the main module's name is its file's stem.  Missing modules
(T218), modules whose file cannot be read (T223, with the operating system's reason), import
cycles (T219) and missing names (T220) are errors at the import.  A main file that cannot be
read is E109 (T218 when there is no such file).

Caching.  Nothing is cached across loads except ``langur.syntax.diffeo.complete``'s memo of
completed conditions (a pure function of the condition, the variables and the box).

Parameters.  ``Loaded.params`` are the main module's declared params (defaults as Fraction) in
declaration order, followed by any declared param of an imported module that an inlined def body
uses (a def body may use its arguments, ``let``-bound names and its own module's declared params;
those are shared by name with the importing program).
"""

from __future__ import annotations

import hashlib
import os
from fractions import Fraction

from . import typesys as ty
from .core import Diffeo, Term, free_params
from .diagnostics import Diagnostic, LangurError, Span
from .modules import ElaboratedModule, Loaded
from .syntax.desugar import Desugarer, DiffeoSig, Env, Scope
from .syntax.elaborate import elaborate
from .syntax.inline import inline
from .syntax.parser import parse_bytes, parse_term
from .syntax.support import numeric_box

__all__ = ["core_term_from_text", "load", "load_bytes", "load_text"]


def load(path: str, modules: dict[str, str] | None = None) -> Loaded:
    """Load the module in the file ``path`` and everything it imports."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except FileNotFoundError:
        raise LangurError(ty.diag(Span(path, 1, 1, 1, 1), "T218", f"module not found: no file {path}")) from None
    except OSError as e:
        raise LangurError(Diagnostic(Span(path, 1, 1, 1, 1), "error", "E109",
                                     f"cannot read this file: {e.strerror or type(e).__name__}")) from None
    return load_bytes(data, path, modules)


def load_text(text: str, path: str = "<string>", modules: dict[str, str] | None = None) -> Loaded:
    """Load a module given as text (imports resolve beside ``path``, or the working directory)."""
    return load_bytes(text.encode("utf-8"), path, modules)


def load_bytes(data: bytes, path: str = "<bytes>", modules: dict[str, str] | None = None) -> Loaded:
    """Load a module given as bytes (UTF-8; a decoding error is the parser's E101)."""
    loader = _Loader(modules or {})
    main = loader.module(_module_name(path), path, data, None)
    if loader.errors or main is None:
        raise LangurError(loader.errors or [ty.diag(None, "T218", f"cannot load {path}")])
    program = None
    params: dict[str, Fraction | None] = dict(main.params)
    if main.program is not None:
        program = inline(main.program, loader.done)
        used = set()
        for t in [program.body] + [b for pair in program.box for b in pair]:
            used |= free_params(t)
        for m in loader.done.values():
            for p, default in m.params.items():
                if p in used and p not in params:
                    params[p] = default
        found = ty.type_program(program, frozenset(params))
        if found:
            raise LangurError(found)
    return Loaded(main=main, modules=dict(loader.done), program=program, params=params)


def _module_name(path: str) -> str:
    base = os.path.basename(path)
    return base.removesuffix(".lgr")


class _Loader:
    """Finds, parses and elaborates modules, each once; detects import cycles."""

    def __init__(self, overrides: dict[str, str]):
        self.overrides = dict(overrides)
        self.done: dict[str, ElaboratedModule] = {}
        self.stack: list[str] = []
        self.errors: list[Diagnostic] = []

    def module(self, name: str, path: str, data: bytes, span: Span | None) -> ElaboratedModule | None:
        try:
            mod = parse_bytes(data, path)
        except LangurError as e:
            self.errors.extend(e.diagnostics)
            return None
        self.stack.append(name)
        try:
            elab = elaborate(mod, name, path, hashlib.sha256(data).hexdigest(),
                             lambda m, sp: self.resolve(m, sp, path), self.errors)
        finally:
            self.stack.pop()
        self.done[name] = elab
        return elab

    def resolve(self, name: str, span: Span | None, importer: str) -> ElaboratedModule | None:
        if name in self.stack:
            cycle = self.stack[self.stack.index(name):] + [name]
            self.errors.append(ty.diag(span, "T219", "import cycle: " + " -> ".join(cycle)))
            return None
        path = self.overrides.get(name) or os.path.join(os.path.dirname(importer), name + ".lgr")
        if name in self.done:
            first = self.done[name].path
            if name not in self.overrides and os.path.abspath(first) != os.path.abspath(path):
                self.errors.append(ty.diag(span, "T218", f"module name `{name}` refers to two files, {first} and "
                                           f"{path}: rename one, or choose one with --module {name}=PATH"))
                return None
            return self.done[name]
        where = "given by --module" if name in self.overrides else "beside the importing file"
        try:
            with open(path, "rb") as f:
                data = f.read()
        except FileNotFoundError:
            self.errors.append(ty.diag(span, "T218", f"module `{name}` not found: no file {path} ({where})"))
            return None
        except OSError as e:
            self.errors.append(ty.diag(span, "T223", f"module `{name}`: cannot read {path} ({where}): "
                                       f"{e.strerror or type(e).__name__}"))
            return None
        return self.module(name, path, data, span)


def core_term_from_text(text: str, variables=(), params=(), path: str = "<string>", box=None,
                        diffeos: dict[str, tuple[Diffeo, tuple[str, ...]]] | None = None) -> Term:
    """Parse one term and desugar it with variables ``variables`` (Δ, in order) and parameters
    ``params`` (Γ): the inverse of the core printer (``desugar(parse(print(t))) == t``).

    ``box`` (one ``(lo, hi)`` pair of variable-free core terms per variable, as ``Program.box``)
    bounds the variables for completing periodic conditions; ``diffeos`` maps a name to a
    declared ``(Diffeo, parameter names)`` that ``ifge0 NAME(vars; params)`` may apply."""

    st = parse_term(text, path)
    env = Env(module="<term>", diffeos={k: DiffeoSig(d, ps) for k, (d, ps) in (diffeos or {}).items()})
    ds = Desugarer(env)
    variables = tuple(variables)
    nb = numeric_box(variables, box) if box is not None else ()
    t = ds.term(st, Scope(variables=variables, gamma=frozenset(params) - set(variables), box=nb))
    if ds.errors:
        raise LangurError(ds.errors)
    return t
