"""``langur.lint.affineclear`` (issue 15): where it says the transversality analysis would find
nothing at the parameter values, the full analysis (``langur.transversality.check_loaded``, sympy)
finds nothing there; and it does decide the simple cases (Fig. 1, microbenchmark 1, Fig. 9 away
from its corners, 2-D affine programs), so ``deriv --engine mc`` runs without sympy on them.

The reference is the full analysis itself, run on hand-written programs where it reports each kind
of finding (a jump on the domain's end at the values, a condition counted twice, parallel jumps
meeting at the values, three lines through a point, a blow-up), and on random well-typed programs
of ``langur.strategies`` (not restricted to generic ones) at their defaults and at parameter
values chosen to make zero sets meet (0, 1/2, 1, −1).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from langur import frontend, transversality
from langur import strategies as ls
from langur.lint import affineclear, singular
from langur.primitives import REGISTRY

ROOT = Path(__file__).resolve().parents[1]


def mb1(n: int, a: str = "1") -> str:
    """Microbenchmark 1 as bench/bench_peers.py writes it (§10.3.2): n jumps, twice."""
    return (f"param a = {a}\n"
            f"int ([-1, 1]) (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 + x))"
            f" + (sum i in 10..{9 + n}: [x + 1/i + a - 1 >= 0] * (1/i + a - 1 - x)) d(x)\n")


FIG1 = (ROOT / "examples" / "fig1.lgr").read_text()
FIG9 = (ROOT / "examples" / "fig9.lgr").read_text()
TWO_LINES = "param t = 0.7, s = 0.1\nint ([0, 1], [0, 1]) [x + y <= t] * [x - y <= s] * (1 + x*y) d(x, y)\n"

#: (name, text, values overriding the defaults, whether the pre-check must decide it)
CASES = [
    ("fig1", FIG1, {}, True),
    ("fig1 jump at the lower end", FIG1, {"theta": 0}, False),  # X305
    ("fig1 jump at the upper end", FIG1, {"theta": 1}, False),  # X305
    ("fig1 at 0.3", FIG1, {"theta": 0.3}, True),
    ("a condition twice", "param t = 0.5\nint ([0, 1]) [x <= t] * [x <= t] d(x)", {}, False),  # X301
    ("a condition squared", "param t = 0.5\nint ([0, 1]) [x <= t]^2 d(x)", {}, False),  # X301
    ("exp of a condition", "param t = 0.5\nint ([0, 1]) exp([x <= t]) d(x)", {}, False),  # X301
    ("a fixed condition twice", "int ([0, 1]) [x <= 0.5] * [x <= 0.5] d(x)", {}, False),  # X308
    ("a window closing", "param a = 0.5, b = 0.5\nint ([0, 1]) [x <= a] * [x >= b] d(x)", {}, False),  # X305
    ("a window open", "param a = 0.6, b = 0.3\nint ([0, 1]) [x <= a] * [x >= b] * exp(x) d(x)", {}, True),
    ("a window reversed", "param a = 0.3, b = 0.6\nint ([0, 1]) [x <= a] * [x >= b] d(x)", {}, True),
    ("same side, moving", "param t = 0.5\nint ([0, 1]) [x <= t] * [x <= 2*t] d(x)", {}, False),  # X304
    ("same side, two params", "param t = 0.5, s = 0.25\nint ([0, 1]) [x <= t] * [x <= s] d(x)", {}, False),  # X304
    ("summands never multiply", "param t = 0.5\nint ([0, 1]) [x <= t] + [x <= t] d(x)", {}, True),
    ("1/sqrt blow-up", "param t = 0.5\nint ([0, 1]) 1/sqrt(abs(x - t)) d(x)", {}, False),  # X313
    ("a cube", "param t = 0.5\nint ([0, 1]) (x - t)^3 * [x <= t] d(x)", {}, True),
    ("a parametric coefficient", "param t = 0.5\nint ([0, 1]) [t*x <= 0.25] d(x)", {}, False),
    ("mb1", mb1(8), {}, True),
    ("mb1 at a = 1/2", mb1(8), {"a": 0.5}, True),
    ("mb1 jump at the lower end", mb1(8), {"a": -0.1}, False),  # x = -1/10 - a + 1 = -1: X305
    ("fig9 at its corners", FIG9, {}, False),  # X303 at (-1, -1) and (1, 1)
    ("fig9 at 1/4", FIG9, {"theta": 0.25}, True),
    ("two lines", TWO_LINES, {}, True),
    ("two lines through a corner", TWO_LINES, {"t": 1, "s": 0}, False),  # X303
    ("three lines through a point", "param t = 0.5\nint ([0, 1], [0, 1]) [x <= t] * [y <= t] * [x + y <= 2*t] d(x, y)",
     {}, False),  # X303 for every t
    ("bounds as factors", "param t = 0.5\nint [0 <= x] * [x <= 1] * [x <= t] d(x)", {}, True),
    ("bounds as factors, jump on one", "param t = 0.5\nint [0 <= x] * [x <= 1] * [x <= t] d(x)", {"t": 1}, False),  # X305
    ("a branch on the parameter", "param t = 0.5\nint ([0, 1]) (if t >= 0.2 then [x <= t] else [x >= t]) * [x <= 0.5] d(x)",
     {}, False),  # X305: x = t meets x = 1/2
    ("an abs window on both ends", "param t = 0.5\nint ([0, 1]) [abs(x - t) <= 0.5] d(x)", {}, False),  # X305 twice
    ("a min kink", "param t = 0.3\nint ([0, 1]) [min(x, t) <= 0.2] * x d(x)", {}, True),
    ("a max square", "param t = 0.3\nint ([0, 1], [0, 1]) [max(x, y) <= t] * [x + y >= 0.1] d(x, y)", {}, True),
    ("opposite sides", "param t = 0.5\nint ([0, 1], [0, 1]) [x + y <= t] * [x + y >= t] d(x, y)", {}, False),  # X301
]


def _point(loaded, at) -> dict[str, float]:
    """The values ``deriv`` gives the gate (``commands._defined.transversal``: floats)."""
    return {k: float(v) for k, v in {**loaded.param_values({}), **at}.items()}


def _full(loaded, point) -> list:
    return transversality.check_loaded(loaded, at=point)


@pytest.mark.parametrize("name,text,at,decided", CASES, ids=[c[0] for c in CASES])
def test_hand_written(name, text, at, decided):
    loaded = frontend.load_text(text)
    point = _point(loaded, at)
    found = _full(loaded, point)
    pre = affineclear.nothing_to_find(loaded.program, point)
    assert pre == decided, (pre, [f.code for f in found])
    if pre:
        assert found == []  # sound: the full analysis finds nothing either


def test_the_undecided_cases_do_have_findings():
    """The hand-written cases the pre-check must not decide are real findings of the full analysis
    (so that the test above can fail on a pre-check that answers True too often)."""
    for name, text, at, decided in CASES:
        if decided or name == "a parametric coefficient":
            continue
        loaded = frontend.load_text(text)
        assert _full(loaded, _point(loaded, at)), name


def test_derivative_bounded_against_the_integrability_analysis():
    """Where ``derivative_bounded`` holds, the integrability analysis of ⦇p⦈ in each parameter
    (X313, X312) finds no blow-up; it holds for Fig. 1 and not for the 1/sqrt blow-up."""
    bounded = set()
    for name, text, at, _decided in CASES:
        loaded = frontend.load_text(text)
        point = {**loaded.param_values({}), **at}
        if not affineclear.derivative_bounded(loaded.program, point):
            continue
        bounded.add(name)
        for p in loaded.params:
            res = singular.derivative_integrability(loaded.program, point, {q: int(q == p) for q in loaded.params})
            assert res.blowups == [] and res.note is None, (name, p)
    assert {"fig1", "mb1", "two lines"} <= bounded and "1/sqrt blow-up" not in bounded


def test_smooth_primitives_are_defined_everywhere():
    assert affineclear.SMOOTH <= {name for name, p in REGISTRY.items() if p.domain.everywhere}


SPECIAL = (0.0, 0.5, 1.0, -1.0)
_seen = {"decided": 0, "programs": 0}


@settings(max_examples=150, deadline=None, derandomize=True, database=None,
          suppress_health_check=list(HealthCheck))
@given(ls.programs(max_variables=2, max_conds=4, generic=False, kinks=True, lets=True, defs=True),
       st.integers(0, 3))
def test_random_programs(g, k):
    loaded = g.load()
    if loaded.program is None:
        return
    _seen["programs"] += 1
    names = list(loaded.params)
    points = [{}] + [{n: SPECIAL[(k + i + j) % 4] for j, n in enumerate(names)} for i in range(2)]
    points += [{n: SPECIAL[k]} for n in names[:2]]
    for at in points:
        point = _point(loaded, at)
        if not affineclear.nothing_to_find(loaded.program, point):
            continue
        _seen["decided"] += 1
        found = _full(loaded, point)
        assert found == [], (g.text, point, [(f.code, f.message) for f in found])


def test_random_programs_were_decided_sometimes():
    """(after test_random_programs, in file order) the random check was not vacuous."""
    if not _seen["programs"]:
        pytest.skip("test_random_programs did not run")
    assert _seen["decided"] >= 10, _seen


def test_three_variables():
    """n = 3: two planes with independent normals never meet badly; a third through their common
    line at the values (t = 0: x + y + z = 1, x = y and z = 1/2 … meet the box) is left undecided."""
    text = "param t = 0.3\nint ([0, 1], [0, 1], [0, 1]) [x + y + z <= 1 + t] * [x - y <= t] d(x, y, z)"
    loaded = frontend.load_text(text)
    for t in (0.3, 0.0, 0.5, 1.0):
        point = _point(loaded, {"t": t})
        if affineclear.nothing_to_find(loaded.program, point):
            assert _full(loaded, point) == [], t


def test_powers_of_nonzero_constants_are_bounded():
    """MB1's ``1/i`` is a constant: ``langur.lint.bounded`` skips the integrability analysis for
    it (which finds nothing there), but not a power of 0 or a fractional power of a negative."""
    from fractions import Fraction

    from langur.core import Const, Pow
    from langur.lint import bounded

    loaded = frontend.load_text(mb1(8))
    point = loaded.param_values({})
    assert bounded.nothing_to_find(loaded.program, point)
    res = singular.value_integrability(loaded.program, point)
    assert res.blowups == [] and res.note is None
    assert bounded.bounded(Pow(Const(Fraction(10)), Fraction(-1)))
    assert bounded.bounded(Pow(Const(Fraction(2)), Fraction(-1, 2)))
    assert not bounded.bounded(Pow(Const(Fraction(0)), Fraction(-1)))
    assert not bounded.bounded(Pow(Const(Fraction(-2)), Fraction(1, 2)))
