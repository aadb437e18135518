"""
The Silverbox: a measured Duffing oscillator, fitted and predicted
==================================================================

The Silverbox (Wigren & Schoukens 2013) is an electronic circuit that behaves as a mass-spring-
damper with a cubic spring. It is not a SATMD rig: satmd fits it with its single-mode nonlinear
oscillator, `satmd.identification.oscillator.fit_oscillator`,

.. math:: \\ddot y + c\\dot y + k y + k_2 y^2 + k_3 y^3 = g\\,u(t - \\tau),

by simulation output error on the first 75 % of the multisine part of ``SNLS80mV.mat`` (the split
of the nonlinear_benchmarks package), then predicts the "arrow" (filtered noise of growing
amplitude) from rest. The linear model is the output-error fit the nonlinear fit starts from.
``benchmarks/silverbox.py`` records the same figures for the results page (it also fits the
variant with a lag of the nonlinear force, ``lag=True``).

Real data are read from ``../shared/data/real/silverbox``; when that folder is absent the example
says so and stops.
"""

# %%

import matplotlib.pyplot as plt
import numpy as np
from scipy.io import loadmat

from satmd.identification.oscillator import fit_oscillator, rms_error
from satmd.io.shared import shared_dir

FS = 610.35                    # Hz (10 MHz / 2^14)
FIT = (40650, 40650 + 65062)   # the first 75 % of the multisine part
ARROW = (100, 40575)           # the arrow; its first 50 samples (start-up) are not scored

shared = shared_dir()  # ../shared beside the checkout, or $SATMD_SHARED
mat = shared / "data" / "real" / "silverbox" / "SNLS80mV.mat" if shared else None
fit = None
if mat is None or not mat.is_file():
    print("SNLS80mV.mat (../shared/data/real/silverbox) is not here: ../shared is absent")
else:
    d = loadmat(mat)
    u, y = d["V1"].ravel().astype(float), d["V2"].ravel().astype(float)
    fit = fit_oscillator(u, y, FS, ranges=[FIT])
    print(fit.report())

# %%
# Predict the arrow from rest
# ---------------------------
if fit is not None:
    ua, ya = u[ARROW[0]:ARROW[1]], y[ARROW[0]:ARROW[1]]
    preds = {"linear": fit.predict(ua, linear=True), "cubic": fit.predict(ua)}
    print(f"arrow: output RMS {1e3 * np.sqrt(np.mean(ya[50:] ** 2)):.2f} mV")
    for name, yp in preds.items():
        err = rms_error(yp, ya, 50)
        print(f"  {name:>6}: RMS error {1e3 * err['rms']:.3f} mV ({err['pct']:.2f} % of the output RMS)")

    t = np.arange(ua.size) / FS
    fig, ax = plt.subplots(2, 1, figsize=(8, 5.5), sharex=True)
    ax[0].plot(t, 1e3 * ya, lw=0.3, color="k")
    ax[0].set_ylabel("measured output [mV]")
    for name, yp in preds.items():
        ax[1].plot(t, 1e3 * (yp - ya), lw=0.3, label=name)
    ax[1].set_ylabel("simulation error [mV]")
    ax[1].set_xlabel("time [s]")
    ax[1].legend()
    fig.tight_layout()
