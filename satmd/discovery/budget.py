"""Practical significance: an effect the estimator's own systematic error could make is not physics.

An FRF estimated from a recording may carry a bias the noise std does not describe: where no force-noise
floor could be told from the force, the H estimate may be pulled towards zero by up to a known share at
each point (`FRFData.bias_bound`). An effect whose whole signature (the change it makes to the fitted
model, against the model refitted without it) stays within that share at every point and in every channel
could be that bias: it is reported as a ``measurement`` finding, never as physics (SPEC §9: ``effects``
lists physics only). The fit keeps it, so nothing is left for an ``unexplained`` finding to claim.
"""
from __future__ import annotations

import numpy as np

from ..conventions import ESTIMATE_REL_FLOOR, TINY

__all__ = ["bias_share", "bias_note"]


def bias_share(with_effect, without_effect, bound) -> float:
    """The largest share of the bias bound that the effect's signature takes.

    Parameters
    ----------
    with_effect, without_effect : FitResult of the model with the effect and refitted without it.
    bound : (n,) relative bias the estimate may carry at each point (`FRFData.bias_bound`), or None.

    Returns
    -------
    float
        max over channels and points of |H_with − H_without| / (|H_without| · bound); at most 1: the
        estimator's bias alone could make the whole signature. ``inf`` when no bound is known.
    """
    if bound is None:
        return float("inf")
    bound = np.asarray(bound, float)
    a, b = with_effect.prediction(), without_effect.prediction()
    if bound.shape != a.freq_hz.shape:  # the fit saw another grid than the estimate's: no budget to compare
        return float("inf")
    worst = 0.0
    for c in a.channels:
        change = np.abs(a[c] - b[c]) / np.maximum(np.abs(b[c]), TINY)
        worst = max(worst, float(np.max(change / np.maximum(bound, TINY))))
    return worst


def bias_note(name: str, explanation: str, share: float, bound) -> dict:
    """The ``measurement`` finding for an effect within the estimator's bias."""
    if float(np.max(bound)) <= ESTIMATE_REL_FLOOR:  # only the floor every estimate carries, no force-noise bias
        return {"name": "within_estimator_bias",
                "explanation": f"{name} would explain part of the mismatch ({explanation}), but its change to the "
                               f"FRF is nowhere larger than the {100 * ESTIMATE_REL_FLOOR:.2g} % systematic error an "
                               "estimate from a recording carries beyond its noise (its model, sampling, the chain's "
                               "filters): too small to be told from the measurement, so it is not named as physics",
                "remedy": "a change that moves it tests it (a recalibrated or second sensor, another rig setting); "
                          "more averaging narrows the noise, not this floor",
                "corrected": False}
    return {"name": "within_estimator_bias",
            "explanation": f"{name} would explain part of the mismatch ({explanation}), but its change to the FRF "
                           f"is nowhere larger than the bias the estimate may carry (at most {100 * share:.0f} % of "
                           f"it; that bias reaches {100 * float(np.max(bound)):.2g} % at its worst point): the "
                           "measurement chain could make it, so it is not named as physics",
            "remedy": "measure the load cell's noise with the shaker off (or record at a higher sample rate so the "
                      "force's noise floor shows): with the force-noise bias corrected, the effect can be tested",
            "corrected": False}
