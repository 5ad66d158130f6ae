"""The implicit root ``x*`` of :class:`langur.core.ImplicitRoot` as a sympy function (issue 18).

``ImplicitRootFn(Lambda(x, f), target, lo, hi, -1, 0)`` is the one ``x`` in ``[lo, hi]`` with
``f(x) = target``, ``f`` strictly monotone on ``[lo, hi]`` (an inverse branch of a condition
between two of its turning points, :mod:`langur.syntax.turning`); with an index k ≥ 0 and a
bound n it is the k-th sign change of ``f − target`` on ``[lo, hi]`` (a turning point that moves
with the parameters).  It stays symbolic in the exact engine's closed forms; its derivative is
the implicit function theorem's,

    ∂x*/∂s = (∂target/∂s − ∂f/∂s(x*)) / ∂f/∂x(x*),

so every derivative (and the Jacobian dx*/du₀ = 1/f'(x*) of the delta's change of variables) is
exact in terms of ``x*``; ``evalf`` finds ``x*`` to the requested precision by bisection with
mpmath (on a bracket where ``f − target`` changes sign: for the unique root, the whole piece;
for the k-th sign change, a bracket certified to hold exactly one by interval enclosures,
:func:`langur.enclosures.certified_brackets`, or for a polynomial equation isolated exactly by
its Sturm sequence, :func:`langur.sturm.sturm_brackets`), and ``lambdify`` calls the same solver
on the compiled ``f``.  The Monte Carlo engine has its own vectorized solver (no sympy
there: ``langur.operational.compile``).
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter
from sympy.printing.str import StrPrinter

from . import lazy
from .core import TooManyRoots
from .enclosures import DEPTH, _interval_fn, certified_brackets
from .memo import make_room, remember
from .sturm import sturm_brackets


def bracketed_root(f, target, lo, hi, bits: int = 53):
    """The ``x`` in ``[lo, hi]`` with ``f(x) = target`` for ``f`` monotone there, to within
    ``|hi − lo|·2^−(bits + 8)`` (so the result has full precision in that many bits): false
    position with the Illinois rule, the bracket halved whenever two steps did not halve it;
    NaN when ``target`` is not between ``f(lo)`` and ``f(hi)`` (no root there)."""
    try:
        a, b = lo, hi
        fa, fb = f(a) - target, f(b) - target
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        return math.nan
    if fa == 0:
        return a
    if fb == 0:
        return b
    if not (fa < 0) ^ (fb < 0):
        return math.nan
    tol = abs(hi - lo) / 2 ** (bits + 8)
    side = 0  # the end kept by the last step (Illinois: its value is halved when kept twice)
    width = b - a
    for i in range(3 * (bits + 8) + 64):
        if not b - a > tol:
            break
        # false position (Illinois), or a halving when the last two steps did not halve the bracket
        m = (a + b) / 2 if i % 2 == 0 and b - a > width / 2 else a - fa * (b - a) / (fb - fa)
        if i % 2 == 0:
            width = b - a
        if not a < m < b:
            m = (a + b) / 2
            if m == a or m == b:
                break
        fm = f(m) - target
        if fm == 0:
            return m
        if (fm < 0) == (fa < 0):
            a, fa = m, fm
            if side == -1:
                fb /= 2
            side = -1
        else:
            b, fb = m, fm
            if side == 1:
                fa /= 2
            side = 1
    return (a + b) / 2


def double_root(f, target, lo, hi, args: tuple = ()):
    """:func:`bracketed_root` in double precision, by Brent's method (scipy's ``brentq``: ~10
    evaluations of ``f`` instead of ~60 halvings; the same root to within a few units in the
    last place); bisection where ``f`` fails inside the bracket.  ``f`` is called as
    ``f(x, *args)`` (no closure per root: a quadrature asks for tens of thousands)."""
    try:
        a, b = float(lo), float(hi)
        fa, fb = float(f(a, *args)) - target, float(f(b, *args)) - target
    except (ValueError, ZeroDivisionError, OverflowError, TypeError):
        return math.nan
    if fa == 0:
        return a
    if fb == 0:
        return b
    if math.isnan(fa) or math.isnan(fb) or not (fa < 0) ^ (fb < 0):
        return math.nan
    try:
        # scipy's C routine itself, as ``so.brentq`` calls it with these tolerances (its wrapper
        # only checks them and raises on NaN, which ``_root_value`` already does): the same root
        return _BRENTQ(_root_value, a, b, 1e-300, _RTOL, _MAXITER, (f, target, args), False, True)
    except (ValueError, ZeroDivisionError, OverflowError, TypeError, RuntimeError):
        return bracketed_root(lambda z: f(z, *args), target, lo, hi)


def _root_value(z, f, target, args):
    """``f(z, *args) − target`` for Brent's method, raising where it is NaN."""
    v = float(f(z, *args)) - target
    if v != v:
        raise ValueError
    return v


