"""Table 2, the ablation (kind x input noise x preset), the off-curve check and the loop speed-up.

Shared by ``benchmarks/inverse.py``, ``examples/uc2_inverse.py`` and the
``satmd reproduce`` section, so the three print the same measurements.

Test sets (fixed seeds, never seen in training):

- *blind*: the six blind pairs of Table 2 plus ``per_pair`` neighbours of each
  (R ± 1 Ω, L ± 0.005 H), i.e. interpolation between the paper's reference
  pairs, on the paper's R-L line;
- *off-curve*: ``OFF_CURVE_PAIRS`` (e.g. R = 10 Ω with L = 0.3 H) plus
  neighbours, far from that line.

Test inputs get the same relative noise level as the model was trained with
and carry its std, as a measured FRF would.
"""
from __future__ import annotations

import dataclasses
import platform
import time
from typing import Any

import numpy as np

from .dataset import BLIND_PAIRS, OFF_CURVE_PAIRS, PAPER_TABLE2, PAPER_TABLE2_MAE, pairs_dataset
from .evaluation import evaluate

NOISES = (0.0, 0.005, 0.01, 0.02)
PRESETS = ("paper", "box")
KINDS = ("physics", "supervised", "optimization", "hybrid")
METRICS = ("mae_R", "mae_L", "rel_R", "rel_L", "frf_error", "coverage", "coverage_R", "coverage_L",
           "infer_s_per_frf", "n")


def _summary(res: dict) -> dict:
    return {k: res[k] for k in METRICS}


def table2(model, noise: float = 0.0) -> dict:
    """The six blind pairs (noise-free by default) beside the paper's predictions."""
    res = evaluate(model, pairs_dataset(BLIND_PAIRS, freq_hz=model.freq_hz, rig=model.rig), noise=noise)
    rows = []
    for i in range(6):
        rows.append({"R": float(BLIND_PAIRS[i, 0]), "L": float(BLIND_PAIRS[i, 1]),
                     "R_pred": res["R"][i], "L_pred": res["L"][i], "R_std": res["R_std"][i], "L_std": res["L_std"][i],
                     "paper_R_pred": float(PAPER_TABLE2[i, 2]), "paper_L_pred": float(PAPER_TABLE2[i, 3])})
    return {"rows": rows, **_summary(res)}


def loop_speedup(preset: str = "paper", epochs: int = 3, loop_epochs: int = 2, n_loop: int | None = None,
                 seed: int = 0) -> dict:
    """Seconds per physics epoch: vectorised training vs a Python loop over samples.

    Same ensemble, same data, same eq. 22 objective with the Gauss-Newton
    preconditioner, same batch size. The vectorised trainer runs ``epochs``
    epochs, the loop ``loop_epochs`` full epochs (or ``n_loop`` samples,
    scaled to an epoch, for quick runs).
    """
    import torch

    from .model import InverseModel
    from .nets import EnsembleNet
    from .training import Scaler, per_sample_epoch, train_ensemble

    m = InverseModel("physics", preset)
    data = m.make_data()
    scaler = Scaler.fit(data.train.features())
    cfg = dataclasses.replace(m.train_config("physics"), epochs=epochs, warm_start_epochs=0, seed=seed, device="cpu")
    _, hist = train_ensemble(data.train, None, cfg, scaler, verbose=False)
    vec = float(np.mean(hist["epoch_s"]))
    net = EnsembleNet(m.n_members, generator=torch.Generator().manual_seed(seed))
    runs = [per_sample_epoch(net, data.train, scaler, batch_size=m.batch_size, max_samples=n_loop,
                             dtype=getattr(torch, m.twin_dtype))
            for _ in range(1 if n_loop else loop_epochs)]
    loop = float(np.mean(runs))
    return {"vectorised_epoch_s": vec, "per_sample_epoch_s": loop, "speedup": loop / vec, "n_train": len(data.train),
            "epochs_timed": epochs, "loop_epochs_timed": len(runs) if not n_loop else n_loop / len(data.train),
            "batch_size": m.batch_size, "n_members": m.n_members}


