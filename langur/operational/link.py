"""Separate compilation and linking (§9, Theorem 9.1: compositional evaluation).

Every module's elaborated form (``Loaded.modules[name]``: its defs with ``Call`` links and its
program) is compiled *per def* into a :class:`~langur.operational.compile.Unit` and cached under
a key made of the def's content: ``(module source_hash, CoreDef)`` (structural equality and
hashing of the frozen dataclasses; spans take no part).  A program is *linked* from compiled parts: a ``Call`` node evaluates its ``param``
arguments once in the caller (value and tangent, exactly as a ``let`` would) and runs the callee's
compiled body in an environment where its ``var`` arguments are renamings of the caller's
variables.  Swapping a module (``load(path, modules={"shader": ...})``) changes that module's
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

from dataclasses import dataclass, field

from ..core import (Call, Diffeo, IfDiffeo, Let, Program, Term, Var, children, extend_diffeo, free_params,
                    substitute, substitute_diffeo, subterms)
from ..modules import Loaded
from .compile import Unit, compile_term
from .sample import SiteSampler


@dataclass
class Site:
    """One delta: its canonical Ψ̂'s sampler and the program parameters its condition reads."""

    sampler: SiteSampler
    deps: frozenset[str]


@dataclass
class Linked:
    """A program ready to evaluate: its body's compiled unit and everything it links to."""

    fn: object
    offsets: list | None
    units: dict
    variables: tuple[str, ...]
    box_fns: list
    sites: list[Site]
    how: str  # "linked" or "inlined"


@dataclass
class CompileCache:
    units: dict = field(default_factory=dict)
    linked: dict = field(default_factory=dict)
    samplers: dict = field(default_factory=dict)
    compiled: list = field(default_factory=list)  # (kind, module, name) of every compilation
    hits: int = 0
    last_link: str | None = None


CACHE = CompileCache()


def cache_stats() -> dict:
    """What the cache compiled (in order) since the last reset, how many lookups hit it, and
    whether the last program was ``"linked"`` or evaluated ``"inlined"``."""
    return {"compiled": list(CACHE.compiled), "hits": CACHE.hits, "units": len(CACHE.units),
            "last_link": CACHE.last_link}


def reset_cache_stats() -> None:
    CACHE.compiled.clear()
    CACHE.hits = 0


def clear_cache() -> None:
    CACHE.units.clear()
    CACHE.linked.clear()
    CACHE.samplers.clear()
    reset_cache_stats()


def _unit(key: tuple, term: Term, label: tuple) -> Unit:
    u = CACHE.units.get(key)
    if u is None:
        u = compile_term(term)
        CACHE.units[key] = u
        CACHE.compiled.append(label)
    else:
        CACHE.hits += 1
    return u


def _sampler(psi: Diffeo, variables: tuple[str, ...]) -> SiteSampler:
    k = (psi, variables)
    s = CACHE.samplers.get(k)
    if s is None:
        s = CACHE.samplers[k] = SiteSampler(psi, variables)
    return s


# -- the inlined program ------------------------------------------------------------------------

def compile_program(program: Program) -> Linked:
    """Compile a pure core program (no ``Call``) once; cached by its content."""
    key = ("program", program)
    hit = CACHE.linked.get(key)
    if hit is not None:
        CACHE.hits += 1
        CACHE.last_link = "inlined"
        return hit
    unit = _unit(("unit", program.body), program.body, ("program", None, None))
    sites = []
    collect_sites(program.body, {}, {}, program.variables, None, sites)
    linked = Linked(unit.fn, None, {}, program.variables, _box(program), sites, "inlined")
    CACHE.linked[key] = linked
    CACHE.last_link = "inlined"
    return linked


def _box(program: Program) -> list:
    return [(compile_term(lo).fn, compile_term(hi).fn) for lo, hi in program.box]


# -- linking separately compiled modules --------------------------------------------------------

