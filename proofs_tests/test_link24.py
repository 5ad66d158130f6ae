"""The Monte Carlo engine's cheaper link and evaluation (issue 15, branch link24): what changed gives
the same doubles as what it replaced.

* A zero set's point in one variable is found on Python floats where the sampler's terms are sums,
  products and the powers 0, ±1, 2 (``Sharing.numbers``): bit for bit the numbers of the same terms
  on numpy arrays of one point (random terms; random one-variable programs estimated both ways).
* ``x + (−0.0)`` and ``x · 1.0`` are left out of the compiled closures: the bits of every double
  (±0, ±∞, NaN, subnormals) come out unchanged.
* The linker's site search skips smooth subterms: the sites (their Ψ̂, in pre-order) are those a walk
  of every node finds.
"""

from __future__ import annotations

from fractions import Fraction

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from langur.core import Add, Const, IfDiffeo, Mul, Param, Pow, Prim, Var, children, const
from langur.frontend import load_text
from langur.operational import CACHE, clear_cache, estimate_derivative
from langur.operational.compile import compile_pure
from langur.operational.link import _canonical_sites
from langur.operational.point import TANGENT, UNLINKED, Point
from langur.operational.sample import SiteSampler

x, a = Var("x"), Param("a")
SPECIAL = [0.0, -0.0, np.inf, -np.inf, np.nan, 5e-324, -5e-324, 1.5, -2.0 ** 1000, 1e308, 3.0]


def bits(v) -> bytes:
    """The doubles' bits, every NaN as numpy's ``nan`` (a NaN's sign and payload are not a value: x86
    gives the first NaN operand of a sum, and a C compiler may swap a sum's operands, so which of two
    NaNs a Python float sum returns is not the one numpy's loop returns)."""
    v = np.array(v, dtype=float).reshape(-1)
    v[np.isnan(v)] = np.nan
    return v.tobytes()


def _exact_terms():
    leaves = st.one_of(st.just(x), st.just(a), st.sampled_from([-2, -1, 0, 1, 3]).map(const),
                       st.fractions(-5, 5, max_denominator=7).map(lambda f: Const(Fraction(f))))

    def extend(c):
        return st.one_of(st.builds(Add, c, c), st.builds(Mul, c, c),
                         st.builds(Pow, c, st.sampled_from([Fraction(0), Fraction(1), Fraction(2), Fraction(-1)])))
    return st.recursive(leaves, extend, max_leaves=10)


@given(_exact_terms(), st.sampled_from(SPECIAL + [0.25, -0.7, 1e-300]), st.sampled_from(SPECIAL + [0.4, -1.3]))
@settings(max_examples=300, deadline=None)
def test_sums_products_and_exact_powers_give_the_same_doubles_on_numbers_as_on_arrays(term, xv, av):
    (fn,), numbers = compile_pure([term])
    assert numbers  # only sums, products and the powers 0, ±1, 2: the sampler may run it on numbers
    with np.errstate(all="ignore"):
        on_numbers = fn(Point({"x": float(xv)}, {"a": float(av)}, dvars={"x": 1.0}, dparams={"a": 0.5},
                              mode=TANGENT), UNLINKED)
        on_arrays = fn(Point({"x": np.array([xv])}, {"a": float(av)}, dvars={"x": 1.0}, dparams={"a": 0.5},
                             mode=TANGENT), UNLINKED)
    for mine, ref in zip(on_numbers, on_arrays):
        if mine is None or ref is None:
            assert mine is None and ref is None
        else:
            assert bits(mine) == bits(np.broadcast_to(ref, (1,))), (term, xv, av, mine, ref)


def test_primitives_and_other_powers_are_not_run_on_numbers():
    for t in (Prim("exp", x), Pow(x, Fraction(1, 2)), Pow(x, Fraction(3)), Add(x, Prim("sin", a))):
        assert not compile_pure([t])[1]
    assert compile_pure([Add(Mul(x, a), Pow(x, Fraction(-1)))])[1]


