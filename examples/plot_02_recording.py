"""
A recording and its measurement findings
========================================

A random-excitation test gives time signals, not FRFs: force and two accelerations, the rig at
rest at the start, noise on every channel (the force too). satmd turns the recording into FRFs
with a standard deviation at every point, and keeps what the measurement chain does to the data
apart from the physics.

Here a 120 s recording of the paper's rig (1 kHz, random force 20-200 Hz, 1 % noise on the force,
2 % on the accelerometers) is estimated twice:

- by the local polynomial method, satmd's default: no window, full 1/T resolution, leakage and
  start-up transient removed, std from the recording's own noise;
- by Welch H1 (Hann window, about 0.5 Hz), the textbook estimate, whose window smears the lightly
  damped first resonance.

Both go through identification and discovery. Nothing is missing from this rig's physics: the
first estimate says so; the second estimate's bias comes back as a *measurement* finding, with the
setting that removes it, never as physics.
"""

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from satmd import Rig, discover, frf, identify
from satmd.io import load_recording, save_recording
from satmd.signal import detect_excitation, estimate_frf
from satmd.simulation import simulate_recording

truth = Rig()
rec = simulate_recording(120.0, 1000.0, truth, noise=0.02, force_noise=0.01, seed=1)
rec = load_recording(save_recording(rec, Path(tempfile.mkdtemp()) / "rec.csv"))  # through the file
exc = detect_excitation(rec)
print(f"{rec.duration_s:g} s at {rec.fs_hz:g} Hz, channels {', '.join(rec.channels)}; "
      f"excitation detected from the force: {exc.kind}")

# %%
# Two estimates, two fits, two discovery reports
# ----------------------------------------------
estimates = {"local polynomial method (default)": estimate_frf(rec),
             "Welch H1, Hann": estimate_frf(rec, estimator="H1")}
for label, est in estimates.items():
    fit = identify(est, warn=False)
    rep = discover(est)
    print(f"== {label}: {len(est)} points, {est.freq_hz[0]:.1f}-{est.freq_hz[-1]:.1f} Hz")
    print("   " + ", ".join(f"{p} {fit.values[p]:.5g} (true {getattr(truth, p):.5g})" for p in ("m2", "kp", "R", "L")))
    print(f"   reduced chi-square {fit.chi2_reduced:.2f}; physics missing: {', '.join(rep.effect_names) or 'none'}")
    for m in rep.measurement:
        print(f"   measurement finding {m['name']}: {m['explanation']}\n     remedy: {m['remedy']}")

# %%
# The first resonance, where the window does its harm
# ---------------------------------------------------
fig, ax = plt.subplots(figsize=(7, 4))
band = (44.0, 58.0)
f_true = np.linspace(*band, 400)
ax.semilogy(f_true, np.abs(frf(f_true, truth).a1), "k", lw=1.2, label="true rig")
for (label, est), style in zip(estimates.items(), ("o", "s")):
    keep = (est.freq_hz >= band[0]) & (est.freq_hz <= band[1])
    ax.errorbar(est.freq_hz[keep], np.abs(est.channels["a1"][keep]), yerr=est.std["a1"][keep], fmt=style,
                ms=3, lw=0.6, capsize=1.5, label=label)
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|A1| [m/s² / N]")
ax.set_title("first resonance: estimates with their std against the true FRF", fontsize=10)
ax.legend(fontsize=8)
fig.tight_layout()

# %%
# On the command line::
#
#     satmd simulate --time --duration 120 --fs 1000 --noise 0.02 --force-noise 0.01 --seed 1 -o rec.csv
#     satmd estimate-frf rec.csv -o frf.csv --plot frf.png
#     satmd discover rec.csv --json      # `estimator` and `measurement` blocks beside `effects`
