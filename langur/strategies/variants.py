"""Whole-program variants only ``programs(wide=True)`` draws (fuzz30): what the builders of
:mod:`.conditions` and :mod:`.wide` could not reach from inside one factor.

* negative parameter defaults (``param b = -0.61``): a parametric coefficient of either sign
  (``P*v CMP k`` is completed by dividing by ``P``: its direction flips with the sign), levels
  below the box, ``sin(3*P*v)`` turning the other way; where a primitive's domain needs a
  positive parameter term the builders write ``-P`` (:meth:`~.conditions.Scope.positive`), and
  the box's moving ends and ``let s = …`` use the positive parameters only (boxes stay in [-1, 2]);
* programs without parameters (LANGUAGE.md §6: ``param`` declarations are optional): every
  parameter replaced by its default as a literal, so only ⟦p⟧ is compared, conditions on
  parameters alone become conditions on constants and a def's param arguments are literals;
* a ``def`` called at a second site with *other* parameter terms (``g(x, y, a)`` and ``g(x, y, a +
  0.3)``): two sets of zero sets from one body, which the Monte Carlo engine compiles once and
  links twice (§9, Theorem 9.1) and the front end inlines twice; the body's zero sets are
  registered again at the new terms, so the program stays generic at its defaults.

fuzz31 added:

* a def whose body reads a ``let`` called at two parameter terms: a ``let tN = <parameter term> in
  …`` inside the def's body (:func:`~.wide.let_level`), so that the let's value and its tangent
  (Fig. 8, let: γ′[z ↦ ⦇t⦈]) differ between the sites, or the program's own ``let s = …`` passed to
  the def as a parameter argument (``g(x, s)`` and ``g(x, s + 0.3)``); the let's zero sets are
  registered at each site's value of its bound (:func:`call_elsewhere`);
* modules (§9, separate compilation): the def in a library module imported by name, under another
  name (``from lib import f as g``), or through a second library (``lib`` imports ``h`` from
  ``lib2`` and defines ``g`` as a call of it), and the declared diffeos in a module of their own
  (``from geo import sh``): :func:`modular`.
"""

from __future__ import annotations

import itertools
from fractions import Fraction as F

from hypothesis import strategies as st

from ..syntax import surface as S
from . import conditions as C
from . import terms as T
from .terms import call, mul, name, num, offset

#: A parameter term a def is called with at its second site keeps the sign of the first one's
#: value and a magnitude of at most this (``acos(P*v/3)`` stays in its domain: :data:`.wide.ACOS_SCALE`).
LARGEST = 1.4


def signed(draw, defaults: list[F]) -> list[F]:
    """Each default negated with chance ¼ (shrinks to the positive one)."""
    return [-d if draw(st.integers(0, 3)) == 3 else d for d in defaults]


def bare(draw) -> bool:
    """Whether the program is drawn without parameters (one in four; shrinks to with)."""
    return draw(st.integers(0, 3)) == 3


def without_parameters(module: S.ModuleS, params: dict[str, F]) -> S.ModuleS:
    """``module`` without its ``param`` declaration, each parameter in the program (body, box and
    the call sites' parameter arguments) replaced by its default as a literal.  Declared diffeos and
    defs keep their own parameter names (a def's body reads only its arguments)."""
    p = module.program
    literals = {n: num(d) for n, d in params.items()}
    domain = None if p.domain is None else tuple(
        S.Interval(T.substitute(i.lo, literals), T.substitute(i.hi, literals)) for i in p.domain)
    program = S.ProgramS(domain, T.substitute(p.body, literals), p.variables)
    items = tuple(i for i in module.items if not isinstance(i, S.ParamItem))
    return S.ModuleS(module.path, items, program)


def _others(scope: C.Scope, p: str, params: list[str]) -> list[S.STerm]:
    """Parameter terms for ``p`` at a second call site: ``p + 0.3``, ``p - 0.15``, ``2*p``, another
    parameter; each of the sign of ``p``'s value, another value, at most :data:`LARGEST` in size."""
    x = scope.env[p]
    terms = [offset(name(p), F(3, 10)), offset(name(p), F(-3, 20)), mul(num(2), name(p)),
             *(name(q) for q in params if q != p)]
    return [t for t in terms if (v := T.evaluate(t, scope.env)) * x > 0 and v != x and abs(v) <= LARGEST]


def _kept(scope: C.Scope, t: str, bound: S.STerm) -> bool:
    """Whether the let ``t`` bound to ``bound`` keeps its sign and is at most :data:`LARGEST`."""
    v = T.evaluate(bound, scope.env)
    return v * scope.env[t] > 0 and abs(v) <= LARGEST


