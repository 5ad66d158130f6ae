"""Separate compilation and linking (§9, Theorem 9.1: compositional evaluation).

Every module's elaborated form (``Loaded.modules[name]``: its defs with ``Call`` links and its
program) is compiled *per def* into a :class:`~langur.operational.point.Unit` and cached under
a key made of what determines the def's elaborated form: ``(module name, module source,
def name, import signature)`` — the module's own text and the *signatures* (argument kinds,
declared diffeos) of what it imports, never the imported bodies (modules.py: "a module's
elaborated form depends only on its own text and the signatures of what it imports").  A
program seen again is found by the same kind of key (a pure Program by structural equality), in
a :class:`CompileCache` the caller owns; its tables of linked programs and samplers are bounded.

A program is *linked* from compiled parts: a ``Call`` node evaluates its ``param`` arguments once
in the caller (value and tangent, exactly as a ``let`` would) and runs the callee's compiled body
at a point that binds only those arguments (the callee's other parameters are its module's
declared params, read from the program's parameters) and where its ``var`` arguments are
renamings of the caller's variables.  Swapping a module (``load(path, modules={"shader": ...})``) changes that module's
source hash only, so only its defs are recompiled; :func:`cache_stats` says what was compiled.

Sites.  Each syntactic diffeomorphic conditional is a *site*; inside a def every call is its own
site.  Sites are numbered in pre-order of the program with calls expanded in place — the order in
which they occur in the inlined program — and each site gets a *canonical* Ψ̂ over the
program's variables (extended by the identity to all of them) that mentions program parameters
only (let-bound parameters and ``param`` arguments substituted), from which its zero-set sampler
is built (sample.py).  The samplers are link-time objects: by default they are taken from the
inlined program's sites (same pre-order), because the front end re-completes a def's conditions
when it inlines and a different (equally valid) Ψ̂ would sample different points; with
``link(loaded, sites="defs")`` they come from the defs' own Ψ̂ renamed and extended, fully
separately.  The integrand itself is always evaluated by the separately compiled units, which
perform the same floating-point operations in the same order as the inlined program, so linked
and inlined evaluation agree bit for bit.

Fallback: a ``var`` argument that is not a plain variable (``f(2*x)``) would need the callee's
conditions re-completed as diffeomorphisms of the caller's variables (a job for the front end's
``langur.syntax.diffeo``, which this package may not import).  Such a program is evaluated from
its inlined form ``Loaded.program`` instead; ``cache_stats()["last_link"]`` says ``"inlined"``.
"""

from __future__ import annotations

from dataclasses import field

from .. import gcpause
from ..core import (
    SMOOTH,
    Add,
    Call,
    Diffeo,
    IfDiffeo,
    Let,
    Mul,
    Program,
    Term,
    Var,
    children,
    extend_diffeo,
    free_params,
    substitute,
    substitute_diffeo,
    subterms,
)
from ..memo import remember
from ..modules import Loaded
from ..records import record
from .compile import compile_pure, compile_term
from .point import UNLINKED, Linking, Unit
from .sample import SiteSampler


@record
class Site:
    """One delta: its canonical Ψ̂'s sampler and the program parameters its condition reads."""

    sampler: SiteSampler
    deps: frozenset[str]


@record
class Linked:
    """A program ready to evaluate (§9): its body's unit, the :class:`Linking` it runs under, and more."""

    fn: object
    linking: Linking
    variables: tuple[str, ...]
    box_fns: list
    sites: list[Site]
    how: str  # "linked" or "inlined"


SAMPLER_CAPACITY = 4096
LINKED_CAPACITY = 16  # linked programs kept (each holds its samplers); compiled units are kept


