"""Two-variable programs as pyvista surfaces (paper Fig. 9): (a) the integrand, (b) the derivative
with its delta ridge, (c) standard AD.

Every surface is cut exactly along the jumps: the box is a fine triangle mesh, clipped by each
condition's Φ (linear interpolation of Φ along the edges that cross Φ = 0, so a straight jump is
cut exactly and a curved one to the mesh's resolution), and each region is lifted by the field's
value *in that region* (``Field.on_side``), never by values sampled across a jump.  A delta is a
curtain standing on the regular part along its zero set, topped by a tube at the height of its
weight per unit length (``geometry.ridges``).

Rendering is off-screen through EGL (``VTK_DEFAULT_OPENGL_WINDOW=vtkEGLRenderWindow``); VTK's own
font has no Greek letters, so titles use matplotlib's DejaVu Sans.
"""

from __future__ import annotations

import itertools
import os

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402
import pyvista as pv  # noqa: E402

from .geometry import Field, Ridge, Scene, ridges  # noqa: E402

FONT = os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf")
RESOLUTION = 160
RIDGE_COLOR = "#e8710a"
WINDOW = (1800, 700)


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def regions(s: Scene, f: Field, resolution: int = RESOLUTION) -> list[pv.PolyData]:
    """``f`` over the box as surfaces, one per sign pattern of its conditions, cut along Φ = 0;
    each has point data ``value`` (the field in that region) and is not yet lifted."""
    (x0, x1), (y0, y1) = s.box
    plane = pv.Plane(center=((x0 + x1) / 2, (y0 + y1) / 2, 0.0), direction=(0, 0, 1), i_size=x1 - x0,
                     j_size=y1 - y0, i_resolution=resolution, j_resolution=resolution).triangulate()
    conds = [(c.expr, fn) for c in f.conditions
             for fn in [next(phi for p in f.pieces for phi, _, e in p[0] if e == c.expr or e == -c.expr)]]
    out = []
    for signs in itertools.product((True, False), repeat=len(conds)):
        mesh = plane
        for (expr, _), sign in zip(conds, signs):
            pts = mesh.points
            phi = _phi(f, expr)(pts[:, 0], pts[:, 1])
            mesh = mesh.copy()
            mesh.point_data["phi"] = np.nan_to_num(phi, nan=-1.0)
            mesh = mesh.clip_scalar(scalars="phi", value=0.0, invert=not sign)
            if mesh.n_points == 0:
                break
        if mesh.n_points == 0:
            continue
        mesh = mesh.extract_surface(algorithm="dataset_surface")
        if mesh.n_points == 0 or mesh.n_cells == 0:
            continue
        pts = mesh.points
        mesh.point_data["value"] = f.on_side(dict(zip((e for e, _ in conds), signs)), pts[:, 0], pts[:, 1])
        out.append(mesh)
    return out


def _phi(f: Field, expr):
    """The numeric Φ of ``expr`` (or of its complement, negated) among the field's pieces."""
    for conds, _ in f.pieces:
        for fn, _, e in conds:
            if e == expr:
                return fn
            if e == -expr:
                return lambda *xs, fn=fn: -fn(*xs)
    raise KeyError(expr)


def _lift(mesh: pv.PolyData, scale: float) -> pv.PolyData:
    m = mesh.copy()
    m.points[:, 2] = np.nan_to_num(m.point_data["value"]) * scale
    return m


def _curtain(r: Ridge, base: np.ndarray, scale: float) -> tuple[pv.PolyData, pv.PolyData]:
    """The vertical strip from the regular part up to the ridge's density, and the top polyline."""
    n = len(r.points)
    top = np.column_stack([r.points, (base + np.nan_to_num(r.density)) * scale])
    bottom = np.column_stack([r.points, base * scale])
    pts = np.vstack([bottom, top])
    faces = np.hstack([[4, i, i + 1, n + i + 1, n + i] for i in range(n - 1)])
    strip = pv.PolyData(pts, faces=faces)
    strip.point_data["value"] = np.concatenate([base, base + np.nan_to_num(r.density)])
    return strip, pv.lines_from_points(top)


def _base(s: Scene, r: Ridge) -> np.ndarray:
    """The regular part along the ridge: the mean of its two sides (it may jump there)."""
    d = np.gradient(r.points, axis=0)
    normal = np.column_stack([-d[:, 1], d[:, 0]])
    normal /= np.maximum(np.linalg.norm(normal, axis=1, keepdims=True), 1e-300)
    eps = 1e-6 * max(s.box[0][1] - s.box[0][0], s.box[1][1] - s.box[1][0])
    a, b = r.points + eps * normal, r.points - eps * normal
    return (s.regular(a[:, 0], a[:, 1]) + s.regular(b[:, 0], b[:, 1])) / 2


def render(s: Scene, path: str, title: str, wrt: str, window=WINDOW) -> str:
    """The three panels of Fig. 9 as one PNG at ``path``."""
    (x0, x1), (y0, y1) = s.box
    size = max(x1 - x0, y1 - y0)
    integrand, regular = regions(s, s.integrand), regions(s, s.regular)
    rs = ridges(s)
    bases = [_base(s, r) for r in rs]
    values = [m.point_data["value"] for m in integrand + regular] + \
        [b + np.nan_to_num(r.density) for r, b in zip(rs, bases)]
    vmax = max([float(np.nanmax(np.abs(v))) for v in values if len(v)] + [1e-12])
    scale = 0.6 * size / vmax
    pl = pv.Plotter(shape=(1, 3), window_size=window, off_screen=True, border=False)
    panels = [
        (f"(a) integrand, integral = {_fmt(s.value)}", integrand, [], "integrand"),
        (f"(b) d/d{wrt}: regular + delta ridge = {_fmt(s.derivative)}", regular, rs, "derivative"),
        (f"(c) standard AD = {_fmt(s.standard_ad)} (no ridge)", regular, [], "standard AD"),
    ]
    clim = (-vmax, vmax)
    for col, (text, meshes, ridge_list, bar) in enumerate(panels):
        pl.subplot(0, col)
        mapper = None
        for m in meshes:
            actor = pl.add_mesh(_lift(m, scale), scalars="value", cmap="coolwarm", clim=clim, show_scalar_bar=False)
            mapper = actor.mapper
        for r, b in zip(ridge_list, bases):
            strip, top = _curtain(r, b, scale)
            pl.add_mesh(strip, color=RIDGE_COLOR, opacity=0.55)
            pl.add_mesh(top.tube(radius=0.008 * size), color=RIDGE_COLOR)
        if mapper is not None:
            pl.add_scalar_bar(title=bar, mapper=mapper, n_labels=5, fmt="%.3g", vertical=True, position_x=0.86,
                              position_y=0.25, width=0.07, height=0.5, title_font_size=14, label_font_size=12)
        pl.add_text(text, font_size=11, font_file=FONT, position="upper_edge")
        outline = pv.Box(bounds=(x0, x1, y0, y1, 0, 0))
        pl.add_mesh(outline, style="wireframe", color="gray")
        pl.show_bounds(xtitle=s.variables[0], ytitle=s.variables[1], show_zaxis=False, show_zlabels=False, font_size=9,
                       location="outer", ticks="outside")
        pl.view_vector((1.2, -1.6, 1.2), viewup=(0, 0, 1))
        pl.reset_camera()
        pl.camera.zoom(0.8)
    pl.subplot(0, 0)
    pl.add_text(title, font_size=9, font_file=FONT, position="lower_left")
    pl.screenshot(path)
    pl.close()
    return path