#: Brent's method as ``so.brentq`` runs it (its relative tolerance and iteration limit).
_RTOL = 4 * np.finfo(float).eps
_MAXITER = 100

# scipy.optimize, imported when a root is first solved (``langur.lazy``): its import (linprog,
# linalg, …) costs ~0.3 s, and the commands that import this module through ``sympy_bridge`` for
# an analysis that solves no implicit root (``deriv --engine mc`` of an affine program) never need it.
so = lazy.module("scipy.optimize")
_zeros = lazy.module("scipy.optimize._zeros")


def _BRENTQ(g, a, b, xtol, rtol, maxiter, args, full_output, disp):
    """scipy's C routine of Brent's method (resolved at the first call, then called directly);
    its public wrapper, the same root, for a scipy without it."""
    global _BRENTQ
    try:
        _BRENTQ = _zeros._brentq
    except (ImportError, AttributeError):
        def _BRENTQ(g, a, b, xtol, rtol, maxiter, args, full_output, disp):
            return so.brentq(g, a, b, args=args, xtol=xtol, rtol=rtol, maxiter=maxiter)
    return _BRENTQ(g, a, b, xtol, rtol, maxiter, args, full_output, disp)


class ImplicitRootFn(sp.Function):
    """``x*(target; θ)``: ``ImplicitRootFn(Lambda(x, f), target, lo, hi, index, of)`` is the root of
    ``f(x; θ) = target`` in ``[lo, hi]`` (``index`` = −1, ``f`` monotone there), or the ``index``-th
    sign change of ``f − target`` there (:class:`langur.core.ImplicitRoot`)."""

    nargs = 6
    is_real = True

    @property
    def is_number(self) -> bool:  # the bound variable of the Lambda is not a free symbol
        return not self._free()

    @property
    def free_symbols(self) -> set:
        """sympy's free symbols of the root (its arguments', the equation's without its bound
        variable), a new set each time as sympy gives it (callers may change it); found once per
        root (:meth:`_free`)."""
        return set(self._free())

    def _free(self) -> frozenset:
        """The free symbols, walked once per root: sympy asks for them at every assumption query
        and ``evalf`` of an expression holding the root (``is_number``), each time a walk of the
        equation and of the roots nested in its bracket (issue 15, exact13t)."""
        known = self.__dict__.get("_langur_free")
        if known is None:
            known = self.__dict__["_langur_free"] = frozenset(super().free_symbols)
        return known

    @classmethod
    def eval(cls, lam, target, lo, hi, index, of):
        return None  # stays symbolic: it has no closed form (that is why it exists)

    def _eval_derivative(self, s):
        """The implicit function theorem's derivative (module doc), built once per root and
        symbol (:data:`_DERIVATIVES`): sympy's ``solve`` and the Jacobians differentiate the same
        roots again and again, and each build asks sympy's assumptions of the root."""
        try:
            known = _DERIVATIVES.get((self, s))
        except TypeError:  # (an unhashable symbol: built again)
            known = None
        if known is None:
            lam, target = self.args[:2]
            (x,), f = lam.variables, lam.expr
            at = {x: self}
            known = (sp.diff(target, s) - sp.diff(f, s).xreplace(at)) / sp.diff(f, x).xreplace(at)
            remember(_DERIVATIVES, (self, s), known, PRINTED, at_once=True)
        return known

    def _eval_evalf(self, prec):
        if self._free():
            return None
        return _evalf(self.args, prec)

    @staticmethod
    def _imp_(fn, target, lo, hi, index, of, *free):
        """``lambdify``'s implementation: ``fn`` is ``f`` compiled by lambdify (module namespace),
        called as ``fn(x, *free)`` with the values of the equation's other symbols (the other inputs
        of a condition in several variables, the parameters), or for an indexed root the key of its
        equation (certified by :func:`langur.enclosures.certified_brackets`, as ``evalf``); arrays (the numpy module)
        are solved element by element."""
        if not _SCALARS.issuperset(map(type, (target, lo, hi, *free))) and any(
                isinstance(v, _ARRAYS) and np.ndim(v) for v in (target, lo, hi, *free)):
            t, a, b, *rest = np.broadcast_arrays(target, lo, hi, *free)
            return np.array([_solve(fn, ti, ai, bi, index, of, *r)
                             for ti, ai, bi, *r in zip(t.flat, a.flat, b.flat, *(c.flat for c in rest))],
                            dtype=float).reshape(t.shape)
        return _solve(fn, target, lo, hi, index, of, *free)

    def _code(self, printer):
        """``lambdify``'s text: the equation as a Python ``lambda`` of the root's variable and the
        equation's other symbols, whose values follow the bracket."""
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        free = sorted(f.free_symbols - {x}, key=str)
        params = ", ".join(printer._print(s) for s in (x, *free))
        args = ", ".join(printer._print(a) for a in (target, lo, hi))
        values = "".join(f", {printer._print(s)}" for s in free)
        if index >= 0:  # certified by the exact engine's own enclosures: the equation named by a key
            return f"ImplicitRootFn({_indexed_key(lam, free)!r}, {args}, {int(index)}, {int(of)}{values})"
        return (f"ImplicitRootFn((lambda {params}: {printer._print(f)}), {args}, {int(index)}, {int(of)}"
                f"{values})")

    _pythoncode = _mpmathcode = _numpycode = _lambdacode = _code

    def _latex(self, printer, exp=None):
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        which = r"\operatorname{root}" if index < 0 else rf"\operatorname{{sign\,change}}_{{{int(index)}}}"
        out = (rf"{which}_{{{printer.doprint(x)} \in [{printer.doprint(lo)}, {printer.doprint(hi)}]}}"
               rf"\left({printer.doprint(f)} = {printer.doprint(target)}\right)")
        return out if exp is None else rf"\left({out}\right)^{{{exp}}}"

    def _sympystr(self, printer):
        """``root(x: f = target in [lo, hi])`` (``sign_change_k(…; at most n)`` for an indexed
        root); by sympy's own ``StrPrinter`` with its settings, remembered (:data:`_PRINTED`): sympy's
        ``solve`` prints an equation holding roots again and again (each nested root once more)."""
        if type(printer) is not StrPrinter:
            return self._text(printer)
        try:
            # (a Float is printed stripped below the top level: the level's side of 1 is part of it)
            key = (self, tuple(sorted(printer._settings.items())), getattr(printer, "_print_level", 0) > 0)
            known = _PRINTED.get(key)
        except TypeError:  # a setting that cannot be hashed: printed again
            return self._text(printer)
        if known is None:
            make_room(_PRINTED, PRINTED, at_once=True)
            known = _PRINTED[key] = self._text(printer)
        return known

    def _text(self, printer):
        lam, target, lo, hi, index, of = self.args
        (x,), f = lam.variables, lam.expr
        which = "root" if index < 0 else f"sign_change_{int(index)}"
        bound = "" if index < 0 else f"; at most {int(of)}"
        return (f"{which}({printer.doprint(x)}: {printer.doprint(f)} = {printer.doprint(target)} "
                f"in [{printer.doprint(lo)}, {printer.doprint(hi)}]{bound})")


