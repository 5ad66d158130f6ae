"""Hostile input, sixth round (hostile32): the cases hostile31 left bounded but slow or wrong — a
named pipe imported as a module, a box wider than the largest double, 41 integration variables,
31,831 turning points — each failing on main at 36a3225 (a hang, NaN, a CPU limit) and passing here.

Every command runs in a subprocess bounded in memory (``RLIMIT_AS``), CPU time (``RLIMIT_CPU``) and
wall clock; the contract (CLI.md): exit 0, 1 or 2, a located diagnostic or one usage line, never a
traceback or an internal error.  bench/history/2026-11-29.md#hostile32.
"""

from __future__ import annotations

import json
import math
import os
import resource
import stat
import subprocess
import sys
import threading
import time
from fractions import Fraction
from pathlib import Path

import mpmath
import numpy as np
import pytest

from langur.enclosures import certified_brackets, interval_function
from langur.operational.sample import spread, volume_parts

ROOT = Path(__file__).resolve().parents[1]
WALL = 120


def _langur(cwd: Path, *argv: str, cpu: int = 40, wall: float = WALL):
    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))
        resource.setrlimit(resource.RLIMIT_CPU, (cpu, cpu + 5))

    env = {k: v for k, v in os.environ.items() if k != "LANGUR_DEBUG"}
    env.update(PYTHONPATH=str(ROOT), OPENBLAS_NUM_THREADS="1")
    r = subprocess.run([sys.executable, "-P", "-m", "langur", *argv], cwd=cwd, env=env, capture_output=True,
                       text=True, errors="replace", timeout=wall, preexec_fn=limit)
    said = f"langur {' '.join(argv)}: exit {r.returncode}\n{r.stdout[-1500:]}\n{r.stderr[-1500:]}"
    assert r.returncode in (0, 1, 2), said  # (a CPU limit is SIGXCPU: negative)
    assert "Traceback" not in r.stderr and "internal error" not in r.stderr, said
    return r, said


def _file(tmp_path: Path, name: str, text: str) -> Path:
    (tmp_path / name).write_text(text, encoding="utf-8")
    return tmp_path / name


# --- (3) a named pipe imported as a module ------------------------------------------------------------


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_a_module_that_is_a_named_pipe_nobody_writes_to(tmp_path):
    """``from pipe import f`` where pipe.lgr is a FIFO: ``open`` blocks until a writer comes, which a
    CPU-time budget never interrupts (main: check sat for its 605 s wall-clock backstop, then X399;
    killed here after 60 s).  Now T223 at the import after --timeout seconds of waiting."""
    os.mkfifo(tmp_path / "pipe.lgr")
    _file(tmp_path, "main.lgr", "from pipe import f\nint ([0, 1]) f(x) d(x)\n")
    start = time.monotonic()
    r, said = _langur(tmp_path, "check", "main.lgr", "--timeout", "2", wall=60)
    assert time.monotonic() - start < 50, said
    assert r.returncode == 1, said
    assert "main.lgr:1:6: error T223 module `pipe`: cannot read pipe.lgr" in r.stdout, said
    assert "nothing to read after 2 s" in r.stdout, said


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_a_module_from_a_named_pipe_is_read_once(tmp_path):
    """A writer puts ``def f(x: var) = x`` into the FIFO once.  The loader asked for a module's bytes
    three times (loadable, key, elaborate) and the checker once more to quote it: the second read of
    a pipe waits for a writer that never comes (main: the check never ended — X399 after the
    backstop; killed here).  Now read once: the program loads and ∫₀¹ x dx = 1/2 has no finding."""
    os.mkfifo(tmp_path / "pipe.lgr")
    _file(tmp_path, "main.lgr", "from pipe import f\nint ([0, 1]) f(x) d(x)\n")

    def write():
        with open(tmp_path / "pipe.lgr", "w", encoding="utf-8") as fh:  # (blocks until the check opens it)
            fh.write("def f(x: var) = x\n")

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    r, said = _langur(tmp_path, "check", "main.lgr", "--timeout", "20", "--format", "json", wall=60)
    writer.join(5)
    assert r.returncode == 0, said
    assert json.loads(r.stdout)["diagnostics"] == [], said


