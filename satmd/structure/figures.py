"""Figures of a structure: where its joint acts (the sensors, the joint between two, the evidence per place), and a
prediction (measured, linear and nonlinear responses in time and spectrum)."""
from __future__ import annotations

import numpy as np

from ..conventions import TINY
from .bands import band_top


def joint_figure(location, path, title: str = ""):
    """`draw_joint` saved into ``path`` (its suffix sets the format); returns the Path."""
    from ..plots import save

    return save(draw_joint(location, title), path)


def draw_joint(location, title: str = ""):
    """The figure of ``location`` (a `JointLocation`): left, the sensors in a row above the ground with the
    joint between its two (equally supported places dashed); right, ΔBIC of every place to the best.

    Parameters
    ----------
    location : JointLocation
    title : a title above both panels

    Returns
    -------
    matplotlib Figure
    """
    from ..plots import pyplot

    plt = pyplot()
    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 3.8), gridspec_kw={"width_ratios": [1.1, 1.0]})
    _draw_sensors(ax, location)
    _draw_evidence(bx, location)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def draw_structure_discovery(location, model, title: str = ""):
    """What `discover` found on a structure's levels: where the joint acts (`draw_joint`'s two panels) and,
    with a fitted model, each recording's worst-channel NRMSE, linear against the joint's model (its ``fit``).

    Parameters
    ----------
    location : JointLocation, or the joint finding read as one (``between``, ``law``, ``location``, ``detected``)
    model : StructureModel or None
    title : a title above the panels

    Returns
    -------
    matplotlib Figure
    """
    from ..plots import pyplot

    plt = pyplot()
    fitted = model is not None and model.joint is not None and bool(model.fit)
    fig, axes = plt.subplots(1, 3 if fitted else 2, figsize=(15.5 if fitted else 11, 3.8),
                             gridspec_kw={"width_ratios": [1.1, 1.0, 1.0] if fitted else [1.1, 1.0]})
    _draw_sensors(axes[0], location)
    _draw_evidence(axes[1], location)
    if fitted:
        _draw_fit_table(axes[2], model.fit)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig


def _draw_sensors(ax, location):
    """The sensors in a row above the ground, the joint between its two, equally supported places dashed."""
    sensors = sorted({c for e in location.location for c in e["between"] if c != "ground"},
                     key=lambda c: (len(c), c))
    x = {c: float(i) for i, c in enumerate(sensors)}

    def ends(pair):
        a, b = pair
        return (x[a], 1.0), ((x[a] + 0.25, 0.0) if b == "ground" else (x[b], 1.0))

    ax.axhline(0.0, color="0.3", lw=2)
    ax.fill_between([-0.6, len(sensors) - 0.4], -0.15, 0.0, color="0.85", hatch="///", lw=0)
    for e in location.location[1:]:
        if e["delta_bic"] <= 10.0:
            (x0, y0), (x1, y1) = ends(e["between"])
            ax.plot([x0, x1], [y0, y1 + (0.25 if y1 == 1.0 else 0)], "--", color="tab:orange", lw=1.5)
    if location.detected:
        (x0, y0), (x1, y1) = ends(location.between)
        t = np.linspace(0, 1, 41)
        zig = 0.06 * np.sign(np.sin(2 * np.pi * 6 * t)) * (t > 0.15) * (t < 0.85)
        arc = 0.35 if y1 == 1.0 else 0.0
        ax.plot(x0 + (x1 - x0) * t, y0 + (y1 - y0) * t + arc * np.sin(np.pi * t) + zig, color="tab:red", lw=2.5,
                label=f"joint ({location.law})")
        ax.legend(loc="lower right", fontsize=8)
    ax.scatter([x[c] for c in sensors], [1.0] * len(sensors), s=260, color="tab:blue", zorder=3)
    for c in sensors:
        ax.annotate(c, (x[c], 1.0), xytext=(0, -22), textcoords="offset points", ha="center", fontsize=9)
    ax.set_xlim(-0.6, len(sensors) - 0.4)
    ax.set_ylim(-0.2, 1.6)
    ax.axis("off")
    ax.set_title("where the joint acts" if location.detected else "no joint: one linear structure explains every level")


def _draw_evidence(bx, location):
    """ΔBIC of every place to the best, the best in red; places weighed with the mode shapes' inputs marked (their
    ΔBIC is among themselves, `choice.weighed`)."""
    rows = location.location[::-1]
    labels = [" – ".join(e["between"]) + (" ◆" if e.get("inputs") == "reciprocal" else "") for e in rows]
    values = [max(e["delta_bic"], 0.0) + 1.0 for e in rows]
    colors = ["tab:red" if i == len(rows) - 1 and location.detected else "0.6" for i in range(len(rows))]
    bx.barh(labels, values, color=colors)
    bx.set_xscale("log")
    bx.set_xlabel("ΔBIC to the best place + 1 (lower is better)")
    bx.axvline(11.0, color="tab:orange", ls="--", lw=1, label="equally supported (ΔBIC ≤ 10)")
    weighed = [e for e in rows if e.get("inputs") == "reciprocal"]  # a `JointLocation` or its JSON's fields
    if weighed:
        bx.plot([], [], " ", label=f"◆ weighed with the mode shapes' inputs (through {weighed[-1]['driving_point']})")
    bx.legend(fontsize=8, loc="lower right")
    bx.tick_params(axis="y", labelsize=8)


