"""``langur check``'s findings do not depend on its time budgets (branch determ30).

The linter's limits count CPU seconds (langur/timebox.py), so a loaded machine does not change them;
what still did was how close a question came to its limit: the z-depth shader against the ray
tracer's triangle (examples/raytrace/scene.lgr, reported at shader.lgr:6:20) needed 1.8 to 12 CPU s
of ``sympy.solve`` per pair, against a limit of 2 s, and was X304 or X310 with sympy's caches and
the first ``simplify``'s import of physical units.  Here each sympy question's limit is made 10×
smaller by a CPU clock that runs 10× fast (:func:`fast_cpu_clock`; the whole analysis's 30 s as it
is, :func:`whole_analysis_as_is`), and the findings must not change.  The solution sets are
checked by hand.
"""

from __future__ import annotations

import _signal
import subprocess
import sys
import time
import types

import pytest
import sympy as sp
from paths import EXAMPLES

from langur import frontend, timebox
from langur.lint import algebra, classify
from langur.lint.coincidence import _common_zeros
from langur.transversality import check_library, check_loaded

RAYTRACE = EXAMPLES / "raytrace"


@pytest.fixture
def fast_cpu_clock(monkeypatch):
    """Within the test, ``langur.timebox`` sees the process's CPU clock run 10× fast: every CPU
    limit of the linter (a sympy call's 2 s, the analysis's 30 s, …) is 10× smaller."""
    factor = 10.0
    sig = types.SimpleNamespace(**{k: getattr(_signal, k) for k in dir(_signal) if not k.startswith("__")})

    def setitimer(which, seconds, interval=0.0):
        if which != _signal.ITIMER_PROF:
            return _signal.setitimer(which, seconds, interval)
        left, every = _signal.setitimer(which, seconds / factor, interval / factor)
        return left * factor, every * factor

    def getitimer(which):
        left, every = _signal.getitimer(which)
        return (left * factor, every * factor) if which == _signal.ITIMER_PROF else (left, every)

    sig.setitimer, sig.getitimer = setitimer, getitimer
    clock = types.SimpleNamespace(**{k: getattr(time, k) for k in dir(time) if not k.startswith("__")})
    clock.process_time = lambda: time.process_time() * factor
    monkeypatch.setattr(timebox, "signal", sig)
    monkeypatch.setattr(timebox, "time", clock)


def _findings(path, **kw):
    loaded = frontend.load(str(path), **kw)
    found = check_loaded(loaded) if loaded.program is not None else check_library(loaded)
    return [(f.span.path.rsplit("/", 1)[-1], f.span.line, f.span.col, f.code, f.message) for f in found]


def test_the_fast_clock_makes_a_limit_ten_times_smaller(fast_cpu_clock):
    start = time.process_time()
    with pytest.raises(TimeoutError):
        timebox.run_with_timeout(lambda: sum(i for i in range(10**9)), 2.0, cpu=True)
    assert time.process_time() - start < 1.0  # 2 "CPU s" of the fast clock: 0.2 s


@pytest.fixture
def whole_analysis_as_is(monkeypatch):
    """With :func:`fast_cpu_clock`: the whole analysis's budget (30 CPU s) as it is, 10× the fast
    clock's seconds (scene.lgr's analysis takes ~4 of them), so that only each sympy question's
    limit is 10× smaller."""
    monkeypatch.setattr(classify, "BUDGET", classify.BUDGET * 10)


def test_the_shader_against_the_triangle_is_decided_with_a_tenth_of_the_limit(fast_cpu_clock, whole_analysis_as_is):
    found = _findings(RAYTRACE / "scene.lgr")
    shader = [f for f in found if f[0] == "shader.lgr"]
    assert not [f for f in found if f[3] == "X310"], found
    # the plane z = zth holds the edge B C (both at z = 3) exactly when zth = 3: one X304, by hand (at the
    # edge's comparison, col 7, as the scene's own X306 at 24:7: a condition the desugarer builds has no span)
    assert [(f[1], f[2], f[3]) for f in shader] == [(6, 20, "X304"), (6, 20, "X306"), (6, 20, "X306")]
    assert "when zth = 3" in shader[0][4] and "scene.lgr:24:7" in shader[0][4]
    # since pole31 the depth condition zth − k/(n·d) is split at its pole n·d = 0 (it moves with t) into
    # conditionals on its factors' signs, n·d and zth·(n·d) − k, each with its own X306 (two findings, not one
    # repeated): n·d degenerates where n is along z (nx = ny = 0), zth·(n·d) − k also where zth = 0.
    # (Before the split: one X306 "when k = 0 or nx = 0 and ny = 0"; the k = 0 case is X304 on line 7 only now.)
    assert sorted(f[4].split(" stops being")[1].split(" (its")[0] for f in shader[1:]) == [
        " a diffeomorphism when nx = 0 and ny = 0", " a diffeomorphism when zth = 0 or nx = 0 and ny = 0"]


def test_the_scene_findings_are_the_same_with_a_tenth_of_the_limit(fast_cpu_clock, whole_analysis_as_is, monkeypatch):
    tenth = _findings(RAYTRACE / "scene.lgr")
    monkeypatch.undo()
    assert _findings(RAYTRACE / "scene.lgr") == tenth