def test_unit_operations_left_out_keep_every_double():
    v = np.array(SPECIAL)
    minus_zero = Mul(const(-1), const(0))  # −0.0, folded (as an affine completion writes ``- 0``)
    for term, ref in ((Add(x, minus_zero), v + (-0.0)), (Add(minus_zero, x), (-0.0) + v),
                      (Mul(x, const(1)), v * 1.0), (Mul(const(1), x), 1.0 * v)):
        (fn,), _ = compile_pure([term])
        out, d = fn(Point({"x": v}, {}, dvars={"x": v}, mode=TANGENT), UNLINKED)
        assert out is v and d is v  # no operation at all …
        assert bits(out) == bits(ref)  # … and the doubles the operation gives
    # +0.0 is not a unit (−0.0 + 0.0 is +0.0): that sum stays
    (fn,), _ = compile_pure([Add(x, const(0))])
    out, _ = fn(Point({"x": v}, {}), UNLINKED)
    assert out is not v and bits(out) == bits(v + 0.0)


def _one_variable_programs():
    coeff = st.sampled_from(["1", "2", "-1", "1/3", "-5/7", "3"])
    shift = st.sampled_from(["0", "1/10", "-1/4", "2/3", "-0.35"])
    jump = st.tuples(coeff, coeff, shift, st.sampled_from(["1", "x", "x*x", "a*x - 1", "exp(x)"]))
    return st.lists(jump, min_size=1, max_size=6)


@given(_one_variable_programs(), st.sampled_from([0.3, 1.0, -0.8]))
@settings(max_examples=40, deadline=None)
def test_one_variable_zero_sets_on_numbers_equal_the_array_path(jumps, av):
    terms = " + ".join(f"[{c}*x + {d}*a + {s} >= 0] * ({body})" for c, d, s, body in jumps)
    loaded = load_text(f"param a = 1\nint ([-1, 1]) {terms} d(x)\n")

    def estimate():
        clear_cache()
        e = estimate_derivative(loaded, {"a": av}, {"a": 1.0}, samples=16, seed=3)
        return [e.value, e.stderr, e.regular.value, e.boundary.value, e.boundary.stderr]

    fast = estimate()
    live = [s.sampler for linked in CACHE.linked.values() for s in linked.sites if "a" in s.deps]
    assert live and all(s.on_numbers for s in live)  # affine conditions: every zero set found on numbers
    numbers = SiteSampler.numbers
    try:
        SiteSampler.numbers = property(lambda self: False)  # every zero set's point on arrays, as before
        slow = estimate()
    finally:
        SiteSampler.numbers = numbers
        clear_cache()
    assert bits(fast) == bits(slow), (terms, fast, slow)


def _walk_sites(t, out):
    if isinstance(t, IfDiffeo):
        out.append(t.psi)
    for c in children(t):
        _walk_sites(c, out)
    return out


@given(st.lists(st.tuples(st.sampled_from(["x", "-x", "2*x + a"]), st.sampled_from(["1", "x", "a", "x*a"]),
                          st.booleans()), min_size=1, max_size=5), st.integers(1, 4))
@settings(max_examples=30, deadline=None)
def test_the_site_search_finds_what_a_walk_of_every_node_finds(parts, n):
    pieces = []
    for cond, body, smooth_side in parts:
        piece = f"[{cond} + 1/i - a >= 0] * ({body})"
        pieces.append(f"({body} + {piece})" if smooth_side else piece)
    text = f"param a = 1\nint ([-1, 1]) (sum i in 2..{n + 1}: {' + '.join(pieces)}) d(x)\n"
    program = load_text(text).program
    clear_cache()
    found = [s.sampler.psi for s in _canonical_sites(program, None, CACHE)]
    clear_cache()
    assert found == _walk_sites(program.body, [])
