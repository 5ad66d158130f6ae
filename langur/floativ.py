"""Interval enclosures in floating point that bracket mpmath's (issue 15/18).

:func:`langur.enclosures.certified_brackets` proves where an equation has no zero or is monotone by
mpmath's interval arithmetic (``mpmath.iv``: every operation the exact hull of its result over its
input intervals, rounded outward to 53 bits), about 40 µs per evaluation of a small polynomial;
turning2d's quadrature asks for tens of thousands.  :func:`compile_enclosure` traces the very
function mpmath evaluates (lambdify's interval text of the equation) on recording values and
compiles the operations it meets (+, −, ×, powers by non-negative integers, division by a
constant; constants are folded by mpmath itself, so they are mpmath's) into two Python functions
of float ends:

* ``outer``: for each operation the exact hull over inputs that contain mpmath's, its ends moved
  one unit in the last place outward (``math.nextafter``): an interval containing mpmath's;
* ``inner``: the exact hull over inputs contained in mpmath's, ends moved one unit inward (an end
  that rounds to 0 kept: then the exact end is within half the least subnormal of 0, and mpmath's
  end, rounded outward, is on the far side of 0 or at 0): an interval contained in mpmath's (None
  when some step is empty or not finite).

So at 53 bits ``inner ⊆ mpmath ⊆ outer``: ``outer`` excluding 0 proves that mpmath's enclosure
does (and so that the equation has no zero there: ``outer`` is a rigorous enclosure in its own
right), ``inner`` containing 0 proves that mpmath's does too; only in between (0 within rounding
of an end) is mpmath asked.  Every decision is then mpmath's own: the brackets, hence the roots,
are bitwise those of mpmath alone (``proofs_tests/test_float_enclosures_tw3.py``).  Anything else
in the text (a function call, a fractional power) makes the equation unsupported (None): mpmath
alone then decides, as before.
"""

from __future__ import annotations

import math
import types

import mpmath
from mpmath import libmp

_INF = math.inf
#: The precision (bits) at which mpmath's intervals are bracketed: that of a double.
PREC = 53


class Unsupported(Exception):
    """An operation :func:`compile_enclosure` does not compile (mpmath alone decides)."""


def ends(v) -> tuple[float, float]:
    """The float ends of an mpmath interval (or number) rounded outward: exact at 53 bits."""
    if isinstance(v, mpmath.ctx_iv.ivmpf):
        a, b = v._mpi_
        return libmp.to_float(a, rnd="f"), libmp.to_float(b, rnd="c")
    if isinstance(v, (int, float)) and not isinstance(v, bool) and float(v) == v:
        return float(v), float(v)
    return ends(mpmath.iv.mpf(v))


class _Recorder:
    """The operations of one traced evaluation, as lines of the outer and the inner function."""

    def __init__(self):
        self.outer: list[str] = []
        self.inner: list[str] = []
        self.registers: list[str] = []
        self.n = 0

    def new(self) -> str:
        r = f"r{self.n}"
        self.n += 1
        self.registers.append(r)
        return r


