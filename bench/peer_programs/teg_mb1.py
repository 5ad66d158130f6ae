"""Microbenchmark 1 (§10.3.2, Fig. 16) as a user of Teg writes it (not a test).

Run:  PYTHONPATH=DIR python bench/peer_programs/teg_mb1.py N

DIR is a checkout of github.com/ChezJrk/Teg: this program imports Teg from there, through its
public API, as its authors' microbenchmarks do; none of Teg's code is in this project.

∫₋₁¹ Σᵢ [x + aᵢ > 0]·(aᵢ + x) dx + ∫₋₁¹ Σᵢ [x + aᵢ > 0]·(aᵢ − x) dx for i = 10 … 9 + n at aᵢ = 1/i,
its forward derivative in the direction where every aᵢ moves by 1, reduced to Teg's base language
and evaluated by its numpy backend with 10 samples.  ``bench/bench_peers.py`` and
``bench/bench_issue15.py`` time :func:`program` (building the expression and its derivative) and
:func:`number`; the second also times compiling this file's text.
"""

import sys

from teg import Const, IfElse, Teg, TegVar, Var
from teg.derivs.fwd_deriv import fwd_deriv
from teg.eval import evaluate
from teg.passes.reduce import reduce_to_base


def plus(a, x):
    return a + x


def minus(a, x):
    return a - x


def integral(first: int, last: int, shade):
    """∫₋₁¹ Σᵢ [x + aᵢ > 0]·shade(aᵢ, x) dx for i = first … last, and the direction (every aᵢ by 1)."""
    x = TegVar("x")
    big, ctx = Const(0), []
    for i in range(first, last + 1):
        a = Var(f"a{i}", float(1 / i))
        big += IfElse(x + a > 0, 1, 0) * shade(a, x)
        ctx.append((a, 1))
    return Teg(Const(-1), Const(1), big, x), ctx


def derivative(expr, ctx):
    """The forward derivative, reduced to the base language (Teg's compile step)."""
    return reduce_to_base(fwd_deriv(expr, ctx))


def program(n: int):
    """Microbenchmark 1's derivative at n jumps (2n deltas), and nothing else to evaluate it at."""
    total, ctx = Const(0), []
    for shade in (plus, minus):
        expr, moved = integral(10, 9 + n, shade)
        total += expr
        ctx += moved
    return derivative(total, ctx), None


def number(expr, values=None, samples: int = 10) -> float:
    return float(evaluate(expr, backend="numpy", num_samples=samples))


if __name__ == "__main__":
    print(number(*program(int(sys.argv[1]))))
