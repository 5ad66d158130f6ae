"""An implicit root in lambdify's compiled code, in doubles (paper §7.2: a point of an inverse
branch Ψ̂⁻¹, where quadrature evaluates ⟦p⟧'s and ⦇p⦈'s pieces; issue 18).

:func:`lambdified_root` is ``ImplicitRootFn``'s implementation for ``lambdify``: the equation
compiled by lambdify, solved by Brent's method on its bracket
(:func:`langur.implicit.solvers.double_root`); an indexed root (the k-th sign change) named by the
key of its equation (:func:`indexed_key`), its brackets certified as ``evalf`` certifies them
(:mod:`langur.implicit.evalf`) — once for a whole box of the other symbols' values
(:func:`_box_brackets`), or for a polynomial equation exactly (:func:`_exact_brackets`).  Roots are
remembered by their arguments (a quadrature asks for the same one several times).
"""

from __future__ import annotations

import math
from fractions import Fraction
from functools import lru_cache

import mpmath
import numpy as np
import sympy as sp

from langur.core import TooManyRoots
from langur.enclosures import certified_brackets, interval_function
from langur.implicit.equations import COUNTED, LENIENT, NODES, form, polynomial_coefficients, too_many_roots
from langur.implicit.solvers import double_root
from langur.memo import make_room
from langur.sturm import sturm_brackets


def lambdified_root(fn, target, lo, hi, index, of, *free):
    """``lambdify``'s implementation of ``ImplicitRootFn``: ``fn`` is ``f`` compiled by lambdify
    (module namespace), called as ``fn(x, *free)`` with the values of the equation's other symbols
    (the other inputs of a condition in several variables, the parameters), or for an indexed root
    the key of its equation (:func:`indexed_key`; certified by
    :func:`langur.enclosures.certified_brackets`, as ``evalf``); arrays (the numpy module) are solved
    element by element."""
    if not _SCALARS.issuperset(map(type, (target, lo, hi, *free))) and any(
            isinstance(v, _ARRAYS) and np.ndim(v) for v in (target, lo, hi, *free)):
        t, a, b, *rest = np.broadcast_arrays(target, lo, hi, *free)
        return np.array([_solve(fn, ti, ai, bi, index, of, *r)
                         for ti, ai, bi, *r in zip(t.flat, a.flat, b.flat, *(c.flat for c in rest))],
                        dtype=float).reshape(t.shape)
    return _solve(fn, target, lo, hi, index, of, *free)


#: The arguments :func:`lambdified_root` solves element by element (anything else is a number: ndim 0).
_ARRAYS = (np.ndarray, list, tuple)
#: Types that are numbers for certain (no test of ``np.ndim`` needed).
_SCALARS = frozenset({float, int, np.float64})


def _solve(fn, target, lo, hi, index, of, *values):
    """One root for :func:`lambdified_root` (numbers, not arrays), remembered by its arguments."""
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


#: The equations of indexed roots lambdify printed (by a key: ``lambdify``'s code calls back with
#: it and the values of their other symbols, and the root is found as ``evalf`` finds it).
_INDEXED: dict[str, tuple] = {}
_KEYS: dict = {}
#: Keys by :func:`~langur.implicit.equations.form`.
_BY_FORM: dict = {}


def indexed_key(lam, free) -> str:
    """The key naming the equation ``lam`` with its other symbols ``free``: one key for every
    equation that differs from an earlier one only in its bound variable's identity (a new Dummy
    of the same name each time ⟦p⟧ or ⦇p⦈ is built: Theorem 8.1's shifted points build
    ``3*_y**2 - x`` again; :func:`~langur.implicit.equations.form`), so its compiled functions,
    certified boxes, brackets and roots are found once (issue 15, exact13t)."""
    key = _KEYS.get((lam, tuple(free)))
    if key is None:
        same = form(lam, tuple(free))
        key = _BY_FORM.get(same) if same is not None else None
        if key is None:
            key = f"indexed root {len(_INDEXED)}"
            _INDEXED[key] = (lam, tuple(free))
            if same is not None:
                _BY_FORM[same] = key
        _KEYS[(lam, tuple(free))] = key
    return key


def _indexed_at(key: str, target, lo, hi, index, of, *values) -> float:
    """The indexed root of the equation named ``key`` at these values of its other symbols, as
    ``evalf`` finds it (certified brackets, then bisection with mpmath), its equation compiled
    once for all values (a quadrature over the other inputs asks for thousands)."""
    t, a, b = float(target), float(lo), float(hi)
    if t != t or a != a or b != b:  # NaN
        return math.nan
    vals = tuple(map(float, values))
    most = max(int(of), COUNTED)
    brackets = _brackets_of(key, t, a, b, vals, most)
    if len(brackets) > of:  # (past ``most``, the first ones only: certified_brackets stops there)
        lam, _ = _INDEXED[key]
        raise too_many_roots(len(brackets), a, b, of, lam.variables[0], at_least=len(brackets) > most)
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
    return (on_mpmath, interval_function(x, f, free), interval_function(x, sp.diff(f, x), free),
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
def _brackets_of(key: str, t: float, a: float, b: float, vals: tuple, most: int | None = None) -> tuple:
    """:func:`langur.implicit.evalf._brackets_at` for the equation named ``key`` at these values of its other symbols:
    those certified once for a box of them holding these values (:func:`_box_brackets`), else
    certified at these values."""
    if vals:
        found = _box_brackets(key, t, a, b, vals, most)
        if found is not None:
            return found
    lam, _ = _INDEXED[key]
    x = lam.variables[0]  # (sympy builds it anew each time: only past the boxes)
    if x in LENIENT:  # a polynomial equation: isolated exactly (where roots merge, enclosures fail)
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
                                       lenient=x in LENIENT, most=most)
        except TooManyRoots as err:
            raise TooManyRoots(str(err), NODES.get(x)) from None
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


def _box_brackets(key: str, t: float, a: float, b: float, vals: tuple, most: int | None = None) -> tuple | None:
    """The certified brackets of the indexed root's sign changes for every value of its other
    symbols in a dyadic box holding ``vals`` (the widest of :data:`BOX_LEVELS` that certifies,
    :func:`langur.enclosures.certified_brackets` with ``box``): a quadrature over those symbols
    asks at thousands of nodes, and one certification serves every node in a box (the brackets are the same there, so
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
        k = (shared, t, a, b, level, cell, most)
        found = _BOXES.get(k, _UNSEEN)
        if found is _UNSEEN:
            make_room(_BOXES, BOXES, at_once=True)
            box = [mpmath.iv.mpf([c * w, (c + 1) * w]) for c in cell]  # dyadic: exact in binary
            with mpmath.workprec(53):
                try:
                    found = tuple((float(p), float(q)) for p, q in certified_brackets(
                        None, g_iv.bind(*box), dg_iv.bind(*box), t, a, b, depth=BOX_DEPTH,
                        box=True, most=most))
                except TooManyRoots:
                    found = None
            _BOXES[k] = found
        if found is not None:
            return found
    return None


@lru_cache(maxsize=256)
def _exact_coefficients(key: str):
    """:func:`~langur.implicit.equations.polynomial_coefficients` of the equation named ``key`` in
    the root's variable (None: not such a polynomial)."""
    lam, free = _INDEXED[key]
    (x,), f = lam.variables, lam.expr
    return polynomial_coefficients(x, f, tuple(free))


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