def link(loaded: Loaded, sites: str = "inlined") -> Linked:
    """Link ``loaded``'s main program from its modules' separately compiled defs.

    ``sites`` chooses where the zero-set samplers come from: ``"inlined"`` (default) from the
    diffeomorphisms of ``Loaded.program`` matched by pre-order position, so that linked and inlined
    evaluation draw the same points and agree bit for bit; ``"defs"`` from each def's own Ψ̂,
    renamed and extended (fully separate, an equally unbiased but different parametrization of
    the same zero sets: the front end *re-completes* a def's conditions over the program's
    variables and box when it inlines, see langur.syntax.inline)."""
    if sites not in ("inlined", "defs"):
        raise ValueError(f"sites must be 'inlined' or 'defs', not {sites!r}")
    main = loaded.main
    if main.program is None or loaded.program is None:
        raise ValueError(f"module {main.name} has no program (no `int … d(…)`) to evaluate")
    keys = {}
    for m in loaded.modules.values():
        for d in m.defs.values():
            keys[(m.name, d.name)] = ("def", m.source_hash, d)
    prog_key = ("program", main.source_hash, main.program)
    defs = {(m.name, d.name): d for m in loaded.modules.values() for d in m.defs.values()}
    if not _linkable(main.program, defs):
        return compile_program(loaded.program)
    link_key = ("link", sites, prog_key, frozenset(keys.items()))
    hit = CACHE.linked.get(link_key)
    if hit is not None:
        CACHE.hits += 1
        CACHE.last_link = "linked"
        return hit
    units = {name: _unit(k, defs[name].body, ("def",) + name) for name, k in keys.items()}
    body = _unit(prog_key, main.program.body, ("program", main.name, None))
    counts: dict = {}

    def count(unit: Unit) -> list:
        """Offsets of the unit's slots within its own sites, and (last) its total."""
        offs, n = [], 0
        for kind, target in unit.slots:
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
        table[name] = (u.fn, counts[name], tuple(a for a, _ in d.args), tuple(k for _, k in d.args))
    found: list[Site] = []
    collect_sites(main.program.body, {}, {}, main.program.variables, defs, found)
    if sites == "inlined":
        inl: list[Site] = []
        collect_sites(loaded.program.body, {}, {}, loaded.program.variables, None, inl)
        if len(inl) != len(found) or loaded.program.variables != main.program.variables:
            return compile_program(loaded.program)  # the inliner changed the structure: evaluate it
        found = inl
    box = main.program.box
    if any(isinstance(s, Call) for lo, hi in box for t in (lo, hi) for s in subterms(t)):
        box = loaded.program.box
    linked = Linked(body.fn, count(body), table, main.program.variables,
                    [(compile_term(lo).fn, compile_term(hi).fn) for lo, hi in box], found, "linked")
    CACHE.linked[link_key] = linked
    CACHE.last_link = "linked"
    return linked


def _linkable(program: Program, defs: dict) -> bool:
    """Every reachable call passes plain variables as its ``var`` arguments."""
    seen, stack = set(), [program.body]
    while stack:
        for t in subterms(stack.pop()):
            if isinstance(t, Call):
                d = defs.get((t.module, t.name))
                if d is None:
                    raise ValueError(f"unresolved call {t.module}.{t.name}")
                for a, (_, kind) in zip(t.args, d.args):
                    if kind == "var" and not isinstance(a, Var):
                        return False
                if (t.module, t.name) not in seen:
                    seen.add((t.module, t.name))
                    stack.append(d.body)
    return True


def collect_sites(t: Term, varmap: dict, parammap: dict, variables: tuple[str, ...], defs, out: list) -> None:
    """Append the canonical site of every diffeomorphic conditional of ``t``, in pre-order."""
    match t:
        case IfDiffeo(psi, then, orelse):
            ren = {v: Var(varmap[v]) for v in psi.variables if v in varmap and varmap[v] != v}
            canon = substitute_diffeo(psi, ren, parammap) if ren or parammap else psi
            canon = extend_diffeo(canon, variables)
            out.append(Site(_sampler(canon, variables), free_params(canon.forward[0])))
            collect_sites(then, varmap, parammap, variables, defs, out)
            collect_sites(orelse, varmap, parammap, variables, defs, out)
        case Let(name, bound, body):
            collect_sites(bound, varmap, parammap, variables, defs, out)
            inner = {**parammap, name: substitute(bound, {}, parammap) if parammap else bound}
            collect_sites(body, varmap, inner, variables, defs, out)
        case Call(module, name, args):
            d = defs[(module, name)]
            vm, pm = {}, {}
            for a, (argname, kind) in zip(args, d.args):
                if kind == "var":
                    vm[argname] = varmap.get(a.name, a.name)
                else:
                    pm[argname] = substitute(a, {}, parammap) if parammap else a
            collect_sites(d.body, vm, pm, variables, defs, out)
        case _:
            for c in children(t):
                collect_sites(c, varmap, parammap, variables, defs, out)