#: :meth:`ImplicitRootFn._sympystr`'s texts by root and printer settings; at most :data:`PRINTED`
#: kept (then forgotten all at once).
_PRINTED: dict = {}
PRINTED = 4096
#: :meth:`ImplicitRootFn._eval_derivative`'s derivatives by root and symbol (at most
#: :data:`PRINTED` kept, then forgotten all at once).
_DERIVATIVES: dict = {}


def _solve(fn, target, lo, hi, index, of, *values):
    if isinstance(fn, str):  # an indexed root: certified as evalf certifies it (remembered: see below)
        key = (fn, target, lo, hi, index, of, values)
        try:
            root = _ROOTS.get(key)
        except TypeError:  # an argument that is not a number (no hash): not remembered
            return _indexed_at(fn, target, lo, hi, int(index), int(of), *values)
        if root is None:
            root = _indexed_at(fn, target, lo, hi, int(index), int(of), *values)
            if not _has_zero(lo, hi, values):
                _remember(key, root)
        return root
    t = float(target)
    # the same root asked again (a quadrature's conditions, guards and breakpoints at one abscissa
    # name it several times): ``double_root`` is a function of its arguments, so it is remembered
    # by them — the equation by its code and namespace (a new lambda per call, the same code); not
    # a function whose code alone does not say what it computes (a closure, default arguments)
    code = getattr(fn, "__code__", None)
    if code is None or fn.__closure__ is not None or fn.__defaults__ is not None or fn.__kwdefaults__:
        return double_root(fn, t, lo, hi, values)
    key = (code, id(fn.__globals__), t, lo, hi, values)
    try:
        return _ROOTS[key]
    except KeyError:
        pass
    except TypeError:  # an argument that is not a number (no hash): not remembered
        return double_root(fn, t, lo, hi, values)
    root = double_root(fn, t, lo, hi, values)
    if not _has_zero(lo, hi, values):
        _remember(key, root, fn.__globals__)
    return root


