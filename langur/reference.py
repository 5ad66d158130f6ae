"""Hand-written numpy models of the paper's ray-traced scene (§10.2, Fig. 14), independent of both
engines: what ``langur reproduce raytrace`` checks the engines' images against.

The scene is written out here a second time, from its description (the comments of
``examples/raytrace/*.lgr``), as plain numpy: a pinhole camera at the origin, the image plane z = 1,
one triangle A B C expanding with t, the z-depth shader and the thresholded point-light shader.
A pixel's value is the average of the colour over the pixel, computed by supersampling it on a
fine midpoint grid; derivatives in t by central finite differences of such values.  Nothing here
reads a Langur program.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Scene:
    """The constants of ``examples/raytrace/``: the depth threshold, the light and its radius."""

    zth: float = 2.6
    light: tuple[float, float, float] = (0.0, -0.1, 2.0)
    rho: float = 0.62
    falloff: float = 1.5


def vertices(t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A comes towards the camera as t grows; B and C spread outward."""
    a = np.array([-0.45 - 0.3 * t, -0.45 - 0.3 * t, 2 - 0.6 * t])
    b = np.array([0.55 + 0.3 * t, -0.25, 3.0])
    c = np.array([-0.15, 0.6 + 0.3 * t, 3.0])
    return a, b, c


def colour(x: np.ndarray, y: np.ndarray, t: float, shader: str, channel: int, scene: Scene = Scene()) -> np.ndarray:
    """The colour of channel ``channel`` (0 red, 1 green, 2 blue) seen along the ray (x, y, 1)."""
    a, b, c = vertices(t)
    d = np.stack([x, y, np.ones_like(x)], axis=-1)
    inside = ((d @ np.cross(a, b)) >= 0) & ((d @ np.cross(b, c)) >= 0) & ((d @ np.cross(c, a)) >= 0)
    n = np.cross(b - a, c - a)
    k = float(n @ a)
    depth = k / (d @ n)  # the hit point is depth · d: its z is depth
    if shader == "depth":
        out = [(depth <= scene.zth) * 1.0, (depth > scene.zth) * 1.0, np.zeros_like(x)][channel]
    else:
        hit = depth[..., None] * d
        dist = np.linalg.norm(np.array(scene.light) - hit, axis=-1)
        lambert = (k - n @ np.array(scene.light)) / (np.linalg.norm(n) * dist)
        lit = lambert * (1 - dist / scene.falloff)
        dim = dist > scene.rho
        out = np.where(dim, 1.0 if channel == 0 else 0.0, lit)
    return np.where(inside, out, 0.0)


def pixels(xs: np.ndarray, ys: np.ndarray, h: float, t: float, shader: str, channel: int, per_side: int) -> np.ndarray:
    """Each pixel [x, x + h] × [y, y + h]'s average colour (rows: y, columns: x), by the midpoint
    rule on ``per_side``² points."""
    off = (np.arange(per_side) + 0.5) / per_side * h
    out = np.empty((len(ys), len(xs)))
    for i, y0 in enumerate(ys):  # a row of pixels at a time: memory stays small
        X, Y = np.meshgrid(np.add.outer(xs, off).ravel(), y0 + off)
        v = colour(X, Y, t, shader, channel)
        out[i] = v.reshape(per_side, len(xs), per_side).mean(axis=(0, 2))
    return out


def derivative(xs, ys, h: float, t: float, shader: str, channel: int, per_side: int, step: float) -> np.ndarray:
    """D_t of each pixel's average by a central difference of supersampled averages."""
    return (pixels(xs, ys, h, t + step, shader, channel, per_side)
            - pixels(xs, ys, h, t - step, shader, channel, per_side)) / (2 * step)