def run_ablation(kinds=KINDS, noises=NOISES, presets=PRESETS, per_pair: int = 40, off_per_pair: int = 8, seed: int = 0,
                 quick: bool = False, speedup: bool = True, log=print, model_kwargs: dict | None = None) -> dict:
    """Train and score every (kind, noise, preset) cell; returns a JSON-ready dict.

    ``hybrid`` reuses the ``physics`` nets of its cell (its training time is
    theirs); ``optimization`` trains nothing and is scored once per noise
    level (it does not depend on the preset).
    ``quick``: tiny training for smoke tests (numbers not meaningful).
    """
    import torch

    from .model import InverseModel

    model_kwargs = dict(model_kwargs or {})
    if quick:
        model_kwargs = {"epochs": 3, "warm_start_epochs": 1, "n_members": 2, "samples_per_pair": 8, "n_samples": 300,
                        "mc_samples": 8, **model_kwargs}
        per_pair, off_per_pair = min(per_pair, 1), min(off_per_pair, 1)
    blind = pairs_dataset(BLIND_PAIRS, per_pair=per_pair, seed=seed + 1000)
    off = pairs_dataset(OFF_CURVE_PAIRS, per_pair=off_per_pair, seed=seed + 2000)
    t_start = time.perf_counter()
    out: dict[str, Any] = {"schema": "satmd-inverse-ablation/1", "kinds": list(kinds), "noises": list(noises),
           "presets": list(presets), "per_pair": per_pair, "off_per_pair": off_per_pair, "n_test": len(blind),
           "n_off_curve": len(off),
           "quick": quick, "seed": seed, "model_kwargs": model_kwargs,
           "machine": {"cpu_count": __import__("os").cpu_count(), "torch_threads": torch.get_num_threads(),
                       "platform": platform.platform(), "torch": torch.__version__},
           "paper_table2_mae": PAPER_TABLE2_MAE, "cells": [], "table2": {}, "off_curve": []}
    opt_cache = {}
    for preset in presets:
        for noise in noises:
            nets = {}
            for kind in ("physics", "supervised"):
                if kind in kinds or (kind == "physics" and "hybrid" in kinds):
                    log(f"[inverse] train {kind:10s} preset={preset:5s} noise={noise:g}")
                    m = InverseModel(kind, preset, noise, seed=seed, verbose=False, **model_kwargs).fit()
                    nets[kind] = m
            for kind in kinds:
                cell = {"kind": kind, "preset": preset, "noise": noise}
                if kind == "optimization":
                    if noise not in opt_cache:
                        log(f"[inverse] score optimization noise={noise:g} ({len(blind)} global fits)")
                        opt_cache[noise] = _summary(evaluate(InverseModel("optimization").fit(), blind, noise, seed))
                    cell.update(opt_cache[noise], train_s=0.0, train_cpu_s=0.0)
                else:
                    base = nets["physics" if kind == "hybrid" else kind]
                    model = base
                    if kind == "hybrid":
                        model = _as_hybrid(base)
                    on = _summary(evaluate(model, blind, noise, seed))
                    cell.update(on)
                    info = base.fit_info_
                    cell.update(train_s=info["train_s"], train_cpu_s=info["train_cpu_s"],
                                val_coverage=info.get("val_coverage_2sd"),
                                warm_start_epochs=info.get("warm_start_epochs", 0))
                    if noise == 0:
                        if preset == "paper" and kind in ("physics", "hybrid", "supervised"):
                            out["table2"][kind] = table2(model)
                        oc = _summary(evaluate(model, off, noise, seed))
                        out["off_curve"].append({"kind": kind, "preset": preset, "on_curve": on, "off_curve": oc})
                out["cells"].append(cell)
                log(f"[inverse]   {kind:12s} MAE R {cell['mae_R']:.4g} Ω  L {cell['mae_L']:.3g} H  "
                    f"coverage {100 * cell['coverage']:.0f} %")
    if "physics" in kinds and "paper" in presets and 0.0 in noises:
        log("[inverse] physics without the Gauss-Newton preconditioner (paper, noise 0)")
        plain = InverseModel("physics", "paper", 0.0, seed=seed, verbose=False, precondition=False,
                             **model_kwargs).fit()
        out["plain_physics"] = {**_summary(evaluate(plain, blind, 0.0, seed)), "table2": table2(plain),
                                "train_s": plain.fit_info_["train_s"]}
    if speedup:
        log("[inverse] timing the per-sample training loop ...")
        out["speedup"] = loop_speedup("paper", epochs=1 if quick else 3, n_loop=50 if quick else None, seed=seed)
    out["total_s"] = time.perf_counter() - t_start
    return out


def _as_hybrid(physics_model):
    """A hybrid model sharing the trained nets of a physics model."""
    import copy

    h = copy.copy(physics_model)
    h.kind = "hybrid"
    return h


