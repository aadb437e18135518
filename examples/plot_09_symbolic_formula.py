"""
A formula for the FRFs: symbolic distillation of ξ
==================================================

The paper's use case III ends with a formula: ξ_FRF (eq. 27), a scalar summary of the two
acceleration FRFs, written as a short expression of the rig's R, L, m2 and kp (z-scored as x0..x3),
within 20 nodes. `satmd.explain.distill` searches for one; its ``skeleton`` back end is a beam over
products of one to three factors plus linear terms, with the constants fitted by variable
projection.

The search here is cut down (a narrower beam, a 15 s cap on it) to stay under a minute; the
benchmark (``benchmarks/distill.py``, see the results page) runs the full hybrid search, operon
pooled with the skeleton pass, and compares six splits.
"""

# %%
import matplotlib.pyplot as plt
import numpy as np

from satmd.explain import PAPER_FORMULA, distill, paper_formula_result, xi_dataset

data = xi_dataset()  # the SPEC §6 grid of 6400 rigs, ξ computed from the forward model
X, y = data.X, data.targets["xi"]
print(f"{X.shape[0]} samples of {', '.join(data.names)} (x0..x3)")

# %%
# The paper's formula, refitted on the same split
# -----------------------------------------------
paper = paper_formula_result(X, y)
print(f"paper: {PAPER_FORMULA}\n  test R² {paper['r2_test']:.3f}, {paper['complexity']} nodes")

# %%
# A search within the same 20 nodes
# ---------------------------------
res = distill(X, y, backend="skeleton", names=data.names, max_complexity=20,
              beam=(8, 4), expand=12, keep=8, time_limit=15)
print(f"found: {res.expression}\n  test R² {res.r2_test:.3f}, {res.complexity} nodes, {res.seconds:.0f} s")

# %%
# The accuracy-complexity trade-off the search kept, and the fit on the test rows.
fig, axes = plt.subplots(1, 2, figsize=(10, 4))
front = [p for p in res.pareto if np.isfinite(p["r2_test"])]
axes[0].plot([p["complexity"] for p in front], [p["r2_test"] for p in front], "o-", label="Pareto front (search)")
axes[0].plot(paper["complexity"], paper["r2_test"], "s", color="tab:red", label="paper's formula")
axes[0].set_xlabel("nodes")
axes[0].set_ylabel("test R²")
axes[0].legend(fontsize=8)
rng = np.random.default_rng(0)
rows = rng.choice(len(y), 800, replace=False)
axes[1].plot(y[rows], res.predict(X[rows]), ".", ms=2, alpha=0.6)
lims = [y.min(), y.max()]
axes[1].plot(lims, lims, "k", lw=0.8)
axes[1].set_xlabel("ξ from the forward model")
axes[1].set_ylabel("ξ from the formula")
fig.tight_layout()