#: Roots already found (:func:`_solve`, :func:`_indexed_root`), by their arguments; at most
#: :data:`ROOTS` kept (then forgotten all at once, with the namespaces their keys name by id).
_ROOTS: dict = {}
_HELD: list = []
ROOTS = 100_000


def _has_zero(lo, hi, values) -> bool:
    """Whether a bracket's end or a value is ±0 (then not remembered: a dict does not tell −0.0
    from 0.0, and a root at that end would be returned with its sign; the target's sign of zero
    changes only the sign of a zero difference, which Brent's method tests by ``== 0``)."""
    return 0 in (lo, hi) or 0 in values


def _remember(key, root, held=None) -> None:
    make_room(_ROOTS, ROOTS, at_once=True, also=(_HELD,))
    if held is not None:
        _HELD.append(held)  # alive while the key names it by id
    _ROOTS[key] = root


#: The arguments ``_imp_`` solves element by element (anything else is a number: ndim 0).
_ARRAYS = (np.ndarray, list, tuple)
#: Types that are numbers for certain (no test of ``np.ndim`` needed).
_SCALARS = frozenset({float, int, np.float64})


@lru_cache(maxsize=4096)
def _evalf(args, prec):
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
            brackets = [(mpmath.mpf(p), mpmath.mpf(q)) for p, q in _brackets_at(x, shape, consts, float(t), float(a),
                                                                                   float(b))]
            if len(brackets) > of:
                raise TooManyRoots(f"{len(brackets)} turning points on [{float(a):g}, {float(b):g}] at these "
                                   f"parameter values, more than the {int(of)} the condition was split for: Langur "
                                   "cannot differentiate it here; split the variable's domain (a sum of integrals over "
                                   "sub-intervals, each with at most that many turning points)", _SPANS.get(x))
            if index >= len(brackets):
                return sp.Float(b, dps)
            a, b = brackets[int(index)]
        r = bracketed_root(fn, t, a, b, bits=prec + 10)
        if isinstance(r, float) and math.isnan(r):
            return sp.nan
        return sp.Float(r, dps)


#: The first ``(bound variable, shape)`` of each :func:`_shape_form`.
_SHAPES: dict = {}


def _canonical_shape(x, shape) -> tuple:
    """The first ``(x, shape)`` (:func:`_shape`) of the same form as this one (:func:`_form`: the
    same equation up to the identity of its bound variable, of the same name, assumptions, source
    place and leniency): its compiled versions (:func:`_shape_compiled`) and certified brackets
    (:func:`_brackets_at`) are this one's — the same code but for the bound variable's name — and
    are made once instead of once per build of ⟦p⟧ or ⦇p⦈ (issue 15, exact13t)."""
    form = _form(sp.Lambda(x, shape), ())
    if form is None:
        return x, shape
    known = _SHAPES.get(form)
    return known if known is not None else remember(_SHAPES, form, (x, shape), PRINTED, at_once=True)


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
    return (sp.lambdify([x, *cs], shape, modules="mpmath"), _interval_fn(x, shape, cs),
            _interval_fn(x, sp.diff(shape, x), cs))


@lru_cache(maxsize=4096)
def _brackets_at(x, shape, consts: tuple, t: float, a: float, b: float) -> tuple:
    """The certified brackets of the sign changes of ``f − t`` (``f`` in ``x`` only: ``shape``
    with the constants ``consts``, :func:`_shape`) on ``[a, b]``, found once for every index and
    precision: in double precision, since the certificate does not depend on the precision the
    root is wanted in."""
    coefficients = _polynomial_coefficients(x, shape, tuple(_PLACEHOLDERS[:len(consts)]))
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
                                       lenient=x in _LENIENT)
        except TooManyRoots as err:
            raise TooManyRoots(str(err), _SPANS.get(x)) from None
    return tuple((float(p), float(q)) for p, q in found)