@record
class CompileCache:
    """Compiled units, linked programs and samplers (§9), owned by whoever evaluates: every
    function here takes one (``cache=``); the public ones default to :data:`CACHE`.

    ``units``: compiled unit by its key (a def's key names what its elaborated form depends on);
    ``linked``: linked programs by link key (bounded, the least recently used forgotten first);
    ``samplers``: one per canonical Ψ̂ (bounded); ``compiled``, ``hits``, ``last_link``: what
    :func:`cache_stats` reports."""

    units: dict = field(default_factory=dict)
    linked: dict = field(default_factory=dict)
    samplers: dict = field(default_factory=dict)
    compiled: list = field(default_factory=list)  # (kind, module, name) of every compilation
    hits: int = 0
    last_link: str | None = None

    def unit(self, key: tuple, term: Term, label: tuple, local: frozenset[str] | None = None) -> Unit:
        u = self.units.get(key)
        if u is None:
            u = self.units[key] = compile_term(term, local)
            self.compiled.append(label)
        else:
            self.hits += 1
        return u

    def sampler(self, psi: Diffeo, variables: tuple[str, ...]) -> SiteSampler:
        """A site's sampler, shared by every program with the same canonical Ψ̂ (a swap does not
        change the scene's conditions)."""
        key = (psi, variables)
        s = self.samplers.get(key)
        if s is None:
            s = remember(self.samplers, key, SiteSampler(psi, variables), SAMPLER_CAPACITY)
        return s

    def find(self, key) -> Linked | None:
        """The program linked before under ``key`` (§9: what was linked is not linked again)."""
        linked = self.linked.get(key)
        if linked is not None:
            self.hits += 1
            self.keep(key, linked)
        return linked

    def keep(self, key, linked: Linked) -> Linked:
        """Remember ``linked`` under ``key``, forgetting the oldest beyond LINKED_CAPACITY (a long
        session of swaps must not grow the heap without bound)."""
        self.linked.pop(key, None)  # (moved to the end: the least recently used is forgotten first)
        remember(self.linked, key, linked, LINKED_CAPACITY)
        self.last_link = linked.how
        return linked

    def stats(self) -> dict:
        """What was compiled (in order) since the last reset, how many lookups hit, and whether
        the last program was ``"linked"`` or evaluated ``"inlined"``."""
        return {"compiled": list(self.compiled), "hits": self.hits, "units": len(self.units),
                "last_link": self.last_link}

    def reset_stats(self) -> None:
        self.compiled.clear()
        self.hits = 0

    def clear(self) -> None:
        for table in (self.units, self.linked, self.samplers):
            table.clear()
        self.reset_stats()


#: The cache the public API (``operational.estimate_value`` and friends) uses unless given one.
CACHE = CompileCache()
cache_stats, reset_cache_stats, clear_cache = CACHE.stats, CACHE.reset_stats, CACHE.clear


# -- the inlined program ------------------------------------------------------------------------

def compile_program(program: Program, cache: CompileCache = CACHE) -> Linked:
    """Compile a pure core program (no ``Call``) once; cached by its content."""
    key = ("program", program)
    return cache.find(key) or cache.keep(key, _compile_inlined(program, cache))


def _compile_inlined(program: Program, cache: CompileCache) -> Linked:
    """The whole program as one unit, unlinked (§9: the inlined program Theorem 9.1 compares to)."""
    unit = cache.unit(("unit", program.body), program.body, ("program", None, None))
    return Linked(unit.fn, UNLINKED, program.variables, _box(program.box),
                  _canonical_sites(program, None, cache), "inlined")


def _box(box) -> list:
    """The box's bounds, each compiled as a unit of its own (pure core, run unlinked, §9)."""
    fns = compile_pure([t for bounds in box for t in bounds])[0]
    return list(zip(fns[::2], fns[1::2]))


# -- linking separately compiled modules --------------------------------------------------------

