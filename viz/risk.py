"""The risk minimization of §2 (paper Fig. 2 and 3), drawn from ``langur reproduce risk``'s descents.

Fig. 2: (a) the truncated density h = N(x; μ, 5)·[a ≤ x ≤ b] and the target g = N(x; 2, 5) at the
start; (b) standard AD's first step −Dˢ (zero in a and b) over the shared uniform samples (black
dots); (c) where standard AD ends; (d) Langur's first step, which also samples the two jumps
(orange stars at a and b); (e) where Langur ends.  Fig. 3: a, b, μ and the risk against the
iterations for both.  The risk is the exact engine's closed form of ⟦p⟧ (valid for all parameter
values) evaluated along each path.
"""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import sympy as sp  # noqa: E402

from langur.denote import denote_program  # noqa: E402
from langur.operational.sample import design  # noqa: E402
from langur.sympy_bridge import symbol  # noqa: E402

LANGUR, STANDARD = "#e8710a", "#1f4e9c"
LO, HI = -10.0, 10.0


def density(x, m):
    """N(x; m, 5), as densities.lgr's ``density``."""
    return np.exp(-0.5 * ((x - m) / 5.0) ** 2) / (5.0 * math.sqrt(2 * math.pi))


def _h(x, q):
    return density(x, q["mu"]) * ((x >= q["a"]) & (x <= q["b"]))


def _num(v: float) -> str:
    """A parameter's value in a title: two decimals, a true minus sign (as the tick labels)."""
    return f"{v:.2f}".replace("-", "\u2212")


def _curves(ax, q, title):
    x = np.linspace(LO, HI, 2001)
    ax.plot(x, density(x, 2.0), color="0.25", lw=1.5, ls="--", label="g = N(x; 2, 5)")
    ax.plot(x, _h(x, q), color=STANDARD, lw=2, label="h = N(x; μ, 5)·[a ≤ x ≤ b]")
    ax.set_title(title, fontsize=10)
    ax.set_xlim(LO - 0.5, HI + 0.5)
    ax.set_ylim(-0.012, 0.105)
    ax.set_xlabel("x")


def _step(ax, q0, q1, color, samples, stars):
    """The first step −rate·D as arrows at a, b and μ, the samples on h."""
    for k, y, ha in (("a", 0.097, "right"), ("mu", 0.088, "center"), ("b", 0.097, "left")):
        d = q1[k] - q0[k]
        if abs(d) > 1e-9:
            ax.annotate("", xy=(q0[k] + d, y), xytext=(q0[k], y),
                        arrowprops=dict(arrowstyle="-|>", color="black", lw=1.8))
        ax.plot([q0[k]], [y], "|", color="black", ms=8)
        ax.text(q0[k], y + 0.004, f"Δ{'μ' if k == 'mu' else k} = {d:+.2f}".replace("-", "\u2212"), ha=ha, fontsize=8)
    ax.plot(samples, _h(samples, q0), "o", color="black", ms=3.5, label="shared uniform samples")
    if stars:
        ax.plot([q0["a"], q0["b"]], [density(q0["a"], q0["mu"]), density(q0["b"], q0["mu"])], "*", color=color,
                ms=14, label="delta samples at a and b")


def fig2(figures: dict, path: str) -> str:
    runs, seed = figures["runs"], figures["seed"]
    lang, std = runs["Langur"], runs["standard AD"]
    u = design(np.random.default_rng(seed), 1, 50, "uniform").points[:, 0]
    samples = LO + (HI - LO) * u
    fig, axes = plt.subplots(1, 5, figsize=(22, 4.4), constrained_layout=True, sharey=True)
    fig.suptitle("Risk minimization (paper §2, Fig. 2): truncated normal h against the normal g", fontsize=12)
    _curves(axes[0], lang[0], "(a) initialization a = −1, b = 4, μ = 1")
    _curves(axes[1], std[0], "(b) standard AD's first step −Dˢ")
    _step(axes[1], std[0], std[1], STANDARD, samples, False)
    q = std[-1]
    _curves(axes[2], q, f"(c) standard AD after {len(std) - 1} steps: a = {_num(q['a'])}, b = {_num(q['b'])}, "
            f"μ = {_num(q['mu'])}")
    _curves(axes[3], lang[0], "(d) Langur's first step: the jumps are sampled")
    _step(axes[3], lang[0], lang[1], LANGUR, samples, True)
    q = lang[-1]
    _curves(axes[4], q, f"(e) Langur after {len(lang) - 1} steps: a = {_num(q['a'])}, b = {_num(q['b'])}, "
            f"μ = {_num(q['mu'])}")
    axes[0].legend(loc="upper left", fontsize=8)
    axes[3].legend(loc="center left", fontsize=8)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def fig3(figures: dict, path: str) -> str:
    runs, loaded = figures["runs"], figures["loaded"]
    closed = denote_program(loaded.program, runs["Langur"][0]).expr  # valid for all a, b, μ
    risk = sp.lambdify([symbol("a"), symbol("b"), symbol("mu")], closed, modules=["numpy", "scipy"])
    fig, axes = plt.subplots(1, 4, figsize=(20, 4.2), constrained_layout=True)
    fig.suptitle("Risk minimization (paper §2, Fig. 3): the parameters and the risk against iterations",
                 fontsize=12)
    for label, color in (("standard AD", STANDARD), ("Langur", LANGUR)):
        run = runs[label]
        it = np.arange(len(run))
        for ax, k in zip(axes, ("a", "b", "mu")):
            ax.plot(it, [q[k] for q in run], color=color, lw=2, label=label)
        axes[3].plot(it, [float(risk(q["a"], q["b"], q["mu"])) for q in run], color=color, lw=2, label=label)
    for ax, k, best in zip(axes, ("a", "b", "μ"), (-10.0, 10.0, 2.0)):
        ax.axhline(best, color="0.5", ls=":", lw=1)
        lo, hi = ax.get_ylim()  # the optimum's line inside the frame, not on its edge
        lo, hi = min(lo, best), max(hi, best)
        ax.set_ylim(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo))
        ax.set_title(f"{k} (optimum {best:g})".replace("-", "\u2212"))
        ax.set_xlabel("iteration")
    axes[3].set_yscale("log")
    axes[3].set_title("risk R (exact closed form of ⟦p⟧)")
    axes[3].set_xlabel("iteration")
    for ax in axes:
        ax.legend(fontsize=9)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
