"""Show the fit improve (issue 27 item 3): the linear and the nonlinear model, per level, side by side.

For every recording: the time-domain error of each model (fitted on ``train``, so a held-out
recording is a prediction) and the FRF residual: the H1 FRF of the measured a1, a2 against
the H1 of each model's simulated response to the same measured force, relative, over the
excited band. A linear model fitted across levels carries one FRF for all; the nonlinear
model's equivalent FRF moves with level as the data do.
"""
from __future__ import annotations

import numpy as np
from scipy.signal import csd, welch

from .nonlinear import fit_nonlinear, predict, prepare


def _h1(force, acc, fs, band):
    nper = int(min(force.size // 4, 4 * fs))
    f, pff = welch(force, fs, nperseg=nper)
    keep = (f >= band[0]) & (f <= band[1])
    out = []
    for x in acc:
        _, pfx = csd(force, x, fs, nperseg=nper)
        out.append(pfx[keep] / pff[keep])
    return f[keep], np.array(out)


def frf_residual(recording, prediction, band_hz=None, seconds=None) -> float:
    """Relative FRF residual ‖H1(model) − H1(measured)‖ / ‖H1(measured)‖ over the band, a1 and a2 together.

    Parameters
    ----------
    recording : Recording (force, acc1, acc2).
    prediction : dict with simulated ``a1``, ``a2`` for the same force (`predict`).
    band_hz : (lo, hi) (default: the force's excited band).
    seconds : the first this many seconds (as given to `predict`).

    Returns
    -------
    float
    """
    d = prepare(recording, seconds)
    band = band_hz or d["band"]
    _, meas = _h1(d["force"], d["acc"], d["fs"], band)
    _, model = _h1(d["force"], np.vstack([prediction["a1"], prediction["a2"]]), d["fs"], band)
    return float(np.linalg.norm(model - meas) / np.linalg.norm(meas))


def compare_models(train, held_out, element, seconds: float | None = 30.0, **fit_options) -> dict:
    """Fit the linear and the nonlinear model on ``train``; errors of both on every recording.

    Parameters
    ----------
    train : recordings the models are fitted to (e.g. the lowest and highest level).
    held_out : recordings predicted (e.g. a level in between, or above).
    element : SPEC §8b name (or NonlinearElement) of the nonlinear model.
    seconds : seconds of each recording used.
    **fit_options : passed to `fit_nonlinear`.

    Returns
    -------
    dict
        ``nonlinear`` and ``linear`` (NonlinearFit.to_dict()), and ``levels``: one entry per
        recording (train then held out) with ``level``, ``held_out``, ``td_error`` and
        ``frf_residual`` {"linear", "nonlinear"}, and ``td_ratio`` = linear / nonlinear.
    """
    nl = fit_nonlinear(train, element, seconds=seconds, **fit_options)
    lin = fit_nonlinear(train, None, seconds=seconds, start=nl.rig, **fit_options)
    rows = []
    for held, recs in ((False, train), (True, held_out)):
        for rec in recs:
            p_nl, p_lin = predict(nl, rec, seconds), predict(lin, rec, seconds)
            row = {"level": float(np.sqrt(np.mean(np.asarray(rec["force"]) ** 2))), "held_out": held,
                   "td_error": {"linear": p_lin["rel_error"]["both"], "nonlinear": p_nl["rel_error"]["both"]},
                   "frf_residual": {"linear": frf_residual(rec, p_lin, seconds=seconds),
                                    "nonlinear": frf_residual(rec, p_nl, seconds=seconds)}}
            row["td_ratio"] = row["td_error"]["linear"] / max(row["td_error"]["nonlinear"], 1e-300)
            rows.append(row)
    return {"nonlinear": nl.to_dict(), "linear": lin.to_dict(), "levels": rows, "fits": (nl, lin)}