class _Value:
    """A traced value: a register (``name``: its outer ends ``name_l``/``name_h``, inner
    ``name_L``/``name_H``) or a constant (an mpmath interval, folded by mpmath)."""

    __slots__ = ("rec", "name", "const")

    def __init__(self, rec: _Recorder, name: str | None = None, const=None):
        self.rec, self.name, self.const = rec, name, const

    # the ends of a value as code: outer low, outer high, inner low, inner high
    def code(self) -> tuple[str, str, str, str]:
        if self.const is not None:
            lo, hi = ends(self.const)
            if not (math.isfinite(lo) and math.isfinite(hi)):
                raise Unsupported("a constant that is not finite")
            return repr(lo), repr(hi), repr(lo), repr(hi)
        n = self.name
        return f"{n}_l", f"{n}_h", f"{n}_L", f"{n}_H"

    def _other(self, o) -> _Value:
        if isinstance(o, _Value):
            return o
        if isinstance(o, bool) or not isinstance(o, (int, float, mpmath.ctx_iv.ivmpf)):
            raise Unsupported(f"an operand {type(o).__name__}")
        return _Value(self.rec, const=mpmath.iv.mpf(o))

    def _emit(self, outer: list[str], inner: list[str]) -> _Value:
        r = self.rec.new()
        self.rec.outer += [s.format(r=r) for s in outer]
        self.rec.inner += [s.format(r=r) for s in inner]
        return _Value(self.rec, r)

    def __add__(self, o):
        o = self._other(o)
        if self.const is not None and o.const is not None:
            return _Value(self.rec, const=self.const + o.const)
        al, ah, aL, aH = self.code()
        bl, bh, bL, bH = o.code()
        return self._emit([f"{{r}}_l = nx({al} + {bl}, NI); {{r}}_h = nx({ah} + {bh}, PI)"],
                          [f"{{r}}_L = w if (w := {aL} + {bL}) == 0 else nx(w, PI); {{r}}_H = w if (w := {aH} + {bH}) == 0 else nx(w, NI)"])

    def __radd__(self, o):
        return self._other(o).__add__(self)

    def __neg__(self):
        if self.const is not None:
            return _Value(self.rec, const=-self.const)
        al, ah, aL, aH = self.code()
        return self._emit([f"{{r}}_l = -{ah}; {{r}}_h = -{al}"], [f"{{r}}_L = -{aH}; {{r}}_H = -{aL}"])

    def __pos__(self):
        return self

    def __sub__(self, o):
        o = self._other(o)
        if self.const is not None and o.const is not None:
            return _Value(self.rec, const=self.const - o.const)
        al, ah, aL, aH = self.code()
        bl, bh, bL, bH = o.code()
        return self._emit([f"{{r}}_l = nx({al} - {bh}, NI); {{r}}_h = nx({ah} - {bl}, PI)"],
                          [f"{{r}}_L = w if (w := {aL} - {bH}) == 0 else nx(w, PI); {{r}}_H = w if (w := {aH} - {bL}) == 0 else nx(w, NI)"])

    def __rsub__(self, o):
        return self._other(o).__sub__(self)

    def __mul__(self, o):
        o = self._other(o)
        if self.const is not None and o.const is not None:
            return _Value(self.rec, const=self.const * o.const)
        return self._product(o, "*")

    def __rmul__(self, o):
        return self._other(o).__mul__(self)

    def __truediv__(self, o):
        o = self._other(o)
        if self.const is not None and o.const is not None:
            return _Value(self.rec, const=self.const / o.const)
        lo, hi = ends(o.const) if o.const is not None else (0.0, 0.0)
        if o.const is None or not (lo > 0 or hi < 0):
            raise Unsupported("a division by a variable or by an interval holding 0")
        return self._product(o, "/")

    def __rtruediv__(self, o):
        return self._other(o).__truediv__(self)

    def _product(self, o: _Value, op: str) -> _Value:
        """``self op o`` (``*`` or ``/``): the exact hull is the least and the greatest of the
        four products (quotients) of ends; their rounding to nearest, moved one ulp."""
        al, ah, aL, aH = self.code()
        bl, bh, bL, bH = o.code()
        outer = (f"p = ({al} {op} {bl}, {al} {op} {bh}, {ah} {op} {bl}, {ah} {op} {bh}); "
                 "{r}_l = nx(mn(p), NI); {r}_h = nx(mx(p), PI)")
        inner = (f"p = ({aL} {op} {bL}, {aL} {op} {bH}, {aH} {op} {bL}, {aH} {op} {bH}); "
                 "{r}_L = w if (w := mn(p)) == 0 else nx(w, PI); {r}_H = w if (w := mx(p)) == 0 else nx(w, NI)")
        return self._emit([outer], [inner])

    def __pow__(self, n):
        if isinstance(n, _Value) and n.const is not None:
            lo, hi = ends(n.const)
            if lo != hi or not lo.is_integer():
                raise Unsupported("a power that is not an integer")
            n = int(lo)
        if isinstance(n, bool) or not isinstance(n, int) or n < 0:
            raise Unsupported("a power that is not a non-negative integer")
        if self.const is not None:
            return _Value(self.rec, const=self.const ** n)
        if n == 0:
            return _Value(self.rec, const=mpmath.iv.mpf(1))
        if n == 1:
            return self
        al, ah, aL, aH = self.code()
        return self._emit([f"{{r}}_l, {{r}}_h = po({al}, {ah}, {n})"], [f"{{r}}_L, {{r}}_H = pi({aL}, {aH}, {n})"])

    def __rpow__(self, o):
        raise Unsupported("a variable exponent")


