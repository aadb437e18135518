"""
Where the F-16's joint acts: three accelerometers, four levels
==============================================================

A ground vibration test has one shaker and many accelerometers; the question its engineer asks is which
connection is nonlinear. The F-16 benchmark (J.P. Noël and M. Schoukens, "F-16 aircraft benchmark based on
ground vibration test data", 2017 Workshop on Nonlinear System Identification Benchmarks,
nonlinearbenchmark.org: cite it when you report results on it) has three: at the shaker (``acc1``), on the
wing next to the payload's mounting (``acc2``) and on the payload (``acc3``), at four levels of a
2-15 Hz multisine.

`satmd.structure.locate_joint` takes the lowest level as the linear reference and asks, for every pair of
sensors and every sensor to the ground, whether that pair's relative motion explains how the structure
changes with level (the nonlinear force as an input to the linear structure, on its own poles). The
benchmark's description puts the nonlinearity in the payload's mounting: between acc2 and acc3.

Real data are read from ``../shared/data/real/f16``; when that folder is absent the example says so and
stops.
"""

# %%
import warnings

from satmd.io import load_recording
from satmd.io.shared import shared_dir
from satmd.structure import locate_joint

CHANNELS = "force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]"  # every accelerometer

shared = shared_dir()  # ../shared beside the checkout, or $SATMD_SHARED
folder = shared / "data" / "real" / "f16" if shared else None
files = [folder / f"F16Data_FullMSine_Level{i}.mat" for i in (1, 3, 5, 7)] if folder else []
if not files or not all(f.is_file() for f in files):
    print("the F-16 files (../shared/data/real/f16) are not here: ../shared is absent")
else:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        recs = [load_recording(f, channel_map=CHANNELS) for f in files]
    loc = locate_joint(recs)
    print(loc.report())
    for place in loc.location:
        print(f"  {' - '.join(place['between']):16s} ΔBIC {place['delta_bic']:8.1f}  (best law there: {place['law']})")
    loc.plot("f16_joint.png", title="F-16, levels 1, 3, 5, 7: where the joint acts")

# %%
# The figure: the sensors with the joint drawn between the two whose relative motion explains the change
# with level, and the evidence (ΔBIC to the best place) for every place considered.
import matplotlib.image as mpimg  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402

if files and all(f.is_file() for f in files):
    plt.figure(figsize=(11, 3.8))
    plt.imshow(mpimg.imread("f16_joint.png"))
    plt.axis("off")
    plt.show()
