"""Core terms ↔ sympy expressions, for the front end's diffeomorphism work (LANGUAGE.md §6).

This is a front-end utility: ``langur.syntax.diffeo`` completes conditions over variables and
checks declared diffeomorphisms with sympy, then converts the results back to core terms.  It is
not the symbolic semantics (that is ``langur.denote``).

* :func:`to_sympy` maps a smooth core term (constants, variables, parameters, ``+``, ``·``,
  primitives, constant powers, ``let``) to a sympy expression over real symbols.
* :func:`from_sympy` maps such an expression back to a core term; ``Pow(b, 1/2)`` becomes
  ``Prim('sqrt', b)``.  Sympy keeps its arguments in a canonical order, so the same expression
  always gives the same term (the completion of a condition is deterministic).
* :func:`time_limited` runs a sympy call under a wall-clock limit: sympy never hangs the front end.
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable, Iterable
from fractions import Fraction
from typing import TypeVar

import sympy as sp

from ..core import (
    ALL_PRIMITIVES,
    PI,
    Add,
    Call,
    Const,
    IfDiffeo,
    IfGe0,
    Let,
    Mul,
    Param,
    Pow,
    Prim,
    Term,
    Var,
    shared,
)
from ..timebox import run_with_timeout

T = TypeVar("T")


class NotSmooth(Exception):
    """The term has a conditional or a call: it is not a smooth function we can hand to sympy."""


class SympyTimeout(Exception):
    """A sympy computation exceeded its time limit."""


_FUNCS: dict[str, Callable] = {
    "exp": sp.exp, "log": sp.log, "sin": sp.sin, "cos": sp.cos, "tan": sp.tan, "sqrt": sp.sqrt,
    "tanh": sp.tanh, "atan": sp.atan, "asin": sp.asin, "acos": sp.acos, "atanh": sp.atanh,
}
_BACK: dict[type, str] = {
    sp.exp: "exp", sp.log: "log", sp.sin: "sin", sp.cos: "cos", sp.tan: "tan", sp.tanh: "tanh",
    sp.atan: "atan", sp.asin: "asin", sp.acos: "acos", sp.atanh: "atanh",
}


def symbol(name: str) -> sp.Symbol:
    """The real sympy symbol standing for the variable, input or parameter ``name``."""
    return sp.Symbol(name, real=True)


def to_sympy(t: Term, env: dict[str, sp.Expr] | None = None) -> sp.Expr:
    """The smooth core term ``t`` as a sympy expression (variables and parameters as real symbols).

    ``env`` maps names (of variables or parameters) to expressions to use instead of symbols.
    Raises :class:`NotSmooth` on conditionals and calls.
    """
    env = dict(env or {})

    @shared  # per node and scope: a term shared after inlining is converted once
    def go(u: Term, env: dict[str, sp.Expr]) -> sp.Expr:
        match u:
            case Const(v):
                return sp.pi if v == PI else sp.Rational(v.numerator, v.denominator)
            case Var(name) | Param(name):
                return env[name] if name in env else symbol(name)
            case Add(a, b):
                return go(a, env) + go(b, env)
            case Mul(a, b):
                return go(a, env) * go(b, env)
            case Prim(op, a):
                if op not in ALL_PRIMITIVES:
                    raise NotSmooth(f"unknown primitive {op}")
                return _FUNCS[op](go(a, env))
            case Pow(a, k):
                return go(a, env) ** sp.Rational(k.numerator, k.denominator)
            case Let(name, bound, body):
                return go(body, {**env, name: go(bound, env)})
            case IfGe0() | IfDiffeo():
                raise NotSmooth("a conditional")
            case Call():
                raise NotSmooth("a call")
        raise TypeError(f"not a core term: {u!r}")

    return go(t, env)


def from_sympy(expr: sp.Expr, variables: Iterable[str], params: Iterable[str] = ()) -> Term:
    """The sympy expression ``expr`` as a core term: symbols named in ``variables`` become ``Var``,
    those in ``params`` become ``Param``.  Raises ``ValueError`` on anything not expressible
    (complex numbers, infinities, unknown functions, symbols not listed)."""
    vs, ps = set(variables), set(params)

    def go(e: sp.Expr) -> Term:
        if e is sp.pi:
            return Const(PI)
        if e.is_Rational:
            return Const(Fraction(int(e.p), int(e.q)))
        if e is sp.E:
            return Prim("exp", Const(Fraction(1)))
        if e.is_Symbol:
            if e.name in vs:
                return Var(e.name)
            if e.name in ps:
                return Param(e.name)
            raise ValueError(f"unexpected symbol {e.name}")
        if e.is_Add:
            return _fold(Add, [go(a) for a in e.args])
        if e.is_Mul:
            return _fold(Mul, [go(a) for a in e.args])
        if e.is_Pow:
            base, ex = e.args
            if not ex.is_Rational:
                if ex.is_Symbol or ex.free_symbols:
                    raise ValueError(f"non-constant exponent in {e}")
                raise ValueError(f"irrational exponent in {e}")
            k = Fraction(int(ex.p), int(ex.q))
            if base is sp.E:
                return Prim("exp", Const(k))
            if k == Fraction(1, 2):
                return Prim("sqrt", go(base))
            if k == Fraction(-1, 2):
                return Pow(Prim("sqrt", go(base)), Fraction(-1))
            return Pow(go(base), k)
        if isinstance(e, sp.Abs):  # |t| = sqrt(t^2), as sympy writes sqrt(u^2) for real u
            return Prim("sqrt", Pow(go(e.args[0]), Fraction(2)))
        op = _BACK.get(type(e)) or _BACK.get(e.func)
        if op is not None and len(e.args) == 1:
            return Prim(op, go(e.args[0]))
        raise ValueError(f"cannot express {e} in the core language")

    return go(sp.sympify(expr))


def _fold(node, parts: list[Term]) -> Term:
    out = parts[0]
    for p in parts[1:]:
        out = node(out, p)
    return out


def lambdify(t: Term, names: list[str]):
    """A numpy function of ``names`` (positional) evaluating the smooth term ``t`` (tests, checks)."""
    return sp.lambdify([symbol(n) for n in names], to_sympy(t), modules="numpy")


def time_limited(f: Callable[[], T], seconds: float) -> T:
    """``f()`` if it finishes within ``seconds``, else :class:`SympyTimeout`.

    In the main thread this is ``langur.timebox.run_with_timeout`` (an interval timer
    that nests correctly with the symbolic engine's own limits); elsewhere ``f`` runs in a daemon
    thread that is abandoned on timeout (it cannot be interrupted, but it never blocks exit).
    """
    if threading.current_thread() is threading.main_thread() and hasattr(signal, "setitimer"):
        try:
            return run_with_timeout(f, seconds)
        except TimeoutError:
            raise SympyTimeout(f"sympy took longer than {seconds}s") from None
    box: dict[str, object] = {}

    def run():
        try:
            box["value"] = f()
        except BaseException as e:  # noqa: BLE001 - re-raised in the caller's thread
            box["error"] = e

    th = threading.Thread(target=run, daemon=True)
    th.start()
    th.join(seconds)
    if th.is_alive():
        raise SympyTimeout(f"sympy took longer than {seconds}s")
    if "error" in box:
        raise box["error"]  # type: ignore[misc]
    return box["value"]  # type: ignore[return-value]
