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
"""

from __future__ import annotations

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


def call_elsewhere(scope: C.Scope, factor: S.STerm, used: list[str], params: list[str]) -> S.Apply | None:
    """``g(v…, T1, …)``, the def made of ``factor`` (its parameters ``used`` in order) called with
    other parameter terms ``Ti`` (:func:`_others`), the factor's zero sets that mention them
    registered at those terms; None when the factor has no parameter, or reads a ``let`` name
    (whose value the scope knows only at the defaults)."""
    if not used or T.names_in(factor) & (set(scope.env) - set(params)):
        return None
    sets = next((zs for f, zs in scope.made if f is factor), ())
    terms = []
    for p in used:
        options = _others(scope, p, params)
        if not options:
            return None
        terms.append(scope.pick(options))
    mapping = dict(zip(used, terms))
    again = {}
    for z in sets:
        if z.term is not None and T.names_in(z.term) & set(used):
            key = ("call", z.key, tuple(terms))
            again[key] = T.zero_set(T.substitute(z.term, mapping), scope.variables, scope.env, key=key)
    scope.zero_sets += list(again.values())
    return call("g", *(name(v) for v in scope.variables), *terms)
