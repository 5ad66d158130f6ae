"""Pictures looked at (look31): what a reader found wrong or unreadable in ``langur reproduce --out``
and ``langur plot``, each fixed and pinned here at the level of the numbers drawn (or of the pixels,
rendered in a subprocess for VTK).

* ``plot examples/window.lgr`` never finished: the surfaces enumerated all 2¹⁵ sign patterns of its
  15 conditions; they are now split condition by condition where Φ changes sign.
* A delta of negative weight hung its curtain below the opaque regular part (implicit2d.lgr: the
  whole ridge hidden); the derivative's surfaces are translucent then, and the z axis is labelled
  in the field's units (it said "Z Axis" and had no ticks).
* The view from above drew a zero set in the diverging map's white where its weight is near 0
  (fig9 at x = −1/2): a black edge keeps it visible.
* Fig. 1-style panels wrote the weights of nearby deltas on top of one another, a label on the far
  side of its spike (turning.lgr).
"""

from __future__ import annotations

import math
import os
import subprocess
import sys

import numpy as np
import pytest
from paths import EXAMPLES, REPO

pytest.importorskip("matplotlib")
pytest.importorskip("pyvista")

from langur.frontend import load  # noqa: E402
from viz import geometry as G  # noqa: E402


def _scene(name: str, wrt: str):
    loaded = load(str(EXAMPLES / name))
    return G.scene(loaded.program, loaded.param_values(), {k: float(k == wrt) for k in loaded.params})


def _triangles(mesh):
    mesh = mesh.triangulate()
    faces = mesh.faces.reshape(-1, 4)[:, 1:]
    p = mesh.points
    area = 0.5 * np.abs(np.cross(p[faces[:, 1]] - p[faces[:, 0]], p[faces[:, 2]] - p[faces[:, 0]])[:, 2])
    return faces, area


def test_regions_of_fifteen_conditions_tile_the_box_with_the_right_values():
    # window.lgr at a = 1/2, c = 3/10: [|x − c| ≤ 0.2]·eʸ + [max(|x|, |y|) ≤ a] on [−1, 1]², whose
    # kinks make 15 conditions (2¹⁵ sign patterns: the old enumeration ran > 10 min).  The regions
    # tile the box (area 4), each carries the field of its own side (checked at its triangles'
    # centroids, inside the region, against the field evaluated point by point), and together
    # they integrate to 0.4·(e − 1/e) + (2a)² = 1.94016 (by hand), up to the linear interpolation
    # of eʸ on a 40 × 40 mesh.
    from viz import surfaces

    s = _scene("window.lgr", "a")
    assert len(s.integrand.conditions) == 15
    meshes = surfaces.regions(s, s.integrand, resolution=40)
    total_area = total = 0.0
    for m in meshes:
        faces, area = _triangles(m)
        c = m.triangulate().points[faces].mean(axis=1)
        v = m.triangulate().point_data["value"]
        assert np.allclose(v[faces].mean(axis=1)[area > 1e-6], s.integrand(c[:, 0], c[:, 1])[area > 1e-6],
                           atol=0.01)
        total_area += area.sum()
        total += float(np.sum(area * v[faces].mean(axis=1)))
    assert total_area == pytest.approx(4.0, abs=1e-6)
    assert total == pytest.approx(0.4 * (math.e - 1 / math.e) + 1.0, abs=1e-3)
    assert s.value == pytest.approx(0.4 * (math.e - 1 / math.e) + 1.0, abs=1e-12)


def test_z_axis_ticks_are_round_and_cover_what_is_drawn():
    from viz.surfaces import heights

    # fig9's heights run from −1 (the integrand at (−1, −1)) and −0.81 to 3: ticks −1 … 3 by 1
    assert heights([np.array([-0.811, 3.0]), np.array([0.0])]).tolist() == [-1.0, 0.0, 1.0, 2.0, 3.0]
    # implicit2d's ridge: −0.81 … 0.14, with 0 (the plane) inside
    assert heights([np.array([-0.81, 0.14])]).tolist() == [-1.0, -0.75, -0.5, -0.25, 0.0, 0.25]
    # a field that is 0 everywhere still gets an axis around 0
    t = heights([np.zeros(3)])
    assert t[0] < 0 < t[-1]


def test_surfaces_see_through_exactly_when_a_ridge_hangs_below():
    from viz.surfaces import see_through

    # fig9: density (1 + 2x)/√2 < 0 for x < −1/2; implicit2d: weight −0.81 … 0.14
    for name, wrt in (("fig9.lgr", "theta"), ("implicit2d.lgr", "a")):
        s = _scene(name, wrt)
        rs = G.ridges(s)
        assert min(float(np.min(r.density)) for r in rs) < 0 and see_through(rs)
    # window.lgr in a: density 1 on the square's edges (d/da (2a)² = 8a = 4 over the perimeter 8a)
    rs = G.ridges(_scene("window.lgr", "a"))
    assert all(np.allclose(r.density, 1.0) for r in rs) and not see_through(rs)


def _langur(*args, timeout=300):
    env = dict(os.environ, VTK_DEFAULT_OPENGL_WINDOW="vtkEGLRenderWindow")
    return subprocess.run([sys.executable, "-m", "langur", *args], capture_output=True, text=True,
                          timeout=timeout, cwd=REPO, env=env)


