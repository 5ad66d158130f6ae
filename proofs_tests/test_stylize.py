"""§10.3.1, Fig. 15 (issue 12): the image stylization kernel (examples/stylize/), checked against
an independent numpy computation: the triangle clipped to the pixel (Sutherland–Hodgman), the
squared colour error integrated over the clipped polygon by a Gauss rule exact for its degree
(a fan of triangles, each through the Duffy map), and derivatives by central differences of that
(exact up to rounding, so the step can be tiny).  The Monte Carlo value and derivative — its
boundary part is the edges' deltas — must lie within 5 standard errors, at a few pixels."""

from __future__ import annotations

import numpy as np
import pytest
from paths import EXAMPLES

from langur.frontend import load
from langur.operational.batch import estimate_batch

GX, GW = np.polynomial.legendre.leggauss(6)
GX, GW = (GX + 1) / 2, GW / 2  # on [0, 1]: exact for degree 11 per axis


def clip(poly, lo, hi):
    """The polygon (list of (x, y)) cut to the box [lo, hi]² (Sutherland–Hodgman)."""
    for axis, bound, keep_le in ((0, hi[0], True), (0, lo[0], False), (1, hi[1], True), (1, lo[1], False)):
        out = []
        for i, p in enumerate(poly):
            q = poly[i - 1]
            pin = p[axis] <= bound if keep_le else p[axis] >= bound
            qin = q[axis] <= bound if keep_le else q[axis] >= bound
            if pin != qin:
                t = (bound - q[axis]) / (p[axis] - q[axis])
                out.append((q[0] + t * (p[0] - q[0]), q[1] + t * (p[1] - q[1])))
            if pin:
                out.append(p)
        poly = out
        if not poly:
            return []
    return poly


def colour(x, y, prm, quadratic):
    a, b, c = (np.array([prm[k + "x"], prm[k + "y"]]) for k in "abc")
    area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])

    def edge(u, v):  # the signed area of (u, v, p), twice
        return (v[0] - u[0]) * (y - u[1]) - (v[1] - u[1]) * (x - u[0])

    la, lb, lc = edge(b, c) / area, edge(c, a) / area, edge(a, b) / area
    col = lambda k: np.array([prm[k + ch] for ch in "rgb"])[:, None]  # noqa: E731
    if not quadratic:
        return la * col("a") + lb * col("b") + lc * col("c")
    return (la * (2 * la - 1) * col("a") + lb * (2 * lb - 1) * col("b") + lc * (2 * lc - 1) * col("c")
            + 4 * lb * lc * col("m") + 4 * lc * la * col("n") + 4 * la * lb * col("q"))


def kernel(prm, quadratic):
    """∫ over the pixel of [p in abc]·|colour(p) − pixel colour|², by the clipped polygon."""
    lo = (prm["px"], prm["py"])
    hi = (prm["px"] + prm["h"], prm["py"] + prm["h"])
    poly = clip([(prm["ax"], prm["ay"]), (prm["bx"], prm["by"]), (prm["cx"], prm["cy"])], lo, hi)
    target = np.array([prm["pr"], prm["pg"], prm["pb"]])[:, None]
    total = 0.0
    for i in range(1, len(poly) - 1):
        p0, p1, p2 = (np.array(poly[0]), np.array(poly[i]), np.array(poly[i + 1]))
        u, w = np.meshgrid(GX, GX, indexing="ij")
        wt = np.outer(GW, GW) * u  # Duffy: (u, w) in the square -> p0 + u (p1 - p0) + u w (p2 - p1)
        pts = p0 + u[..., None] * (p1 - p0) + (u * w)[..., None] * (p2 - p1)
        jac = abs((p1 - p0)[0] * (p2 - p1)[1] - (p1 - p0)[1] * (p2 - p1)[0])
        e = colour(pts[..., 0].ravel(), pts[..., 1].ravel(), prm, quadratic) - target
        total += jac * float(np.sum(wt.ravel() * np.sum(e * e, axis=0)))
    return total


def defaults(name):
    loaded = load(str(EXAMPLES / "stylize" / f"{name}.lgr"))
    return loaded, {k: float(v) for k, v in loaded.params.items()}


@pytest.mark.parametrize("name", ["linear", "quadratic"])
def test_the_numpy_kernel_is_the_triangle_area_for_a_constant_error(name):
    # a check on the reference itself: one colour everywhere, error 1 in red: the covered area
    _, prm = defaults(name)
    prm.update({k + ch: 0.0 for k in "abcmnq" for ch in "rgb"}, pr=1.0, pg=0.0, pb=0.0, px=-1.0, py=-1.0, h=3.0)
    area = abs((prm["bx"] - prm["ax"]) * (prm["cy"] - prm["ay"]) - (prm["by"] - prm["ay"]) * (prm["cx"] - prm["ax"])) / 2
    assert kernel(prm, name == "quadratic") == pytest.approx(area, rel=1e-12)


@pytest.mark.parametrize("name", ["linear", "quadratic"])
def test_kernel_value_and_derivatives_agree_with_numpy(name):
    loaded, prm = defaults(name)
    quad = name == "quadratic"
    # a 3 × 3 grid of pixels over [0, 1]²: some covered, some cut by one or two edges, some empty
    h = 1 / 3
    px, py = np.meshgrid(np.arange(3) * h, np.arange(3) * h)
    grid = {"px": px.ravel(), "py": py.ravel(), "h": h}
    for wrt in ("ax", "cy", "bx", "ar", "pg"):
        b = estimate_batch(loaded, grid, direction={wrt: 1.0}, samples=3000, seed=4)
        for i in range(9):
            at = {**prm, "px": float(px.ravel()[i]), "py": float(py.ravel()[i]), "h": h}
            value = kernel(at, quad)
            step = 1e-6
            fd = (kernel({**at, wrt: at[wrt] + step}, quad) - kernel({**at, wrt: at[wrt] - step}, quad)) / (2 * step)
            assert abs(b.value[i] - value) <= 5 * b.stderr[i] + 1e-9, (wrt, i, b.value[i], value)
            assert abs(b.derivative[i] - fd) <= 5 * b.derivative_stderr[i] + 1e-6, (wrt, i, b.derivative[i], fd)
        if wrt in ("ax", "cy", "bx"):  # a vertex moves: some pixel's derivative is mostly its edges' deltas
            assert np.max(np.abs(b.boundary)) > 10 * np.max(b.boundary_stderr)
