"""Microbenchmark 1 (§10.3.2, Fig. 16) as a user of Potto writes it (not a test).

Run:  PYTHONPATH=DIR python bench/peer_programs/potto_mb1.py N

DIR is a checkout of github.com/divicomp/potto: this program imports Potto from there, through
its public API, as its authors' microbenchmarks do; none of Potto's code is in this project.

∫₋₁¹ Σᵢ H(x + aᵢ)·f(aᵢ, x) dx for i = 10 … 9 + n, differentiated once as a function of the shader f
(separate compilation), then applied to the shaders a + x and a − x and their derivatives, in the
direction where every aᵢ moves by 1, at aᵢ = 1/i; evaluated with 10 samples.
``bench/bench_peers.py`` and ``bench/bench_issue15.py`` time :func:`program` (building the
expression and its derivative) and :func:`number` (evaluating it); the second also times
compiling this file's text, Potto's counterpart of a front end.
"""

import sys

from potto import (
    App,
    BoundedLebesgue,
    Const,
    Function,
    Heaviside,
    Int,
    Shift,
    Sym,
    TegVar,
    Var,
    VarVal,
    deriv,
    evaluate,
)


def integral(first: int, last: int):
    """∫₋₁¹ Σᵢ H(x + aᵢ)·f(aᵢ, x) dx for i = first … last as a function of the shader f,
    differentiated once; returns the derivative, the shader's variables, the derivative context
    and the values (aᵢ = 1/i, daᵢ = 1)."""
    x, f = TegVar("x"), Var("f")
    big, ctx, vals = Const(0), {}, {}
    for i in range(first, last + 1):
        a = Var(f"a{i}")
        vals[a.name] = 1 / i
        big += Heaviside(Shift((a,), (x,), Const(1))) * App(f, (a, x))
        da = Sym(f"da{i}")
        ctx[a.name] = da
        vals[da] = 1
    x0, a0 = TegVar("x0"), Var("a0")
    ctx[x0.name], ctx[a0.name] = Sym("x0"), Sym("a0")
    return deriv(Function((f,), Int(big, BoundedLebesgue(-1, 1, x))), ctx), (a0, x0), ctx, vals


def applied(di, shader, ctx):
    """The compiled integral's derivative applied to a shader and the shader's derivative."""
    return App(di, (shader, deriv(shader, ctx)))


def program(n: int):
    """Microbenchmark 1's derivative at n jumps (2n deltas) and the values to evaluate it at."""
    di, (a0, x0), ctx, vals = integral(10, 9 + n)
    s1, s2 = Function((a0, x0), a0 + x0), Function((a0, x0), a0 - x0)
    return applied(di, s1, ctx) + applied(di, s2, ctx), VarVal(vals)


def number(expr, values, samples: int = 10) -> float:
    return float(evaluate(expr, values, samples))


if __name__ == "__main__":
    print(number(*program(int(sys.argv[1]))))
