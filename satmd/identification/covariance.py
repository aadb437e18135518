"""Parameter covariance of a least-squares fit, in relative scaling (Jacobian or HC3 sandwich).

Shared by the result of a fit (`satmd.identification.statistics`) and its profile intervals
(`satmd.identification.intervals`).
"""
from __future__ import annotations

import numpy as np


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


def jacobian_covariance(jac, noise_variance: float = 1.0) -> np.ndarray:
    """``noise_variance · (JᵀJ)⁻¹`` of a least-squares fit from its Jacobian: every fit's covariance, written once.

    Columns are scaled to unit norm first (well conditioned whatever the parameters' units); a Jacobian
    that is numerically rank deficient gives NaN (no interval), never a pseudo-inverse's arbitrary one.

    Parameters
    ----------
    jac : (n, p) Jacobian of the (weighted) residuals
    noise_variance : the residuals' variance (1 for residuals already divided by their std)

    Returns
    -------
    ndarray (p, p)
    """
    J = np.asarray(jac)
    J = J.astype(complex if np.iscomplexobj(J) else float)  # complex: (JᴴJ)⁻¹ of complex parameters
    norm = np.linalg.norm(J, axis=0)
    sc = np.where(norm > 0, 1.0 / np.where(norm > 0, norm, 1.0), 1.0)
    A, _ = inverse_gram(J * sc)
    if not np.all(np.isfinite(A)) or not np.all(norm > 0):
        return np.full((J.shape[1], J.shape[1]), np.nan)
    return A * np.outer(sc, sc) * noise_variance


def inverse_gram(Js):
    """(JᵀJ)⁻¹ through the SVD (all inf when J is numerically rank deficient), and the singular values."""
    _, sv, vt = np.linalg.svd(Js, full_matrices=False)
    if sv[-1] <= sv[0] * 1e-14:
        return np.full((sv.size, sv.size), np.inf), sv
    return (vt.conj().T / sv**2) @ vt, sv
