"""Batched Monte Carlo estimates over parameter points (issue 12, §10.1): the batch API gives
point by point the per-point API's numbers (same seed, same design), and an image of the Fig. 13
scene has the boundary the paper's analysis gives."""

from __future__ import annotations

import numpy as np
import pytest
from paths import EXAMPLES

from langur.frontend import load, load_text
from langur.operational import estimate_derivative, estimate_value
from langur.operational.batch import estimate_batch


def _scene(shader: str = "shader"):
    return load(str(EXAMPLES / "scene.lgr"), modules={"shader": str(EXAMPLES / f"{shader}.lgr")})


CASES = [
    # (program, grid, direction): the renderer's pixel, Fig. 9, a 1-D jump (roots: exact sifting),
    # a fold (two inverse branches with guards in 2-D), a parametric box that empties
    ("renderer", {"c": np.linspace(-2.2, 0.4, 6)}, {"c": 1}),
    ("fig9", {"theta": np.linspace(-1.5, 1.5, 5)}, {"theta": 1}),
    ("param a = 0.3\nint ([0, 1]) [x <= a] * (x + a) d(x)", {"a": np.linspace(-0.2, 1.2, 6)}, {"a": 1}),
    ("param a = 0.5\nint ([-1, 1], [0, 1]) [x^2 + y - a <= 0] * (1 + x * y) d(x, y)",
     {"a": np.array([0.2, 0.5, 0.9, 1.7])}, {"a": 1}),
    ("param a = 0.5, b = 1\nint ([a, b], [0, 1]) [x + y - 1 >= 0] * x d(x, y)",
     {"a": np.array([0.0, 0.5, 0.9, 1.5]), "b": 1.0}, {"a": 1}),
]


def _load(name):
    if name == "renderer":
        return load(str(EXAMPLES / "renderer.lgr"), modules={"shader": str(EXAMPLES / "lin_shader.lgr")})
    if name == "fig9":
        return load(str(EXAMPLES / "fig9.lgr"))
    return load_text(name)


@pytest.mark.parametrize("case", range(len(CASES)))
@pytest.mark.parametrize("method", ["uniform", "stratified", "qmc"])
def test_batch_gives_the_per_point_numbers(case, method):
    name, grid, direction = CASES[case]
    loaded = _load(name)
    batch = estimate_batch(loaded, grid, direction=direction, samples=600, seed=7, method=method)
    npts = max(np.size(v) for v in grid.values())
    for i in range(npts):
        at = {k: float(np.broadcast_to(v, (npts,))[i]) for k, v in grid.items()}
        v = estimate_value(loaded, at, samples=600, seed=7, method=method)
        d = estimate_derivative(loaded, at, direction, samples=600, seed=7, method=method)
        assert (batch.value[i], batch.stderr[i]) == (v.value, v.stderr), (i, at)
        assert (batch.regular[i], batch.regular_stderr[i]) == (d.regular.value, d.regular.stderr), (i, at)
        assert (batch.boundary[i], batch.boundary_stderr[i]) == (d.boundary.value, d.boundary.stderr), (i, at)
        assert batch.params["a" if "a" in grid else next(iter(grid))][i] == at["a" if "a" in grid else next(iter(grid))]


def test_an_empty_box_is_zero_and_chunks_do_not_change_the_numbers(monkeypatch):
    loaded = load_text("param a = 0.5, b = 1\nint ([a, b], [0, 1]) [x + y - 1 >= 0] * x d(x, y)")
    grid = {"a": np.linspace(-0.5, 1.5, 9)}
    whole = estimate_batch(loaded, grid, direction={"a": 1}, samples=100, seed=2)
    assert whole.value[-1] == 0.0 and whole.stderr[-1] == 0.0  # [1.5, 1] is empty
    import langur.operational.batch as batch

    monkeypatch.setattr(batch, "CHUNK", 250)  # two points per pass
    parts = estimate_batch(loaded, grid, direction={"a": 1}, samples=100, seed=2)
    assert np.array_equal(whole.value, parts.value) and np.array_equal(whole.boundary, parts.boundary)


def test_bad_parameter_values_are_refused():
    from langur.values import ParameterError

    loaded = _scene()
    with pytest.raises(ParameterError):
        estimate_batch(loaded, {"px": np.array([0.1, np.nan])})
    with pytest.raises(ValueError):
        estimate_batch(loaded, {"px": np.zeros(3), "py": np.zeros(4)})