#: The equations of indexed roots lambdify printed (by a key: ``lambdify``'s code calls back with
#: it and the values of their other symbols, and the root is found as ``evalf`` finds it).
_INDEXED: dict[str, tuple] = {}
_KEYS: dict = {}


def _indexed_key(lam, free) -> str:
    """The key naming the equation ``lam`` with its other symbols ``free``: one key for every
    equation that differs from an earlier one only in its bound variable's identity (a new Dummy
    of the same name each time ⟦p⟧ or ⦇p⦈ is built: Theorem 8.1's shifted points build
    ``3*_y**2 - x`` again; :func:`_form`), so its compiled functions, certified boxes, brackets and
    roots are found once (issue 15, exact13t)."""
    key = _KEYS.get((lam, tuple(free)))
    if key is None:
        form = _form(lam, tuple(free))
        key = _BY_FORM.get(form) if form is not None else None
        if key is None:
            key = f"indexed root {len(_INDEXED)}"
            _INDEXED[key] = (lam, tuple(free))
            if form is not None:
                _BY_FORM[form] = key
        _KEYS[(lam, tuple(free))] = key
    return key


#: Keys by :func:`_form`.
_BY_FORM: dict = {}
#: The bound variable of :func:`_form`'s equations.
_CANONICAL = sp.Dummy("langur_bound", real=True)


def _form(lam, free: tuple):
    """``lam``'s equation up to the identity of its bound variable, with everything else that
    decides what its key computes and says: its other symbols, the bound variable's name and
    assumptions (they order the printed terms: the compiled code), its source place (named when
    refused) and whether it is certified leniently; None when the equation holds another Dummy
    (its order against the bound variable could depend on their creation).  Two equations of the
    same form print the same code but for the bound variable's name: the same function."""
    (x,), f = lam.variables, lam.expr
    if f.atoms(sp.Dummy) != {x}:
        return None
    span = _SPANS.get(x)
    try:
        hash(span)
    except TypeError:
        span = ("unhashable", id(span))
    return (f.xreplace({x: _CANONICAL}), free, x.name, tuple(sorted(x.assumptions0.items())), span,
            x in _LENIENT)


def _indexed_at(key: str, target, lo, hi, index, of, *values) -> float:
    """The indexed root of the equation named ``key`` at these values of its other symbols, as
    ``evalf`` finds it (certified brackets, then bisection with mpmath), its equation compiled
    once for all values (a quadrature over the other inputs asks for thousands)."""
    t, a, b = float(target), float(lo), float(hi)
    if t != t or a != a or b != b:  # NaN
        return math.nan
    vals = tuple(map(float, values))
    brackets = _brackets_of(key, t, a, b, vals)
    if len(brackets) > of:
        lam, _ = _INDEXED[key]
        raise TooManyRoots(f"{len(brackets)} turning points on [{a:g}, {b:g}] at these parameter values, more than "
                           f"the {int(of)} the condition was split for: Langur cannot differentiate it here; split the variable's "
                               "domain (a sum of integrals over sub-intervals, each with at most that many turning points)",
                           _SPANS.get(lam.variables[0]))
    if index >= len(brackets):
        return b
    p, q = brackets[index]
    return _indexed_root(key, t, p, q, vals)


def _indexed_root(key: str, t: float, p: float, q: float, vals: tuple) -> float:
    """The root of the equation named ``key`` in its certified bracket ``[p, q]`` in doubles,
    remembered by its arguments (a quadrature's conditions and breakpoints at one abscissa ask for
    the same turning point several times)."""
    k = (_same_code(key), t, p, q, vals)
    root = _ROOTS.get(k)
    if root is None:
        root = float(double_root(_compiled(key)[3], t, p, q, vals))  # in doubles: the result is one
        if not _has_zero(p, q, vals):
            _remember(k, root)
    return root


@lru_cache(maxsize=256)
def _compiled(key: str) -> tuple:
    """The equation named ``key`` compiled once: on mpmath numbers, and its and its derivative's
    interval versions, each called as ``(x, *values of its other symbols)``."""
    lam, free = _INDEXED[key]
    (x,), f = lam.variables, lam.expr
    mp = []  # on mpmath numbers only where no box certifies (rare): compiled when first called

    def on_mpmath(*args):
        if not mp:
            mp.append(sp.lambdify([x, *free], f, modules="mpmath"))
        return mp[0](*args)
    return (on_mpmath, _interval_fn(x, f, free), _interval_fn(x, sp.diff(f, x), free),
            sp.lambdify([x, *free], f, modules="math"))


