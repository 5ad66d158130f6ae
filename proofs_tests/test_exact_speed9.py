"""The exact engine's shortcuts of issue 15 (ninth pass, exact9) give what the slow paths gave:
exact rationals added and multiplied by Henrici's algorithm (the operands' denominators' gcds) are
the exact sums and products, reduced; a polygon's triangles remembered across weights give the
closed forms computed afresh; ``text.shared_lambdify``'s own generation of sympy's code
(without lambdify's walks of the tree with its repeats) makes sympy's source text, namespace and
values, and leaves to sympy what it does not handle (dummies, unsafe names, ``Subs``, implemented
functions)."""

from __future__ import annotations

import inspect
import math
import random
import re
from fractions import Fraction

import pytest
import sympy as sp
from sympy.utilities.lambdify import implemented_function

from langur.symbolic import exactpairs, local, rational, text
from langur.symbolic.context import Cond as local_cond
from langur.symbolic.text import shared_lambdify

x, y, z = sp.symbols("x y z", real=True)


def _pair(rng: random.Random, bits: int) -> tuple[int, int]:
    """A reduced pair ``(n, d > 0)``, often sharing factors with others (small primes, powers of 2)."""
    n = rng.choice([0, 1, -1, rng.getrandbits(bits) - (1 << (bits - 1))]) * rng.choice([1, 2 ** rng.randint(0, 60), 3 * 7])
    d = max(1, rng.getrandbits(bits)) * rng.choice([1, 2 ** rng.randint(0, 80), 5, 9])
    f = Fraction(n, d)
    return f.numerator, f.denominator


@pytest.mark.parametrize("bits", [4, 64, 700])
def test_rational_pairs_add_and_multiply_to_fractions_reduced(bits):
    rng = random.Random(bits)
    for _ in range(400):
        p, q = _pair(rng, bits), _pair(rng, bits)
        if rng.random() < 0.2 and math.gcd(q[0], p[1]) == 1:
            q = (q[0], p[1])  # equal denominators
        for got, want in ((exactpairs.qadd(p, q), Fraction(*p) + Fraction(*q)),
                          (exactpairs.qmul(p, q), Fraction(*p) * Fraction(*q))):
            assert got == (want.numerator, want.denominator)  # exact, reduced, denominator > 0


def test_exact_values_and_slopes_at_float_points_match_sympy():
    """Large forms at points of floats (dyadic rationals of ~60 bits, as Theorem 8.1's nearby points:
    values of hundreds of digits) against sympy's exact substitution and derivative along the line."""
    a, b, c = sp.symbols("a b c", real=True)
    rng = random.Random(9)
    pt = {a: sp.Rational(0.1 + 1e-3 * rng.uniform(-1, 1)), b: sp.Rational(0.85 + 1e-3 * rng.uniform(-1, 1)),
          c: sp.Rational(0.35 + 1e-3 * rng.uniform(-1, 1))}
    tg = {a: 0, b: 1, c: 0}
    s = sp.Symbol("s", real=True)
    checked = 0
    for _ in range(4):
        pool = [a, b, c, a * b - c, (b - a) * (c + 1)]
        for _ in range(18):
            p, q = rng.choice(pool), rng.choice(pool)
            pool.append([p + q, p * q, p - q, p / (q**2 + 1), (p - q) ** 2][rng.randrange(5)])
        e = sp.Add(*pool[-6:]) + sp.Abs(pool[-1] - 7)
        want = e.xreplace(pt)
        assert want.is_Rational
        assert rational.rational_value(e, pt) == want
        slope = sp.diff(e.xreplace({k: v + s * tg[k] for k, v in pt.items()}), s).subs(s, 0)
        assert rational.dual_derivative(e, pt, tg) == slope
        checked += 1
    assert checked == 4


def _shared_tree(seed: int):
    rng = random.Random(seed)
    pool = [x, y, z, sp.pi, sp.Rational(3, 7), sp.Float("0.1", 30), x * y + 1, sp.sqrt(z**2 + 1)]
    for _ in range(25):
        p, q = rng.choice(pool), rng.choice(pool)
        pool.append([p + q, p * q, p / (q**2 + 1), sp.exp(p) * q, sp.Abs(p) + q,
                     sp.Piecewise((p, q > 0), (q, True)), sp.sin(p) ** 2][rng.randrange(7)])
    return sp.Add(*pool[-4:])


def _printer(module: str):
    cls = {"math": text._SharedPython, "mpmath": text._SharedMpmath, "numpy": text._SharedNumPy}[module]
    return cls({"fully_qualified_modules": False, "inline": True, "allow_unknown_functions": True,
                "user_functions": {}})


def _ours(f) -> bool:
    return f.__code__.co_filename.startswith("<lambdifygenerated-langur-")


