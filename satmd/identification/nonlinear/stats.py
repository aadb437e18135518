"""Uncertainty of a time-domain nonlinear fit: the errors-in-variables correction and the sandwich covariance."""
from __future__ import annotations

import math

import numpy as np

from ...numerics import jacobian_covariance
from .drive import band_gain


def _gauss_newton_step(coords, x, data, weights, skip, simulate, residuals):
    """The Gauss-Newton step from ``x`` on ``data`` (forward-difference Jacobian, one batched simulation)."""
    h = 1e-6 * np.maximum(1.0, np.abs(x))
    X = np.vstack([x] + [x + h[i] * np.eye(x.size)[i] for i in range(x.size)])
    R = residuals(simulate(coords, X, data), data, weights, skip)
    J = ((R[1:] - R[0]) / h[:, None]).T
    return -np.linalg.lstsq(J, R[0], rcond=None)[0]


def simex_shift(coords, x, data, weights, skip, draws: int, seed: int = 0, simulate=None, residuals=None):
    """Errors-in-variables correction: the model is driven by the *measured* force, noise included.

    That noise biases the fit (it enters the model's nonlinear force and its Jacobian). One step
    of SIMEX (Cook & Stefanski 1994): the estimate at twice the force noise, extrapolated linearly
    in the noise variance back to none, ``x0 = 2 x1 - x2``. ``x1`` is the estimate on the data
    (``x`` plus its own Gauss-Newton step ``s0``, which finishes the optimiser's convergence),
    ``x2`` the mean estimate with ``draws`` copies of the force-sensor noise added (its variance
    estimated from the force's spectrum outside the excited band, shaped like the drive's band,
    `band_gain`): ``x + mean(s)``, so ``x0 = x + 2 s0 - mean(s)``. The copies come in antithetic
    pairs (+e, -e): a step's part linear in the added noise, as large as the estimate's own noise,
    cancels in the mean instead of being carried into the estimate (with 4 independent draws it
    moved an inductor's isat by up to 2 %, as much as its interval); what remains is the part even
    in the noise, the bias being corrected. (Without ``s0`` an
    unfinished optimisation would be doubled instead of corrected.) Returns the correction
    ``x0 - x`` and a covariance to add to the sandwich: the steps' spread (x (1 + 1/draws)), the
    errors-in-variables part the sandwich's first order misses (conservative). No out-of-band
    spectrum: only ``s0``.

    Parameters
    ----------
    coords : the fit's coordinates; x : the fitted coordinates.
    data, weights, skip : as in the fit.
    draws : noise draws.
    seed : seed of the draws.
    simulate, residuals : the fit's batched simulation and weighted residuals.

    Returns
    -------
    (ndarray, ndarray)
    """
    s0 = _gauss_newton_step(coords, x, data, weights, skip, simulate, residuals)
    if not any(d["force_noise_var"] > 0 for d in data) or draws < 1:
        return s0, np.zeros((x.size, x.size))
    rng = np.random.default_rng(seed)
    steps = []
    noise: list = []
    for j in range(draws):
        if j % 2 == 0:  # antithetic pairs: +e and -e, so the steps' part linear in the noise cancels in their mean
            noise = []
            for d in data:
                n = d["force"].size
                f = np.fft.rfftfreq(n, 1.0 / d["fs_hz"])
                spec = np.fft.rfft(rng.standard_normal(n)) * math.sqrt(d["force_noise_var"]) * band_gain(f, d["band_hz"])
                noise.append(np.fft.irfft(spec, n))
        sign = 1.0 if j % 2 == 0 else -1.0
        noisy = [{**d, "force": d["force"] + sign * e} for d, e in zip(data, noise)]
        steps.append(_gauss_newton_step(coords, x, noisy, weights, skip, simulate, residuals))
    step_arr = np.array(steps)
    # the steps' spread is what one more unit of force noise does to the estimate, through the model's
    # input *and* its Jacobian, which the sandwich's first order misses: added in full (conservative),
    # plus the uncertainty of their mean
    cov = np.cov(step_arr.T).reshape(x.size, x.size) * (1 + 1 / draws) if draws > 1 else np.zeros((x.size, x.size))
    return 2 * s0 - step_arr.mean(axis=0), cov


def sandwich(J, r, block_sizes, channel_length, lags: int = 1024) -> np.ndarray:
    """Covariance B M B: B = (JᵀJ)⁻¹, M the long-run variance of the score (Newey-West).

    The score of each recording is ``s_t = Σ_c J_c,t r_c,t`` over its channels; ``M`` sums its
    autocovariances up to ``lags`` with Bartlett weights. Residuals may then be coloured,
    coherent across a1 and a2 (force-sensor noise drives both through the rig) and
    non-stationary (a hardening rig's small-signal response follows the trajectory).

    Parameters
    ----------
    J : (n, p) Jacobian of the weighted residuals; r : (n,) residuals.
    block_sizes : samples per recording (both channels); channel_length : samples per channel.
    lags : largest lag [samples] (about the rig's memory).

    Returns
    -------
    ndarray (p, p)
    """
    B = jacobian_covariance(J)
    M = np.zeros_like(B)
    start = 0
    for size, n in zip(block_sizes, channel_length):
        score = sum(J[start + c * n:start + (c + 1) * n] * r[start + c * n:start + (c + 1) * n, None] for c in range(2))
        L = int(min(lags, n - 1))
        size_fft = int(2 ** np.ceil(np.log2(n + L + 1)))
        S = np.fft.rfft(score, size_fft, axis=0)  # (f, p)
        cross = np.fft.irfft(np.conj(S)[:, :, None] * S[:, None, :], size_fft, axis=0)[:L + 1]  # Γ_l, l = 0..L
        w = 1.0 - np.arange(L + 1) / (L + 1.0)
        G = np.tensordot(w[1:], cross[1:], axes=(0, 0))
        M += cross[0] + G + G.T
        start += size
    return B @ M @ B