def link(loaded: Loaded, sites: str = "inlined", cache: CompileCache = CACHE) -> Linked:
    """Link ``loaded``'s main program from its modules' separately compiled defs (§9).

    ``sites`` chooses where the zero-set samplers come from: ``"inlined"`` (default) from the
    diffeomorphisms of ``Loaded.program`` matched by pre-order position, so that linked and inlined
    evaluation draw the same points and agree bit for bit; ``"defs"`` from each def's own Ψ̂,
    renamed and extended (fully separate, an equally unbiased but different parametrization of
    the same zero sets: the front end *re-completes* a def's conditions over the program's
    variables and box when it inlines, see langur.syntax.inline)."""
    _check_linkable(loaded, sites)
    keys = _def_keys(loaded)
    prog_key = ("program", loaded.main.name, loaded.main.source, _import_signature(loaded.main, loaded))
    link_key = ("link", sites, prog_key, frozenset(keys.items()))
    found = cache.find(link_key)
    if found:
        return found
    with gcpause.paused():  # compiling builds many closures and tables, few cycles (issue 15: ~6 % of MB1)
        return cache.keep(link_key, _link(loaded, sites, keys, prog_key, cache))


def _check_linkable(loaded: Loaded, sites: str) -> None:
    """A request §9's linker can serve: a known source of samplers, a main module with a program."""
    if sites not in ("inlined", "defs"):
        raise ValueError(f"sites must be 'inlined' or 'defs', not {sites!r}")
    if loaded.main.program is None or loaded.program is None:
        raise ValueError(f"module {loaded.main.name} has no program (no `int … d(…)`) to evaluate")


def _link(loaded: Loaded, sites: str, keys: dict, prog_key: tuple, cache: CompileCache) -> Linked:
    """§9's linker: compile every def and the program body separately (each once per key), number
    the sites, attach their samplers; the inlined program where linking cannot reproduce it."""
    main = loaded.main.program
    defs = {(m.name, d.name): d for m in loaded.modules.values() for d in m.defs.values()}
    units = _compile_defs(defs, keys, cache)
    body = cache.unit(prog_key, main.body, ("program", loaded.main.name, None))
    if not _linkable(body, units, defs):
        return compile_program(loaded.program, cache)
    offsets, table = _site_offsets(body, units, defs)
    if sites == "inlined":
        found = _canonical_sites(loaded.program, None, cache)
        if len(found) != offsets[-1] or loaded.program.variables != main.variables:
            return compile_program(loaded.program, cache)  # the inliner changed the structure
    else:
        found = _canonical_sites(main, defs, cache)
    return Linked(body.fn, Linking(0, offsets, table), main.variables, _box(_linked_box(loaded)), found,
                  "linked")


def _def_keys(loaded: Loaded) -> dict:
    """Each def's cache key: what its elaborated form depends on (§9)."""
    keys = {}
    for m in loaded.modules.values():
        sig = _import_signature(m, loaded)
        for d in m.defs.values():
            keys[(m.name, d.name)] = ("def", m.name, m.source, d.name, sig)
    return keys


def _compile_defs(defs: dict, keys: dict, cache: CompileCache) -> dict:
    """Every def compiled on its own (§9, separate compilation), once per key."""
    return {name: cache.unit(k, defs[name].body, ("def",) + name,
                             frozenset(a for a, kind in defs[name].args if kind == "param"))
            for name, k in keys.items()}


def _linked_box(loaded: Loaded) -> tuple:
    """The box the linked program integrates over (§9): the main program's own, unless a bound
    calls a def (then the inlined program's, whose bounds are pure core)."""
    box = loaded.main.program.box
    if any(isinstance(s, Call) for lo, hi in box for t in (lo, hi) for s in subterms(t)):
        return loaded.program.box
    return box


def _site_offsets(body: Unit, units: dict, defs: dict) -> tuple[list, dict]:
    """Global site numbering (§9: pre-order with calls expanded in place): the offsets of the
    program body's slots (last: its total) and, per def, ``(fn, its slots' offsets, argument
    names)`` for the linked calls."""
    counts: dict = {}

    def count(unit: Unit) -> list:
        offs, n = [], 0
        for kind, target, _ in unit.slots:
            offs.append(n)
            n += 1 if kind == "site" else total(target)
        offs.append(n)
        return offs

    def total(target) -> int:
        if target not in counts:
            counts[target] = count(units[target])
        return counts[target][-1]

    table = {}
    for name, u in units.items():
        d = defs[name]
        total(name)
        table[name] = (u.fn, counts[name], tuple(a for a, _ in d.args))
    return count(body), table