def _up_pow(v: float, n: int) -> float:
    """An upper bound of ``v**n`` for ``v ≥ 0`` (0 for 0: exact)."""
    r = v
    if v == 0:
        return 0.0
    for _ in range(n - 1):
        r = math.nextafter(r * v, _INF)
    return r


def _dn_pow(v: float, n: int) -> float:
    """A lower bound of ``v**n`` for ``v ≥ 0`` (0 for 0: exact)."""
    r = v
    if v == 0:
        return 0.0
    for _ in range(n - 1):
        r = math.nextafter(r * v, -_INF)
    return r


def _pow_outer(lo: float, hi: float, n: int) -> tuple[float, float]:
    """An interval containing ``{x**n : lo ≤ x ≤ hi}`` (mpmath's hull, ``n ≥ 2``)."""
    if n % 2:  # increasing
        return (_dn_pow(lo, n) if lo >= 0 else -_up_pow(-lo, n)), (_up_pow(hi, n) if hi >= 0 else -_dn_pow(-hi, n))
    if lo >= 0:
        return _dn_pow(lo, n), _up_pow(hi, n)
    if hi <= 0:
        return _dn_pow(-hi, n), _up_pow(-lo, n)
    return 0.0, _up_pow(max(-lo, hi), n)


def _pow_inner(lo: float, hi: float, n: int) -> tuple[float, float]:
    """An interval contained in ``{x**n : lo ≤ x ≤ hi}`` (``n ≥ 2``; empty: lo > hi)."""
    if n % 2:
        return (_up_pow(lo, n) if lo >= 0 else -_dn_pow(-lo, n)), (_dn_pow(hi, n) if hi >= 0 else -_up_pow(-hi, n))
    if lo >= 0:
        return _up_pow(lo, n), _dn_pow(hi, n)
    if hi <= 0:
        return _up_pow(-hi, n), _dn_pow(-lo, n)
    return 0.0, _dn_pow(max(-lo, hi), n)


_NAMESPACE = {"nx": math.nextafter, "NI": -_INF, "PI": _INF, "mn": min, "mx": max, "po": _pow_outer,
              "pi": _pow_inner}


def compile_enclosure(fn, nargs: int):
    """``(outer, inner)`` for ``fn`` (lambdify's interval function of ``nargs`` intervals), each a
    function ``(x_lo, x_hi, v1_lo, v1_hi, …, t_lo, t_hi) ↦ (lo, hi)`` enclosing ``fn − [t_lo,
    t_hi]`` (module docstring); None when ``fn`` uses an operation this does not compile."""
    code = getattr(fn, "__code__", None)
    if code is None or fn.__closure__ or code.co_argcount != nargs or fn.__defaults__:
        return None
    if mpmath.iv.prec != PREC:  # constants are folded at mpmath's precision: it must be 53 bits
        return None
    rec = _Recorder()
    traced = types.FunctionType(code, {"mpf": lambda v: _Value(rec, const=mpmath.iv.mpf(v)), "__builtins__": {}})
    args = [_Value(rec, f"a{i}") for i in range(nargs)]
    try:
        out = traced(*args)
        out = out if isinstance(out, _Value) else args[0]._other(out)
        out = out - _Value(rec, "t")  # the target, subtracted as mpmath does (G − t)
    except (Unsupported, NameError, TypeError, AttributeError, ValueError, ZeroDivisionError, ArithmeticError):
        return None
    params = ", ".join(f"a{i}_l, a{i}_h" for i in range(nargs)) + ", t_l, t_h"
    regs = rec.registers
    every_l = " + ".join(f"{r}_l + {r}_h" for r in regs)
    every_L = " + ".join(f"{r}_L + {r}_H" for r in regs)
    proper = " and ".join(f"{r}_L <= {r}_H" for r in regs)
    text = (f"def outer({params}):\n    " + "\n    ".join(rec.outer)
            + f"\n    s = {every_l}\n    if s - s != 0:\n        return None\n    return {out.name}_l, {out.name}_h\n"
            + f"def inner({params.replace('_l', '_L').replace('_h', '_H')}):\n    " + "\n    ".join(rec.inner)
            + f"\n    s = {every_L}\n    if s - s != 0 or not ({proper}):\n        return None\n"
            + f"    return {out.name}_L, {out.name}_H\n")
    namespace = dict(_NAMESPACE)
    exec(compile(text, "<langur.floativ>", "exec"), namespace)  # noqa: S102 - our own generated text
    return namespace["outer"], namespace["inner"]
