"""Silverbox: fit a cubic-stiffness oscillator on the multisine, predict the arrow (issue 27 item 5).

    python examples/silverbox.py [path/to/SNLS80mV.mat]

The Silverbox (Wigren & Schoukens 2013) is an electronic Duffing oscillator. A single-mode model
ÿ + cẏ + ky + k2z² + k3z³ = g·u(t − τ), z = y − λẏ (a small lag λ of the nonlinear force),
observed as y + y0, is fitted by simulation output error
on the first 75 % of the multisine part of the record, then predicts the "arrow" (filtered noise
of growing amplitude, the first 40 000 samples) from rest. The linear model is the output-error
fit the nonlinear fit starts from. `benchmarks/silverbox.py` runs the same and records the figures.
"""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.io import loadmat

from satmd.identification.oscillator import fit_oscillator, rms_error
from satmd.io.shared import shared_dir

MAT = Path(sys.argv[1]) if len(sys.argv) > 1 else (shared_dir() or Path("../shared")) / "data" / "real" / "silverbox" / "SNLS80mV.mat"
FS = 610.35                     # Hz (10 MHz / 2^14)
FIT = (40650, 40650 + 65062)    # the first 75 % of the multisine part (nonlinear_benchmarks split)
ARROW = (100, 40575)            # the arrow; 50 samples of start-up are not scored
IN_RANGE = 32000                # the arrow's first 32 000 samples stay within the multisine's amplitude


def main():
    if not MAT.exists():
        sys.exit(f"{MAT} not found: pass the path of SNLS80mV.mat")
    d = loadmat(MAT)
    u, y = d["V1"].ravel().astype(float), d["V2"].ravel().astype(float)
    fit = fit_oscillator(u, y, FS, ranges=[FIT], lag=True)
    print(fit.report())
    ua, ya = u[ARROW[0]:ARROW[1]], y[ARROW[0]:ARROW[1]]
    preds = {"linear": fit.predict(ua, linear=True), "nonlinear": fit.predict(ua)}
    print(f"\narrow: output RMS {1e3 * np.sqrt(np.mean(ya[50:] ** 2)):.2f} mV")
    for name, yp in preds.items():
        full, inr = rms_error(yp, ya, 50), rms_error(yp, ya, 50, IN_RANGE)
        print(f"  {name:>9s}: full {1e3 * full['rms']:.3f} mV ({full['pct']:.3f} %), "
              f"within the fit's amplitude {1e3 * inr['rms']:.3f} mV ({inr['pct']:.3f} %)")
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return
    t = np.arange(ua.size) / FS
    fig, ax = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    ax[0].plot(t, 1e3 * ya, lw=0.3, color="k")
    ax[0].set_ylabel("measured output [mV]")
    for name, yp in preds.items():
        ax[1].plot(t, 1e3 * (yp - ya), lw=0.3, label=name)
    ax[1].axvline(IN_RANGE / FS, color="grey", ls="--")
    ax[1].set_ylabel("simulation error [mV]")
    ax[1].set_xlabel("time [s]")
    ax[1].legend()
    out = Path("silverbox_arrow.png")
    fig.savefig(out, dpi=120, bbox_inches="tight")
    print(f"figure: {out}")


if __name__ == "__main__":
    main()
