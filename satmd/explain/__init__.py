"""Use case III: explaining the inverse model and distilling FRF descriptors (SPEC §6).

>>> from satmd.explain import attribution, physical_sensitivity, agreement, latent_map
>>> from satmd.explain import xi_dataset, modal_descriptors, distill

Neural analyses (need torch and a trained net, e.g. ``InverseModel.load(dir)``):

- `latent_map(model, data)`: PCA of the 64-d latent, linear probe, R/L sweeps
  and the angle between their latent directions (disentanglement test);
- `attribution(model, frfs)`: S_R(f), S_L(f) (eq. 26); ``.table3()`` gives
  the paper's Table 3 statistics and the peak locations.

Physics (NumPy only):

- `physical_sensitivity(rig, freq)`: |∂A/∂R|, |∂A/∂L| per frequency from the
  analytic Jacobian, normalised like the attribution; `agreement` compares
  the two per case (cosine, Spearman); `chain_rule_check` tests G J = I;
- `xi_frf`, `xi_dataset` (eq. 27 and the SPEC §6 grid), `modal_descriptors`
  (resonances, splitting, anti-resonance, peak attenuation);
- `grid_anova(X, y)`: main-effect and two-way shares of a descriptor over a
  full-factorial grid, i.e. what additive or pairwise formulas can reach;
  `structure_ceiling(X, y, products, linear)`: the most any formula of a given
  sum-of-products structure can reach, whatever the shapes of its factors.

The contract a model must follow is `ExplainableModel` (a typing.Protocol;
`satmd.inverse.InverseModel` follows it). `satmd.explain.run` computes the
whole use case as typed results; `satmd.report.explain_text` formats them.

Symbolic distillation: `distill(X, y, backend="hybrid"|"skeleton"|"operon"|"pysr"|"sindy")`
(needs sympy; its names are imported on first use, so ``import
satmd.explain`` works with NumPy/SciPy alone). The skeleton pass is
`satmd.explain.skeletons` (the family), `skeleton_search` (the beam) and
`varpro` (the constants).
"""
from .anova import GridAnova, grid_anova, structure_ceiling
from .attributions import BLIND_CASES, PAPER_TABLE3, Attribution, attribution, peak_frequencies, table3_stats
from .contract import ExplainableModel
from .descriptors import NOMINAL, XI_GRID, DescriptorData, modal_descriptors, modal_physics, xi_dataset, xi_frf
from .distillation import DistillResult, distill, paper_formula_result
from .latent import LatentMap, latent_map
from .sensitivity import PhysicalSensitivity, agreement, chain_rule_check, physical_sensitivity

# sympy-backed names, imported on first use
_LAZY = {"node_count": "symbolic", "paper_complexity": "symbolic", "PAPER_FORMULA": "symbolic",
         "PAPER_METRICS": "symbolic"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        return getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")

__all__ = [
    "latent_map", "LatentMap", "attribution", "Attribution", "table3_stats", "peak_frequencies", "PAPER_TABLE3",
    "BLIND_CASES", "physical_sensitivity", "PhysicalSensitivity", "agreement", "chain_rule_check", "xi_frf",
    "xi_dataset", "modal_descriptors", "modal_physics", "DescriptorData", "NOMINAL", "XI_GRID", "distill", "DistillResult",
    "paper_formula_result", "grid_anova", "GridAnova", "structure_ceiling", "ExplainableModel", "node_count", "paper_complexity", "PAPER_FORMULA", "PAPER_METRICS",
]