# --- (4) a box beyond the doubles --------------------------------------------------------------------


def test_points_and_volume_of_a_box_beyond_the_doubles():
    """[−1e308, 1e308]: hi − lo = ∞, lo + u·∞ is NaN at u = 0.  ``spread`` gives points inside the box;
    ``volume_parts`` the volume 2e308 as mantissa · 2**exponent (checked against exact integers)."""
    lo, hi = np.array([-1e308, 0.0]), np.array([1e308, 3.0])
    u = np.array([[0.0, 0.0], [0.5, 0.5], [1.0, 1.0]])
    pts = spread(lo, hi, u)
    assert np.isfinite(pts).all() and (pts[0] == lo).all() and (pts[2] == hi).all() and pts[1, 0] == 0.0
    m, e = volume_parts(lo, hi)
    assert Fraction(float(m)) * 2 ** int(e) == (Fraction(1e308) - Fraction(-1e308)) * 3  # 6e308, exact here
    m, e = volume_parts(np.array([[0.0, -2.0]]), np.array([[1.5, 2.0]]))
    assert float(np.ldexp(m, e)[0]) == 6.0  # an ordinary box: its volume


def test_monte_carlo_on_a_box_beyond_the_doubles(tmp_path):
    """``[x <= a]`` on [−1e308, 1e308] at a = 0.5: by hand ⟦p⟧ = a + 1e308 and d/da = 1, all of it on
    the boundary (the integrand does not depend on a off x = a: regular part 0).  main: value and
    regular part NaN (∞ · 0); now the value within 4 standard errors of 1e308 and the regular part 0."""
    _file(tmp_path, "p.lgr", "param a = 0.5\nint ([-1e308, 1e308]) [x <= a] d(x)\n")
    r, said = _langur(tmp_path, "eval", "p.lgr", "--engine", "mc", "--samples", "4000", "--json")
    mc = json.loads(r.stdout)["mc"]
    assert r.returncode == 0 and math.isfinite(mc["value"]) and math.isfinite(mc["stderr"]), said
    assert abs(mc["value"] - (0.5 + 1e308)) <= 4 * mc["stderr"] and mc["stderr"] < 0.05 * 1e308, said
    r, said = _langur(tmp_path, "deriv", "p.lgr", "--wrt", "a", "--engine", "mc", "--samples", "4000", "--json")
    mc = json.loads(r.stdout)["mc"]
    assert r.returncode == 0 and mc["regular"]["value"] == 0.0 and mc["boundary"]["value"] == 1.0, said
    assert mc["value"] == 1.0, said


# --- (2) 41 integration variables ----------------------------------------------------------------------


def test_forty_one_integration_variables_end_early(tmp_path):
    """``[x1 <= a]`` over [0, 1]⁴¹ at a = 0.5: by hand ⟦p⟧ = a, d/da = 1 (the face x1 = a has area 1).
    main: past 40 CPU s (the linter's C(41, k) minors per family and 41-generator polynomials per
    pair, then the sampler's 6⁴⁰-cell grid, then 40-fold nested quadrature: killed by RLIMIT_CPU).
    Now the Monte Carlo value 1 and the exact engine's refusal, said at once."""
    xs = [f"x{i}" for i in range(1, 42)]
    _file(tmp_path, "p.lgr", f"param a = 0.5\nint ({', '.join(['[0, 1]'] * 41)}) [x1 <= a] d({', '.join(xs)})\n")
    r, said = _langur(tmp_path, "deriv", "p.lgr", "--wrt", "a", "--samples", "1000", "--json", cpu=40)
    out = json.loads(r.stdout)
    assert out["mc"]["value"] == 1.0 and out["mc"]["boundary"]["value"] == 1.0, said
    assert out["exact"] is None, said
    assert "no exact value: nested quadrature over 40 variables is out of reach" in r.stderr, said


