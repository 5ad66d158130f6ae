"""Two roots of a condition closer than the quadrature's grid step (``quadrature.roots._hidden_pairs``).

``∫₀²∫₀² [x ≥ sin(z) + a] dx dz`` = 3 − 2a + cos 2 by hand (∫₀² (2 − a − sin z) dz, the set in x
is [sin z + a, 2]).  Integrated the other way round, z innermost, the set in z for x just below
a + 1 is [0, asin(x − a)] ∪ [π − asin(x − a), 2]: its gap around π/2 is narrower than the grid step
(2/40) of the sign-change search, which saw no root there, and the exact engine's quadrature gave
1.843859159 ± 5.7e−10 for 1.843853163 at a = 0.37 — then preferred it to sympy's correct closed
form.  Found while measuring the campaign (program 641 of seed 1).
"""

import math

import pytest

from langur import exact as api
from langur.frontend import load_text
from langur.symbolic.quadrature.roots import _roots
from langur.timebox import budget


def test_a_maximum_between_nodes_that_crosses_zero_gives_both_roots():
    a, x = 0.37, 0.37 + 1 - 1e-4
    found = sorted(_roots(lambda z: x - a - math.sin(z), 0.0, 2.0))
    r = math.asin(x - a)
    assert found == pytest.approx([r, math.pi - r], abs=1e-12)


def test_a_minimum_between_nodes_and_one_next_to_the_end():
    found = sorted(_roots(lambda z: (z - 1.0123) ** 2 - 1e-8, 0.0, 2.0))
    assert found == pytest.approx([1.0123 - 1e-4, 1.0123 + 1e-4], abs=1e-12)
    found = sorted(_roots(lambda z: 1e-6 - (z - 0.01) ** 2, 0.0, 2.0))
    assert found == pytest.approx([0.01 - 1e-3, 0.01 + 1e-3], abs=1e-12)


def test_a_turn_the_grid_sees_or_that_stays_on_one_side_adds_nothing():
    assert _roots(lambda z: 0.5 - math.sin(z), 0.0, 2.0) == pytest.approx([math.asin(0.5)])
    assert _roots(lambda z: 1.001 - math.sin(z), 0.0, 2.0) == []


@pytest.mark.parametrize("a", [0.37, 0.95])
def test_the_quadrature_of_the_program_matches_its_value_by_hand(a):
    program = load_text(f"param a = {a}\nint ([0, 2], [0, 2]) [x >= sin(z) + a] d(x, z)\n").program
    with budget(0.0):  # no closed form: the quadrature alone
        r = api.exact_eval(program, {"a": a})
    assert r.method == "quadrature"
    exact = 3 - 2 * a + math.cos(2)
    assert abs(float(r.value) - exact) <= r.error + 1e-12, (float(r.value), r.error, exact)
