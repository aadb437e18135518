"""Practical significance: an effect the estimator's own systematic error could make is not physics.

An FRF estimated from a recording carries a systematic error the noise std does not describe: a floor
every estimate has (`conventions.ESTIMATE_REL_FLOOR`: its model, sampling, the chain's filters) and,
where no force-noise floor could be told from the force, a pull towards zero of up to a known share at
each point (`FRFData.bias_bound`). An effect is evidence of physics only through the part of its
signature (the change it makes to the fitted model, against the model refitted without it) that such
a bias cannot make: at each point, what exceeds the bound. When that part alone would not earn the
effect its place (χ² over the noise, less the effect's BIC penalty, at most ``MIN_DELTA_BIC``), the
effect is reported as a ``measurement`` finding, never as physics (SPEC §9: ``effects`` lists physics
only). The fit keeps it, so nothing is left for an ``unexplained`` finding to claim.
"""
from __future__ import annotations

import numpy as np

from ..conventions import ESTIMATE_REL_FLOOR, TINY

__all__ = ["evidence_beyond_bias", "bias_note"]


def evidence_beyond_bias(with_effect, without_effect, bound) -> float:
    """The BIC evidence for an effect that is left once the estimator's bias has taken its share.

    Parameters
    ----------
    with_effect, without_effect : FitResult of the model with the effect and refitted without it.
    bound : (n,) relative bias the estimate may carry at each point (`FRFData.bias_bound`), or None.

    Returns
    -------
    float
        Σ over channels and points of (max(|H_with − H_without| − bound·|H_without|, 0) / σ)², less the
        effect's BIC penalty (its extra parameters times ln n, as the fits' BIC counts them). ``inf`` when
        no bound is known or the fits are unweighted: nothing to take away.
    """
    if bound is None or with_effect.data.std is None:
        return float("inf")
    bound = np.asarray(bound, float)
    a, b = with_effect.prediction(), without_effect.prediction()
    if bound.shape != a.freq_hz.shape:  # the fit saw another grid than the estimate's: no budget to compare
        return float("inf")
    chi2 = 0.0
    for c in a.channels:
        beyond = np.maximum(np.abs(a[c] - b[c]) - bound * np.abs(b[c]), 0.0)
        chi2 += float(np.sum((beyond / np.maximum(with_effect.data.std[c], TINY)) ** 2))
    penalty = (with_effect.bic - with_effect.chi2) - (without_effect.bic - without_effect.chi2)
    return chi2 - penalty


def bias_note(name: str, explanation: str, evidence: float, bound) -> dict:
    """The ``measurement`` finding for an effect the estimator's bias could make."""
    beyond = (f"the part of its change to the FRF beyond that error is no evidence on its own (ΔBIC "
              f"{evidence:.3g})")
    if float(np.max(bound)) <= ESTIMATE_REL_FLOOR:  # only the floor every estimate carries, no force-noise bias
        return {"name": "within_estimator_bias",
                "explanation": f"{name} would explain part of the mismatch ({explanation}), but it stays within the "
                               f"{100 * ESTIMATE_REL_FLOOR:.2g} % systematic error an estimate from a recording "
                               f"carries beyond its noise (its model, sampling, the chain's filters): {beyond}, so "
                               "it is not named as physics",
                "remedy": "a change that moves it tests it (a recalibrated or second sensor, another rig setting); "
                          "more averaging narrows the noise, not this floor",
                "corrected": False}
    return {"name": "within_estimator_bias",
            "explanation": f"{name} would explain part of the mismatch ({explanation}), but it stays within the bias "
                           f"the estimate may carry (up to {100 * float(np.max(bound)):.2g} % at its worst point): "
                           f"{beyond}; the measurement chain could make it, so it is not named as physics",
            "remedy": "measure the load cell's noise with the shaker off (or record at a higher sample rate so the "
                      "force's noise floor shows): with the force-noise bias corrected, the effect can be tested",
            "corrected": False}
