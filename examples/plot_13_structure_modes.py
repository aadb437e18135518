"""
A structure's FRFs and modes: every accelerometer, one set of poles
===================================================================

A ground vibration test's first answer is its modes: each one's frequency and damping, and how it moves the
structure's sensors. Here the F-16 at its lowest level (J.P. Noël and M. Schoukens, "F-16 aircraft benchmark
based on ground vibration test data", 2017 Workshop on Nonlinear System Identification Benchmarks,
nonlinearbenchmark.org: cite it when you report results on it), its three accelerometers read by their rows:
acc1 at the shaker, acc2 on the wing and acc3 on the payload, both next to the mounting.

`satmd.signal.estimate_frfs` estimates every sensor's FRF over the force as a rig's A1 is (here the mean over
steady periods of the multisine, at the excited lines); `satmd.modal.survey` fits them with one set of poles and
reads each mode's shape from its residues, mass-normalised through the sensor at the force's point. The command
line does the same: ``satmd estimate-frf FILE --channels all -o frfs.uff`` and ``satmd modes FILE --plot m.png``.

Real data are read from ``../shared/data/real/f16``; when that folder is absent the example says so and stops.
"""

# %%
import warnings

import matplotlib.pyplot as plt
import numpy as np

from satmd.io import load_recording
from satmd.io.shared import shared_dir
from satmd.modal import survey
from satmd.signal import estimate_frfs

CHANNELS = "force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]"  # the lab's own names

shared = shared_dir()  # ../shared beside the checkout, or $SATMD_SHARED
path = shared / "data" / "real" / "f16" / "F16Data_FullMSine_Level1.mat" if shared else None
frfs = None
if path is None or not path.is_file():
    print("the F-16 files (../shared/data/real/f16) are not here: ../shared is absent")
else:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        rec = load_recording(path, channel_map=CHANNELS)
    frfs = estimate_frfs(rec)
    print(f"{len(frfs.channels)} FRFs ({', '.join(frfs.channels)}), {frfs.freq_hz.size} lines "
          f"{frfs.freq_hz[0]:.3g}-{frfs.freq_hz[-1]:.3g} Hz, median coherence {np.median(frfs.coherence):.4f}")

# %%
# The modes, their shapes mass-normalised through the shaker's sensor
# -------------------------------------------------------------------
# The driving point is found from the residues: the sensor whose receptance modal constants (φ_o φ_d) are positive
# on every mode, as φ_d² is. The three sensors sit near one another and move in phase in every mode but a weak one
# at 12.4 Hz, where acc1 alone keeps its sign: the shaker's sensor, as the benchmark's description says.
if frfs is not None:
    found = survey(frfs.freq_hz, dict(zip(frfs.channels, frfs.frf)), dict(zip(frfs.channels, frfs.std)))
    print(f"driving point: {found.driving_point}")
    print(found.report())

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8, 7))
    fitted = found.fit.predict(frfs.freq_hz)
    for k, name in enumerate(frfs.channels):
        top.semilogy(frfs.freq_hz, np.abs(frfs[name]), color=f"C{k}", lw=0.8, label=name)
        top.semilogy(frfs.freq_hz, np.abs(fitted[name]), color=f"C{k}", lw=1.5, ls="--", alpha=0.7)
    top.set_xlabel("frequency [Hz]")
    top.set_ylabel("|acceleration / force| [m/s²/N]")
    top.set_title("measured (solid) and the modes' fit (dashed)")
    top.legend()
    x = np.arange(len(found.channels))
    for m, shape in zip(found.fit.modes, found.shapes):
        bottom.plot(x, shape, marker="o", label=f"{m.f_hz:.3g} Hz")
    bottom.axhline(0.0, color="k", lw=0.6)
    bottom.set_xticks(x, found.channels)
    bottom.set_ylabel("mass-normalised shape [1/√kg]")
    bottom.legend(fontsize=8, ncol=4)
    for ax in (top, bottom):
        ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    plt.show()
