"""Figures. Everything draws with matplotlib's Agg backend into files."""
from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np

from .io.frfdata import UNITS

LABELS = {"a1": "A1 (primary)", "a2": "A2 (absorber)", "u1": "U1", "u2": "U2", "q": "Q (charge)"}


def pyplot():
    """matplotlib.pyplot on the Agg backend, imported on first use (it is slow to import).

    Returns
    -------
    module
        ``matplotlib.pyplot``.
    """
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def save(fig, path) -> Path:
    from .io.atomic import atomic_write

    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    try:
        with atomic_write(path) as fh:  # a file object: the format comes from the suffix, not the temp name
            fig.savefig(fh, format=path.suffix.lstrip(".").lower() or None, dpi=120, bbox_inches="tight")
    finally:
        pyplot().close(fig)
    return path


def frf_figure(curves: Sequence[tuple], channels: Sequence[str], title: str = "", bands=(), phase: bool = True):
    """Magnitude (and phase) of several FRF sets.

    ``curves`` are (label, freq_hz, {channel: complex array}, style dict).
    ``bands`` are (lo, hi) frequency ranges to shade.
    """
    plt = pyplot()
    rows = 2 if phase else 1
    fig, axes = plt.subplots(rows, len(channels), figsize=(4.2 * len(channels), 3.0 * rows), squeeze=False,
                             sharex=True)
    for j, ch in enumerate(channels):
        for label, f, data, style in curves:
            if ch not in data:
                continue
            axes[0, j].semilogy(f, np.abs(data[ch]), label=label, **style)
            if phase:
                axes[1, j].plot(f, np.degrees(np.angle(data[ch])), **style)
        axes[0, j].set_title(LABELS.get(ch, ch))
        axes[0, j].set_ylabel(f"|{ch}| [{UNITS.get(ch, '')}]")
        if phase:
            axes[1, j].set_ylabel("phase [deg]")
        axes[-1, j].set_xlabel("frequency [Hz]")
        for ax in axes[:, j]:
            for lo, hi in bands:
                ax.axvspan(lo, hi, color="tab:red", alpha=0.12, lw=0)
            ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_frfdata(data, path, title="", others: Sequence[tuple] = ()):
    """Plot an FRFData (with ±2σ band when std is given) and optional model curves."""
    pyplot()  # selects the non-interactive backend before the figure is made
    channels = list(data.channels)
    curves = [("data", data.freq_hz, data.channels, {"color": "k", "marker": ".", "ms": 3, "lw": 0.6})]
    curves += [(lbl, f, d, st) for lbl, f, d, st in others]
    fig = frf_figure(curves, channels, title)
    if data.std:
        for j, ch in enumerate(channels):
            if ch in data.std:
                mag, s = np.abs(data[ch]), data.std[ch]
                fig.axes[j].fill_between(data.freq_hz, np.maximum(mag - 2 * s, mag * 1e-3), mag + 2 * s,
                                         color="0.6", alpha=0.3, lw=0, label="±2σ")
    return save(fig, path)


def fit_figure(data, curves: Sequence[tuple], residuals: Sequence[tuple] = (), bands=(), title=""):
    """Measured vs model magnitude and phase, with standardised residuals below.

    ``curves``: (label, {channel: complex array}, style) on the data grid.
    ``residuals``: (label, {channel: complex standardised residual}, style).
    """
    plt = pyplot()
    channels = [c for c in data.channels if any(c in d for _, d, _ in curves)] or list(data.channels)
    rows = 3 if residuals else 2
    fig, axes = plt.subplots(rows, len(channels), figsize=(4.6 * len(channels), 2.6 * rows), squeeze=False,
                             sharex=True)
    f = data.freq_hz
    for j, ch in enumerate(channels):
        y = data[ch]
        axes[0, j].semilogy(f, np.abs(y), "k.", ms=3, label="measured")
        axes[1, j].plot(f, np.degrees(np.angle(y)), "k.", ms=3)
        for label, d, style in curves:
            if ch in d:
                axes[0, j].semilogy(f, np.abs(d[ch]), label=label, **style)
                axes[1, j].plot(f, np.degrees(np.angle(d[ch])), **style)
        axes[0, j].set_title(LABELS.get(ch, ch))
        axes[0, j].set_ylabel(f"|{ch}| [{UNITS.get(ch, '')}]")
        axes[1, j].set_ylabel("phase [deg]")
        if residuals:
            ax = axes[2, j]
            for label, d, style in residuals:
                if ch in d:
                    ax.plot(f, np.abs(d[ch]), label=label, **style)
            ax.axhline(np.sqrt(2 * 3.0), color="0.5", ls=":", lw=1)  # |z|² ~ χ²₂/2: 3 = rough 95 % level
            ax.set_ylabel("|standardised residual|")
            ax.legend(fontsize=7)
        axes[-1, j].set_xlabel("frequency [Hz]")
        for ax in axes[:, j]:
            for lo, hi in bands:
                ax.axvspan(lo, hi, color="tab:red", alpha=0.12, lw=0)
            ax.grid(True, alpha=0.3)
    axes[0, 0].legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig
