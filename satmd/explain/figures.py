"""Figures of use case III (paper Figures 4-9 and the new comparisons). Each returns a matplotlib Figure."""
from __future__ import annotations

import numpy as np

from ..plots import pyplot
from .attributions import OUTPUTS, PAPER_PEAK_BANDS_HZ

_UNITS = {"R": "Ω", "L": "H"}


def _bands(ax):
    for lo, hi in PAPER_PEAK_BANDS_HZ:
        ax.axvspan(lo, hi, color="tab:orange", alpha=0.15, lw=0)


def latent_figure(lm, title: str = "Latent PCA (64-d penultimate layer)"):
    """Figure 4: the same PCA points coloured by R and by L, with the R/L sweeps of the disentanglement test."""
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4))
    for ax, name, c in zip(axes, OUTPUTS, (lm.R, lm.L)):
        sc = ax.scatter(lm.pcs[:, 0], lm.pcs[:, 1], c=c, s=8, cmap="viridis")
        fig.colorbar(sc, ax=ax, label=f"{name} [{_UNITS[name]}]")
        for k, s in enumerate(lm.sweeps):
            ax.plot(*s["pcs_R"].T, "-", color="tab:red", lw=1.5, label="R sweep (L fixed)" if k == 0 else None)
            ax.plot(*s["pcs_L"].T, "-", color="k", lw=1.5, label="L sweep (R fixed)" if k == 0 else None)
        ax.set_xlabel(f"Latent PC1 ({100 * lm.explained[0]:.0f} %)")
        ax.set_ylabel(f"Latent PC2 ({100 * lm.explained[1]:.0f} %)")
        ax.set_title(f"coloured by {name}; linear probe R² = {lm.probe_r2[name]:.3f}", fontsize=9)
    axes[0].legend(fontsize=7, loc="best")
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def attribution_curves(att, k: int):
    """Figures 5 / 7: normalised sensitivity curves per case, their mean, the paper's peak bands shaded."""
    plt = pyplot()
    name = OUTPUTS[k]
    fig, ax = plt.subplots(figsize=(8, 3.8))
    _bands(ax)
    for i, lab in enumerate(att.labels):
        ax.plot(att.freq_hz, att.curves[i, k], lw=1, label=lab)
    mean = att.curves[:, k].mean(axis=0)
    ax.plot(att.freq_hz, mean / mean.max(), "k--", lw=2, label="mean (re-normalised)")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel(f"normalised S_{name}(f)")
    ax.set_title(f"Neural attribution to {name} (paper bands shaded)")
    ax.legend(fontsize=7, ncol=2)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    return fig


def attribution_heatmap(att, k: int):
    """Figures 6 / 8: cases x frequency heatmap of the normalised sensitivity."""
    plt = pyplot()
    name = OUTPUTS[k]
    fig, ax = plt.subplots(figsize=(8, 0.45 * len(att.labels) + 1.6))
    f = att.freq_hz
    im = ax.imshow(att.curves[:, k], aspect="auto", cmap="inferno", vmin=0, vmax=1,
                   extent=(f[0], f[-1], len(att.labels) - 0.5, -0.5))
    ax.set_yticks(range(len(att.labels)), att.labels, fontsize=8)
    ax.set_xlabel("frequency [Hz]")
    ax.set_title(f"Normalised neural sensitivity to {name}")
    fig.colorbar(im, ax=ax)
    fig.tight_layout()
    return fig


def agreement_figure(att, phys_curves: np.ndarray, rows: list, title: str = ""):
    """Neural attribution against physical sensitivity |∂A/∂θ|, every blind case on one figure."""
    plt = pyplot()
    n = len(att.labels)
    fig, axes = plt.subplots(2, n, figsize=(2.6 * n, 5.2), sharex=True, sharey=True, squeeze=False)
    for k, name in enumerate(OUTPUTS):
        for i in range(n):
            ax = axes[k, i]
            ax.plot(att.freq_hz, att.curves[i, k], color="tab:blue", lw=1.2, label="neural ∂θ̂/∂X")
            ax.plot(att.freq_hz, phys_curves[i, k], color="tab:red", lw=1.2, ls="--", label="physical ∂A/∂θ")
            ax.set_title(f"{att.labels[i]}\n{name}: cos {rows[i][f'cosine_{name}']:.2f}, "
                         f"ρ {rows[i][f'spearman_{name}']:.2f}", fontsize=7)
            ax.grid(alpha=0.3)
        axes[k, 0].set_ylabel(f"normalised, {name}")
    axes[0, 0].legend(fontsize=6)
    fig.supxlabel("frequency [Hz]")
    if title:
        fig.suptitle(f"Neural attribution vs physical sensitivity ({title})")
    fig.tight_layout()
    return fig


def distill_figure(res, X, y, title: str = "ξ_FRF"):
    """Figure 9 (predicted vs true on the test split) and the accuracy-complexity Pareto front."""
    from .distillation import split

    plt = pyplot()
    _, Zte, _, yte, _, _ = split(X, y)
    from .symbolic import evaluate

    pred = evaluate(res.expression, Zte)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    axes[0].scatter(yte, pred, s=5, alpha=0.5)
    lim = [min(yte.min(), pred.min()), max(yte.max(), pred.max())]
    axes[0].plot(lim, lim, "k--", lw=1)
    axes[0].set_xlabel(f"true {title}")
    axes[0].set_ylabel(f"formula {title}")
    axes[0].set_title(f"test R² {res.r2_test:.3f}, {res.complexity} nodes ({res.backend})", fontsize=9)
    c = [p["complexity"] for p in res.pareto]
    axes[1].plot(c, [p["r2_train"] for p in res.pareto], "o-", label="train")
    axes[1].plot(c, [p["r2_test"] for p in res.pareto], "s--", label="test")
    axes[1].axvline(res.complexity, color="grey", lw=0.8)
    axes[1].set_xlabel("complexity [sympy nodes]")
    axes[1].set_ylabel("R²")
    axes[1].set_ylim(max(0.0, min(p["r2_test"] for p in res.pareto if np.isfinite(p["r2_test"])) - 0.05), 1.0)
    axes[1].legend()
    axes[1].grid(alpha=0.3)
    axes[1].set_title("Pareto front", fontsize=9)
    fig.tight_layout()
    return fig
