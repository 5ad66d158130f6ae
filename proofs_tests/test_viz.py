"""Pictures (``viz``, the plot extra): the geometry they are drawn from, checked by hand at the numpy
level, and each picture produced — in a subprocess, so that a crash of VTK fails one test and
does not kill the run.

Geometry (values derived by hand beside each assertion):

* a one-variable delta sits at its roots with weight h/|Φ'| (the sifting property);
* a two-variable delta is a ridge along Φ = 0 whose density per unit length integrates, along the
  curve, to the delta's integral — the boundary part of ⦇p⦈.
"""

from __future__ import annotations

import math
import os
import struct
import subprocess
import sys

import numpy as np
import pytest
from paths import EXAMPLES, REPO

pytest.importorskip("matplotlib")
pytest.importorskip("pyvista")

from langur.frontend import load, load_text  # noqa: E402
from viz import geometry as G  # noqa: E402


def scene_of(text: str, direction: dict, params: dict | None = None):
    loaded = load_text(text, "t.lgr")
    return G.scene(loaded.program, params or loaded.param_values(), direction)


def test_fig1_spike_and_pieces():
    # ∫₀¹ [x ≤ θ] dx: one delta at x = θ = 1/2 with weight D_θ(θ − x)·1 / |d(θ − x)/dx| = 1
    loaded = load(str(EXAMPLES / "fig1.lgr"))
    s = G.scene(loaded.program, {"theta": 0.5}, {"theta": 1.0})
    assert G.spikes(s) == [G.Spike(0.5, 1.0, 1)]
    assert G.breakpoints(s, s.integrand) == [0.0, 0.5, 1.0]
    (xa, ya), (xb, yb) = G.curve(s, s.integrand)
    assert np.all(ya == 1.0) and np.all(yb == 0.0) and xa[-1] < 0.5 < xb[0]
    assert (s.value, s.derivative, s.standard_ad) == (0.5, 1.0, 0.0)


def test_two_roots_each_carry_their_weight():
    # ∫₋₁¹ [x² ≥ a] dx = 2 − 2√a, d/da = −1/√a = −2 at a = 1/4.  Φ = x² − a has roots ±1/2,
    # ∂_aΦ = −1, |Φ'(±1/2)| = 1: two spikes of weight −1.
    s = scene_of("param a = 0.25\nint ([-1, 1]) [x^2 >= a] d(x)\n", {"a": 1.0})
    got = sorted((round(p.x, 12), round(p.weight, 12)) for p in G.spikes(s))
    assert got == [(-0.5, -1.0), (0.5, -1.0)]
    assert s.derivative == pytest.approx(-2.0, abs=1e-12)


def test_fig9_ridge_lies_on_the_diagonal_with_the_delta_density():
    # [y < x + θ](1 + θ + x + y) at θ = 0: the delta lies on y = x with h = 1 + x + y and
    # |∇Φ| = √2, so the density per unit length is (1 + 2x)/√2; along the diagonal (length 2√2)
    # it integrates to ∫₋₁¹ (1 + 2x) dx = 2, the boundary part.
    loaded = load(str(EXAMPLES / "fig9.lgr"))
    s = G.scene(loaded.program, {"theta": 0.0}, {"theta": 1.0})
    (r,) = G.ridges(s)
    x, y = r.points[:, 0], r.points[:, 1]
    assert np.allclose(x, y, atol=1e-12)
    assert (x.min(), x.max()) == pytest.approx((-1.0, 1.0), abs=1e-9)
    assert np.allclose(r.density, (1 + 2 * x) / math.sqrt(2), atol=1e-12)
    assert r.integral() == pytest.approx(2.0, abs=1e-9) and s.boundary == pytest.approx(2.0, abs=1e-12)
    # at θ = 0.3 the ridge is y = x + 0.3 for x in [−1, 0.7]: ∫ (1.3 + 2x + 0.3) dx = 2.21
    s = G.scene(loaded.program, {"theta": 0.3}, {"theta": 1.0})
    assert sum(r.integral() for r in G.ridges(s)) == pytest.approx(2.21, abs=1e-9)


def test_circle_ridge_has_both_inverse_branches():
    # d/dr of the disc's area πr² is the circumference 2πr = π at r = 1/2: the delta of
    # Φ = r² − x² − y² with ∂_rΦ = 2r = 1 and |∇Φ| = 2r = 1 has density 1 on the circle, whose
    # two halves come from the two inverse branches y = ±√(r² − x²).
    s = scene_of("param r = 0.5\nint ([-1, 1], [-1, 1]) [x^2 + y^2 <= r^2] d(x, y)\n", {"r": 1.0})
    rs = G.ridges(s)
    assert len(rs) == 2
    for r in rs:
        assert np.allclose(np.hypot(r.points[:, 0], r.points[:, 1]), 0.5, atol=1e-9)
        assert np.allclose(r.density, 1.0, atol=1e-6)
    assert sum(r.integral() for r in rs) == pytest.approx(math.pi, rel=1e-4)
    assert s.derivative == pytest.approx(math.pi, rel=1e-12)