@pytest.mark.parametrize("shader,on_line", [("shader", 1.0), ("lin_shader", 0.5), ("quad_shader", 0.25)])
def test_the_scene_image_boundary_sums_to_the_line_integral(shader, on_line):
    # Fig. 13: pixels of side h = 0.05 tile [0, 1]²; each pixel is the average light over its area
    # (the integral / h²).  The boundary part of D_c is ∫ s·δ(x + y + c) over the pixel / h²; summed
    # over all pixels and times h² it is ∫ s(x, −x − c) dx over the line's part in [0, 1]², which
    # for c = −1.003 is x ∈ [0.003, 1], where s = 1, 1/2, 1/4 for the three shaders (by hand:
    # x + y + c = 0 on the line).  Standard AD has no boundary: its image has no line.
    loaded = _scene(shader)
    xs = np.arange(20) * 0.05
    px, py = np.meshgrid(xs, xs)
    b = estimate_batch(loaded, {"px": px.ravel(), "py": py.ravel(), "h": 0.05}, direction={"c": 1},
                       samples=200, seed=1)
    total = float(np.sum(b.boundary)) * 0.05 ** 2
    # every point draws the same design (common random numbers): the points' errors are
    # correlated, so the sum's standard deviation is bounded by the sum of theirs, not by the root
    # of the sum of squares (with the latter this check fails: 20 pixels share one +1.9σ error)
    se = float(np.sum(b.boundary_stderr)) * 0.05 ** 2
    assert abs(total - 0.997 * on_line) <= 5 * se + 1e-9
    # the line is where the boundary part is: pixels the line misses have none
    crossed = (px.ravel() + py.ravel() <= 1.003) & (px.ravel() + py.ravel() + 0.1 >= 1.003)
    assert np.all(b.boundary[~crossed] == 0.0) and np.all(b.boundary[crossed] > 0)
    # the value: lit pixels (fully below the line, x + y + c ≥ 0 means x + y ≥ 1.003) average the
    # shader; dark ones are 0
    dark = px.ravel() + py.ravel() + 0.1 < 1.003
    assert np.all(b.value[dark] == 0.0)


# -- the exact engine over a grid ------------------------------------------------------------------

def test_exact_batch_uses_each_closed_form_in_its_cell_only():
    # ⟦p⟧ = t²/2 where t < t1 and t1²/2 where t ≥ t1 (by hand, ∫₀^min(t, t1) x dx on [0, 1]); one
    # derivation per cell the grid meets, values as the per-point engine gives them
    from langur.exact_batch import exact_batch

    program = load_text("param t = 0.3, t1 = 0.6\nint ([0, 1]) [x < min(t, t1)] * x d(x)\n").program
    ts = np.linspace(0.05, 0.95, 19)
    e = exact_batch(program, {"t": ts, "t1": 0.6}, {"t": 1})
    expected = np.minimum(ts, 0.6) ** 2 / 2
    assert np.allclose(e.value, expected, rtol=0, atol=1e-12)
    assert np.allclose(e.derivative, np.where(ts < 0.6, ts, 0.0), rtol=0, atol=1e-12)
    assert e.closed.all() and e.missing == 0
    assert 2 <= e.derivations <= 3


@pytest.mark.parametrize("shader", ["shader", "lin_shader", "quad_shader"])
def test_exact_and_monte_carlo_images_of_the_scene_agree(shader):
    from langur.exact_batch import exact_batch

    loaded = _scene(shader)
    xs = np.arange(10) * 0.1
    px, py = np.meshgrid(xs, xs)
    grid = {"px": px.ravel(), "py": py.ravel(), "c": -1.003, "h": 0.1}
    e = exact_batch(loaded.program, grid, {"c": 1})
    m = estimate_batch(loaded, grid, direction={"c": 1}, samples=400, seed=3)
    assert e.closed.all()
    # Where all 400 samples of a pixel agree the standard error is 0, yet a part of the pixel
    # smaller than the samples can see may differ (a corner the line clips: 0.99955 lit, all
    # samples lit).  A part of measure q is missed by all n samples with probability (1 − q)ⁿ,
    # below 1e-6 once q ≥ 14/n: there the bound is 14/n times the integrand's range (1 here).
    slack = np.where(m.stderr > 0, 5 * m.stderr, 14 / 400) + 1e-9
    assert np.all(np.abs(m.value - e.value) <= slack)
    assert np.all(np.abs(m.derivative - e.derivative) <= 5 * m.derivative_stderr + 1e-9)
    # and the exact boundary sums to the line integral (see the test above), to rounding
    assert abs(float(np.sum(e.boundary)) * 0.01 - 0.997 * {"shader": 1, "lin_shader": 0.5, "quad_shader": 0.25}[shader]) < 1e-12
