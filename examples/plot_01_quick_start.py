"""
Quick start: from an FRF file to R, L and the discovery report
==============================================================

A lab gives you a file of measured FRFs of a shunted piezoelectric tuned mass damper. satmd
fits the shunt's R and L and the absorber's m2 and kp to it, with uncertainties, then says
where the model is wrong and what physics it leaves out.

Here the "lab file" is simulated: the paper's rig with an absorber mass of 0.6 kg and a host
mode at 66 Hz that the SATMD model does not have, with 1 % noise, written as a
``satmd-frf v1`` CSV with std columns.
"""

# %%
# Write a file as a lab would give it
# -----------------------------------
import tempfile
from pathlib import Path

from satmd import Rig, discover, effect, identify, load_frf, save_frf, simulate

work = Path(tempfile.mkdtemp())
mode = effect("extra_mode", f_hz=66.0, zeta=0.01, mass_ratio=0.03)  # 3 % of the primary mass
data = simulate(rig=Rig(m2=0.6), effects=[mode], noise=(0.01, 0.002), seed=1)
path = save_frf(data, work / "rig.csv")
print(path.read_text().splitlines()[0])
print(f"{len(data)} frequencies, {data.freq_hz[0]:g}-{data.freq_hz[-1]:g} Hz, channels {list(data.channels)}")

# %%
# Identify m2, kp, R and L
# ------------------------
# A global fit: no start values are needed. The report is lmfit-style: values, standard
# deviations, correlations and the goodness of fit. Here it also warns that the nominal model does
# not fit within the noise: something is missing.
fit = identify(load_frf(path), warn=False)
print(fit.report())

# %%
# Discover what is missing
# ------------------------
# Discovery tests the residuals against the noise, fits every effect of its vocabulary on top of
# the free parameters and keeps what the data support (BIC). It finds the host mode and refits.
rep = discover(load_frf(path))
print(rep.report())

# %%
# The figure: measured FRFs, the nominal model and the augmented one, with the standardised
# residuals below and the mismatch band shaded.
fig = rep.figure()

# %%
# The same on the command line::
#
#     satmd identify rig.csv --ci --plot fit.png
#     satmd discover rig.csv --plot discovery.png     # --json for the report as JSON
