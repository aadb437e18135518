"""
A structure that is not a SATMD rig: the model is not adequate
==============================================================

Discovery names missing physics only when the SATMD model, with its vocabulary effects, can
describe the data at all. Here the data are a measured accelerance of a beam (three files of the
shared data, ``../shared/data/real/meas_point_*.txt``: 1001 complex values from 0 to 1000 Hz,
third-party measurements from the pyuff repository). The best SATMD fit reproduces little of them:
``model_adequate`` is false, the reason is named, and no effect is reported.

The beam's own modes come from `satmd.modal.fit_modes`, which fits any number of modes.
Real data are read from ``../shared``; when that folder is absent the example says so and stops.
"""

# %%
import warnings

import matplotlib.pyplot as plt
import numpy as np

from satmd import discover, load_frf
from satmd.modal import fit_modes
from satmd.io.shared import shared_dir

shared = shared_dir()  # ../shared beside the checkout, or $SATMD_SHARED
path = shared / "data" / "real" / "meas_point_1.txt" if shared else None
beam = None
if path is None or not path.is_file():
    print("the beam FRF (../shared/data/real/meas_point_1.txt) is not here: ../shared is absent")
else:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "dropped 1 point at f <= 0 Hz": FRFs are used for f > 0
        beam = load_frf(path, freq_axis="0:1")  # one complex value per line, 0 Hz in steps of 1 Hz
    print(f"{path.name}: {len(beam)} points, {beam.freq_hz[0]:g}-{beam.freq_hz[-1]:g} Hz, "
          f"channels {list(beam.channels)}")

# %%
# Discovery: not adequate
# -----------------------
if beam is not None:
    rep = discover(beam)
    doc = rep.to_dict()
    print(f"model_adequate: {doc['model_adequate']}")
    for reason in doc["adequacy_reasons"]:
        print(f"  {reason['kind']}: {reason['message']}")
    print(f"effects named: {doc['effects'] or 'none'}")

# %%
# What the structure is: its modes
# --------------------------------
if beam is not None:
    modal = fit_modes(None, beam)
    modes = sorted(modal.modes, key=lambda m: m.f_hz)
    for m in modes:
        print(f"mode at {m.f_hz:7.2f} Hz, damping ratio {100 * m.zeta:.2f} %")

    fig, ax = plt.subplots(figsize=(8, 4))
    ax.semilogy(beam.freq_hz, np.abs(beam.channels["a1"]), "k", lw=0.8, label="measured beam")
    best = rep.nominal_fit.prediction()
    ax.semilogy(best.freq_hz, np.abs(best.channels["a1"]), color="tab:orange", lw=1.0,
                label="best SATMD fit (not adequate)")
    for m in modes:
        ax.axvline(m.f_hz, color="0.8", lw=0.8, zorder=0)
    ax.set_xlabel("frequency [Hz]  (grey: the beam's modes)")
    ax.set_ylabel("|A| [m/s² / N]")
    ax.legend(fontsize=8)
    fig.tight_layout()
