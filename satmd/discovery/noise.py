"""Noise level when the data carry no std: estimated from the residual's roughness.

After the nominal fit, the residual is noise plus model mismatch. Mismatch is
smooth across frequency (it comes from a few physical parameters), noise is
not, so the second difference of the residual along frequency,

    d_i = (r_{i-1} - 2 r_i + r_{i+1}) / sqrt(6),

has (for white noise) the same variance as the noise and little of the
mismatch. Per channel the noise is modelled as the SPEC form
σ(f) = a |A(f)| + b max|A| (relative error plus a floor) and (a, b) are
fitted by maximum likelihood to the d_i, with a Student-t likelihood so a
few sharp features (an unmodelled light mode) do not inflate the estimate.
"""
from __future__ import annotations

import numpy as np

from ..conventions import TINY


def second_difference(r: np.ndarray) -> np.ndarray:
    return (r[:-2] - 2 * r[1:-1] + r[2:]) / np.sqrt(6.0)


def estimate_channel_std(residual: np.ndarray, magnitude: np.ndarray, nu: float = 4.0) -> np.ndarray:
    """σ per point (on each of Re and Im) for one channel."""
    from scipy.optimize import minimize  # heavy: imported where used, not at `import satmd`

    d = second_difference(residual)
    # variance seen by each difference: the (1, 4, 1)/6 average of σ² over its stencil
    peak = magnitude.max()
    m2 = magnitude**2

    # below the model's round-off no noise can be estimated (noise-free data fit exactly)
    floor2 = (1e-13 * peak) ** 2

    def sigma2(params):
        a, b = np.exp(params)
        s = a * magnitude + b * peak
        return np.maximum(s**2, floor2)

    def nll(params):
        s2 = sigma2(params)
        v = (s2[:-2] + 4 * s2[1:-1] + s2[2:]) / 6.0
        # complex d: Re and Im each ~ t_ν(0, v)
        q = (d.real**2 + d.imag**2)
        # bivariate t: -log density ∝ log v + (ν+2)/2 log(1 + q/(ν v))
        return np.sum(np.log(v) + 0.5 * (nu + 2) * np.log1p(q / (nu * v)))

    scale = np.sqrt(np.median(d.real**2 + d.imag**2) / 2) + TINY
    rel0 = np.log(max(scale / np.sqrt(np.mean(m2)), 1e-12))
    best = None
    for x0 in ([rel0, rel0 - 2.3], [rel0 - 2.3, np.log(scale / peak)], [rel0 - 4.6, np.log(scale / peak)]):
        res = minimize(nll, np.array(x0), method="Nelder-Mead", options={"xatol": 1e-4, "fatol": 1e-6, "maxiter": 600})
        if best is None or res.fun < best.fun:
            best = res
    assert best is not None  # three starts
    s = np.sqrt(sigma2(best.x))
    # the t-likelihood scale is not the Gaussian std: rescale by the Gaussian consistency factor
    return s * _t_scale_correction(nu)


def _t_scale_correction(nu):
    # For a bivariate Gaussian fitted with a bivariate t likelihood, the ML scale is smaller than σ by a
    # known factor; computed once by Monte Carlo-free fixed point: E[(ν+2) q/(ν v + q)] = 2.
    from scipy.integrate import quad

    def eq(c):
        # q = c² χ²₂ with v = 1 → E[(ν+2) q/(ν+q)] = 2 for the right c
        f = lambda x: (nu + 2) * c**2 * x / (nu + c**2 * x) * 0.5 * np.exp(-x / 2)
        return quad(f, 0, np.inf)[0] - 2

    from scipy.optimize import brentq

    c = brentq(eq, 0.2, 5.0)  # the t fit's scale is 1/c of σ (see above), so σ = c · scale
    return c


def estimate_std(data, fit) -> dict:
    """Estimated std per channel from a nominal FitResult on ``data``."""
    pred = fit.prediction()
    out = {}
    for c in fit.channels:
        r = data[c] - pred[c]
        out[c] = estimate_channel_std(r, np.abs(pred[c]))
    return out
