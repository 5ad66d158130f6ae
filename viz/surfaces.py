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

import os

os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")

import matplotlib  # noqa: E402
import numpy as np  # noqa: E402
import pyvista as pv  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

from .geometry import Field, Ridge, Scene, ridges  # noqa: E402

FONT = os.path.join(matplotlib.get_data_path(), "fonts", "ttf", "DejaVuSans.ttf")
RESOLUTION = 160
RIDGE_COLOR = "#e8710a"
WINDOW = (1800, 700)


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def regions(s: Scene, f: Field, resolution: int = RESOLUTION) -> list[pv.PolyData]:
    """``f`` over the box as surfaces, one per sign pattern of its conditions that occurs in the box,
    cut along Φ = 0; each has point data ``value`` (the field in that region) and is not yet lifted.

    The box is split condition by condition, each part only where Φ changes sign on it: the work
    grows with the regions there are, not with the 2ⁿ sign patterns of n conditions (window.lgr's
    15 conditions from its kinks)."""
    (x0, x1), (y0, y1) = s.box
    plane = pv.Plane(center=((x0 + x1) / 2, (y0 + y1) / 2, 0.0), direction=(0, 0, 1), i_size=x1 - x0,
                     j_size=y1 - y0, i_resolution=resolution, j_resolution=resolution).triangulate()
    exprs = [c.expr for c in f.conditions]
    parts: list[tuple[pv.PolyData, dict]] = [(plane, {})]
    for expr in exprs:
        phi = _phi(f, expr)
        split = []
        for mesh, signs in parts:
            v = np.nan_to_num(phi(mesh.points[:, 0], mesh.points[:, 1]), nan=-1.0)
            if np.all(v >= 0) or np.all(v < 0):  # one side only: nothing to cut
                split.append((mesh, {**signs, expr: bool(np.all(v >= 0))}))
                continue
            for sign in (True, False):
                m = mesh.copy()
                m.point_data["phi"] = v
                m = m.clip_scalar(scalars="phi", value=0.0, invert=not sign)
                if m.n_points:
                    split.append((m, {**signs, expr: sign}))
        parts = split
    out = []
    for mesh, signs in parts:
        mesh = mesh.extract_surface(algorithm="dataset_surface") if not isinstance(mesh, pv.PolyData) else mesh
        if mesh.n_points == 0 or mesh.n_cells == 0:
            continue
        pts = mesh.points
        mesh.point_data["value"] = f.on_side(signs, pts[:, 0], pts[:, 1])
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


def cliffs(s: Scene, f: Field, resolution: int = RESOLUTION) -> list[pv.PolyData]:
    """The walls of ``f``'s jumps: along each condition's zero set Φ = 0 in the box (a contour of Φ
    on the mesh), a vertical strip from the field on one side to the field on the other, read a
    hair off the curve along ∇Φ; kept where the two differ (a kink split without a jump has none).
    Point data ``value`` as the surfaces': the wall is lifted with them (:func:`_lift`)."""
    (x0, x1), (y0, y1) = s.box
    plane = pv.Plane(center=((x0 + x1) / 2, (y0 + y1) / 2, 0.0), direction=(0, 0, 1), i_size=x1 - x0,
                     j_size=y1 - y0, i_resolution=resolution, j_resolution=resolution).triangulate()
    eps = h = 1e-7 * max(x1 - x0, y1 - y0)
    out = []
    for c in f.conditions:
        phi = _phi(f, c.expr)
        m = plane.copy()
        m.point_data["phi"] = np.nan_to_num(phi(m.points[:, 0], m.points[:, 1]), nan=-1.0)
        line = m.contour([0.0], scalars="phi")
        if line.n_points < 2 or line.n_lines == 0:
            continue
        p = line.points.copy()
        for _ in range(4):  # the contour is Φ's linear interpolant: Newton steps onto Φ = 0 itself
            grad = np.column_stack([phi(p[:, 0] + h, p[:, 1]) - phi(p[:, 0] - h, p[:, 1]),
                                    phi(p[:, 0], p[:, 1] + h) - phi(p[:, 0], p[:, 1] - h)]) / (2 * h)
            g2 = np.sum(grad * grad, axis=1)
            step = np.where(g2 > 0, phi(p[:, 0], p[:, 1]) / np.where(g2 > 0, g2, 1.0), 0.0)
            p[:, :2] -= np.nan_to_num(step)[:, None] * grad
        p[:, 0], p[:, 1] = np.clip(p[:, 0], x0, x1), np.clip(p[:, 1], y0, y1)
        grad /= np.maximum(np.linalg.norm(grad, axis=1, keepdims=True), 1e-300)
        a = f(p[:, 0] + eps * grad[:, 0], p[:, 1] + eps * grad[:, 1])
        b = f(p[:, 0] - eps * grad[:, 0], p[:, 1] - eps * grad[:, 1])
        segs = _segments(line.lines)
        # a continuous field differs across the hair by about |∇f|·2ε: far below a visible jump
        jump = np.abs(a - b) > 1e-4 * max(1.0, float(np.nanmax(np.abs(np.concatenate([a, b])))))
        segs = segs[jump[segs[:, 0]] & jump[segs[:, 1]]]
        if len(segs) == 0:
            continue
        n = len(p)
        pts = np.vstack([p, p])
        faces = np.hstack([[4, i, j, n + j, n + i] for i, j in segs])
        wall = pv.PolyData(pts, faces=faces)
        wall.point_data["value"] = np.concatenate([a, b])
        out.append(wall)
    return out


