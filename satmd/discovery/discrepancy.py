"""A generic data-driven correction for mismatch that no vocabulary effect explains.

The measured channels are modelled as the physical model plus a smooth
discrepancy δA_c(f) = Σ_j θ_cj T_j(x), with T_j Chebyshev polynomials of the
normalised frequency x ∈ [-1, 1] and complex θ. The fit is a weighted linear
least squares (the physics stays fixed), and the number of terms per channel
is chosen by BIC with a sequentially thresholded least squares (the STLSQ
idea of SINDy): terms whose coefficients are not significant are dropped.
The share of the mismatch it removes says how much of it is structured
(smooth across frequency) rather than noise-like, and where it lives.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..conventions import TINY
from ..numerics import jacobian_covariance

MAX_DEGREE = 12


@dataclass
class Discrepancy:
    terms: dict  # channel -> number of Chebyshev terms kept
    coefficients: dict  # channel -> complex coefficients (full length, zeros where dropped)
    correction: dict  # channel -> δA on the data grid
    chi2_before: float
    chi2_after: float
    n_parameters: int  # real parameters added

    @property
    def structured_fraction(self) -> float:
        """Share of the excess χ² (above its expectation) removed by the correction."""
        return float(max(0.0, self.chi2_before - self.chi2_after) / max(self.chi2_before, TINY))


def fit_discrepancy(freq_hz, residual: dict, sigma: dict) -> Discrepancy:
    """Fit δA to ``residual = data - model`` (per channel, complex), weights 1/σ."""
    x = 2 * (freq_hz - freq_hz[0]) / (freq_hz[-1] - freq_hz[0]) - 1
    n = x.size
    basis = np.polynomial.chebyshev.chebvander(x, min(MAX_DEGREE, n // 3))  # (n, D+1)
    terms, coefs, corr = {}, {}, {}
    chi2_before = chi2_after = 0.0
    n_par = 0
    for c, r in residual.items():
        w = 1.0 / sigma[c]
        rw = r * w
        chi2_c = float(np.sum(np.abs(rw) ** 2))
        chi2_before += chi2_c
        best = (chi2_c, 0, np.zeros(basis.shape[1], complex))  # (BIC, kept, θ)
        best_bic = chi2_c
        for d in range(1, basis.shape[1] + 1):
            active = np.arange(d)
            for _ in range(3):  # STLSQ: refit on the terms that matter
                A = basis[:, active] * w[:, None]
                theta, *_ = np.linalg.lstsq(A, rw, rcond=None)
                cov = jacobian_covariance(A)
                z = np.abs(theta) / np.sqrt(np.maximum(np.real(np.diag(cov)), TINY))  # NaN (dependent terms): kept
                keep = z > 2.0
                if keep.all() or not keep.any():
                    break
                active = active[keep]
            A = basis[:, active] * w[:, None]
            theta, *_ = np.linalg.lstsq(A, rw, rcond=None)
            chi2 = float(np.sum(np.abs(rw - A @ theta) ** 2))
            bic = chi2 + 2 * active.size * np.log(2 * n)
            if bic < best_bic:
                full = np.zeros(basis.shape[1], complex)
                full[active] = theta
                best, best_bic = (chi2, active.size, full), bic
        chi2_after += best[0]
        terms[c], coefs[c] = best[1], best[2]
        corr[c] = basis @ best[2]
        n_par += 2 * best[1]
    return Discrepancy(terms, coefs, corr, chi2_before, chi2_after, n_par)
