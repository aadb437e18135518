"""
A nonlinear rig: detected, named, modelled and tuned across levels
==================================================================

A hardening absorber spring (a cubic term, SPEC §8b) makes the rig's FRF depend on how hard it is
driven. A linear fit at one level would take it for an offset of kp, at another level for another
offset. satmd reports nonlinearity in its own block and never as a linear effect:

1. **detect and name**: `satmd.discover` on two recordings of the rig at 1 and 10 N RMS;
2. **model**: `~satmd.identification.fit_nonlinear` fits the element's coefficient with m2, kp, R
   and L to both recordings at once (time-domain output error), with a 95 % interval;
3. **tune across levels**: `satmd.tuning.nonlinear.tune_nonlinear` picks the R, L with the lowest
   worst-case peak over 1, 4 and 10 N by direct simulation, and says what tuning on the low-level
   linear model would cost.

Recordings of 16 s at 1024 Hz keep this example under a minute; the benchmark
(``benchmarks/nonlinear_model.py``) uses longer ones.
"""

# %%
import warnings

import matplotlib.pyplot as plt
import numpy as np

from satmd import Rig, discover, nonlinear_element, simulate
from satmd.identification import fit_nonlinear
from satmd.signal import estimate_frf
from satmd.tuning.nonlinear import tune_nonlinear

truth = Rig(m2=0.55, kp=1.2e5, R=30.0, L=0.07)
spring = nonlinear_element("cubic_absorber_spring", k3=2e11)  # N/m³: kp about +12 % at 10 N
levels = [1.0, 10.0]
recs = [simulate(rig=truth, time=True, nonlinear=[spring], level=lv, seed=i, duration_s=16.0, fs_hz=1024.0,
                 noise=0.01) for i, lv in enumerate(levels)]

# %%
# Detect and name
# ---------------
rep = discover(recs)
nl = rep.nonlinear
print(f"nonlinear: {nl.detected}; linear effects named: {rep.effect_names or 'none'}")
for f in nl.findings:
    print(f"{f['name']}: {f['explanation']}")
    print(f"  equivalent linear values, one per recording: {f['equivalent_linear']}")

# %%
# The two FRFs, estimated from the recordings: the absorber's resonance moves up with the level.
fig, ax = plt.subplots(figsize=(7, 3.8))
for lv, rec in zip(levels, recs):
    est = estimate_frf(rec)
    keep = (est.freq_hz > 30) & (est.freq_hz < 200)
    ax.semilogy(est.freq_hz[keep], np.abs(est.channels["a2"][keep]), lw=0.9, label=f"{lv:g} N RMS")
ax.set_xlabel("frequency [Hz]")
ax.set_ylabel("|A2| [m/s² / N]")
ax.set_title("absorber FRF at two drive levels", fontsize=10)
ax.legend()
fig.tight_layout()

# %%
# Model the element
# -----------------
# (The linear start comes from the lowest level's FRF; with 16 s recordings its estimate has few
# averages, which satmd says in a warning, silenced here.)
warnings.filterwarnings("ignore", message=".*averages.*")
fit = fit_nonlinear(recs, nl.findings[0]["name"], seconds=None)
lo, hi = fit.ci95["k3"]
print(f"k3 = {fit.values['k3']:.4g} N/m³, 95 % interval {lo:.4g}-{hi:.4g} (true 2e11)")
print(", ".join(f"{p} = {fit.values[p]:.5g} (true {getattr(truth, p):.5g})" for p in ("m2", "kp", "R", "L")))

# %%
# Tune across levels
# ------------------
res = tune_nonlinear(fit.rig, [fit.element], levels=[1, 4, 10], duration_s=10.0)
print(res.report())
