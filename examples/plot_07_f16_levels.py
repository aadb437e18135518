"""
The F-16 at four levels: how each resonance moves with the force
================================================================

The F-16 ground vibration test (J.P. Noël and M. Schoukens, "F-16 aircraft benchmark based on
ground vibration test data", 2017 Workshop on Nonlinear System Identification Benchmarks,
nonlinearbenchmark.org: cite it when you report results on it): a full multisine from 2 to 15 Hz
at four force levels on an aircraft whose wing-tip payload sits on a nonlinear mounting; a1 is on
the wing, a2 on the payload next to it.

`satmd.discover` detects the multisine from the force, estimates the FRFs at the excited lines,
judges the four levels together, finds the SATMD model not adequate and names no SATMD element:
one ``joint`` finding between the wing and the payload sensors (SPEC §11; the
:ref:`joint example <sphx_glr_auto_examples_plot_11_structure_joint.py>` reads all three accelerometers),
told per resonance (frequency and damping ratio at every level, with 95 % intervals, and their trends). ``python examples/f16_levels.py`` prints the full
table; ``benchmarks/f16_levels.py`` records it for the results page.

Real data are read from ``../shared/data/real/f16``; when that folder is absent the example says so
and stops.
"""

# %%
import warnings

import matplotlib.pyplot as plt
import numpy as np

import satmd
from satmd.io import load_recording
from satmd.signal import detect_excitation, estimate_frf
from satmd.io.shared import shared_dir

LEVELS = (1, 3, 5, 7)
CHANNELS = "force=Force,a1=Acceleration[2],a2=Acceleration[3]"  # the lab's own variable names

shared = shared_dir()  # ../shared beside the checkout, or $SATMD_SHARED
folder = shared / "data" / "real" / "f16" if shared else None
files = [folder / f"F16Data_FullMSine_Level{i}.mat" for i in LEVELS] if folder else []
recs = []
if not files or not all(f.is_file() for f in files):
    print("the F-16 files (../shared/data/real/f16) are not here: ../shared is absent")
else:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        recs = [load_recording(f, channel_map=CHANNELS) for f in files]
    exc = detect_excitation(recs[0])
    print(f"excitation detected: {exc.kind}, {exc.periods} periods of {exc.period_s:g} s, "
          f"{len(exc.lines)} excited lines")

# %%
# Discovery on the four levels together
# -------------------------------------
if recs:
    rep = satmd.discover(recs)
    nl = rep.nonlinear
    levels = [float(x) for x in nl.levels]
    print(f"force: {', '.join(f'{x:.1f}' for x in levels)} N RMS")
    print(f"SATMD model adequate: {rep.model_adequate}; findings: {', '.join(f['name'] for f in nl.findings)}")
    finding = next((f for f in nl.findings if f.get("modes")), None)
    modes = finding["modes"] if finding else []
    for m in modes:
        f, z = np.asarray(m["f_hz"]), 100 * np.asarray(m["zeta"])
        print(f"{f[0]:6.2f} Hz: f {f[-1] / f[0] - 1:+.1%} from the lowest to the highest level ({m['trend']}), "
              f"damping ratio {z[0]:.2f} % -> {z[-1]:.2f} % ({m['damping_trend']})")

# %%
# The FRFs per level, and each resonance against the force
# --------------------------------------------------------
if recs:
    frfs = [estimate_frf(r) for r in recs]
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(levels)))
    fig, axes = plt.subplots(2, 1, figsize=(9, 6.5))
    for lev, d, c in zip(levels, frfs, colours):
        axes[0].semilogy(d.freq_hz, np.abs(d.channels["a1"]), color=c, lw=0.8, label=f"{lev:.1f} N RMS")
    for m in modes:
        axes[0].axvspan(min(m["f_hz"]), max(m["f_hz"]), color="0.88", zorder=0)
    axes[0].set_xlabel("frequency [Hz]  (grey: where each resonance moves)")
    axes[0].set_ylabel("|A1| [m/s² / N]")
    axes[0].legend(fontsize=8, ncol=4)
    for m in modes:
        f = np.asarray(m["f_hz"])
        err = np.abs(np.asarray(m["f_ci95"]) - f[:, None]).T / f[0] * 100
        axes[1].errorbar(levels, 100 * (f / f[0] - 1), yerr=err, marker="o", ms=3, capsize=2,
                         label=f"{f[0]:.2f} Hz")
    axes[1].set_xlabel("force [N RMS]")
    axes[1].set_ylabel("frequency change [%]")
    axes[1].legend(fontsize=7, ncol=4)
    axes[1].grid(alpha=0.3)
    fig.tight_layout()