def call_elsewhere(scope: C.Scope, factor: S.STerm, used: list[str], params: list[str]) -> S.Apply | None:
    """``g(v…, T1, …)``, the def made of ``factor`` (its parameter terms ``used`` in order: parameters
    or the program's ``let`` name) called with other parameter terms ``Ti`` (:func:`_others` among
    ``params``), the factor's zero sets that mention them registered at those terms.  A ``let``
    bound inside the factor (:attr:`~.conditions.Scope.lets`, its bound over parameters only) is
    registered at its bound's value at the new terms, which must keep the let's sign and be at most
    :data:`LARGEST` in size (the body's primitives stay in their domains).  None when the factor
    has no parameter term or reads a name of neither kind."""
    reads = T.names_in(factor) & (set(scope.env) - set(params) - set(used))
    if not used or any(t not in scope.lets or T.names_in(scope.lets[t]) - set(params) - set(used)
                       for t in reads):
        return None
    sets = next((zs for f, zs in scope.made if f is factor), ())
    choices = [dict(zip(used, terms)) for terms in itertools.product(*(_others(scope, p, params) for p in used))]
    for mapping in choices:  # the lets inside the body, at the new terms
        for t in sorted(reads):
            mapping[t] = T.substitute(scope.lets[t], mapping)
    choices = [m for m in choices if all(_kept(scope, t, m[t]) for t in reads)]
    if not choices:
        return None
    mapping = scope.pick(choices)
    terms = [mapping[p] for p in used]
    again = {}
    for z in sets:
        if z.term is not None and T.names_in(z.term) & set(mapping):
            key = ("call", z.key, tuple(terms))
            again[key] = T.zero_set(T.substitute(z.term, mapping), scope.variables, scope.env, key=key)
    scope.zero_sets += list(again.values())
    return call("g", *(name(v) for v in scope.variables), *terms)


#: The library modules :func:`modular` writes: the def's, the one it may call through, the diffeos'.
LIBRARY, SECOND, GEOMETRY = "lib", "lib2", "geo"


def _imports(module: str, *names: str | tuple[str, str]) -> S.ImportItem:
    """``from module import a, b as c`` (a pair is a name and its alias)."""
    return S.ImportItem(S.Ident(module), tuple(
        S.ImportName(S.Ident(n), None) if isinstance(n, str) else S.ImportName(S.Ident(n[0]), S.Ident(n[1]))
        for n in names))


def modular(draw, d: S.DefDecl, diffeos: tuple[S.DiffeoDecl, ...]):
    """The def ``d`` (named ``g``) moved to a library module (§9: modules are compiled separately and
    linked), in one of three ways: ``from lib import g``; ``from lib import f as g`` (``lib``
    defines ``f``); ``lib`` imports ``h`` from ``lib2`` (which defines it) and defines ``g(args) =
    h(args)``; and maybe the declared ``diffeos`` moved to a module ``geo`` of their own.  Returns
    ``(libraries, imports, diffeos left in the main module)``: ``libraries`` as (name, module)
    pairs, ``imports`` the main module's import items."""
    kind = draw(st.integers(0, 2))
    if kind == 0:
        libraries = [(LIBRARY, S.ModuleS(f"{LIBRARY}.lgr", (d,), None))]
        imports = [_imports(LIBRARY, "g")]
    elif kind == 1:
        f = S.DefDecl(S.Ident("f"), d.args, d.body)
        libraries = [(LIBRARY, S.ModuleS(f"{LIBRARY}.lgr", (f,), None))]
        imports = [_imports(LIBRARY, ("f", "g"))]
    else:
        h = S.DefDecl(S.Ident("h"), d.args, d.body)
        g = S.DefDecl(d.name, d.args, call("h", *(name(a.name.name) for a in d.args)))
        libraries = [(LIBRARY, S.ModuleS(f"{LIBRARY}.lgr", (_imports(SECOND, "h"), g), None)),
                     (SECOND, S.ModuleS(f"{SECOND}.lgr", (h,), None))]
        imports = [_imports(LIBRARY, "g")]
    if diffeos and draw(st.booleans()):
        libraries.append((GEOMETRY, S.ModuleS(f"{GEOMETRY}.lgr", diffeos, None)))
        imports.append(_imports(GEOMETRY, *(x.name.name for x in diffeos)))
        diffeos = ()
    return tuple(libraries), imports, diffeos
