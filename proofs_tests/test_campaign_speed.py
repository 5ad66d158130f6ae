"""Issue 13's throughput changes keep every answer: the linter's exact solver for affine systems
(``langur.lint.algebra._affine_solution``) finds what ``sympy.solve`` finds, the findings of
generated programs are the same with and without it, and a campaign's programs are checked as
they are generated (same programs, same order)."""

import random
import time

import pytest
import sympy as sp

from langur import fuzz
from langur.frontend import load_text
from langur.lint import algebra
from langur.transversality import check_loaded

X, Y, Z = sp.symbols("x y z")


def _by_sympy(eqs, unknowns):
    """What ``_solve_points`` returned before the affine case: sympy's solutions, verified."""
    return [s for s in sp.solve(eqs, unknowns, dict=True)
            if s and all(e.subs(s) == 0 for e in eqs)]


def test_affine_systems_are_solved_as_sympy_solves_them():
    rng = random.Random(13)
    decided = {"none": 0, "one": 0}
    for _ in range(400):
        k = rng.choice([1, 2, 3])
        xs = (X, Y, Z)[:k]
        eqs = [sum(sp.Rational(rng.randint(-2, 2), rng.randint(1, 3)) * v for v in xs)
               + sp.Rational(rng.randint(-3, 3), rng.randint(1, 4)) for _ in range(rng.randint(1, k + 1))]
        eqs = [e for e in eqs if e != 0]
        if not eqs:
            continue
        fast = algebra._affine_solution(eqs, xs)
        if fast is None:  # an unknown left free: sympy words the curve of solutions
            assert sp.Matrix([[e.coeff(v) for v in xs] for e in eqs]).rank() < k and _by_sympy(eqs, xs)
            continue
        assert fast == _by_sympy(eqs, xs), eqs
        decided["one" if fast else "none"] += 1
    assert decided["none"] > 20 and decided["one"] > 20  # both outcomes were exercised


def test_what_is_not_affine_and_rational_is_left_to_sympy():
    a = sp.Symbol("a")
    assert algebra._affine_solution([X - a, Y], (X, Y)) is None           # a parameter left
    assert algebra._affine_solution([X * X - 1, Y], (X, Y)) is None       # not affine
    assert algebra._affine_solution([X - sp.sqrt(2), Y], (X, Y)) is None  # irrational coefficient
    assert algebra._affine_solution([sp.Float(0.5) * X - 1, Y], (X, Y)) is None  # a float
    assert algebra._affine_solution([X - 1, X - 2], (X, Y)) == []         # parallel lines
    assert algebra._affine_solution([X + Y - 1, X - Y], (X, Y)) == [{X: sp.Rational(1, 2), Y: sp.Rational(1, 2)}]


PROGRAMS = [
    # three lines through the point (1/2, 1/2) of the square: X303 at that point
    "param a = 0.5\nint ([0, 1], [0, 1])\n  [x + y >= 2 * a] * [x >= y] * [y <= 0.5]\nd(x, y)\n",
    # three lines with no common point, and a circle
    "param a = 0.3, b = 0.6\nint ([0, 1], [0, 1])\n  [x + y <= a + 0.5] * [x >= b] * [y >= 0.2] * [x * x + y * y <= b]\nd(x, y)\n",
    # planes in three variables
    "param a = 0.4\nint ([0, 1], [0, 1], [0, 1])\n  [x + y + z <= 3 * a] * [x >= a] * [y >= a] * [z <= 0.5 * x + a]\nd(x, y, z)\n",
]


def _findings(text):
    loaded = load_text(text, path="p.lgr")
    at = {k: float(v) for k, v in loaded.param_values({}).items()}
    return [(f.code, f.message) for f in check_loaded(loaded, at=at, sources={"p.lgr": text})]


def _forget():
    algebra._solve_points_cached.cache_clear()


@pytest.mark.parametrize("text", PROGRAMS + fuzz.generated(6, 13, light=True))
def test_the_findings_are_the_same_without_the_affine_solver(text, monkeypatch):
    _forget()
    fast = _findings(text)
    _forget()
    monkeypatch.setattr(algebra, "_affine_solution", lambda eqs, unknowns: None)
    assert _findings(text) == fast
    _forget()


def test_the_first_program_is_reported_three_zero_sets_through_a_point():
    _forget()
    assert any(code == "X303" and "(1/2, 1/2)" in m for code, m in _findings(PROGRAMS[0]))


def test_a_campaign_checks_each_program_as_it_is_generated():
    seen = []
    assert fuzz.generated(5, 2, light=True, each=seen.append) == seen == fuzz.generated(5, 2, light=True)

    class Boom(Exception):
        pass

    def fail(text):
        raise Boom(text)

    with pytest.raises(Boom) as e:  # not caught and shrunk by hypothesis: raised as it is
        fuzz.generated(5, 2, light=True, each=fail)
    assert str(e.value) == seen[0]


def test_a_unit_killed_at_its_time_limit_says_in_which_phase(monkeypatch):
    from langur.fuzz import campaign, compare, pool

    def hangs(*args, **kwargs):  # computes forever: killed at its limit in CPU seconds
        while True:
            pass

    monkeypatch.setattr(compare, "_exact_all", hangs)
    monkeypatch.setattr(pool, "GRACE", 0.0)
    text = "param a = 0.37\nint ([0, 1])\n  x + a\nd(x)\n"
    t0 = time.monotonic()
    (res,) = pool.run_units([text], lambda t: compare.compare_text(t, isolate=False), workers=1, limit=1.5,
                            on_time_limit=campaign._time_limited, on_error=campaign._unit_error)
    assert time.monotonic() - t0 < 30
    assert res.status == "timeout" and res.killed_in == "exact" and "in its exact phase" in res.reason
    assert set(res.timing) == {"front_end", "lint"}  # the phases it finished, with their seconds
