"""Two-variable programs seen from above, and Monte Carlo convergence (matplotlib).

* :func:`flat`: the regular part of ⦇t⦈ as an image over the box, each delta's zero set drawn on it
  coloured by its weight per unit length (``geometry.ridges``), the integrand beside it;
* :func:`convergence`: the Monte Carlo estimate ± 2σ of ⦇p⦈ against the number of samples, with the
  deltas (Langur) and without them (standard AD), the exact values as lines.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import patheffects  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402

from langur import operational  # noqa: E402

from .geometry import Scene, ridges  # noqa: E402

GRID = 400
DELTA_COLOR = "#e8710a"


def _fmt(v: float) -> str:
    return f"{v:.6g}"


def _image(ax, s: Scene, f, title: str, cmap: str = "coolwarm"):
    (x0, x1), (y0, y1) = s.box
    gx, gy = np.meshgrid(np.linspace(x0, x1, GRID), np.linspace(y0, y1, GRID))
    z = f(gx, gy)
    vmax = float(np.nanmax(np.abs(z))) or 1.0
    ratio = (y1 - y0) / (x1 - x0)
    im = ax.imshow(z, origin="lower", extent=(x0, x1, y0, y1), cmap=cmap, vmin=-vmax, vmax=vmax,
                   interpolation="nearest", aspect="equal" if 0.25 < ratio < 4 else "auto")
    ax.set_title(title)
    ax.set_xlabel(s.variables[0])
    ax.set_ylabel(s.variables[1])
    return im


def flat(s: Scene, path: str, title: str, wrt: str) -> str:
    """Integrand and regular part as images; the deltas' zero sets coloured by their weight."""
    fig = figure(s, title, wrt)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def figure(s: Scene, title: str, wrt: str):
    """:func:`flat`'s matplotlib figure.  Each zero set is drawn over a black edge: where a delta's
    weight is near 0 its colour (the diverging map's white) would vanish into the image under it."""
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.4), constrained_layout=True)
    fig.suptitle(title)
    im = _image(axes[0], s, s.integrand, f"integrand, integral = {_fmt(s.value)}")
    fig.colorbar(im, ax=axes[0], label="integrand")
    im = _image(axes[1], s, s.regular, f"d/d{wrt} = {_fmt(s.derivative)}: regular part {_fmt(s.standard_ad)} "
                f"+ deltas {_fmt(s.boundary)}")
    fig.colorbar(im, ax=axes[1], label="regular part (standard AD)")
    rs = ridges(s)
    if rs:
        dens = np.concatenate([r.density for r in rs])
        lim = float(np.nanmax(np.abs(dens))) or 1.0
        for r in rs:
            seg = np.stack([r.points[:-1], r.points[1:]], axis=1)
            lc = LineCollection(seg, cmap="PuOr", norm=plt.Normalize(-lim, lim), linewidths=4,
                                path_effects=[patheffects.Stroke(linewidth=7, foreground="black"),
                                              patheffects.Normal()])
            lc.set_array((r.density[:-1] + r.density[1:]) / 2)
            axes[1].add_collection(lc)
        fig.colorbar(lc, ax=axes[1], label="delta weight per unit length")
    return fig


def convergence(s: Scene, target, path: str, title: str, wrt: str, *, seed: int = 0,
                sizes=(100, 300, 1000, 3000, 10000, 30000)) -> str:
    """Monte Carlo estimates of ⦇p⦈ (``target``: the program or a Loaded) ± 2σ against samples."""
    ests = [operational.estimate_derivative(target, s.params, s.direction, samples=n, seed=seed + i)
            for i, n in enumerate(sizes)]
    fig, ax = plt.subplots(figsize=(8, 5), constrained_layout=True)
    n = np.array(sizes, dtype=float)
    for label, vals, errs, color in (
            ("Langur (regular + deltas)", [e.value for e in ests], [e.stderr for e in ests], DELTA_COLOR),
            ("standard AD (deltas dropped)", [e.standard_ad.value for e in ests],
             [e.standard_ad.stderr for e in ests], "#1f4e9c")):
        vals, errs = np.array(vals), np.array(errs)
        ax.errorbar(n, vals, yerr=2 * errs, fmt="o-", color=color, capsize=4, label=label + " ± 2σ")
    ax.axhline(s.derivative, color=DELTA_COLOR, ls="--", label=f"exact d/d{wrt} = {_fmt(s.derivative)}")
    ax.axhline(s.standard_ad, color="#1f4e9c", ls=":", label=f"exact regular part = {_fmt(s.standard_ad)}")
    ax.set_xscale("log")
    ax.set_xlabel("Monte Carlo samples")
    ax.set_ylabel(f"d/d{wrt}")
    ax.set_title(title)
    ax.legend()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
