"""Implicit roots in the Monte Carlo engine (issue 18): a Ψ̂⁻¹ component ``x*`` with
``f(x*) = target`` found by vectorized bisection on each point's bracket, or as the k-th certified
sign change of ``f − target`` (:mod:`langur.operational.signchanges`); its tangent by the implicit
function theorem."""

from __future__ import annotations

import hashlib

import numpy as np

from ..codes import NO_SLOPE_TO_CERTIFY, turning_points_beyond_split
from ..core import Term, TooManyRoots
from ..memo import remember
from .dual import dadd
from .point import NAN, TANGENT, VALUE, Fn, Linking, Point
from .signchanges import certified_brackets

#: Halvings of an implicit root's bracket: past double precision for brackets up to 2^10 wide.
ROOT_HALVINGS = 64 + 10
def bisection(f, t, a, b):
    """Vectorized bisection of ``f − t`` on brackets ``[a, b]`` where it changes sign (NaN where it
    does not)."""
    a0, b0 = a, b
    a, b = a.copy(), b.copy()
    fa, fb = f(a) - t, f(b) - t
    rising = fa < fb
    ok = (np.sign(fa) * np.sign(fb) <= 0) & ~np.isnan(fa) & ~np.isnan(fb)
    for _ in range(ROOT_HALVINGS):
        m = 0.5 * (a + b)
        below = (f(m) - t < 0) == rising
        a, b = np.where(below, m, a), np.where(below, b, m)
    return np.where(ok, np.where(fa == 0, a0, np.where(fb == 0, b0, 0.5 * (a + b))), NAN)


def _root_tangent(fe: Fn, x: str, value, dt, pt: Point, lk: Linking):
    """⦇x*⦈ = (⦇target⦈ − ∂f/∂γ·γ' − ∂f/∂u·u') / ∂f/∂x at x* (implicit function theorem; u: the
    other inputs of Ψ̂⁻¹ the equation mentions, for a condition in several variables)."""
    vals = pt.values()
    at = {**vals.vars, x: value}
    fx = fe(Point(at, vals.params, dvars={x: 1.0}, mode=TANGENT, root=vals.root), lk)[1]
    others = {k: d for k, d in pt.dvars.items() if k != x}
    ftheta = fe(Point(at, pt.params, dvars=others, dparams=pt.dparams, mode=TANGENT, root=pt.root), lk)[1]
    num = dadd(dt, None if ftheta is None else -ftheta)
    return None if num is None else num / fx


def compile_root(fe: Fn, x: str, ft: Fn, flo: Fn, fhi: Fn) -> Fn:
    """The implicit root, vectorized: bisection of ``f − target`` on each point's bracket (``f`` is
    monotone there and changes sign when the branch's guard holds; NaN where it does not)."""
    def root(pt, lk):
        vals = pt.values()
        t, dt = ft(pt, lk)
        lo, hi = flo(vals, lk)[0], fhi(vals, lk)[0]
        t, a, b = np.broadcast_arrays(*(np.asarray(v, dtype=float) for v in (t, lo, hi)))
        value = bisection(lambda at: fe(Point({**vals.vars, x: at}, vals.params, root=vals.root), lk)[0], t, a, b)
        return value, (None if pt.mode == VALUE else _root_tangent(fe, x, value, dt, pt, lk))
    return root


#: The certified sign changes of the last few (equation, points) met, each bisected: the k-th sign
#: changes of one equation are one node per k (and each is read by several branches and guards),
#: all found by one certification (kept with the equation itself, whose id is part of the key; the
#: points by a digest of their table, so a large batch is not held twice).
_SIGN_CHANGES: dict = {}