def test_regions_are_cut_along_the_jump():
    # the integrand of fig9 on each side of y = x + θ, read by region: 0 above, 1 + θ + x + y below
    from viz import surfaces

    loaded = load(str(EXAMPLES / "fig9.lgr"))
    s = G.scene(loaded.program, {"theta": 0.0}, {"theta": 1.0})
    meshes = surfaces.regions(s, s.integrand, resolution=40)
    assert len(meshes) == 2
    for m in meshes:
        x, y, v = m.points[:, 0], m.points[:, 1], m.point_data["value"]
        if np.all(v == 0):
            assert np.all(y >= x - 1e-9)
        else:
            assert np.all(y <= x + 1e-9) and np.allclose(v, 1 + x + y)


def _png_size(path) -> tuple[int, int]:
    with open(path, "rb") as fh:
        head = fh.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", head[16:24])


def _langur(*args, timeout=300):
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    return subprocess.run([sys.executable, "-m", "langur", *args], capture_output=True, text=True,
                          timeout=timeout, cwd=REPO, env=env)


def test_plot_writes_each_kind(tmp_path):
    r = _langur("plot", str(EXAMPLES / "fig1.lgr"), "-o", str(tmp_path / "fig1.png"))
    assert r.returncode == 0, r.stderr
    assert _png_size(tmp_path / "fig1.png") == (1600, 420)
    r = _langur("plot", str(EXAMPLES / "fig9.lgr"), "--kind", "all", "-o", str(tmp_path / "fig9.png"), "--json")
    assert r.returncode == 0, r.stderr
    sizes = {os.path.basename(p): _png_size(p) for p in __import__("json").loads(r.stdout)["written"]}
    assert sizes == {"fig9_surfaces.png": (1800, 700), "fig9_flat.png": (1300, 540),
                     "fig9_convergence.png": (800, 500)}
    for name in sizes:  # a picture, not a blank canvas
        assert os.path.getsize(tmp_path / name) > 20_000


def test_plot_refuses_what_it_cannot_draw(tmp_path):
    three = tmp_path / "three.lgr"
    three.write_text("int ([0, 1], [0, 1], [0, 1]) x*y*z d(x, y, z)\n")
    r = _langur("plot", str(three))
    assert r.returncode == 2 and "one or two variables" in r.stderr and "Traceback" not in r.stderr
    r = _langur("plot", str(EXAMPLES / "fig1.lgr"), "-o", str(three))
    assert r.returncode == 2 and "over a program" in r.stderr
    assert three.read_text().startswith("int (")  # never overwritten


def test_reproduce_writes_the_papers_pictures(tmp_path):
    r = _langur("reproduce", "fig1", "risk", "fig9", "--samples", "2000", "--out", str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    assert sorted(os.listdir(tmp_path)) == ["fig1_abcd.png", "fig9_convergence.png", "fig9_flat.png",
                                            "fig9_surfaces.png", "risk_fig2.png", "risk_fig3.png"]
    assert "a opens to about −9.6" in r.stdout


def _examples_of_one_or_two_variables():
    # (the ray tracer's scene, examples/raytrace/, is checked against its numpy model in
    # test_raytrace.py: its exact derivative takes ~20 s per parameter; the stylization kernels,
    # examples/stylize/, against a numpy clipping of the triangle in test_stylize.py: 15 and 24
    # parameters, each an exact derivative of a triangle's quadratic shading)
    out = []
    for path in sorted(p for p in EXAMPLES.rglob("*.lgr") if p.parent.name not in ("raytrace", "stylize")):
        loaded = load(str(path))
        if loaded.program is not None and len(loaded.program.variables) <= 2:
            out.extend((path, name) for name in loaded.params)
    return out


@pytest.mark.parametrize("path,wrt", _examples_of_one_or_two_variables(),
                         ids=lambda v: v.name if hasattr(v, "name") else v)
def test_what_is_drawn_adds_up_to_the_derivative(path, wrt):
    # every example: the drawn deltas (spikes, or ridges integrated along their curves) carry the
    # exact engine's boundary part, and the drawn regular part is standard AD's integrand
    loaded = load(str(path))
    s = G.scene(loaded.program, loaded.param_values(), {k: float(k == wrt) for k in loaded.params})
    if len(s.variables) == 1:
        drawn = sum(p.weight for p in G.spikes(s))
    else:
        drawn = sum(r.integral() for r in G.ridges(s))
    assert drawn == pytest.approx(s.boundary, rel=1e-3, abs=1e-9)
    assert s.derivative == pytest.approx(s.standard_ad + s.boundary, rel=1e-9, abs=1e-12)


def test_reproduce_renderer_and_raytrace_draw_fig13_and_fig14(tmp_path):
    r = _langur("reproduce", "renderer", "raytrace", "--samples", "2000", "--out", str(tmp_path))
    assert r.returncode == 0, r.stdout + r.stderr
    assert sorted(os.listdir(tmp_path)) == ["raytrace_fig14.png", "renderer_fig13.png"]
    assert "Σ boundary · h² (exact)" in r.stdout and "MC and exact images agree" in r.stdout
    assert "derivative's pattern = FD's" in r.stdout
