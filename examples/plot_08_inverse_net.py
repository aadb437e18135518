"""
The amortized inverse and its calibration
=========================================

`satmd.InverseModel` maps the two acceleration FRFs (a1, a2) of the paper's rig straight to the
shunt's R and L, with a standard deviation, in a millisecond: the amortized inverse of the paper's
use case II. The ``physics`` kind is a deep ensemble of the paper's network trained through the
forward model (the eq. 22 loss); its std combines the ensemble spread with the effect of the input
noise, scaled on validation pairs held out within the one training (``calibration="crossfit"``).

This example trains an ensemble of 3 members (the default has 5) on the paper preset at 1 % noise,
on one core (under a minute), predicts the six blind pairs of the paper's Table 2 and checks the
calibration on 246 held-out FRFs: the share of errors within 2σ should be near 95 %.
The full ablation (4 kinds × 4 noise levels × 2 presets) is ``python benchmarks/inverse.py``.
"""

# %%
import matplotlib.pyplot as plt
import numpy as np
import torch

from satmd import InverseModel
from satmd.inverse import BLIND_PAIRS, PAPER_TABLE2_MAE, evaluate, pairs_dataset

torch.set_num_threads(1)
torch.manual_seed(0)
model = InverseModel("physics", "paper", noise=0.01, n_members=3, verbose=False).fit()
info = model.fit_info_
print(f"trained in {info['train_s']:.0f} s; validation MAE R {info['val_mae'][0]:.3g} Ω, L {info['val_mae'][1]:.3g} H")

# %%
# The six blind pairs (noise-free)
# --------------------------------
blind = evaluate(model)
for (R, L), r, rs, lh, ls in zip(BLIND_PAIRS, blind["R"], blind["R_std"], blind["L"], blind["L_std"]):
    print(f"R {R:5.1f} Ω -> {r:7.3f} ± {rs:.3f};   L {L:.3f} H -> {lh:.4f} ± {ls:.4f}")
print(f"MAE R {blind['mae_R']:.3f} Ω, L {blind['mae_L']:.2e} H "
      f"(the paper's net: {PAPER_TABLE2_MAE['R']} Ω, {PAPER_TABLE2_MAE['L']:.2e} H)")

# %%
# Calibration: are the standard deviations right?
# -----------------------------------------------
# 246 FRFs never seen in training (the six blind pairs and 40 neighbours of each) at the training
# noise, each carrying its std as a measured FRF would.
test = pairs_dataset(BLIND_PAIRS, per_pair=40, seed=1000)
res = evaluate(model, test, noise=0.01)
print(f"{res['n']} FRFs at 1 % noise: 2σ coverage R {res['coverage_R']:.0%}, L {res['coverage_L']:.0%} "
      f"(95 % for a calibrated std)")

fig, axes = plt.subplots(1, 2, figsize=(9, 3.8))
for ax, k, unit in zip(axes, ("R", "L"), ("Ω", "H")):
    z = (np.asarray(res[k]) - np.asarray(res[f"{k}_true"])) / np.asarray(res[f"{k}_std"])
    ax.hist(z, bins=np.linspace(-5, 5, 41), density=True, color="tab:blue", alpha=0.7, label="error / std")
    x = np.linspace(-5, 5, 200)
    ax.plot(x, np.exp(-x ** 2 / 2) / np.sqrt(2 * np.pi), "k", lw=1, label="standard normal")
    ax.axvspan(-2, 2, color="0.9", zorder=0)
    ax.set_title(f"{k} [{unit}]: {np.mean(np.abs(z) <= 2):.0%} within 2σ", fontsize=10)
    ax.set_xlabel("standardised error")
axes[0].legend(fontsize=8)
fig.tight_layout()