#: key -> the first key whose compiled equation is the same code (:func:`_same_code`).
_SAME: dict[str, str] = {}
#: The code signature of each key's compiled equation (:func:`_code_of`) -> the first such key and
#: its compiled functions; at most :data:`SAME_CODES` kept (as many as :func:`_compiled` keeps).
_BY_CODE: dict = {}
SAME_CODES = 256


def _same_code(key: str) -> str:
    """The first key (of :data:`_INDEXED`) whose compiled equation (:func:`_compiled`: the function
    in doubles, the interval enclosures of it and of its derivative, and their float enclosures) is
    the same code as ``key``'s — the same bytecode, constants (with their types) and global
    objects, so the same numbers for the same arguments; ``key`` itself when none is.  Theorem
    8.1's shifted points, ⟦p⟧ and ⦇p⦈ build the same equation again with a new bound variable (a
    new key: ``3*_y**2 - x`` twelve times in turning2d), and the boxes certified for one
    (:func:`_box_brackets`) and the roots found in their brackets (:func:`_indexed_root`) are then
    those of the others: shared by this key (issue 15, exact13t)."""
    out = _SAME.get(key)
    if out is None:
        _, g_iv, dg_iv, fn = _compiled(key)
        sig = (_code_of(fn), *(_code_of(f) for e in (g_iv, dg_iv)
                               for f in (e.fn, *(e.fast if e.fast is not None else (None, None)))))
        if any(s is _NO_CODE for s in sig):
            out = key
        else:  # (the first key's functions kept alive: the signature names their globals by id)
            # (forgotten all at once: keys then start anew, the boxes they certify are the same)
            make_room(_BY_CODE, SAME_CODES, at_once=True, also=(_SAME,))
            out = _BY_CODE.setdefault(sig, (key, (g_iv, dg_iv, fn)))[0]
        _SAME[key] = out
    return out


_NO_CODE = object()


def _code_of(f):
    """What a function computes from its positional arguments, as a hashable signature: its
    bytecode, its constants with their types (``1`` and ``1.0`` compare equal, compute differently),
    and the global objects its names refer to (by identity); :data:`_NO_CODE` for anything else
    (closures, defaults, nested code: not compared)."""
    if f is None:
        return None
    code = getattr(f, "__code__", None)
    if code is None or f.__closure__ is not None or f.__defaults__ is not None or f.__kwdefaults__:
        return _NO_CODE
    consts = []
    for c in code.co_consts:
        if c is not None and type(c) not in (int, float, str, bool):
            return _NO_CODE
        consts.append((type(c), repr(c)))
    names = tuple(id(f.__globals__[n]) if n in f.__globals__ else ("builtin", n) for n in code.co_names)
    return (code.co_code, tuple(consts), code.co_names, names, code.co_argcount, code.co_posonlyargcount,
            code.co_kwonlyargcount, code.co_flags, code.co_nlocals)


@lru_cache(maxsize=65536)
def _brackets_of(key: str, t: float, a: float, b: float, vals: tuple) -> tuple:
    """:func:`_brackets_at` for the equation named ``key`` at these values of its other symbols:
    those certified once for a box of them holding these values (:func:`_box_brackets`), else
    certified at these values."""
    if vals:
        found = _box_brackets(key, t, a, b, vals)
        if found is not None:
            return found
    lam, _ = _INDEXED[key]
    x = lam.variables[0]  # (sympy builds it anew each time: only past the boxes)
    if x in _LENIENT:  # a polynomial equation: isolated exactly (where roots merge, enclosures fail)
        found = _exact_brackets(key, t, a, b, vals)
        if found is not None:
            return found
    fn, g_iv, dg_iv, _ = _compiled(key)
    iv_vals = [mpmath.iv.mpf(v) for v in vals]
    mp_vals = [mpmath.mpf(v) for v in vals]
    with mpmath.workprec(53):
        try:
            found = certified_brackets(lambda z: fn(z, *mp_vals), g_iv.bind(*iv_vals),
                                       dg_iv.bind(*iv_vals), t, a, b, what=f"{lam.expr}",
                                       lenient=x in _LENIENT)
        except TooManyRoots as err:
            raise TooManyRoots(str(err), _SPANS.get(x)) from None
    return tuple((float(p), float(q)) for p, q in found)