@pytest.mark.parametrize("seed", range(6))
def test_generated_functions_are_sympys(seed):
    """Source text, namespace (every name and the object it names) and values as sympy.lambdify's,
    for math, mpmath and numpy, with a free symbol that is not an argument (a name of the namespace)."""
    e = _shared_tree(seed) + sp.Symbol("w") * 0 + sp.Symbol("k", positive=True) * x
    args = [x, y, z]
    for module in ("math", "mpmath", "numpy"):
        # sympy's lambdify with a shared printer as before (its printers start with the module names
        # earlier ones imported, which lambdify imports too), and with its own printer
        before = sp.lambdify(args, e, modules=[module], printer=_printer(module))
        ours, theirs = shared_lambdify(args, e, module), sp.lambdify(args, e, modules=[module])
        assert _ours(ours) and not _ours(theirs) and not _ours(before)
        assert inspect.getsource(ours) == inspect.getsource(theirs) == inspect.getsource(before)
        g1 = {k: v for k, v in ours.__globals__.items() if k != "__builtins__"}
        g0 = {k: v for k, v in before.__globals__.items() if k != "__builtins__"}
        g2 = {k: v for k, v in theirs.__globals__.items() if k != "__builtins__"}
        assert g1.keys() == g0.keys() and g2.keys() <= g1.keys()
        assert all(g1[k] is g0[k] or g1[k] == g0[k] for k in g1)
        assert all(g1[k] is g2[k] or g1[k] == g2[k] for k in g2)
        pt = (0.3, -0.7, 1.1)
        try:
            want = complex(theirs(*pt))
        except (ValueError, ZeroDivisionError, OverflowError, TypeError, NameError) as exc:
            with pytest.raises(type(exc)):
                complex(ours(*pt))
            continue
        got = complex(ours(*pt))
        assert got == want or (math.isnan(got.real) and math.isnan(want.real))


def test_what_lambdify_rewrites_is_left_to_lambdify():
    """Arguments lambdify renames (a Dummy, a keyword, a name that is no identifier), an expression
    holding ``Subs`` or a function with its own implementation: sympy's lambdify makes the function,
    with the same code as before."""
    d = sp.Dummy("d")
    kw, odd = sp.Symbol("lambda"), sp.Symbol("a.b")
    imp = implemented_function("g", lambda t: 2 * t)
    cases = [([d, y], d * y + 1), ([kw, y], kw + y), ([odd, y], odd * y),
             ([x, y, z], sp.Subs(sp.sin(x) * z, x, y) + x), ([x], imp(x) + 1)]
    for args, e in cases:
        ours = shared_lambdify(args, e, "math")
        assert not _ours(ours)
        theirs = sp.lambdify(args, e, modules=["math"])
        assert re.sub(r"Dummy_\d+", "D", inspect.getsource(ours)) == re.sub(r"Dummy_\d+", "D", inspect.getsource(theirs))
    ours = shared_lambdify([x], imp(x) + 1, "math")
    assert ours(1.5) == 4.0


def test_generated_source_is_in_linecache_until_the_function_goes():
    import gc
    import linecache
    f = shared_lambdify([x], sp.cos(x) + 1, "math")
    name = f.__code__.co_filename
    assert "return cos(x) + 1" in "".join(linecache.getlines(name))
    del f
    gc.collect()
    assert name not in linecache.cache
    assert text._NAMESPACES  # (the modules' namespaces are kept, copied for each function)


def test_remembered_triangles_give_the_forms_computed_afresh():
    """⟦p⟧'s and each partial derivative's weights over one polygon (its triangles' rule points
    remembered, :func:`local._triangle_points`): every closed form is the one computed with nothing
    remembered (the same tree: the same printed text), and its value that of scipy's quadrature."""
    from test_local_closed_forms import _clip_halfplanes, _ctx, _triangle_quad

    a, b, c = sp.symbols("a b c", real=True)
    at = {"a": Fraction(3, 10), "b": Fraction(1, 2), "c": Fraction(-1, 5)}
    conds = [local_cond(y - a * x - b / 2), local_cond(c + 1 - x - y), local_cond(x + 2 * y - a)]
    box = {x: (sp.Integer(-1), sp.Integer(1)), y: (sp.Integer(-1), b + 1)}
    weights = [(1 + a * x) * (y - c) ** 2 + b * x * y, sp.diff((1 + a * x) * (y - c) ** 2, a), x**3 * c - y * a**2]
    local._TRIANGLES.clear()
    remembered = [local.polygon_integral(conds, w, x, y, box, _ctx(at)) for w in weights]
    assert local._TRIANGLES
    fresh = []
    for w in weights:
        local._TRIANGLES.clear()
        fresh.append(local.polygon_integral(conds, w, x, y, box, _ctx(at)))
    assert [sp.srepr(e) for e in remembered] == [sp.srepr(e) for e in fresh]
    num = {sp.Symbol(k, real=True): float(q) for k, q in at.items()}
    gs = [sp.lambdify((x, y), cd.expr.xreplace(num)) for cd in conds]
    poly = _clip_halfplanes([(-1.0, -1.0), (1.0, -1.0), (1.0, 1.5), (-1.0, 1.5)], gs)
    for w, e in zip(weights, remembered):
        f = sp.lambdify((x, y), w.xreplace(num))
        ref = sum(_triangle_quad(f, poly[0], p1, p2) for p1, p2 in zip(poly[1:], poly[2:]))
        assert float(e.xreplace(_ctx(at).at)) == pytest.approx(ref, rel=1e-10, abs=1e-12)
