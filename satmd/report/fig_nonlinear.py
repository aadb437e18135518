"""Figure: the linear and the nonlinear model per drive level (issue 27 item 3, "show the fit improve").

>>> out = compare_models(train, held_out, "cubic_absorber_spring")      # doctest: +SKIP
>>> nonlinear_comparison_figure(out, "fit_improves.png")                 # doctest: +SKIP
"""
from __future__ import annotations

from ..conventions import TINY

from pathlib import Path

import numpy as np

from ..errors import DataError
from ..plots import pyplot, save

COLORS = {"linear": "tab:gray", "nonlinear": "tab:blue"}


def _rows(comparison) -> list:
    rows = comparison.get("levels") if isinstance(comparison, dict) else comparison
    if not rows:
        raise DataError("nonlinear_comparison_figure needs the output of compare_models (its 'levels' rows)")
    for i, r in enumerate(rows):
        for key in ("level", "td_error", "frf_residual"):
            if key not in r:
                raise DataError(f"nonlinear_comparison_figure: level row {i} has no {key!r} (not from compare_models?)")
    return sorted(rows, key=lambda r: r["level"])


def nonlinear_comparison_figure(comparison, path=None, title: str = ""):
    """Per drive level: FRF residual and time-domain error of the linear and the nonlinear model.

    Left: the relative FRF residual (H1 of each model's simulated response against the measured
    H1, over the excited band). Right: the relative time-domain error where the response is excited (the
    headline of `compare_models`); levels held out of the fit are marked "held out" (a
    prediction), the others were fitted. Bars are on a log scale; the ratio linear / nonlinear
    is written above each pair.

    Parameters
    ----------
    comparison : dict from `satmd.identification.nonlinear.compare.compare_models` (or its
        ``levels`` list).
    path : PNG/SVG/PDF file to write (None: return the figure unsaved).
    title : figure title (default: the nonlinear model's name).

    Returns
    -------
    pathlib.Path or matplotlib.figure.Figure
        The file written, or the figure when ``path`` is None.
    """
    rows = _rows(comparison)
    if not title and isinstance(comparison, dict):
        title = f"linear vs {comparison.get('nonlinear', {}).get('model', 'nonlinear')} model, per drive level"
    plt = pyplot()
    fig, axes = plt.subplots(1, 2, figsize=(10.0, 3.8))
    x = np.arange(len(rows))
    labels = [f"{r['level']:.3g} N" + ("\nheld out" if r.get("held_out") else "\nfitted") for r in rows]
    panels = (("frf_residual", "FRF residual (relative)"), ("td_error", "time-domain error where the response is excited"))
    for ax, (key, ylabel) in zip(axes, panels):
        for k, model in enumerate(("linear", "nonlinear")):
            vals = np.array([max(float(r[key][model]), 1e-12) for r in rows])
            ax.bar(x + (k - 0.5) * 0.38, vals, width=0.38, color=COLORS[model], label=model)
        for i, r in enumerate(rows):
            lin, nl = float(r[key]["linear"]), float(r[key]["nonlinear"])
            ax.annotate(f"{lin / max(nl, TINY):.1f}×", (x[i], max(lin, nl)), ha="center", va="bottom", fontsize=8)
            if r.get("held_out"):
                ax.axvspan(x[i] - 0.5, x[i] + 0.5, color="tab:orange", alpha=0.08, lw=0)
        ax.set_yscale("log")
        ax.set_xticks(x)
        ax.set_xticklabels(labels, fontsize=8)
        ax.set_ylabel(ylabel)
        ax.grid(True, axis="y", which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path is None:
        return fig
    return save(fig, Path(path))