def test_a_negative_ridge_is_seen_through_the_surface(tmp_path):
    # implicit2d.lgr in a: the delta along x³ + x + y³ + y = a has weight −0.81 … 0.14 and the
    # regular part is 0 (grey): in panel (b) the orange of the ridge is what a reader must see.
    # Opaque, the plane hid all but its two ends (145 orange pixels); seen through, its length.
    from PIL import Image

    out = tmp_path / "i.png"
    r = _langur("plot", str(EXAMPLES / "implicit2d.lgr"), "--wrt", "a", "-o", str(out))
    assert r.returncode == 0, r.stderr
    a = np.asarray(Image.open(out).convert("RGB")).astype(int)[:, 600:1070]
    orange = (a[..., 0] - a[..., 2] > 90) & (a[..., 1] > 60) & (a[..., 1] < 170) & (a[..., 0] > 150)
    assert orange.sum() > 350


def test_flat_draws_a_zero_set_of_weight_zero_visibly():
    # fig9 from above: the ridge's density (1 + 2x)/√2 is 0 at (−1/2, −1/2), where PuOr is white;
    # its black edge must be there (a pixel near the point darker than any colour of the images)
    from viz import flat

    s = _scene("fig9.lgr", "theta")
    fig = flat.figure(s, "fig9", "θ")
    fig.canvas.draw()
    (ax,) = [a for a in fig.axes if a.get_title().startswith("d/dθ")]
    assert ax.get_title().startswith("d/dθ = 4")
    px, py = ax.transData.transform((-0.5, -0.5))
    buf = np.asarray(fig.canvas.buffer_rgba())[..., :3].astype(float) / 255
    h = buf.shape[0]
    row, col = int(round(h - py)), int(round(px))
    patch = buf[row - 6:row + 7, col - 6:col + 7]
    lum = patch @ np.array([0.299, 0.587, 0.114])
    assert lum.min() < 0.1
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_delta_labels_stand_under_their_own_spikes_crossed_by_no_arrow():
    # turning.lgr at a = 0.2: three deltas of negative weight at x ≈ −0.86, −0.2, 1.1 on [−2, 2]
    # (each weight −e^{x/2}/|3x² − 1|, summing to the boundary part −2.2012)
    from viz import curves

    s = _scene("turning.lgr", "a")
    sps = G.spikes(s)
    assert len(sps) == 3 and sum(p.weight for p in sps) == pytest.approx(s.boundary, rel=1e-9)
    for p in sps:
        assert p.weight == pytest.approx(-math.exp(p.x / 2) / abs(3 * p.x ** 2 - 1), rel=1e-6)
    fig = curves.figure(s, "turning", "a")
    fig.canvas.draw()
    ax = fig.axes[2]
    texts = [t for t in ax.texts if t.get_text().startswith("weight ")]
    assert len(texts) == 3
    boxes = [t.get_window_extent() for t in texts]
    for i, b in enumerate(boxes):
        for c in boxes[i + 1:]:
            assert not b.overlaps(c)
    for b in boxes:  # no arrow (from 0 to its weight) runs through a label
        for p in sps:
            (x, y0), (_, y1) = ax.transData.transform([(p.x, 0.0), (p.x, p.weight)])
            assert not (b.x0 <= x <= b.x1 and min(y0, y1) <= b.y1 and b.y0 <= max(y0, y1))
    for p in sps:  # the label whose text is this weight is centred on this spike, inside the axes
        (t, b), = [(t, b) for t, b in zip(texts, boxes) if t.get_text() == f"weight {curves._fmt(p.weight)}"]
        x, _ = ax.transData.transform((p.x, 0))
        assert abs((b.x0 + b.x1) / 2 - x) < 2 and ax.bbox.contains(b.x0, b.y0) and ax.bbox.contains(b.x1, b.y1)
        assert "\u2212" in t.get_text() and "-" not in t.get_text()
    import matplotlib.pyplot as plt

    plt.close(fig)


def test_jumps_are_drawn_as_walls_where_the_field_jumps_only():
    # fig9 at θ = 0: one wall, on y = x, from 0 (above) to 1 + x + y = 1 + 2x (below)
    from viz import surfaces

    s = _scene("fig9.lgr", "theta")
    (w,) = surfaces.cliffs(s, s.integrand, resolution=40)
    n = w.n_points // 2
    used = np.unique(w.faces.reshape(-1, 5)[:, 1:3])  # the curve's points the wall stands on
    p, v = w.points[used], w.point_data["value"]
    assert np.allclose(p[:, 0], p[:, 1], atol=1e-6) and p[:, 0].min() < -0.9 and p[:, 0].max() > 0.9
    lo, hi = np.minimum(v[used], v[used + n]), np.maximum(v[used], v[used + n])
    x = p[:, 0]
    assert np.allclose(np.where(1 + 2 * x >= 0, lo, hi), 0.0, atol=1e-5)
    assert np.allclose(np.where(1 + 2 * x >= 0, hi, lo), 1 + 2 * x, atol=1e-5)
    # window.lgr: jumps on x = c ± 0.2 = 0.1, 0.5 (the strip) and on |x|, |y| = a = 0.5 (the square);
    # the kink of |x − c| at x = 0.3 and of max(|x|, |y|) on its diagonals are splits without a jump
    s = _scene("window.lgr", "a")
    for w in surfaces.cliffs(s, s.integrand, resolution=40):
        n = w.n_points // 2
        x, y = w.points[:n, 0], w.points[:n, 1]
        used = np.unique(w.faces.reshape(-1, 5)[:, 1:3])
        x, y = x[used], y[used]
        on = np.isclose(x, 0.1) | np.isclose(x, 0.5) | np.isclose(np.abs(x), 0.5) | np.isclose(np.abs(y), 0.5)
        assert on.all() and not np.isclose(x, 0.3).all() and not np.isclose(np.abs(x), np.abs(y)).all()
