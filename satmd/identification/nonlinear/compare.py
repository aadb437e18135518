"""Show the fit improve (issue 27 item 3): the linear and the nonlinear model, per level, side by side.

For every recording: the time-domain error of each model (fitted on ``train``, so a held-out
recording is a prediction) and the FRF residual: the H1 FRF of the measured a1, a2 against
the H1 of each model's simulated response to the same measured force, relative, over the
excited band. A linear model fitted across levels carries one FRF for all; the nonlinear
model's equivalent FRF moves with level as the data do.
"""
from __future__ import annotations

from ...conventions import TINY

import numpy as np

from ...numerics import force_level
from scipy.signal import csd, welch

from .fit import fit_nonlinear, predict, prepare


def _h1(force, acc, fs, band_hz):
    nper = int(min(force.size // 4, 4 * fs))
    f, pff = welch(force, fs, nperseg=nper)
    keep = (f >= band_hz[0]) & (f <= band_hz[1])
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
    band = band_hz or d["band_hz"]
    _, meas = _h1(d["force"], d["acc"], d["fs_hz"], band)
    _, model = _h1(d["force"], np.vstack([prediction["a1"], prediction["a2"]]), d["fs_hz"], band)
    return float(np.linalg.norm(model - meas) / np.linalg.norm(meas))


def compare_models(train, held_out, element, seconds: float | None = 30.0, best_linear: bool = True,
                   **fit_options) -> dict:
    """Fit the linear and the nonlinear model on ``train``; errors of both on every recording.

    The linear side is the *best* linear model: the linear rig fitted in the time domain to all
    of ``train`` at once and, with ``best_linear``, also to each training recording alone (a
    linear model is right at one level only); each recording is judged against whichever of
    them predicts it best, chosen on that recording itself. That favours the linear model, so
    the ratio is conservative. Both models are fitted by the same code with the same options,
    driven by the same force and judged on the same samples and band (`predict`).

    Parameters
    ----------
    train : recordings the models are fitted to (e.g. the lowest and highest level).
    held_out : recordings predicted (e.g. a level in between, or above).
    element : SPEC §8b name (or NonlinearElement) of the nonlinear model.
    seconds : seconds of each recording used.
    best_linear : also fit the linear model to each training recording alone.
    **fit_options : passed to `fit_nonlinear`.

    Returns
    -------
    dict
        ``nonlinear`` and ``linear`` (NonlinearFit.to_dict() of the joint linear fit), and
        ``levels``: one entry per recording (train then held out) with ``level``, ``held_out``,
        ``td_error`` (where the response is excited, the headline: `predict`'s ``rel_error_excited``),
        ``td_error_band`` (the force's whole band), ``td_error_broadband`` and ``frf_residual``
        {"linear", "nonlinear"}, ``linear_model`` (which linear fit was best, chosen on the headline
        error), ``td_ratio``, ``td_ratio_band`` and ``td_ratio_broadband`` = linear / nonlinear; ``fits`` (nonlinear, joint
        linear NonlinearFit) and ``linear_fits`` {name: NonlinearFit} (not JSON: pop them).
    """
    nl = fit_nonlinear(train, element, seconds=seconds, **fit_options)
    lin = fit_nonlinear(train, None, seconds=seconds, start=nl.rig, **fit_options)
    linears = {"all training levels": lin}
    if best_linear and len(train) > 1:
        for i, rec in enumerate(train):
            lev = force_level(rec["force"])
            linears[f"level {lev:.3g} N"] = fit_nonlinear([rec], None, seconds=seconds, start=nl.rig, **fit_options)
    rows = []
    for held, recs in ((False, train), (True, held_out)):
        for rec in recs:
            p_nl = predict(nl, rec, seconds)
            preds = {k: predict(f, rec, seconds) for k, f in linears.items()}
            best = min(preds, key=lambda k: preds[k]["rel_error_excited"]["both"])
            p_lin = preds[best]
            row = {"level": force_level(rec["force"]), "held_out": held,
                   "linear_model": best, "band_hz": p_nl["band_hz"]}
            for key, pkey in (("", "rel_error_excited"), ("_band", "rel_error_band"), ("_broadband", "rel_error")):
                row["td_error" + key] = {"linear": p_lin[pkey]["both"], "nonlinear": p_nl[pkey]["both"]}
            row["frf_residual"] = {"linear": frf_residual(rec, p_lin, seconds=seconds),
                                   "nonlinear": frf_residual(rec, p_nl, seconds=seconds)}
            for key in ("", "_band", "_broadband"):
                e = row["td_error" + key]
                row["td_ratio" + key] = e["linear"] / max(e["nonlinear"], TINY)
            rows.append(row)
    return {"nonlinear": nl.to_dict(), "linear": lin.to_dict(), "levels": rows, "fits": (nl, lin),
            "linear_fits": linears}