# --------------------------------------------------------------------- tables
def _fmt(x, spec):
    return "–" if x is None or (isinstance(x, float) and not np.isfinite(x)) else format(x, spec)


def table2_markdown(res: dict) -> str:
    kinds = [k for k in ("physics", "supervised", "hybrid") if k in res["table2"]]
    head = "| R [Ω] | L [H] | paper R̂ | paper L̂ | " + " | ".join(
        f"{k} R̂ ± σ | {k} L̂ ± σ" for k in kinds) + " |"
    lines = [head, "|" + "---|" * (4 + 2 * len(kinds))]
    rows = res["table2"][kinds[0]]["rows"]
    for i, r in enumerate(rows):
        cells = [f"{r['R']:g}", f"{r['L']:.3f}", f"{r['paper_R_pred']:.4f}", f"{r['paper_L_pred']:.5f}"]
        for k in kinds:
            q = res["table2"][k]["rows"][i]
            cells += [f"{q['R_pred']:.4f} ± {q['R_std']:.2g}", f"{q['L_pred']:.5f} ± {q['L_std']:.2g}"]
        lines.append("| " + " | ".join(cells) + " |")
    p = res["paper_table2_mae"]
    cells = ["**MAE**", "", f"{p['R']:.4f} Ω", f"{p['L']:.2e} H"]
    for k in kinds:
        t = res["table2"][k]
        cells += [f"{t['mae_R']:.2e} Ω", f"{t['mae_L']:.2e} H"]
    lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def ablation_markdown(res: dict) -> str:
    lines = ["| preset | noise | kind | MAE R [Ω] | MAE L [H] | rel R | rel L | FRF error | 2σ coverage | "
             "train [s] | infer [ms/FRF] |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in res["cells"]:
        train = "–" if c["kind"] == "optimization" else (
            f"{c['train_s']:.0f}" + (" (shared)" if c["kind"] == "hybrid" else ""))
        # noise-free least squares: error and std are both round-off, coverage means nothing
        lsq0 = c["kind"] in ("optimization", "hybrid") and c["noise"] == 0
        cov = "n/a" if lsq0 else f"{_fmt(100 * c['coverage'], '.0f')} %"
        lines.append(
            f"| {c['preset']} | {100 * c['noise']:g} % | {c['kind']} | {c['mae_R']:.3g} | {c['mae_L']:.3g} | "
            f"{100 * c['rel_R']:.3g} % | {100 * c['rel_L']:.3g} % | {c['frf_error']:.2g} | "
            f"{cov} | {train} | {1e3 * c['infer_s_per_frf']:.3g} |")
    return "\n".join(lines)


def off_curve_markdown(res: dict) -> str:
    lines = ["| trained on | kind | on-curve MAE R / L | off-curve MAE R / L | ratio R / L |", "|---|---|---|---|---|"]
    for o in res["off_curve"]:
        a, b = o["on_curve"], o["off_curve"]
        if max(a["rel_R"], a["rel_L"], b["rel_R"], b["rel_L"]) < 1e-9:
            ratio = "round-off"  # least squares: both errors at machine precision
        else:
            ratio = f"{b['mae_R'] / a['mae_R']:.2g} / {b['mae_L'] / a['mae_L']:.2g}"
        lines.append(f"| {o['preset']} | {o['kind']} | {a['mae_R']:.3g} Ω / {a['mae_L']:.3g} H | "
                     f"{b['mae_R']:.3g} Ω / {b['mae_L']:.3g} H | {ratio} |")
    return "\n".join(lines)


def headline(res: dict) -> str:
    """One line of figures (what the benchmark prints)."""
    parts = []
    t2 = res.get("table2", {})
    if "physics" in t2:
        parts.append(f"physics Table 2 MAE R {t2['physics']['mae_R']:.3g} Ω L {t2['physics']['mae_L']:.3g} H")
    if "hybrid" in t2:
        parts.append(f"hybrid {t2['hybrid']['mae_R']:.2g} Ω {t2['hybrid']['mae_L']:.2g} H")
    for c in res["cells"]:
        if c["kind"] == "physics" and c["preset"] == "paper" and c["noise"] == 0:
            parts.append(f"train paper {c['train_s']:.0f} s")
        if c["kind"] == "physics" and c["preset"] == "paper" and abs(c["noise"] - 0.01) < 1e-12:
            parts.append(f"coverage@1% {100 * c['coverage']:.0f} %")
    if "speedup" in res:
        parts.append(f"loop speed-up x{res['speedup']['speedup']:.0f}")
    return "inverse: " + "; ".join(parts)