#: Widths of the boxes of the other symbols' values over which an indexed root's brackets are
#: certified at once: 2**BOX_LEVELS[0] down to 2**BOX_LEVELS[-1], a box of each width tried (the
#: widest first) before the values themselves.
BOX_LEVELS = range(1, -16, -1)
#: Halvings of a cell of a box's certification before that box is given up (a finer one is tried).
BOX_DEPTH = 8
#: Each box's brackets (None: not certified), by equation, target, domain, width and box.
_BOXES: dict = {}
#: At most this many boxes are kept (then forgotten all at once).
BOXES = 200_000
_UNSEEN = object()


def _box_brackets(key: str, t: float, a: float, b: float, vals: tuple) -> tuple | None:
    """The certified brackets of the indexed root's sign changes for every value of its other
    symbols in a dyadic box holding ``vals`` (the widest of :data:`BOX_LEVELS` that certifies,
    :func:`langur.enclosures.certified_brackets` with ``box``): a quadrature over those symbols asks at thousands of
    nodes, and one certification serves every node in a box (the brackets are the same there, so
    is the k-th root's bracket; each node's root is then bisected at its own values).  None: no
    box certifies (near values where sign changes merge or cross a cell's end, the values'
    own certification decides)."""
    if not all(math.isfinite(v) for v in vals):
        return None
    fn, g_iv, dg_iv, _ = _compiled(key)
    shared = _same_code(key)  # (the boxes of the same equation compiled under another key)
    for level in BOX_LEVELS:
        w = 2.0 ** level
        cell = (math.floor(vals[0] / w),) if len(vals) == 1 else tuple(math.floor(v / w) for v in vals)
        k = (shared, t, a, b, level, cell)
        found = _BOXES.get(k, _UNSEEN)
        if found is _UNSEEN:
            make_room(_BOXES, BOXES, at_once=True)
            box = [mpmath.iv.mpf([c * w, (c + 1) * w]) for c in cell]  # dyadic: exact in binary
            with mpmath.workprec(53):
                try:
                    found = tuple((float(p), float(q)) for p, q in certified_brackets(
                        None, g_iv.bind(*box), dg_iv.bind(*box), t, a, b, depth=BOX_DEPTH,
                        box=True))
                except TooManyRoots:
                    found = None
            _BOXES[k] = found
        if found is not None:
            return found
    return None


class _FractionPrinter(PythonCodePrinter):
    """lambdify's text for exact rational arithmetic: every constant a ``Fraction`` (a float
    constant its exact binary value), so a polynomial's coefficients at rational values of its
    other symbols are computed without rounding."""

    def _print_Rational(self, e):
        return f"Fraction({e.p}, {e.q})"

    def _print_Half(self, e):
        return self._print_Rational(e)

    def _print_Integer(self, e):
        return f"Fraction({e.p})"

    def _print_Float(self, e):
        return self._print_Rational(sp.Rational(e))


#: The degree up to which an indexed root's polynomial equation is isolated exactly.
EXACT_DEGREE = 12


@lru_cache(maxsize=256)
def _exact_coefficients(key: str):
    """The equation named ``key`` as a polynomial in the root's variable whose coefficients are
    polynomials with rational (or float) constants in its other symbols: a function of those
    symbols' values (Fractions) returning the coefficients exactly, highest first; None otherwise."""
    lam, free = _INDEXED[key]
    (x,), f = lam.variables, lam.expr
    return _polynomial_coefficients(x, f, tuple(free))


