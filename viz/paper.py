"""The paper's pictures from ``langur reproduce NAME --out DIR`` (drawn from each experiment's data).

* ``fig1``: Fig. 1 (a)–(d) at θ = 0.5 (:mod:`viz.curves`);
* ``fig9``: Fig. 9's three surfaces, the view from above and Monte Carlo convergence
  (:mod:`viz.surfaces`, :mod:`viz.flat`);
* ``risk``: Fig. 2 and Fig. 3 (:mod:`viz.risk`);
* ``raytrace``: Fig. 14 (a)–(d), each shader's colour image and its derivative's sparsity pattern
  per channel (:func:`fig14`);
* ``renderer``: Fig. 13 (b)–(c), the three shaders' images, their derivative in c and standard AD's
  on the derivative's scale (:mod:`viz.images`).
"""

from __future__ import annotations

import os

from . import curves, flat, geometry, images, risk, surfaces


def _scene(figures: dict) -> geometry.Scene:
    loaded = figures["loaded"]
    params = figures["params"]
    return geometry.scene(loaded.program, params, {k: float(k == figures["wrt"]) for k in loaded.params})


def draw(name: str, figures: dict, out: str) -> list[str]:
    """The pictures of experiment ``name`` in the folder ``out``; their paths."""
    os.makedirs(out, exist_ok=True)
    path = lambda what: os.path.join(out, f"{name}_{what}.png")  # noqa: E731
    if name == "fig1":
        s = _scene(figures)
        return [curves.save(s, path("abcd"), "Fig. 1: ∫₀¹ [x ≤ θ] dx at θ = 0.5 and its derivative", "θ")]
    if name == "fig9":
        s = _scene(figures)
        title = "Fig. 9: [y < x + θ](1 + θ + x + y) at θ = 0"
        return [surfaces.render(s, path("surfaces"), title, "θ"),
                flat.flat(s, path("flat"), title, "θ"),
                flat.convergence(s, figures["loaded"], path("convergence"), title + ": Monte Carlo", "θ")]
    if name == "risk":
        return [risk.fig2(figures, path("fig2")), risk.fig3(figures, path("fig3"))]
    if name == "renderer" and "fig13" in figures:
        return [fig13(figures["fig13"], path("fig13"))]
    if name == "raytrace" and "fig14" in figures:
        return [fig14(figures["fig14"], path("fig14"))]
    return []


SHADERS = {"shader": "constant shader", "lin_shader": "linear shader", "quad_shader": "quadratic shader"}


def fig13(data: dict, out: str) -> str:
    """Fig. 13: a row of images per quantity (value; D_c; standard AD on D_c's scale, where the
    line is missing; standard AD on its own scale, the interior derivative ∂_c s of the linear and
    quadratic shaders), a column per shader."""
    imgs = data["images"]
    rows = [[images.Panel(f"{SHADERS.get(k, k)}: value", v["value"], scale=f"v-{k}") for k, v in imgs.items()],
            [images.Panel(f"{SHADERS.get(k, k)}: d/dc", v["derivative"], True, f"d-{k}") for k, v in imgs.items()],
            [images.Panel(f"{SHADERS.get(k, k)}: standard AD", v["standard_ad"], True, f"d-{k}")
             for k, v in imgs.items()],
            [images.Panel(f"{SHADERS.get(k, k)}: standard AD, own scale", v["standard_ad"], True, f"s-{k}")
             for k, v in imgs.items()]]
    return images.save(rows, data["extent"], ("x", "y"), out,
                       f"Fig. 13: the half-plane x + y + c ≥ 0 at c = {data['c']:g}, 100 × 100 pixels (Monte Carlo)")


def fig14(data: dict, out: str) -> str:
    """Fig. 14: for each shader its image (the three channels as RGB) and the sparsity pattern of
    its derivative in t — a pixel is red where the red channel's derivative is nonzero, and so on —
    as the paper shows it; and, beside them, the derivative's magnitude summed over the channels."""
    import matplotlib.pyplot as plt
    import numpy as np

    imgs = data["images"]
    x0, x1, y0, y1 = data["extent"]
    fig, axes = plt.subplots(1, 2 * len(imgs) + 1, figsize=(4.0 * (2 * len(imgs) + 1), 4.2))
    col = 0
    letters = iter("abcdefgh")
    for name, im in imgs.items():
        rgb = np.clip(im["rgb"], 0.0, 1.0)
        pattern = (np.abs(im["drgb"]) > 1e-12).astype(float)
        for arr, what in ((rgb, f"{name} shader"), (pattern, f"{name} shader: $D_t$ ≠ 0 per channel")):
            ax = axes[col]
            ax.imshow(arr, extent=(x0, x1, y1, y0), origin="upper", interpolation="nearest")
            ax.set_title(f"({next(letters)}) {what}", fontsize=10)
            ax.set_xlabel("x")
            ax.set_ylabel("y")
            col += 1
    ax = axes[col]
    mag = sum(np.abs(im["drgb"]).sum(axis=-1) for im in imgs.values())
    shown = ax.imshow(mag, extent=(x0, x1, y1, y0), origin="upper", interpolation="nearest", cmap="magma")
    ax.set_title(f"({next(letters)}) $|D_t|$ summed over channels and shaders", fontsize=10)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    fig.colorbar(shown, ax=ax, fraction=0.046, pad=0.04)
    fig.suptitle("Fig. 14: a ray-traced triangle expanding with t, two toon shaders (Monte Carlo)", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
