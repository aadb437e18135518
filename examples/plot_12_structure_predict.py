"""
The F-16's joint modelled, and a level it never saw predicted
=============================================================

`satmd.structure.fit_structure` takes recordings of a structure at several levels, the place and law of its
joint (`locate_joint` finds them when they are not given: between the wing, ``acc2``, and the payload,
``acc3``, on the F-16), and fits the structure's linear part and the joint's force law on every level at once,
simulating each recording in time from its measured force. The model then predicts a level it was not fitted
on: here levels 1, 3 and 7 fit it and level 5 judges it, channel by channel (NRMSE: the RMS of the error over
the RMS of the measured response), beside the linear model of the lowest level.

The F-16 benchmark: J.P. Noël and M. Schoukens, "F-16 aircraft benchmark based on ground vibration test data",
2017 Workshop on Nonlinear System Identification Benchmarks (nonlinearbenchmark.org); cite it when you report
results on it. The fit takes about a quarter of a minute here; `benchmarks/structures_predict.py` measures it on
simulated chains as well.

Real data are read from ``../shared/data/real/f16``; when that folder is absent the example says so and stops.
"""

# %%
import warnings

from satmd.io import load_recording
from satmd.io.shared import shared_dir
from satmd.structure import fit_structure

CHANNELS = "force=Force,a1=Acceleration[1],a2=Acceleration[2],a3=Acceleration[3]"

shared = shared_dir()  # ../shared beside the checkout, or $SATMD_SHARED
folder = shared / "data" / "real" / "f16" if shared else None
files = {i: folder / f"F16Data_FullMSine_Level{i}.mat" for i in (1, 3, 5, 7)} if folder else {}
here = bool(files) and all(f.is_file() for f in files.values())
if not here:
    print("the F-16 files (../shared/data/real/f16) are not here: ../shared is absent")
else:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "ignored variable(s) Voltage"
        recs = {i: load_recording(f, channel_map=CHANNELS) for i, f in files.items()}
    model = fit_structure([recs[1], recs[3], recs[7]], between=("acc2", "acc3"), law="friction",
                          files=["level 1", "level 3", "level 7"])
    print(model.report())
    held = model.predict(recs[5], file="level 5")
    print(held.report())
    held.plot("f16_level5.png")

# %%
# Level 5, which the model never saw: the measured response, the linear model of level 1 and the model with
# the joint, a second of each channel (top) and the spectra of the whole record (bottom, log scale: above
# 15 Hz, where the force puts nothing, the response the joint makes).
if here:
    import matplotlib.image as mpimg
    import matplotlib.pyplot as plt

    plt.figure(figsize=(12.6, 6.4))
    plt.imshow(mpimg.imread("f16_level5.png"))
    plt.axis("off")
    plt.show()