# --- (1) a condition with 31,831 turning points -------------------------------------------------------


def test_the_count_of_sign_changes_stops_past_what_is_asked():
    """``sin(100000·x) − 0.3`` on [0, 1]: by hand its zeros are (asin 0.3 + 2πk)/10⁵ and
    (π − asin 0.3 + 2πk)/10⁵, 31,831 of them.  With ``most = 7`` the certification stops once more
    than 7 are certified and gives the first ones, each bracket holding the k-th zero by hand, in order
    (all of them took 26 CPU s in the checker); with ``most`` unset on [0, 0.001] it gives all 32."""
    import sympy as sp

    x = sp.Symbol("x", real=True)
    e = sp.sin(100000 * x)
    g, g_iv, dg_iv = (lambda z: mpmath.sin(100000 * z)), interval_function(x, e), interval_function(x, sp.diff(e, x))
    s = math.asin(0.3)
    zeros = sorted([(s + 2 * math.pi * k) / 1e5 for k in range(16000)] + [(math.pi - s + 2 * math.pi * k) / 1e5
                                                                         for k in range(16000)])
    with mpmath.workprec(53):
        first = certified_brackets(g, g_iv, dg_iv, 0.3, 0.0, 1.0, most=7)
        assert 7 < len(first) < 100
        assert all(p <= z <= q for (p, q), z in zip(first, zeros))
        few = certified_brackets(g, g_iv, dg_iv, 0.3, 0.0, 0.001)
    assert len(few) == sum(z <= 0.001 for z in zeros) == 32
    assert all(p <= z <= q for (p, q), z in zip(few, zeros))


def test_a_condition_with_31831_turning_points_is_refused_quickly(tmp_path):
    """``[sin(100000·x) − a >= 0]``: check (X310) and deriv (X316, both engines) counted every sign
    change (26–28 CPU s each on main: past the 20 s limit here); now "at least 101 turning points …
    more than the 7", within 20 CPU s (7 here, most of it the front end's sympy solveset)."""
    _file(tmp_path, "p.lgr", "param a = 0.3\nint ([0, 1]) [sin(100000 * x) - a >= 0] d(x)\n")
    r, said = _langur(tmp_path, "check", "p.lgr", cpu=20)
    assert "X310" in r.stdout and "at least 101 turning points on [0, 1]" in r.stdout, said
    assert "more than the 7 the condition was split for" in r.stdout, said
    r, said = _langur(tmp_path, "deriv", "p.lgr", "--wrt", "a", "--engine", "exact", cpu=20)
    assert r.returncode == 1 and "X316 no exact value: at least 101 turning points" in r.stderr, said


# --- new round: check --fix --in-place on a named pipe -----------------------------------------------


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="named pipes")
def test_fix_in_place_of_a_named_pipe_is_refused(tmp_path):
    """A writer puts examples/degenerate/coincident.lgr (X301: a rewrite to write) into a FIFO once;
    ``check --fix --in-place`` read it, then opened it again to see that it had not changed — outside
    any time limit, waiting for a writer forever (main: killed here after 60 s).  Now a usage error
    before anything is written; the pipe is still a pipe."""
    pipe = tmp_path / "fx.lgr"
    os.mkfifo(pipe)
    text = (ROOT / "examples" / "degenerate" / "coincident.lgr").read_text(encoding="utf-8")

    def write():
        with open(pipe, "w", encoding="utf-8") as fh:
            fh.write(text)

    writer = threading.Thread(target=write, daemon=True)
    writer.start()
    r, said = _langur(tmp_path, "check", "fx.lgr", "--fix", "--in-place", "--timeout", "20", wall=60)
    writer.join(5)
    assert r.returncode == 2 and "fx.lgr is not a regular file: not rewritten in place" in r.stderr, said
    assert stat.S_ISFIFO(os.stat(pipe).st_mode) and not (tmp_path / "fx.lgr.bak").exists(), said