def compile_sign_change(fe: Fn, x: str, ft: Fn, flo: Fn, fhi: Fn, index: int, of: int, tape, root,
                         others: tuple[str, ...] = (), equation: Term | None = None) -> Fn:
    """The ``index``-th sign change of ``f − target`` on ``[lo, hi]`` (``hi`` when there are
    fewer; :class:`~langur.core.TooManyRoots` when more than ``of``, or when they cannot be
    certified): each sign change certified in a bracket (:mod:`langur.operational.signchanges`,
    ``tape`` encloses f and ∂f/∂x), once per distinct parameter point, and bisected there.
    ``others``: the other inputs of Ψ̂⁻¹ ``f`` mentions (turning points that move with the other
    variables of a condition split along ``x``): part of each point, and a cell left uncertified
    on a null set of them is decided by its ends (``lenient``).  ``root``: the :class:`ImplicitRoot`
    compiled, named by the refusals."""
    def sign_change(pt, lk):
        vals = pt.values()
        if tape is None:
            raise TooManyRoots(NO_SLOPE_TO_CERTIFY, root)
        t, dt = ft(pt, lk)
        (lo, _), (hi, dhi) = flo(vals, lk), fhi(pt, lk)
        columns = [t, lo, hi] + [vals.vars[u] for u in others] + [v for v in vals.params.values() if np.ndim(v)]
        n = max([np.size(c) for c in columns])
        table = np.stack([np.broadcast_to(np.asarray(c, dtype=float).reshape(-1), (n,)) if np.size(c) > 1
                          else np.full(n, float(np.asarray(c).reshape(-1)[0])) for c in columns], axis=1)
        rows, back = np.unique(table, axis=0, return_inverse=True)
        back = back.reshape(-1)
        first = np.unique(back, return_index=True)[1]  # one sample row per distinct point
        params = {k: (np.broadcast_to(np.asarray(v, dtype=float).reshape(-1), (n,))[first] if np.ndim(v) else v)
                  for k, v in vals.params.items()}
        tr, lor, hir = rows[:, 0], rows[:, 1], rows[:, 2]
        moving = {u: rows[:, 3 + i] for i, u in enumerate(others)}

        def at_rows(r):
            return {k: (v[r] if np.ndim(v) else v) for k, v in params.items()}

        def value(at, r):
            at_vars = {x: at, **{u: v[r] for u, v in moving.items()}}
            return np.broadcast_to(fe(Point(at_vars, at_rows(r), root=vals.root), lk)[0], np.shape(at))

        key = (id(equation), x, rows.shape, hashlib.blake2b(rows.tobytes(), digest_size=20).digest(),
               tuple((k, float(v)) for k, v in sorted(vals.params.items()) if not np.ndim(v)))
        found = _SIGN_CHANGES.get(key)
        if found is None or found[0] is not equation:
            r, a, b = certified_brackets(value, tape, x, tr, lor, hir, params, root, what=f"∂/∂{x}", others=moving,
                                         lenient=bool(others))
            counts = np.bincount(r, minlength=len(tr))
            if np.any(counts > of):
                raise TooManyRoots(turning_points_beyond_split(int(counts.max()), of, "on the domain"), root)
            roots = bisection(lambda at: value(at, r), tr[r], a, b)  # every sign change of every row at once
            found = (equation, r, counts, roots)
            remember(_SIGN_CHANGES, key, found, 8)
        _, r, counts, roots = found
        value_rows = hir.copy()
        has = counts > index
        if has.any():
            start = np.concatenate([[0], np.cumsum(counts)[:-1]])
            pick = start[has] + index  # the (index+1)-th bracket of each row that has one
            value_rows[r[pick]] = roots[pick]
        value = value_rows[back] if n > 1 or np.ndim(t) or np.ndim(lo) or np.ndim(hi) else value_rows[0]
        if pt.mode == VALUE:
            return value, None
        inside = has[back] if np.ndim(value) else bool(has[0])
        d = _root_tangent(fe, x, value, dt, pt, lk)
        if d is None and dhi is None:
            return value, None
        return value, np.where(inside, 0.0 if d is None else d, 0.0 if dhi is None else dhi)
    return sign_change