def _segments(lines: np.ndarray) -> np.ndarray:
    """VTK's line cells ``[n, i₀, …, iₙ₋₁, …]`` as the pairs of consecutive points (k × 2)."""
    out, k = [], 0
    while k < len(lines):
        n = int(lines[k])
        ids = lines[k + 1:k + 1 + n]
        out.extend(zip(ids[:-1], ids[1:]))
        k += n + 1
    return np.array(out, dtype=int).reshape(-1, 2)


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


def heights(values: list[np.ndarray]) -> np.ndarray:
    """The z axis' ticks, in the field's own units: round numbers from at most 0 to at least the
    heights drawn (0 included: the box's plane), the first and last the axis' ends."""
    finite = [v[np.isfinite(v)] for v in values if len(v)]
    lo = min([0.0] + [float(v.min()) for v in finite if v.size])
    hi = max([0.0] + [float(v.max()) for v in finite if v.size])
    if hi <= lo:
        lo, hi = lo - 1.0, hi + 1.0
    ticks = MaxNLocator(nbins=4, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    return ticks[(np.searchsorted(ticks, lo, side="right") - 1):np.searchsorted(ticks, hi, side="left") + 1]


def see_through(rs: list[Ridge]) -> bool:
    """Whether the derivative's surfaces are drawn translucent: where a delta's weight is negative
    its curtain hangs below the regular part, which, opaque, would hide it from a camera above."""
    return any(np.any(np.nan_to_num(r.density) < 0) for r in rs)


def render(s: Scene, path: str, title: str, wrt: str, window=WINDOW) -> str:
    """The three panels of Fig. 9 as one PNG at ``path``: heights in the field's units on the z
    axis (titled in words: VTK's font has no Greek letters), a shared colour scale, and in (b) the
    surfaces translucent where a ridge hangs below them (:func:`see_through`)."""
    (x0, x1), (y0, y1) = s.box
    size = max(x1 - x0, y1 - y0)
    integrand, regular = regions(s, s.integrand), regions(s, s.regular)
    walls = [cliffs(s, s.integrand), cliffs(s, s.regular), cliffs(s, s.regular)]
    rs = ridges(s)
    bases = [_base(s, r) for r in rs]
    values = [m.point_data["value"] for m in integrand + regular] + \
        [b + np.nan_to_num(r.density) for r, b in zip(rs, bases)]
    ticks = heights(values)
    zlo, zhi = float(ticks[0]), float(ticks[-1])
    vmax = max(abs(zlo), abs(zhi), 1e-12)
    scale = 0.6 * size / vmax
    pl = pv.Plotter(shape=(1, 3), window_size=window, off_screen=True, border=False)
    panels = [
        (f"(a) integrand, integral = {_fmt(s.value)}", integrand, [], "integrand", 1.0),
        (f"(b) d/d{wrt}: regular + delta ridge = {_fmt(s.derivative)}", regular, rs, "derivative",
         0.45 if see_through(rs) else 1.0),
        (f"(c) standard AD = {_fmt(s.standard_ad)} (no ridge)", regular, [], "standard AD", 1.0),
    ]
    clim = (-vmax, vmax)
    for col, (text, meshes, ridge_list, bar, opacity) in enumerate(panels):
        pl.subplot(0, col)
        mapper = None
        for m in meshes:
            actor = pl.add_mesh(_lift(m, scale), scalars="value", cmap="coolwarm", clim=clim, show_scalar_bar=False,
                                opacity=opacity)
            mapper = actor.mapper
        for w in walls[col]:  # a jump is a cliff, not a gap
            pl.add_mesh(_lift(w, scale), color="gray", opacity=0.7 * opacity)
        for r, b in zip(ridge_list, bases):
            strip, top = _curtain(r, b, scale)
            pl.add_mesh(strip, color=RIDGE_COLOR, opacity=0.55)
            pl.add_mesh(top.tube(radius=0.008 * size), color=RIDGE_COLOR)
        if mapper is not None:
            pl.add_scalar_bar(title=bar, mapper=mapper, n_labels=5, fmt="%.3g", vertical=True, position_x=0.88,
                              position_y=0.2, width=0.06, height=0.55, title_font_size=16, label_font_size=14)
        pl.add_text(text, font_size=11, font_file=FONT, position="upper_edge")
        outline = pv.Box(bounds=(x0, x1, y0, y1, 0, 0))
        pl.add_mesh(outline, style="wireframe", color="gray")
        pl.show_bounds(bounds=(x0, x1, y0, y1, zlo * scale, zhi * scale), axes_ranges=(x0, x1, y0, y1, zlo, zhi),
                       xtitle=s.variables[0], ytitle=s.variables[1], ztitle=bar, n_zlabels=len(ticks), fmt="%.3g",
                       font_size=12, location="outer", ticks="outside")
        pl.view_vector((1.2, -1.6, 1.2), viewup=(0, 0, 1))
        pl.reset_camera()
        pl.camera.zoom(0.85)
    pl.subplot(0, 0)
    pl.add_text(title, font_size=10, font_file=FONT, position="lower_left")
    pl.screenshot(path)
    pl.close()
    return path