def test_the_shader_library_is_decided_with_a_tenth_of_the_budget(fast_cpu_clock):
    found = _findings(RAYTRACE / "shader.lgr")
    # since pole31 each depth condition is split at its moving pole n·d = 0 into conditionals on its factors'
    # signs, n·d and zth·(n·d) − k: one X306 per factor on each line (n·d degenerates where nx = ny = 0,
    # zth·(n·d) − k also where zth = 0), and on line 7 the factors' zero sets coincide where k = 0 (X304: the
    # plane through the camera, where the condition was degenerate before the split too)
    assert [(f[1], f[2], f[3]) for f in found] == [(6, 20, "X306"), (6, 20, "X306"), (7, 25, "X304"),
                                                   (7, 25, "X306"), (7, 25, "X306")]
    whens = [f[4].split(" when ")[1].split(" (its")[0] for f in found if f[3] == "X306"]
    assert sorted(whens) == ["nx = 0 and ny = 0"] * 2 + ["zth = 0 or nx = 0 and ny = 0"] * 2
    assert "coincident zero sets when k = 0" in found[2][4]


a, b, c, t, z = sp.symbols("a b c t zth")


def _as_sets(sols):
    return sorted((sorted((str(k), str(v)) for k, v in s.items()) for s in sols))


def test_a_system_is_solved_factor_by_factor():
    # (a - 1)(b - 2) = (a - 1)·c = 0: a = 1 (any b, c), or b = 2 and c = 0 — by hand
    sols = algebra.solve_by_factors([(a - 1) * (b - 2), (a - 1) * c], [a, b, c])
    assert _as_sets(sols) == [[("a", "1")], [("b", "2"), ("c", "0")]]
    # the shader's equation, (zth − 3)·q(t) with q irreducible: zth = 3, or t a root of q
    q = 36 * t**3 - 342 * t**2 - 1813 * t - 1785
    assert sp.Poly(q, t).is_irreducible
    sols = algebra.solve_by_factors([sp.expand(-(z - 3) * q)], [t, z])
    assert {3} == {s[z] for s in sols if z in s}
    roots = [s[t] for s in sols if t in s]
    assert len(roots) == 3 and all(abs(complex(q.subs(t, r).evalf(30))) < 1e-20 for r in roots)
    # a nonzero number has no zeros; (a − b)·a = (a − b)·(a + 1) = 0: a = b, or a = 0 = −1 (none)
    assert algebra.solve_by_factors([sp.Integer(3), a - b], [a, b]) == []
    assert _as_sets(algebra.solve_by_factors([(a - b) * a, (a - b) * (a + 1)], [a, b])) == [[("a", "b")]]


def test_an_equation_linear_in_its_first_parameter_is_solved_for_it():
    # [x³ − x ≥ a] against [sqrt(x + 2) ≤ b + 1] (a generated program): they meet where
    # a = x³ − x at x = (b + 1)² − 2; sympy's solve took ~1 CPU s of its 2 on the roots of a sextic in b
    e = sp.expand(-a - (b + 1) ** 2 + ((b + 1) ** 2 - 2) ** 3 + 2)
    (sol,) = algebra.solve_by_factors([e], [a, b])
    x = (b + 1) ** 2 - 2
    assert list(sol) == [a] and sp.expand(sol[a] - (x**3 - x)) == 0
    # a linear equation, or one whose first parameter is not of degree 1: sympy's own answer
    assert algebra.solve_by_factors([2 * a - 3 * b + 1], [a, b]) == [{a: 3 * b / 2 - sp.Rational(1, 2)}]
    assert _as_sets(algebra.solve_by_factors([b - a**2], [a, b])) == [[("a", "-sqrt(b)")], [("a", "sqrt(b)")]]


def test_what_is_not_a_polynomial_with_rational_coefficients_is_left_to_sympy():
    assert algebra.solve_by_factors([sp.sin(a) - b], [a, b]) is None
    assert algebra.solve_by_factors([sp.sqrt(2) * a - b], [a, b]) is None
    # a hostile product: more choices of one factor per equation than are solved one by one
    many = [sp.Mul(*(a - k - 10 * i for k in range(3))) for i in range(5)]  # 3⁵ = 243 choices
    assert algebra.solve_by_factors(many, [a]) is None


def test_the_common_zeros_of_a_product_system_are_its_components():
    ax, ay, az, nx, ny, nz = sp.symbols("ax ay az nx ny nz")
    k = ax * nx + ay * ny + az * nz
    sols = _common_zeros([ny * -k, nx * -k], [ax, ay, az, nx, ny, nz])
    # k·ny = k·nx = 0 is k = 0 or nx = ny = 0: one solution each, each one verified by substitution
    assert len(sols) == 2
    assert {nx: 0, ny: 0} in sols
    (on_k,) = [s for s in sols if s != {nx: 0, ny: 0}]
    assert sp.simplify(k.subs(on_k)) == 0


def test_the_first_simplify_does_not_import_physical_units_on_the_clock():
    code = (
        "import sys, sympy as sp\n"
        "from langur.lint import algebra\n"
        "x, y = sp.symbols('x y')\n"
        "assert algebra.vanishes(sp.sin(x)**2 + sp.cos(x)**2 - 1, (x,))\n"
        "print('sympy.physics.units' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
