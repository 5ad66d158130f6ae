"""The front end: `.lgr` text to elaborated modules and the main program in pure core (§4, §9).

Public API::

    load(path, modules: dict[str, str] | None = None) -> Loaded
    load_text(text, path="<string>", modules=None, files=None) -> Loaded
    load_bytes(data, path="<bytes>", modules=None, files=None) -> Loaded
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
read is E109 (T218 when there is no such file).  Files are opened without waiting for a writer
(``langur.source.read_file``); ``wait`` (seconds of wall clock) bounds the wait for the bytes of a
file that is not a regular file, a named pipe nobody writes to (``langur check`` passes its
``--timeout``; the other commands' whole run is bounded by theirs): past it, T223 or E109.
``files`` (path → bytes, :meth:`Loaded.files` of an earlier load) are module files already read in
this run, used instead of reading them again: loading a rewrite of a program (``check --fix``)
sees the very modules the program was loaded with — a named pipe's bytes come only once, and a
module file changed in between would make the rewrite another program.

Incremental loading (the front end's twin of separate compilation, §9).  A module's elaborated
form depends only on its name, its path, its bytes and the *signatures* of the modules it imports
(their defs' argument lists and their diffeos: calls stay links), so :data:`CACHE` keeps it under
exactly these: loading a scene again after a shader swap re-elaborates the new shader only, and a
module whose imported signatures change (an edited dependency) is elaborated again.  Parsed
modules are kept by path and content (the bytes themselves, compared as they are).  Only modules elaborated without any diagnostic are
kept, so every error is reported as on a first load.  :func:`load_stats` says what was
elaborated and how many modules were reused, as ``operational.cache_stats`` does for compiling.
``langur.syntax.diffeo.complete`` also keeps its memo of completed conditions.

Parameters.  ``Loaded.params`` are the main module's declared params (defaults as Fraction) in
declaration order, followed by any declared param of an imported module that an inlined def body
uses (a def body may use its arguments, ``let``-bound names and its own module's declared params;
those are shared by name with the importing program).
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import field
from fractions import Fraction

from . import gcpause
from . import typesys as ty
from .core import Diffeo, Term, free_params
from .diagnostics import Diagnostic, LangurError, Span
from .memo import remember
from .modules import ElaboratedModule, Loaded
from .records import record
from .source import linked_away, read_file
from .syntax.desugar import Desugarer
from .syntax.elaborate import elaborate
from .syntax.inline import inline
from .syntax.parser import parse_bytes, parse_term
from .syntax.scope import DiffeoSig, Env, Scope
from .syntax.support import numeric_box
from .syntax.surface import ImportItem, ModuleS

__all__ = ["CACHE", "LoadCache", "clear_load_cache", "core_term_from_text", "load", "load_bytes", "load_stats",
           "load_text", "reset_load_stats"]

#: Elaborated modules kept (the oldest forgotten first beyond this); parsed modules likewise.
CAPACITY = 512


@record
class LoadCache:
    """Parsed and elaborated modules kept across loads (module docstring, "Incremental loading").

    ``parsed``: ``ModuleS`` by (path, bytes); ``modules``: elaborated module by (name, path,
    bytes, the signatures of its imports) — a file's bytes themselves, compared as they are, are its
    identity (exact, and no ``hashlib``, whose import loads OpenSSL, in a one-shot process);
    ``elaborated``: the names of the modules elaborated since the last reset; ``reused``: how many
    modules were taken from here instead."""

    parsed: dict = field(default_factory=dict)
    modules: dict = field(default_factory=dict)
    elaborated: list = field(default_factory=list)
    reused: int = 0

    def stats(self) -> dict:
        """The modules elaborated (in order) since the last reset and how many were reused."""
        return {"elaborated": list(self.elaborated), "reused": self.reused, "modules": len(self.modules)}

    def reset_stats(self) -> None:
        self.elaborated.clear()
        self.reused = 0

    def clear(self) -> None:
        for table in (self.parsed, self.modules):
            table.clear()
        self.reset_stats()


#: The cache every load uses.
CACHE = LoadCache()
load_stats, reset_load_stats, clear_load_cache = CACHE.stats, CACHE.reset_stats, CACHE.clear


def load(path: str, modules: dict[str, str] | None = None, wait: float | None = None) -> Loaded:
    """Load the module in the file ``path`` and everything it imports."""
    try:
        data = read_file(path, wait)
    except FileNotFoundError:
        raise LangurError(ty.diag(Span(path, 1, 1, 1, 1), "T218", f"module not found: no file {path}")) from None
    except OSError as e:
        raise LangurError(Diagnostic(Span(path, 1, 1, 1, 1), "error", "E109",
                                     f"cannot read this file: {e.strerror or type(e).__name__}")) from None
    return load_bytes(data, path, modules, wait)


def load_text(text: str, path: str = "<string>", modules: dict[str, str] | None = None,
              wait: float | None = None, files: Mapping[str, bytes] | None = None) -> Loaded:
    """Load a module given as text (imports resolve beside ``path``, or the working directory)."""
    return load_bytes(text.encode("utf-8"), path, modules, wait, files)


def load_bytes(data: bytes, path: str = "<bytes>", modules: dict[str, str] | None = None,
               wait: float | None = None, files: Mapping[str, bytes] | None = None) -> Loaded:
    """Load a module given as bytes (UTF-8; a decoding error is the parser's E101); the module files
    in ``files`` are taken from there, not read again (module docstring)."""
    with gcpause.kept():  # loading builds many small objects and no cycles, most of them kept
        return _load_bytes(data, path, modules, wait, files)


def _load_bytes(data: bytes, path: str, modules: dict[str, str] | None, wait: float | None,
                files: Mapping[str, bytes] | None) -> Loaded:
    loader = _Loader(modules or {}, wait, files)
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

    def __init__(self, overrides: dict[str, str], wait: float | None = None,
                 files: Mapping[str, bytes] | None = None):
        self.overrides = dict(overrides)
        self.wait = wait  # (seconds for a module file's bytes: ``langur.source.read_file``)
        self.done: dict[str, ElaboratedModule] = {}
        self.stack: list[str] = []
        self.errors: list[Diagnostic] = []
        self.ok: dict[tuple[str, str], bool] = {}  # (name, path) -> loadable
        # path -> what reading it gave (the files read already in this run: their bytes)
        self.files: dict[str, bytes | OSError | LangurError] = dict(files or {})

    def read(self, path: str) -> bytes:
        """The bytes of the module file ``path`` (``read_file``, waiting at most ``self.wait``), read
        once per load however often the loader asks (``loadable``, ``key``, ``elaborate``): a named
        pipe's bytes can be read only once, and a wait for bytes that never come is waited once."""
        got = self.files.get(path)
        if got is None:
            try:
                away = None if path in self.overrides.values() else linked_away(path)
                if away is not None:
                    raise away
                got = read_file(path, self.wait)
            except (OSError, LangurError) as e:
                got = e
            self.files[path] = got
        if isinstance(got, bytes):
            return got
        raise got

    def module(self, name: str, path: str, data: bytes, span: Span | None) -> ElaboratedModule | None:
        key = self.key(name, path, data) if self.loadable(name, path, data, ()) else None
        if key is not None and key in CACHE.modules:
            self.done[name] = CACHE.modules[key]
            CACHE.reused += 1
            return self.done[name]
        try:
            mod = self.parse(path, data)
        except LangurError as e:
            self.errors.extend(e.diagnostics)
            return None
        self.stack.append(name)
        n_errors = len(self.errors)
        try:
            elab = elaborate(mod, name, path, data, lambda m, sp: self.resolve(m, sp, path), self.errors)
        finally:
            self.stack.pop()
        self.done[name] = elab
        CACHE.elaborated.append(name)
        if key is not None and len(self.errors) == n_errors:
            remember(CACHE.modules, key, elab, CAPACITY)
        return elab

    def key(self, name: str, path: str, data: bytes) -> tuple | None:
        """What module ``name``'s elaborated form depends on: its name, path and bytes and the
        signatures of the modules it imports (their defs' arguments, their diffeos), which are
        loaded here first, in the order ``elaborate`` would load them.  None (and nothing loaded)
        when loading them reports anything: then ``elaborate`` reports it in its place."""
        errors, done = len(self.errors), dict(self.done)
        sigs = []
        self.stack.append(name)
        try:
            for item in self.parse(path, data).items:
                if isinstance(item, ImportItem):
                    dep = self.resolve(item.module.name, item.module.span, path)
                    sigs.append(dep and _signature(dep, tuple(imp.name.name for imp in item.names)))
        finally:
            self.stack.pop()
        if len(self.errors) > errors or None in sigs:
            del self.errors[errors:]
            self.done.clear()
            self.done.update(done)
            return None
        return name, path, data, tuple(sigs)

    def parse(self, path: str, data: bytes) -> ModuleS:
        key = (path, data)
        mod = CACHE.parsed.get(key)
        if mod is None:
            mod = parse_bytes(data, path)
            remember(CACHE.parsed, key, mod, CAPACITY)
        return mod

    def loadable(self, name: str, path: str, data: bytes, visiting: tuple[str, ...]) -> bool:
        """Module ``name`` and everything it imports parse, can be read and form no cycle."""
        key = (name, path)
        if key in self.ok:
            return self.ok[key]
        if name in visiting:
            return False
        try:
            mod = self.parse(path, data)
        except LangurError:
            return False
        ok = True
        for item in mod.items:
            if not isinstance(item, ImportItem):
                continue
            dep = item.module.name
            dpath = self.overrides.get(dep) or os.path.join(os.path.dirname(path), dep + ".lgr")
            try:
                ddata = self.read(dpath)
            except (OSError, LangurError):
                ok = False
                break
            if not self.loadable(dep, dpath, ddata, visiting + (name,)):
                ok = False
                break
        self.ok[key] = ok
        return ok

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
            data = self.read(path)
        except FileNotFoundError:
            self.errors.append(ty.diag(span, "T218", f"module `{name}` not found: no file {path} ({where})"))
            return None
        except OSError as e:
            self.errors.append(ty.diag(span, "T223", f"module `{name}`: cannot read {path} ({where}): "
                                       f"{e.strerror or type(e).__name__}"))
            return None
        except LangurError as e:  # E108: too large to be a program
            self.errors.extend(e.diagnostics)
            return None
        return self.module(name, path, data, span)


def _signature(m: ElaboratedModule, names: tuple[str, ...]) -> tuple:
    """What ``from m import names`` reads of ``m`` (``elaborate``'s pass 1): each name's def
    argument list, or its diffeo (with its declaration's span) and parameter names, or nothing."""
    out = []
    for n in names:
        if n in m.defs:
            out.append(("def", n, m.defs[n].args))
        elif n in m.diffeos:
            out.append(("diffeo", n, m.diffeos[n], m.diffeos[n].span, m.diffeo_params.get(n, ())))
        else:
            out.append(("none", n))
    return m.name, tuple(out)


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
