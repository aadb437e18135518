"""Parameter covariance of a least-squares fit, in relative scaling (Jacobian or HC3 sandwich).

Shared by the result of a fit (`satmd.identification.statistics`) and its profile intervals
(`satmd.identification.intervals`).
"""
from __future__ import annotations

import numpy as np

from ..numerics import inverse_gram, jacobian_covariance  # noqa: F401 - re-exported: the fits' covariance


def parameter_covariance(J, r, scales, free, weighted):
    """Covariance of the parameters and the condition number of the scaled JᵀJ.

    Covariance through relative scaling: well conditioned even for kp ~ 1e5 beside L ~ 1e-2.
    Parameters not ``free`` (pinned at a bound) get NaN rows and columns; the others get the
    covariance given them: (JᵀJ)⁻¹ when ``weighted`` (the data carry a std), else the HC3 sandwich.
    """
    k = J.shape[1]
    cov = np.full((k, k), np.nan)
    cond = np.inf
    if free.any():
        sc = scales[free]
        Js = J[:, free] * sc
        A, sv = inverse_gram(Js)
        cond = float((sv[0] / sv[-1]) ** 2) if sv[-1] > 0 else np.inf
        if weighted or not np.all(np.isfinite(A)):
            cov_s = A
        else:
            # relative fit, noise unknown and (as measured) larger where |A| is: HC3 sandwich
            h = np.einsum("ij,jk,ik->i", Js, A, Js)  # leverages
            w = r**2 / np.clip(1.0 - h, 1e-3, None) ** 2
            cov_s = A @ ((Js.T * w) @ Js) @ A
        cov[np.ix_(free, free)] = cov_s * np.outer(sc, sc)
    return cov, cond


def naive_variance(J, scales, free, noise_factor) -> np.ndarray:
    """diag noise_factor·(JᵀJ)⁻¹ (NaN where singular or not free): the homoscedastic variance."""
    out = np.full(free.size, np.nan)
    if free.any():
        sc = scales[free]
        gram_inv, _ = inverse_gram(J[:, free] * sc)
        out[free] = np.diag(gram_inv) * sc**2 * noise_factor
    return out
