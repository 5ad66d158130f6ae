"""Elaborating one module: a parsed ``ModuleS`` to an :class:`~langur.modules.ElaboratedModule` (§9).

Declarations are checked in order (LANGUAGE.md §6): ``from m import …`` (through a ``resolve``
callback supplied by ``langur.frontend``, which finds and elaborates ``m`` first), ``param``,
``diffeo`` (checked with sympy: ``langur.syntax.diffeo.check_declared``), ``def`` (bodies
desugared with calls left as links; defs may call defs declared anywhere in the module, but not
recursively), and the program (domain, body, box).  Every error found is collected; the caller
raises them together.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import fields, replace
from fractions import Fraction

from .. import lazy
from .. import typesys as ty
from ..core import INT_FRACTIONS, Call, Const, Diffeo, Interval, Program, Term, Var, subterms
from ..diagnostics import Diagnostic, Span
from ..modules import CoreDef, ElaboratedModule
from .desugar import Desugarer, is_smooth
from .folding import defined_everywhere, minus
from .scope import RESERVED, DefSig, DiffeoSig, Env, Scope
from .support import infer_box, numeric_box
from .surface import Apply, DefDecl, DiffeoDecl, ImportItem, ModuleS, ParamItem, ProgramS

#: The checker of declared diffeos (sympy), imported when a module declares one (``langur.lazy``).
diffeo = lazy.module("langur.syntax.diffeo")
#: ``langur.syntax.poles`` (sympy), imported when a body has a pole (``langur.lazy``).
poles = lazy.module("langur.syntax.poles")

#: ``resolve(module name, span of the import) -> Elaborated | None`` (None: already reported).
Resolver = Callable[[str, Span | None], "ElaboratedModule | None"]


def elaborate(mod: ModuleS, name: str, path: str, source: bytes, resolve: Resolver,
              errors: list[Diagnostic]) -> ElaboratedModule:
    """Elaborate ``mod``; diagnostics are appended to ``errors`` (the result is then partial)."""
    env = Env(module=name)
    ds = Desugarer(env, errors)
    declared: dict[str, Span | None] = {}  # module-level names: params, defs, diffeos, imports
    params: dict[str, Fraction | None] = {}
    imports: dict[str, tuple[str, str]] = {}
    diffeos: dict[str, Diffeo] = {}
    diffeo_params: dict[str, tuple[str, ...]] = {}
    defs: dict[str, CoreDef] = {}

    def declare(ident, what: str) -> bool:
        if ident.name in RESERVED:
            errors.append(ty.reject_duplicate(ident.span, f"{what} (shadows the built-in)", ident.name))
            return False
        if ident.name in declared:
            errors.append(ty.reject_duplicate(ident.span, what, ident.name, declared[ident.name]))
            return False
        declared[ident.name] = ident.span
        return True

    # pass 1: imports, params, def signatures (so that defs may be used before their declaration)
    def_items: list[DefDecl] = []
    for item in mod.items:
        if isinstance(item, ImportItem):
            other = resolve(item.module.name, item.module.span)
            for imp in item.names:
                local = imp.alias or imp.name
                if not declare(local, "imported name"):
                    continue
                if other is None:
                    env.poisoned.add(local.name)
                elif imp.name.name in other.defs:
                    d = other.defs[imp.name.name]
                    env.defs[local.name] = DefSig(other.name, d.name, d.args)
                    imports[local.name] = (other.name, imp.name.name)
                elif imp.name.name in other.diffeos:
                    ps = other.diffeo_params.get(imp.name.name, ())
                    env.diffeos[local.name] = DiffeoSig(other.diffeos[imp.name.name], ps)
                    imports[local.name] = (other.name, imp.name.name)
                else:
                    env.poisoned.add(local.name)
                    errors.append(ty.diag(imp.name.span, "T220", f"module `{other.name}` ({other.path}) has no def "
                                          f"or diffeo `{imp.name.name}`"))
        elif isinstance(item, ParamItem):
            for pd in item.decls:
                if declare(pd.name, "param"):
                    params[pd.name.name] = pd.default
        elif isinstance(item, DefDecl):
            if not declare(item.name, "def"):
                continue
            args, ok = _def_args(item, errors)
            if ok:
                env.defs[item.name.name] = DefSig(name, item.name.name, args)
                def_items.append(item)
            else:
                env.poisoned.add(item.name.name)
        elif isinstance(item, DiffeoDecl):
            if not declare(item.name, "diffeo"):
                continue
            psi = _diffeo(item, ds, errors)
            if psi is None:
                env.poisoned.add(item.name.name)
                continue
            ps = tuple(p.name for p in item.params)
            diffeos[item.name.name] = psi
            diffeo_params[item.name.name] = ps
            env.diffeos[item.name.name] = DiffeoSig(psi, ps)

    # pass 2: def bodies
    module_params = frozenset(params)
    for item in _dependency_order(def_items):
        sig = env.defs[item.name.name]
        var_args = tuple(n for n, k in sig.args if k == "var")
        for a in item.args:
            if a.kind == "var" and a.name.name in module_params:
                errors.append(ty.reject_var_param_clash(a.name.span, a.name.name, f"var argument of def "
                                                        f"`{item.name.name}` and a declared param"))
        gamma = (module_params | {n for n, k in sig.args if k == "param"}) - set(var_args)
        sc = Scope(variables=var_args, gamma=frozenset(gamma), in_program=False)
        body = _extended(ds.term(item.body, sc))  # removable poles: their extensions (zero33)
        defs[item.name.name] = CoreDef(name, item.name.name, sig.args, body, span=item.span)
        env.bodies[(name, item.name.name)] = defs[item.name.name]
    defs = {item.name.name: defs[item.name.name] for item in def_items}  # declaration order
    _check_recursion(name, defs, errors)

    program = _program(mod.program, ds, module_params, errors) if mod.program is not None else None
    return ElaboratedModule(name=name, path=path, source=source, params=params, diffeos=diffeos, defs=defs,
                      imports=imports, program=program, diffeo_params=diffeo_params)


def _dependency_order(items: list[DefDecl]) -> list[DefDecl]:
    """Defs ordered so that a def comes after the local defs it calls (declaration order
    otherwise; cycles are left in place for the recursion check)."""
    by_name = {d.name.name: d for d in items}
    out: list[DefDecl] = []
    state: dict[str, int] = {}

    def called(d: DefDecl) -> list[str]:
        found, stack = [], [d.body]
        while stack:
            u = stack.pop()
            if isinstance(u, Apply) and u.name in by_name and u.name not in found:
                found.append(u.name)
            for f in fields(u):
                v = getattr(u, f.name)
                for c in (v if isinstance(v, tuple) else (v,)):
                    if hasattr(c, "span") and not isinstance(c, (str, Span)):
                        stack.append(c)
        return found

    def visit(d: DefDecl) -> None:
        state[d.name.name] = 1
        for n in called(d):
            if state.get(n) is None:
                visit(by_name[n])
        state[d.name.name] = 2
        out.append(d)

    for d in items:
        if state.get(d.name.name) is None:
            visit(d)
    return out


def _def_args(item: DefDecl, errors) -> tuple[tuple[tuple[str, str], ...], bool]:
    seen: dict[str, Span | None] = {}
    ok = True
    for a in item.args:
        if a.name.name in seen:
            errors.append(ty.reject_duplicate(a.name.span, f"argument of def `{item.name.name}`", a.name.name,
                                              seen[a.name.name]))
            ok = False
        elif a.name.name == "pi":
            errors.append(ty.reject_duplicate(a.name.span, "argument (reserved constant)", "pi"))
            ok = False
        seen[a.name.name] = a.name.span
    return tuple((a.name.name, a.kind) for a in item.args), ok


def _diffeo(item: DiffeoDecl, ds: Desugarer, errors) -> Diffeo | None:
    """Desugar and check a diffeo declaration (T211, T212, T214–T216, T222)."""
    name = item.name.name
    n_err = len(errors)
    for group, what in ((item.variables, "variable"), (item.params, "parameter"), (item.inputs, "inverse input")):
        seen: dict[str, Span | None] = {}
        for ident in group:
            if ident.name in seen:
                errors.append(ty.reject_duplicate(ident.span, f"{what} of diffeo `{name}`", ident.name, seen[ident.name]))
            seen[ident.name] = ident.span
    pset = {p.name for p in item.params}
    for v in item.variables:
        if v.name in pset:
            errors.append(ty.reject_var_param_clash(v.span, v.name, f"variable and parameter of diffeo `{name}`"))
    if len(errors) > n_err:
        return None
    variables = tuple(v.name for v in item.variables)
    inputs = tuple(u.name for u in item.inputs)
    fwd_scope = Scope(variables=variables, gamma=frozenset(pset - set(variables)), where=f"diffeo `{name}`",
                      in_program=False)
    inv_scope = Scope(variables=inputs, gamma=frozenset(pset - set(inputs)), where=f"the inverse of diffeo `{name}`",
                      in_program=False)
    forward = tuple(ds.term(t, fwd_scope) for t in item.forward)
    inverse = tuple(ds.term(t, inv_scope) for t in item.inverse)
    for t in forward + inverse:
        if not is_smooth(t):
            errors.append(ty.reject_not_smooth(t.span or item.span, name, "conditionals, let and def calls "
                                               "are not allowed in its components"))
    if len(errors) > n_err:
        return None
    try:
        psi = diffeo.check_declared(name, variables, tuple(p.name for p in item.params), forward, inputs, inverse)
    except diffeo.DiffeoCheckError as e:
        errors.append(ty.diag(item.name.span or item.span, e.code, str(e)))
        return None
    return replace(psi, span=item.span)


def _check_recursion(module: str, defs: dict[str, CoreDef], errors) -> None:
    calls = {n: [u.name for u in subterms(d.body) if isinstance(u, Call) and u.module == module]
             for n, d in defs.items()}
    state: dict[str, int] = {}

    def visit(n: str, path: list[str]) -> None:
        state[n] = 1
        for m in calls.get(n, ()):
            if state.get(m) == 1:
                errors.append(ty.reject_recursive(defs[n].span, path[path.index(m):] + [n, m] if m in path
                                                  else path + [n, m]))
            elif m in calls and state.get(m) is None:
                visit(m, path + [n])
        state[n] = 2

    for n in defs:
        if state.get(n) is None:
            visit(n, [])


def _extended(t: Term) -> Term:
    """``t`` with its removable poles extended (:func:`langur.syntax.poles.extended`: the term both
    engines evaluate on a jump's zero set, Fig. 8); sympy only when ``t`` is not defined everywhere."""
    return t if defined_everywhere(t) else poles.extended(t)


def _program(p: ProgramS, ds: Desugarer, module_params: frozenset[str], errors) -> Program | None:
    """``int domain? t d(x⃗)``: the integrand, the domain as data, and the box (§8.3)."""
    variables: list[str] = []
    seen: dict[str, Span | None] = {}
    n_err = len(errors)
    for v in p.variables:
        if v.name in seen:
            errors.append(ty.reject_duplicate(v.span, "integration variable", v.name, seen[v.name]))
            continue
        if v.name in module_params:
            errors.append(ty.reject_var_param_clash(v.span, v.name, "integration variable and declared param"))
        if v.name == "pi":
            errors.append(ty.reject_duplicate(v.span, "integration variable (reserved constant)", "pi"))
        seen[v.name] = v.span
        variables.append(v.name)
    xs = tuple(variables)
    box = None
    domain: list[Interval] = []
    if p.domain is not None:
        if len(p.domain) != len(xs):
            errors.append(ty.diag(p.domain[0].span if p.domain else p.span, "T203",
                                  f"the domain has {len(p.domain)} interval(s) but d(…) has {len(xs)} variable(s)"))
        else:
            bound_scope = Scope(variables=(), gamma=module_params, where="a domain bound", hidden_vars=frozenset(xs))
            box = tuple((ds.term(iv.lo, bound_scope), ds.term(iv.hi, bound_scope)) for iv in p.domain)
    if len(errors) > n_err:
        return None
    sc = Scope(variables=xs, gamma=module_params - set(xs),
               box=numeric_box(xs, box) if box is not None else ())
    if box is None:  # the box is read off the body: conditions that need it wait for it
        ds.pending = []
    body = ds.term(p.body, sc)
    if box is None:
        inferred = infer_box(body, xs)
        missing = [x for x, (lo, hi) in zip(xs, inferred) if lo is None or hi is None]
        if not missing:
            box = tuple(inferred)
        body = ds.complete_pending(body, xs, numeric_box(xs, box) if box is not None else ())
        if missing:
            errors.append(ty.reject_not_compact(p.span, missing))
            return None
    else:
        # int ([l1, u1], …) t d(x⃗)  is  int [x1 ≥ l1]·[u1 ≥ x1]·…·t d(x⃗): the domain is kept as
        # data, its conditions completed here; Program.body builds the indicators
        one, zero = Const(INT_FRACTIONS[1]), Const(INT_FRACTIONS[0])
        for x, (lo, hi), iv in zip(xs, box, p.domain):
            lower, upper = (ds.conditional(cond, one, zero, sc, p.span, iv.span)
                            for cond in (minus(Var(x), lo), minus(hi, Var(x))))  # ([x - 0 >= 0] is [x >= 0])
            domain.append(Interval(x, lo, hi, lower, upper, span=iv.span))
        if len(errors) > n_err:
            return None
    # removable poles: their continuous extensions, the term both engines evaluate (zero33)
    return Program(integrand=_extended(body), variables=xs, box=box, domain=tuple(domain), span=p.span)

