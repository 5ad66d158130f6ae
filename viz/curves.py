"""One-variable programs with matplotlib: the four panels of paper Fig. 1.

(a) the integrand at the parameters, the integral shaded and its exact value written;
(b) a discretization, as a language without integration evaluates it (midpoint samples);
(c) the derivative ⦇p⦈: its regular part, and each delta as a spike at its root with its weight
    written beside it (what integrating the delta contributes);
(d) standard AD: the regular part alone, what differentiating the discretized program gives.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .geometry import Scene, Spike, curve, spikes  # noqa: E402

DELTA_COLOR = "#e8710a"  # the paper's orange for what the delta contributes
CURVE_COLOR = "#1f4e9c"
SAMPLES = 10


def _fmt(v: float) -> str:
    """Six significant digits, with a true minus sign (as matplotlib's tick labels)."""
    return f"{v:.6g}".replace("-", "\u2212")


def _label_rows(sps: list[Spike], width: float) -> list[tuple[Spike, int, float]]:
    """Each spike with the row of its label and the height the rows start from, centred above (or
    below) it: a label shares a row with no label of the same sign less than a third of the box
    away, and starts past the longest arrow among those, so that no label overlaps another or is
    crossed by a neighbour's arrow, and each stands over its own spike."""
    placed: list[tuple[Spike, int, float]] = []
    for sp_ in sorted(sps, key=lambda p: p.x):
        near = [(p, row) for p, row, _ in placed
                if (p.weight >= 0) == (sp_.weight >= 0) and abs(p.x - sp_.x) < width / 3]
        taken = {row for _, row in near}
        placed.append((sp_, min(set(range(len(taken) + 1)) - taken), 0.0))
    return [(p, row, max((abs(q.weight) for q, _, _ in placed
                          if (q.weight >= 0) == (p.weight >= 0) and abs(q.x - p.x) < width / 3),
                         default=abs(p.weight)) * (1 if p.weight >= 0 else -1))
            for p, row, _ in placed]


def _draw(ax, pieces, **kw):
    for x, y in pieces:
        ax.plot(x, y, **kw)
        kw.pop("label", None)


def figure(s: Scene, title: str, wrt: str):
    """The four panels of Fig. 1 for a one-variable scene; returns the matplotlib figure."""
    (x,) = s.variables
    (lo, hi), = s.box
    fig, axes = plt.subplots(1, 4, figsize=(16, 4.2), constrained_layout=True)
    fig.suptitle(title, fontsize=12)
    integrand = curve(s, s.integrand)
    ymin = min(0.0, *(float(np.nanmin(y)) for _, y in integrand))
    ymax = max(0.0, *(float(np.nanmax(y)) for _, y in integrand))
    pad = 0.1 * (ymax - ymin or 1.0)

    ax = axes[0]
    _draw(ax, integrand, color=CURVE_COLOR, lw=2)
    for xx, y in integrand:
        ax.fill_between(xx, 0, y, color=CURVE_COLOR, alpha=0.25)
    ax.set_title(f"(a) integrand: ∫ = {_fmt(s.value)}")

    ax = axes[1]
    mids = lo + (np.arange(SAMPLES) + 0.5) * (hi - lo) / SAMPLES
    vals = s.integrand(mids)
    ax.bar(mids, vals, width=(hi - lo) / SAMPLES * 0.9, color=CURVE_COLOR, alpha=0.35)
    ax.plot(mids, vals, "o", color="black", ms=4)
    ax.set_title(f"(b) discretized: {SAMPLES} samples, Σ = {_fmt(float(np.sum(vals)) * (hi - lo) / SAMPLES)}")

    regular = curve(s, s.regular)
    ax = axes[2]
    _draw(ax, regular, color=CURVE_COLOR, lw=2, label="regular part")
    top = ymax
    rows = _label_rows(spikes(s), hi - lo)
    for sp_, row, start in rows:
        ax.annotate("", xy=(sp_.x, sp_.weight), xytext=(sp_.x, 0.0),
                    arrowprops=dict(arrowstyle="-|>", color=DELTA_COLOR, lw=2.5))
        up = sp_.weight >= 0
        ax.annotate(f"weight {_fmt(sp_.weight)}", xy=(sp_.x, start), xytext=(0, (4 + 14 * row) * (1 if up else -1)),
                    textcoords="offset points", color=DELTA_COLOR, ha="center", va="bottom" if up else "top")
        top = max(top, sp_.weight)
        ymin = min(ymin, sp_.weight)
    # room for the labels: a row of text is about 7 % of the panel's height
    depth = 1 + max([row for _, row, _ in rows], default=-1)
    label_pad = 0.08 * (max(top, ymax) - ymin or 1.0) * depth
    top += label_pad if any(sp_.weight >= 0 for sp_, _, _ in rows) else 0.0
    ymin -= label_pad if any(sp_.weight < 0 for sp_, _, _ in rows) else 0.0
    ax.set_title(f"(c) derivative = {_fmt(s.derivative)} (deltas {_fmt(s.boundary)})")

    ax = axes[3]
    _draw(ax, regular, color=CURVE_COLOR, lw=2)
    ax.set_title(f"(d) standard AD = {_fmt(s.standard_ad)} (no delta)")

    for ax in axes:
        ax.set_xlim(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
        ax.set_ylim(ymin - pad, max(top, ymax) + pad)
        ax.axhline(0, color="0.6", lw=0.8)
        ax.set_xlabel(x)
    axes[0].set_ylabel("integrand")
    axes[1].set_ylabel("samples")
    axes[2].set_ylabel(f"d/d{wrt} of the integrand")
    axes[3].set_ylabel(f"d/d{wrt}, deltas dropped")
    return fig


def save(s: Scene, path: str, title: str, wrt: str) -> str:
    fig = figure(s, title, wrt)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
