"""An implicit root to the precision sympy asks (its ``evalf``; paper §7.2: a point of an inverse
branch Ψ̂⁻¹, in the closed forms of ⟦p⟧ and ⦇p⦈; issue 18).

:func:`evalf_root` bisects ``f − target`` with mpmath (:func:`langur.implicit.solvers.bracketed_root`)
on a bracket where it changes sign: for the unique root, the whole piece; for the k-th sign
change, a bracket certified to hold exactly one by interval enclosures
(:func:`langur.enclosures.certified_brackets`), or for a polynomial equation isolated exactly by
its Sturm sequence (:func:`langur.sturm.sturm_brackets`).  The equation is compiled once for all
values of its float constants (:func:`_shape`) and once for every build of it under a new bound
variable (:func:`_canonical_shape`, issue 15).
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import lru_cache

import mpmath
import sympy as sp

from langur.core import TooManyRoots
from langur.enclosures import DEPTH, certified_brackets, interval_function
from langur.implicit.equations import COUNTED, LENIENT, NODES, form, polynomial_coefficients, too_many_roots
from langur.implicit.solvers import bracketed_root
from langur.memo import remember
from langur.sturm import sturm_brackets


@lru_cache(maxsize=4096)
def evalf_root(args, prec):
    """``ImplicitRootFn(*args)`` (free of symbols) as a sympy Float of ``prec`` bits (module doc);
    NaN where ``target`` is not between the bracket's values, the bracket's upper end for a sign
    change beyond the last one there."""
    lam, target, lo, hi, index, of = args
    (x,), f = lam.variables, lam.expr
    shape, consts = _shape(f)
    x, shape = _canonical_shape(x, shape)
    dps = mpmath.libmp.prec_to_dps(prec) + 5
    with mpmath.workdps(dps):
        compiled = _shape_compiled(x, shape, len(consts))[0]
        values = [mpmath.mpf(c._mpf_) for c in consts]
        fn = lambda z: compiled(z, *values)  # noqa: E731
        t, a, b = (mpmath.mpf(sp.Float(v.evalf(dps), dps)) for v in (target, lo, hi))
        if index >= 0:  # the index-th of the certified brackets of the sign changes, then bisected
            most = max(int(of), COUNTED)
            brackets = [(mpmath.mpf(p), mpmath.mpf(q)) for p, q in _brackets_at(x, shape, consts, float(t), float(a),
                                                                                   float(b), most)]
            if len(brackets) > of:  # (past ``most``, the first ones only: _brackets_at stops there)
                raise too_many_roots(len(brackets), float(a), float(b), of, x, at_least=len(brackets) > most)
            if index >= len(brackets):
                return sp.Float(b, dps)
            a, b = brackets[int(index)]
        r = bracketed_root(fn, t, a, b, bits=prec + 10)
        if isinstance(r, float) and math.isnan(r):
            return sp.nan
        return sp.Float(r, dps)


#: The first ``(bound variable, shape)`` of each :func:`~langur.implicit.equations.form`; at most
#: :data:`SHAPES` kept (then forgotten all at once).
_SHAPES: dict = {}
SHAPES = 4096


def _canonical_shape(x, shape) -> tuple:
    """The first ``(x, shape)`` (:func:`_shape`) of the same form as this one
    (:func:`~langur.implicit.equations.form`: the
    same equation up to the identity of its bound variable, of the same name, assumptions, source
    place and leniency): its compiled versions (:func:`_shape_compiled`) and certified brackets
    (:func:`_brackets_at`) are this one's — the same code but for the bound variable's name — and
    are made once instead of once per build of ⟦p⟧ or ⦇p⦈ (issue 15, exact13t)."""
    key = form(sp.Lambda(x, shape), ())
    if key is None:
        return x, shape
    known = _SHAPES.get(key)
    return known if known is not None else remember(_SHAPES, key, (x, shape), SHAPES, at_once=True)


#: Placeholders of the float constants of an equation (:func:`_shape`).
_PLACEHOLDERS = [sp.Symbol(f"_langur_c{i}", real=True) for i in range(64)]


@lru_cache(maxsize=4096)
def _shape(f: sp.Expr) -> tuple:
    """``f`` with its float constants (outside exponents) replaced by placeholders, and those
    constants: an equation whose parameters (or a linter's spot values) were put in as numbers
    is compiled once for all of their values (:func:`_shape_compiled`), not once per value."""
    consts: list = []

    def walk(e):
        if isinstance(e, sp.Float) and len(consts) < len(_PLACEHOLDERS):
            consts.append(e)
            return _PLACEHOLDERS[len(consts) - 1]
        if not e.args:
            return e
        if isinstance(e, sp.Pow) and e.exp.is_Number:
            return sp.Pow(walk(e.base), e.exp)
        return e.func(*[walk(a) for a in e.args])
    try:
        return walk(f), tuple(consts)
    except (TypeError, ValueError):  # a node that cannot be rebuilt: the equation as it is
        return f, ()


@lru_cache(maxsize=1024)
def _shape_compiled(x, shape: sp.Expr, n: int) -> tuple:
    """The equation ``shape`` (:func:`_shape`) on mpmath numbers, and its and its derivative's
    interval versions, each called as ``(x, *constants)``."""
    cs = _PLACEHOLDERS[:n]
    return (sp.lambdify([x, *cs], shape, modules="mpmath"), interval_function(x, shape, cs),
            interval_function(x, sp.diff(shape, x), cs))


@lru_cache(maxsize=4096)
def _brackets_at(x, shape, consts: tuple, t: float, a: float, b: float, most: int | None = None) -> tuple:
    """The certified brackets of the sign changes of ``f − t`` (``f`` in ``x`` only: ``shape``
    with the constants ``consts``, :func:`_shape`) on ``[a, b]``, found once for every index and
    precision: in double precision, since the certificate does not depend on the precision the
    root is wanted in.  More than ``most`` of them: the first ones only (``certified_brackets``)."""
    coefficients = polynomial_coefficients(x, shape, tuple(_PLACEHOLDERS[:len(consts)]))
    if coefficients is not None and all(math.isfinite(v) for v in (t, a, b)):
        # a polynomial: its sign changes isolated exactly (no enclosure), unless two roots (or a
        # root and an end) are closer than the enclosures' resolution, where those decide (refuse)
        poly = [Fraction(c) for c in coefficients(*(Fraction(*sp.Rational(c).as_numer_denom()) for c in consts))]
        poly[-1] -= Fraction(t)
        found = sturm_brackets(poly, Fraction(a), Fraction(b), depth=DEPTH + 4, squarefree=True)
        if found is not None and all(float(p) == p and float(q) == q for p, q in found):
            return tuple((float(p), float(q)) for p, q in found)
    fn, g_iv, dg_iv = _shape_compiled(x, shape, len(consts))
    with mpmath.workprec(53):
        mp = [mpmath.mpf(c._mpf_) for c in consts]
        iv = [mpmath.iv.mpf(str(sp.Float(c, c._prec)).strip()) for c in consts]  # enclosing the constants
        try:
            found = certified_brackets(lambda z: fn(z, *mp), g_iv.bind(*iv), dg_iv.bind(*iv), t, a, b,
                                       what=f"{shape.xreplace(dict(zip(_PLACEHOLDERS, consts)))}",
                                       lenient=x in LENIENT, most=most)
        except TooManyRoots as err:
            raise TooManyRoots(str(err), NODES.get(x)) from None
    return tuple((float(p), float(q)) for p, q in found)