@lru_cache(maxsize=1024)
def _polynomial_coefficients(x, f, free: tuple):
    """:func:`_exact_coefficients` of ``f`` in ``x`` with the other symbols ``free``."""
    try:
        poly = sp.Poly(f, x)
    except (sp.PolynomialError, sp.GeneratorsNeeded):
        return None
    coeffs = poly.all_coeffs()
    if poly.degree() < 1 or poly.degree() > EXACT_DEGREE:
        return None
    for c in coeffs:
        if not c.is_polynomial(*free) or any(not isinstance(n, (sp.Rational, sp.Float)) for n in c.atoms(sp.Number)) \
                or c.atoms(sp.Function) or (c.free_symbols - set(free)):
            return None
    return sp.lambdify(list(free), coeffs, modules=[{"Fraction": Fraction}], printer=_FractionPrinter(
        {"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True}))


def _exact_brackets(key: str, t: float, a: float, b: float, vals: tuple) -> tuple | None:
    """The brackets of the sign changes of a polynomial equation (:func:`_exact_coefficients`) at
    these values, by exact rational arithmetic (a Sturm sequence of its square-free part isolates
    each distinct root; a root is a sign change when the equation's signs on its two sides
    differ): certified with no interval enclosure, however close two roots are.  None: not such
    an equation, or the isolating points are not doubles."""
    coefficients = _exact_coefficients(key)
    if coefficients is None or not all(math.isfinite(v) for v in (t, a, b, *vals)):
        return None
    p = [Fraction(c) for c in coefficients(*(Fraction(v) for v in vals))]
    p[-1] -= Fraction(t)
    found = sturm_brackets(p, Fraction(a), Fraction(b))
    if found is None:
        return None
    out = tuple((float(q), float(r)) for q, r in found)
    if any(float(q) != q or float(r) != r for q, r in found):
        return None
    return out


def implicit_root(equation: sp.Expr, variable: sp.Symbol, target: sp.Expr, lo: sp.Expr, hi: sp.Expr,
                  index: int | None = None, of: int = 0, span=None, lenient: bool = False) -> sp.Expr:
    """``ImplicitRootFn`` of ``equation`` in ``variable`` (bound: replaced by a dummy); ``span``:
    the condition's place in the source, named when evaluating it is refused; ``lenient``: the
    equation mentions other integration variables (see :func:`langur.enclosures.certified_brackets`)."""
    x = sp.Dummy(variable.name, real=True)
    lam = sp.Lambda(x, equation.xreplace({variable: x}))
    if span is not None:
        _SPANS[x] = span
    if lenient:
        _LENIENT.add(x)
    return ImplicitRootFn(lam, target, lo, hi, sp.Integer(-1 if index is None else index), sp.Integer(of))


#: The source place of a root's equation (sympy terms carry none), by its bound variable (a
#: Dummy of its own, kept when parameter values are put in the equation).
_SPANS: dict = {}
#: The bound variables of indexed roots whose equation mentions other integration variables (a
#: condition split along a variable at turning points that move with the others): certified
#: leniently on the null set where two of them merge (:func:`langur.enclosures.certified_brackets`).
_LENIENT: set = set()


#: What sympy's ``solve`` says of an equation it has no algorithm for.
NO_ALGORITHM = "No algorithms are implemented to solve equation "


def unsolvable(expr: sp.Expr, v: sp.Symbol) -> str | None:
    """sympy's message (whitespace collapsed) when ``solve(expr, v)`` is certain to raise
    ``NotImplementedError``, decided from the equation's shape without asking sympy; else None.

    The shape: ``k·x* + c`` (or ``x*``) with ``x*`` an implicit root in which ``v`` occurs, ``k`` a
    non-zero rational and ``c`` free of ``v``, everything plain (:func:`_plain`: rationals, symbols,
    +, ·, integer powers, implicit roots of plain equations; no Float, which ``solve`` rewrites,
    nothing ``solve`` rewrites before solving).  ``v`` then occurs only inside the root, which has no
    inverse and no evaluation (:meth:`ImplicitRootFn.eval`): every one of ``solve``'s methods
    (linear, polynomial in the root as generator, then inverting the generator, ``unrad``,
    ``_tsolve``) ends in its "no algorithms" error naming the equation as given.  turning2d's
    ``root(…) + 1 = 0`` cost 0.1–0.2 s to fail (issue 15, exact14t)."""
    if isinstance(expr, ImplicitRootFn):
        root, rest = expr, ()
    elif isinstance(expr, sp.Add):
        dep = [t for t in expr.args if v in t.free_symbols]
        if len(dep) != 1:
            return None
        term, rest = dep[0], [t for t in expr.args if t is not dep[0]]
        coeff, root = term.as_coeff_Mul()
        if not (isinstance(coeff, sp.Rational) and coeff != 0 and isinstance(root, ImplicitRootFn)):
            return None
    else:
        return None
    if v not in root.free_symbols or not _plain(root) or not all(_plain(t) for t in rest):
        return None
    return NO_ALGORITHM + " ".join(str(expr).split())


def _plain(e) -> bool:
    """``e`` is built of rationals, symbols, +, ·, integer powers and implicit roots of such
    equations with such targets and brackets."""
    if isinstance(e, (sp.Rational, sp.Symbol)):
        return True
    if isinstance(e, (sp.Add, sp.Mul)):
        return all(_plain(a) for a in e.args)
    if isinstance(e, sp.Pow):
        return isinstance(e.exp, sp.Integer) and _plain(e.base)
    if isinstance(e, ImplicitRootFn):
        lam, *rest = e.args
        return isinstance(lam, sp.Lambda) and _plain(lam.expr) and all(_plain(a) for a in rest)
    return False
