"""§10.2, Fig. 14 (issue 12): the ray-traced triangle, its two toon shaders, checked at small
resolution against the scene hand-written in numpy (``langur.reference``), and the checks shown
to fail on an engine that drops the deltas (standard AD)."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from paths import EXAMPLES

from langur import reference, reproduce
from langur.frontend import load
from langur.operational.batch import estimate_batch


def test_the_engine_renders_what_the_numpy_scene_says():
    # pixel values of both shaders and all channels, Monte Carlo against the supersampled numpy scene
    h, n = 0.06, 10
    xs = -0.3 + np.arange(n) * h
    px, py = np.meshgrid(xs, xs)
    for shader, module in reproduce.RT_SHADERS.items():
        loaded = load(str(EXAMPLES / "raytrace" / "scene.lgr"), modules={"shader": str(EXAMPLES / "raytrace" / module)})
        for ch in range(3):
            b = estimate_batch(loaded, {"px": px.ravel(), "py": py.ravel(), "h": h, "ch": float(ch)}, samples=400, seed=2)
            ref = reference.pixels(xs, xs, h, 0.0, shader, ch, 96)
            assert np.all(np.abs(b.value.reshape(n, n) - ref) <= 5 * b.stderr.reshape(n, n) + 4 / 96), (shader, ch)


def test_reproduce_raytrace_passes_at_small_resolution():
    ex = reproduce.raytrace(2000, 0, pixels=12)
    assert ex.ok, [c for c in ex.checks if not c.ok]
    assert len(ex.checks) == 2 * 3 * 3 + 1
    assert set(ex.figures["fig14"]["images"]) == {"depth", "lambert"}


def test_reproduce_raytrace_fails_without_the_deltas(monkeypatch):
    # standard AD in place of the derivative: the sums and the sparsity patterns must disagree
    def standard_ad(*args, **kw):
        b = estimate_batch(*args, **kw)
        return dataclasses.replace(b, boundary=np.zeros_like(b.boundary))

    monkeypatch.setattr(reproduce, "estimate_batch", standard_ad)
    ex = reproduce.raytrace(2000, 0, pixels=12)
    failed = {c.what for c in ex.checks if not c.ok}
    assert any("pattern" in w for w in failed) and any("Σ D_t" in w for w in failed)


@pytest.mark.parametrize("t", [0.0, 0.3])
def test_the_numpy_scene_is_the_triangle_described(t):
    # the vertices' projections lie inside the triangle's own image, the centroid is lit, a far
    # corner is not: a check on the reference itself
    a, b, c = reference.vertices(t)
    centre = (a / a[2] + b / b[2] + c / c[2]) / 3
    assert reference.colour(np.array([centre[0]]), np.array([centre[1]]), t, "depth", 0)[0] \
        + reference.colour(np.array([centre[0]]), np.array([centre[1]]), t, "depth", 1)[0] == 1.0
    assert reference.colour(np.array([0.29]), np.array([0.29]), t, "depth", 1)[0] == 0.0