def _draw_fit_table(cx, fit):
    """Each recording's worst-channel NRMSE, simulated from its force: the lowest level's linear model against the
    model with the joint."""
    files = [_file_label(f) for f in fit["files"]]
    lin = [max(r) for r in fit["linear"]]
    nl = [max(r) for r in fit["nonlinear"]]
    at = np.arange(len(files))
    cx.bar(at - 0.2, lin, 0.4, color="tab:blue", label="linear (lowest level)")
    cx.bar(at + 0.2, nl, 0.4, color="tab:red", label="with the joint")
    cx.set_yscale("log")
    cx.set_xticks(at, files, rotation=20, ha="right", fontsize=7)
    cx.set_ylabel("worst-channel NRMSE")
    cx.set_title("simulated from each recording's force", fontsize=10)
    cx.legend(fontsize=8)


def _file_label(source) -> str:
    """A recording's file without its folder and suffix; a realisation of it with its number (``lab #2``)."""
    from pathlib import Path

    name, _, rest = str(source).partition(" (realisation ")
    return f"{Path(name).stem} #{rest.rstrip(')')}" if rest else Path(name).stem


def prediction_figure(prediction, path, title: str = ""):
    """`draw_prediction` saved into ``path`` (its suffix sets the format); returns the Path."""
    from ..plots import save

    return save(draw_prediction(prediction, title), path)


def draw_prediction(prediction, title: str = ""):
    """Measured, linear and nonlinear responses of one recording (a `Prediction`): per channel, a second of the
    time history (top) and the spectrum of the whole record (bottom, log scale: what the model puts above the
    excited band, the harmonics, is seen there).

    Parameters
    ----------
    prediction : Prediction (with its signals)
    title : a title (default: the file and its NRMSE)

    Returns
    -------
    matplotlib Figure
    """
    from ..plots import pyplot

    plt = pyplot()
    names = list(prediction.channels)
    fig, axes = plt.subplots(2, len(names), figsize=(4.2 * len(names), 6.4), squeeze=False)
    fs = prediction.fs_hz or 1.0
    labels = ("measured", "linear", "with the joint")
    styles = (dict(color="0.2", lw=1.2), dict(color="tab:blue", lw=0.9, ls="--"), dict(color="tab:red", lw=0.9))
    for j, c in enumerate(names):
        sig = prediction.signals[c]
        n = sig.shape[1]
        show = slice(max(0, n // 2 - int(fs) // 2), min(n, n // 2 + int(fs) // 2))
        t = np.arange(n)[show] / fs
        freq = np.fft.rfftfreq(n, 1.0 / fs)
        for k, (label, style) in enumerate(zip(labels, styles)):
            axes[0, j].plot(t, sig[k][show], label=label, **style)
            axes[1, j].semilogy(freq, np.abs(np.fft.rfft(sig[k] - sig[k].mean())) / n + TINY, **style)
        axes[0, j].set_title(f"{c}: NRMSE {prediction.nrmse[j]:.3f} (linear {prediction.linear_nrmse[j]:.3f})",
                             fontsize=9)
        axes[0, j].set_xlabel("time [s]")
        axes[1, j].set_xlabel("frequency [Hz]")
        axes[1, j].set_xlim(0, min(fs / 2, 4 * _band_top(sig[0], fs)))
        if prediction.band_top_hz and prediction.above_band:  # where the force's band ends: beyond, the joint's
            axes[1, j].axvline(prediction.band_top_hz, color="0.5", lw=0.8, ls=":")
            axes[1, j].set_title(f"above {prediction.band_top_hz:.3g} Hz: measured "
                                 f"{prediction.above_band['measured'][j]:.3f}, missed "
                                 f"{prediction.above_band['nrmse'][j]:.3f}", fontsize=8)
    axes[0, 0].set_ylabel("acceleration")
    axes[1, 0].set_ylabel("|spectrum|")
    axes[0, 0].legend(fontsize=8)
    flag = " (extrapolated)" if prediction.extrapolated else ""
    fig.suptitle(title or f"{prediction.file}: force {prediction.level:.3g} N RMS{flag}", fontsize=10)
    fig.tight_layout()
    return fig


def _band_top(x, fs) -> float:
    """The frequency below which 99 % of a signal's power lies (to frame the spectrum with its harmonics)."""
    return band_top(x, fs, 0.99) if np.ptp(x) > 0 else fs / 8