def _import_signature(m, loaded: Loaded) -> tuple:
    """What a module's elaborated form depends on besides its own text (§9): the signatures of
    what it imports (a def's argument kinds, a diffeo's definition), never their bodies."""
    out = []
    for local, (mod, name) in sorted(m.imports.items()):
        other = loaded.modules.get(mod)
        if other is None:
            out.append((local, mod, name, None))
        elif name in other.defs:
            out.append((local, mod, name, tuple(other.defs[name].args)))
        else:
            out.append((local, mod, name, other.diffeos.get(name)))
    return tuple(out)


def _linkable(body: Unit, units: dict, defs: dict) -> bool:
    """Every reachable call passes plain variables as its ``var`` arguments (§9, from the slots)."""
    seen, stack = set(), [body]
    while stack:
        for kind, target, plain in stack.pop().slots:
            if kind != "call":
                continue
            d = defs.get(target)
            if d is None:
                raise ValueError(f"unresolved call {target[0]}.{target[1]}")
            if any(k == "var" and not ok for ok, (_, k) in zip(plain, d.args)):
                return False
            if target not in seen:
                seen.add(target)
                stack.append(units[target])
    return True


def _canonical_sites(program: Program, defs: dict | None, cache: CompileCache) -> list[Site]:
    """Every site of ``program`` in §9's pre-order (calls expanded through ``defs``), with its sampler."""
    found: list[Site] = []
    collect_sites(program.body, {}, {}, program.variables, defs, found, cache)
    return found


def collect_sites(t: Term, varmap: dict, parammap: dict, variables: tuple[str, ...], defs, out: list,
                  cache: CompileCache | None = None) -> None:
    """Append the canonical site of every diffeomorphic conditional of ``t``, in pre-order (its
    sampler from ``cache``; without one, a sampler of its own)."""
    match t:
        case IfDiffeo():
            psi = t.psi
            ren = {v: Var(varmap[v]) for v in psi.variables if v in varmap and varmap[v] != v} if varmap else {}
            canon = substitute_diffeo(psi, ren, parammap) if ren or parammap else psi
            canon = extend_diffeo(canon, variables)
            sampler = SiteSampler(canon, variables) if cache is None else cache.sampler(canon, variables)
            out.append(Site(sampler, free_params(canon.forward[0])))
            for c in (t.then, t.orelse):
                if not c.shape[SMOOTH]:  # (a smooth branch has no site: not walked)
                    collect_sites(c, varmap, parammap, variables, defs, out, cache)
        case Let(name, bound, body):
            collect_sites(bound, varmap, parammap, variables, defs, out, cache)
            inner = {**parammap, name: substitute(bound, {}, parammap) if parammap else bound}
            collect_sites(body, varmap, inner, variables, defs, out, cache)
        case Call(module, name, args):
            d = defs[(module, name)]
            vm, pm = {}, {}
            for a, (argname, kind) in zip(args, d.args):
                if kind == "var":
                    vm[argname] = varmap.get(a.name, a.name)
                else:
                    pm[argname] = substitute(a, {}, parammap) if parammap else a
            collect_sites(d.body, vm, pm, variables, defs, out, cache)
        case _ if t.shape[SMOOTH]:  # (``smooth(t)``, read off the node's kept attributes)
            return  # no conditional and no call: no site below
        case Add() | Mul():  # (the spine of a sum of many conditionals: its smooth side not walked)
            for c in (t.left, t.right):
                if not c.shape[SMOOTH]:
                    collect_sites(c, varmap, parammap, variables, defs, out, cache)
        case _:
            for c in children(t):
                collect_sites(c, varmap, parammap, variables, defs, out, cache)
