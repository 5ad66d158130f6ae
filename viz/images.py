"""Images of a program over a grid of two parameters (``langur render``; paper Fig. 13).

Each panel is one array over the grid, the first grid parameter along the columns and the second
along the rows, row 0 at the top (the paper's convention: origin in the top left corner, y
pointing down).  Values use a sequential colour map; derivatives a diverging one centred at 0,
with standard AD drawn on the *same* scale as the derivative, so that the line it misses shows.
"""

from __future__ import annotations

from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


@dataclass(frozen=True)
class Panel:
    """One image: its title, its array (rows × columns) and whether it is a derivative (diverging
    colours; panels with the same ``scale`` key share their colour limits)."""

    title: str
    data: np.ndarray
    derivative: bool = False
    scale: str = ""


def _limits(panels: list[Panel]) -> dict[str, tuple[float, float]]:
    out: dict[str, tuple[float, float]] = {}
    for key in {p.scale for p in panels if p.scale}:
        group = [p.data for p in panels if p.scale == key]
        finite = np.concatenate([g[np.isfinite(g)] for g in group]) if group else np.array([])
        if any(p.derivative for p in panels if p.scale == key):
            m = float(np.max(np.abs(finite))) if finite.size else 1.0
            out[key] = (-(m or 1.0), m or 1.0)
        else:
            lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
            out[key] = (lo, hi if hi > lo else lo + 1.0)
    return out


def save(rows: list[list[Panel]], extent: tuple[float, float, float, float], labels: tuple[str, str], out: str,
         title: str) -> str:
    """Draw ``rows`` of panels (each with its colour bar) over ``extent`` = (x0, x1, y0, y1) of the
    two grid parameters named ``labels``; write PNG ``out``; return its path."""
    nrows, ncols = len(rows), max(len(r) for r in rows)
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.8 * nrows), squeeze=False)
    limits = _limits([p for r in rows for p in r])
    x0, x1, y0, y1 = extent
    for i, row in enumerate(rows):
        for j in range(ncols):
            ax = axes[i][j]
            if j >= len(row):
                ax.axis("off")
                continue
            p = row[j]
            lo, hi = limits.get(p.scale) or _limits([Panel(p.title, p.data, p.derivative, "own")])["own"]
            im = ax.imshow(p.data, cmap="RdBu_r" if p.derivative else "magma", vmin=lo, vmax=hi,
                           extent=(x0, x1, y1, y0), origin="upper", interpolation="nearest", aspect="auto")
            ax.set_title(p.title, fontsize=10)
            ax.set_xlabel(labels[0])
            ax.set_ylabel(labels[1])
            fig.colorbar(im, ax=ax, fraction=0.046, pad=0.04)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return out
