"""Report section: use case III, explaining the inverse net and distilling FRF descriptors."""
from __future__ import annotations

import os
from pathlib import Path

ORDER = 40
TITLE = "Use case III: attribution, physical sensitivity, latent map and symbolic distillation"

#: A model folder written by `satmd inverse train` (or by this section, as a cache).
MODEL_ENV = "SATMD_MODEL_DIR"
#: The net trained here when no model folder is given (the quick variant only shows the pipeline works).
TRAIN = {"epochs": 60, "warm_start_epochs": 20, "samples_per_pair": 60, "n_members": 2, "mc_samples": 16}
TRAIN_QUICK = {"epochs": 4, "warm_start_epochs": 2, "samples_per_pair": 8, "n_members": 1, "mc_samples": 4}


def _model(ctx):
    """(model, provenance) or (None, reason) when no net can be had."""
    try:
        import torch

        from ...inverse import InverseModel
    except ImportError as exc:
        return None, f"The neural analyses are skipped: the inverse package is not available ({exc})."
    torch.set_num_threads(1)
    shared = ctx.shared.get("physics_paper_model")
    if shared is not None:  # trained by the use case II section of this same run
        return shared, "The physics net of the use case II section above (same run)."
    cache = os.environ.get(MODEL_ENV)
    if cache and (Path(cache) / "model.json").is_file():
        model = InverseModel.load(cache)
        return model, f"Model loaded from `{cache}` (${MODEL_ENV}): kind {model.kind}."
    kw = TRAIN_QUICK if ctx.quick else TRAIN
    model = InverseModel("physics", "paper", verbose=False, seed=0, **kw).fit()
    note = (f"A physics net trained here ({kw['n_members']} member(s), {kw['epochs']} epochs, "
            f"{kw['samples_per_pair']} samples per pair, {model.fit_info_['train_s']:.0f} s)")
    if cache:
        model.save(cache)
        note += f", saved to `{cache}` for the next run"
    if ctx.quick:
        note += "; quick run: the net is barely trained, the numbers only show that the pipeline works"
    return model, note + "."


def build(ctx) -> str:
    from ...explain.run import neural_analysis, symbolic_analysis
    from ..explain_text import neural_markdown, symbolic_markdown

    parts = ["The paper's use case III, and the comparisons its discussion asks for: neural attribution against "
             "the physical sensitivity of the forward model, the R/L disentanglement test of the latent, and "
             "symbolic distillation of ξ_FRF and of physically direct descriptors.", ""]
    model, note = _model(ctx)
    parts += [note, ""]
    if model is not None:
        neural = neural_analysis(model, quick=ctx.quick)
        ctx.results["explain_neural"] = neural.to_dict()
        parts.append(neural_markdown(neural, ctx.figure))
    sym = symbolic_analysis(quick=ctx.quick, modal=not ctx.quick)
    md, res = symbolic_markdown(sym, ctx.figure), sym.to_dict()
    ctx.results["explain_symbolic"] = {
        "paper_formula": res["paper_formula"], "paper_reported": res["paper_reported"],
        "xi": {k: res["xi"][k] for k in ("expression", "complexity", "r2_train", "r2_test", "mae_train",
                                         "mae_test", "seconds")},
        "best_within_30": res["best_within_30"],
        "sindy": {d: {k: s[k] for k in ("complexity", "r2_test")} for d, s in res["sindy"].items()},
    }
    parts.append(md)
    return "\n".join(parts)
