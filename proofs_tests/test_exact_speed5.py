"""The exact engine's shortcuts of issue 15 (exact5): each gives what the plain computation gives.

* exact values and derivatives along a line of rational forms remembered per point and flattened
  once (``rational.rational_value``, ``rational.dual_derivative``) against sympy's substitution and
  derivative, for several points and tangents in turn (what Theorem 8.1's check asks for every
  partial derivative), and more points than are remembered;
* ``walks.size`` by distinct subtrees against the node-by-node count;
* the sign probes' compiled conditions (``text.math_lambdify``) and the code printers without the
  ``re`` rewrite walk against ``sympy.lambdify``'s own source text;
* remembered texts of cell relations and the point's 40-digit Floats against recomputing them.
"""

from __future__ import annotations

import inspect
import random
from fractions import Fraction

import sympy as sp

from langur.symbolic import context, integrate, rational, tape, text, walks
from langur.symbolic.context import Context
from langur.timebox import Deadline

a, b, c, x, y = sp.symbols("a b c x y", real=True)


def _forms(seed: int, n: int):
    """Random rational forms over a, b, c sharing their subtrees (a DAG, as the local closed forms)."""
    rng = random.Random(seed)
    out = []
    while len(out) < n:
        pool = [a, b, c, sp.Rational(rng.randint(-9, 9), rng.randint(1, 7))]
        for _ in range(30):
            p, q = rng.choice(pool), rng.choice(pool)
            pool.append([p + q, p * q, p - q, p / (q**2 + 1), p ** rng.randint(-2, 3), sp.Abs(p - q + 3)][rng.randrange(6)])
        e = sp.Add(*pool[-6:]) * pool[-7] + pool[-8]
        if not e.has(sp.zoo, sp.nan, sp.oo) and e.free_symbols:
            out.append(e)
    return out


def test_values_and_slopes_at_many_points_and_tangents_are_sympys():
    rng = random.Random(5)
    # more points than the tape remembers (tape.VALUE_POINTS), revisited: evicted values are recomputed
    points = [{k: sp.Rational(rng.randint(-40, 40), rng.randint(1, 13)) for k in (a, b, c)}
              for _ in range(tape.VALUE_POINTS + 1)]
    points.append({a: sp.Rational(0.1234567), b: sp.Rational(-2.5e-3), c: sp.Rational(7.75)})  # floats' exact values
    tangents = [{a: 1}, {c: 1}, {a: sp.Rational(1, 3), b: -2}]
    checked = 0
    for e in _forms(11, 4):
        grad = {k: sp.diff(e, k) for k in (a, b, c)}  # (sympy: Abs' = sign, 0 where its argument is)
        kinks = [n.args[0] for n in sp.preorder_traversal(e) if isinstance(n, sp.Abs)]
        for pt in points + points[:2]:
            want = e.xreplace(pt)
            if not want.is_Rational:  # a division by 0 there: both say None
                assert rational.rational_value(e, pt) is None
                continue
            assert rational.rational_value(e, pt) == Fraction(int(want.p), int(want.q))
            if any(k.xreplace(pt) == 0 for k in kinks):
                continue
            for tg in tangents:
                slope = sum(t * grad[k].xreplace(pt) for k, t in tg.items())
                assert rational.dual_derivative(e, pt, tg) == Fraction(int(slope.p), int(slope.q)), (e, pt, tg)
                checked += 1
    assert checked > 80


def test_slope_of_a_form_with_a_zero_factor_and_a_cancelling_sum():
    pt = {a: sp.Rational(2), b: sp.Rational(3)}
    e = sp.Mul(a - 2, b**3, evaluate=False) + (a * b - b * a)  # value 0, slope along a: b³ = 27
    assert rational.rational_value(e, pt) == 0
    assert rational.dual_derivative(e, pt, {a: 1}) == 27
    assert rational.dual_derivative(e, pt, {b: 1}) == 0
    assert rational.dual_derivative(sp.sqrt(a) + b, pt, {a: 1}) is None  # not a rational form
    assert rational.dual_derivative(a + c, pt, {a: 1}) is None  # c has no value at the point
    assert rational.dual_derivative(1 / (a - 2), pt, {a: 1}) is None  # a pole there


def _walked(e, limit):
    n, stack = 0, [e]
    while stack and n < limit:
        node = stack.pop()
        n += 1
        stack.extend(node.args)
    return n


def test_size_by_distinct_subtrees_is_the_node_count():
    rng = random.Random(2)
    for _ in range(80):
        pool = [x, y, a, sp.Integer(rng.randint(1, 9))]
        for _ in range(rng.randint(1, 25)):
            p, q = rng.choice(pool), rng.choice(pool)
            pool.append([p + q, p * q, p**2, sp.sin(p) + q][rng.randrange(4)])
        e = pool[-1]
        assert walks.tree_size(e) == _walked(e, 10**12)
        for limit in (1, 7, 400, walks.WALKED_SIZE, walks.WALKED_SIZE + 1, 10**5, 10**9):
            assert walks.size(e, limit) == _walked(e, limit)


def _source(f) -> str:
    return inspect.getsource(f)


def test_compiled_sign_probes_are_lambdifys_code():
    rng = random.Random(3)
    exprs = [x**2 - a, sp.sqrt(a * x + 1) - sp.exp(-x) * b, sp.Abs(x - a) / (1 + x**2), sp.atan2(y, x) - a,
             sp.Piecewise((x, x > a), (a, True)) + sp.log(1 + x**2)]
    for _ in range(20):
        p, q = rng.choice(exprs), rng.choice(exprs)
        exprs.append(p * q + rng.randint(1, 5) * p)
    for e in exprs:
        args = (x, y, a, b)
        mine = text.math_lambdify(args, e)
        want = sp.lambdify(args, e, modules=["math"], docstring_limit=0)
        assert _source(mine) == _source(want)
        pt = (0.3, 0.7, 0.2, 1.5)
        try:
            w = want(*pt)
        except (ValueError, ZeroDivisionError):
            continue
        assert mine(*pt) == w


def test_code_printers_skip_the_re_rewrite_only_when_there_is_no_re():
    e_plain = (x + a) ** 2 * sp.sin(x) + sp.sqrt(y)
    e_re = sp.re(x * a) + x
    for module in ("math", "numpy", "mpmath"):
        for e in (e_plain, e_re):
            if module == "math" and e is e_re:
                continue  # (math has no re: sympy's own code fails the same way)
            mine = text.shared_lambdify([x, y, a], e, module)
            want = sp.lambdify([x, y, a], e, modules=[module], docstring_limit=0)
            assert _source(mine) == _source(want)


def test_remembered_relation_texts_and_floats_are_the_same():
    rels = [sp.StrictGreaterThan(a * b - c / 3 + 1, 0, evaluate=False), sp.GreaterThan(a**2 - b, 0), sp.Eq(a, b)]
    for r in rels + rels:
        assert integrate._relation_text(r) == str(r)
    at = {a: sp.Rational(1, 3), b: sp.Rational(-5, 7), c: sp.Integer(2)}
    ctx = Context(at, Deadline(5.0), frozenset(at))
    e = sp.exp(a) * b - sp.sqrt(c) / (1 + a**2)
    want = complex(e.xreplace({k: sp.Float(float(v), 40) for k, v in at.items()}).evalf(30))
    assert ctx.value(e) == want and ctx.value(e) == want
    assert context._floats40(at) is context._floats40(dict(at))
