"""Verdicts on seeded campaigns (issue 19): the linter's and the Theorem 8.1 check's false alarms
on random well-posed programs (none allowed), and their misses on a random family of degenerate
programs (none allowed).

The well-posed programs are ``langur fuzz``'s generator's (:func:`langur.fuzz.generate.programs`):
by construction no two zero sets, and no zero set and a face of the box, coincide at the
parameter defaults, and no zero set passes through a corner; affine, scaled, nonlinear and
declared conditions, lets and defs, in one and two variables.  The degenerate family is written
here, each template with the reason its derivative is undefined or wrong (paper §7.3, Def. 7.2),
and instantiated at random coefficients.
"""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
from hypothesis import HealthCheck, given, settings

from langur import transversality as tv
from langur.frontend import load_text
from langur.fuzz.generate import programs
from langur.theorem import check_theorem_8_1


def _campaign(n: int):
    """The first ``n`` programs of the derandomized generator (the same on every machine)."""
    found = []

    @settings(max_examples=n, derandomize=True, database=None, deadline=None,
              suppress_health_check=list(HealthCheck))
    @given(programs(light=True))
    def draw(p):
        found.append(p)

    draw()
    return found


@pytest.fixture(scope="module")
def well_posed():
    return _campaign(200)


def test_the_linter_raises_no_error_on_well_posed_random_programs(well_posed):
    assert len(well_posed) >= 150
    false_alarms = []
    for p in well_posed:
        at = {k: float(v) for k, v in p.params}
        errors = [f for f in tv.check_loaded(load_text(p.text), at=at) if f.severity == "error"]
        if errors:
            false_alarms.append((p.text, [(f.code, f.message) for f in errors]))
    assert false_alarms == []


def test_theorem_8_1_never_fails_on_well_posed_random_programs(well_posed):
    # D_γ⟦p⟧·γ' = ⦇p⦈ (Theorem 8.1) at the defaults, in the first parameter's direction; an exact
    # engine timeout is counted apart (not a verdict), and the check must decide most programs
    verdicts = []
    for p in well_posed[:16]:
        loaded = load_text(p.text)
        at = {k: Fraction(v) for k, v in p.params}
        try:
            th = check_theorem_8_1(loaded.program, at, {p.params[0][0]: 1}, timeout=5.0)
        except TimeoutError:
            continue
        verdicts.append((th.holds, p.text, th))
    assert [v for v in verdicts if v[0] is False] == []
    assert len(verdicts) >= 12
    assert sum(v[0] is True for v in verdicts) >= 0.75 * len(verdicts)


def _decimal(rng: random.Random, lo: float, hi: float) -> str:
    return f"{rng.uniform(lo, hi):.3f}"


def _degenerate(rng: random.Random):
    """(template name, program text, parameter point, expected (code, severity)), one per
    template, at random coefficients."""
    a = _decimal(rng, 0.1, 0.9)
    s, t = _decimal(rng, 0.2, 3.0), _decimal(rng, 0.2, 3.0)
    p, q = _decimal(rng, 0.3, 1.5), _decimal(rng, -0.9, 0.9)
    r = _decimal(rng, 0.2, 0.8)
    w = _decimal(rng, 0.5, 2.0)
    err = "error"
    return [
        # one zero set, two conditions on the same side: the jump is counted twice (§7.3.1)
        ("scaled duplicate", f"param a = {a}\nint ([0, 1]) [{s}*(x - a) >= 0] * [{t}*(x - a) >= 0] d(x)",
         {"a": a}, ("X301", err)),
        # [c]² (§7.3.2)
        ("squared", f"param a = {a}\nint ([0, 1]) ({w} + x) * [x - a >= 0]^2 d(x)", {"a": a}, ("X301", err)),
        # opposite sides of one zero set, rotated in two variables: the product is 0 a.e. (§7.3.1)
        ("opposite sides", f"param a = {a}\nint ([0, 1], [0, 1]) [{s}*x - y - a >= 0] * [y - {s}*x + a >= 0] d(x, y)",
         {"a": a}, ("X301", err)),
        # a window [a, b] closing at a = b with weight w + x ≠ 0 there: a kink
        ("window closes", f"param a = {a}, b = {a}\nint ([0, 1]) ({w} + x) * [x - a >= 0] * [b - x >= 0] d(x)",
         {"a": a, "b": a}, ("X305", err)),
        # two jumps on the same side coinciding at a = b: max(a, b) has a kink
        ("jumps coincide", f"param a = {a}, b = {a}\nint ([0, 1]) [x - a > 0] * [x - b > 0] d(x)",
         {"a": a, "b": a}, ("X305", err)),
        # the domain's bounds meet, weight y + w ≠ 0 on the meeting line
        ("bounds meet", f"param a = {a}, v = {a}\nint ([a, v], [0, 1]) (y + {w}) d(x, y)",
         {"a": a, "v": a}, ("X305", err)),
        # a jump on the domain's bound
        ("jump on a bound", f"param a = 1\nint ([0, 1]) ({w} + x) * [x - a >= 0] d(x)", {"a": "1"}, ("X305", err)),
        # a vanishing coefficient: the zero set degenerates
        ("zero coefficient", f"param k = 0\nint ([0, 1]) [k*x - {a} >= 0] d(x)", {"k": "0"}, ("X305", err)),
        # a double root for every parameter value: (p·x − q)² > 0
        ("double root", f"param p = {p}, q = {q}\nint ([-1, 1]) [p^2 * x^2 - 2*p*q*x + q^2 > 0] d(x)",
         {"p": p, "q": q}, ("X315", err)),
        # a circle multiplied by itself
        ("circle twice", f"param r = {r}\nint ([-1, 1], [-1, 1]) [x^2 + y^2 < r^2] * [x^2 + y^2 < r^2] d(x, y)",
         {"r": r}, ("X301", err)),
        # a line tangent to a circle: Def. 7.2 fails on a null set (a warning: the derivative
        # exists, Theorem 8.1 holds almost everywhere)
        ("tangent", f"param r = {r}, h = {r}\nint ([-1, 1], [-1, 1]) [x^2 + y^2 < r^2] * [y < h] d(x, y)",
         {"r": r, "h": r}, ("X302", "warning")),
    ]


@pytest.mark.parametrize("seed", range(4))
def test_the_linter_misses_no_degenerate_program(seed):
    missed = []
    for name, text, at, expected in _degenerate(random.Random(seed)):
        found = {(f.code, f.severity) for f in tv.check_loaded(load_text(text), at={k: float(v) for k, v in at.items()})}
        if expected not in found:
            missed.append((name, text, at, sorted(found)))
    assert missed == []
