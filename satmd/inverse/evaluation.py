"""Scoring an inverse model on labelled test FRFs (Table 2, the ablation, the off-curve check)."""
from __future__ import annotations

import time

import numpy as np

from .dataset import BLIND_PAIRS, InverseDataset, pairs_dataset


def noisy_inputs(test: InverseDataset, noise: float, seed: int = 0):
    """Test FRFs as a list of FRFData; with ``noise`` > 0 noisy (eq. 23 model) and carrying std columns."""
    return [test.frfdata(i, noise=noise, seed=None if not noise else seed * 100_003 + i) for i in range(len(test))]


def evaluate(model, test: InverseDataset | None = None, noise: float = 0.0, seed: int = 0) -> dict:
    """Errors, FRF reconstruction error, 2σ coverage and inference time of ``model`` on ``test``.

    Parameters
    ----------
    model : a fitted `InverseModel`
    test : labelled test FRFs (default: the six blind pairs of Table 2)
    noise : relative input noise (seeded); the inputs then carry its std, as a measured FRF would
    seed : noise seed

    Returns
    -------
    dict : predictions, MAE / relative / max error and 2σ coverage per output,
        mean relative FRF error, inference seconds per FRF. A model that gives
        no std (``R_std`` NaN, see `InverseModel.predict`) has coverage NaN.
    """
    test = pairs_dataset(BLIND_PAIRS, freq_hz=model.freq_hz, rig=model.rig) if test is None else test
    datas = noisy_inputs(test, noise, seed)
    t0 = time.perf_counter()
    pred = model.predict(datas)
    infer = (time.perf_counter() - t0) / len(test)
    truth = {"R": test.R, "L": test.L}
    out = {"n": len(test), "noise": float(noise), "infer_s_per_frf": infer,
           "R_true": test.R.tolist(), "L_true": test.L.tolist()}
    for k in ("R", "L"):
        err = pred[k] - truth[k]
        sd = np.asarray(pred[f"{k}_std"], float)
        out[k] = pred[k].tolist()
        out[f"{k}_std"] = sd.tolist()
        out[f"mae_{k}"] = float(np.mean(np.abs(err)))
        out[f"rel_{k}"] = float(np.mean(np.abs(err) / np.abs(truth[k])))
        out[f"max_{k}"] = float(np.max(np.abs(err)))
        # no std (NaN: a one-member ensemble), no coverage: never an error divided by a std of 0
        out[f"coverage_{k}"] = float(np.mean(np.abs(err) <= 2 * sd)) if np.all(np.isfinite(sd)) else float("nan")
    known = [c for c in (out["coverage_R"], out["coverage_L"]) if np.isfinite(c)]
    out["coverage"] = float(np.mean(known)) if known else float("nan")
    clean = np.stack([test.a1, test.a2], axis=1)
    out["frf_error"] = float(np.mean(model.reconstruction_error(clean, pred)))
    return out
