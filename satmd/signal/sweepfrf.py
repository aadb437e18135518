"""FRFs of a record that starts and ends at rest (a sweep, or hits): the whole record's spectra, fitted locally.

When the force and the responses are both whole transients in the record (the rig at rest before the
sweep and rung down after it), ``Y(k) = G(k) X(k) + N(k)`` holds at every DFT bin with no leakage
term, however fast the sweep: the transient is the signal. ``G`` is then fitted as a local polynomial
(degree 2) in non-overlapping windows of 7 bins, ``Y ≈ (g0 + g1 δ + g2 δ²) X``; the residual gives the
response noise, smoothed over neighbouring windows (it is smooth in frequency), and
``var(g0) = σ² [(AᴴA)⁻¹]₀₀``. A sweep that has not rung down by the record's end keeps the local
polynomial method (`satmd.signal.lpm`), whose transient term takes the leakage.
"""
from __future__ import annotations

import numpy as np

from ..conventions import RECORDING_CHANNELS, TINY

RUNG_DOWN = 1e-2  # the responses' RMS over the record's end, as a share of their loudest 2 %: at rest
TAIL_S = 0.1  # the record's end, at most (s)
HALF = 3  # window: 2·HALF + 1 bins
DEGREE = 2
SMOOTH = 9  # windows the noise variance is averaged over


def at_rest_at_the_end(recording, responses, strict: bool = False) -> bool:
    """Whether every response has rung down by the record's end (so the record holds whole transients).

    ``strict``: 80 dB down, or 40 dB down and no longer falling (the sensor's noise floor), as files joined
    end to end need (each join cuts what is left); otherwise 40 dB down.
    """
    n = recording.n_samples
    m = max(8, n // 50)
    last = max(8, min(m, int(TAIL_S * recording.fs_hz)))  # a long sweep's quiet tail is short beside n / 50
    for r in responses:
        y = np.asarray(recording[r], float)
        blocks = y[: n // m * m].reshape(-1, m)
        rms = np.sqrt(np.mean((blocks - blocks.mean()) ** 2, axis=1))
        if np.sqrt(np.mean((y[-last:] - blocks.mean()) ** 2)) > RUNG_DOWN * rms.max():
            return False
        if strict and rms[-1] > 1e-4 * rms.max() and rms[-1] < 0.97 * rms[-2]:  # still falling
            return False
    return True


def sweep_frf(recording, responses, band_hz, force=None):
    """(freq_hz, frf, std, coherence, noise_dof) of a sweep at rest at both ends, over ``band_hz`` (lo, hi) Hz.

    Parameters
    ----------
    recording : Recording
    responses : recording channels (``acc1``, ``acc2``)
    band_hz : (lo, hi) Hz: the band the force excites
    force : the force to use instead of the recording's (an impact record's force windowed to its pulses)

    Returns
    -------
    tuple
        One point per window (independent points): the FRF (a sweep: the local polynomial's centre; hits:
        Y/X at the window's most strongly forced bin, exact for whole transients), the std of each of its
        parts from the noise the local polynomial leaves (smoothed over neighbouring windows), a local
        coherence (1 − residual share); the noise degrees of freedom.
    """
    fs, n = recording.fs_hz, recording.n_samples
    x = np.asarray(recording["force"] if force is None else force, float)
    X = np.fft.rfft(x - np.median(x) if force is None else x)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    width = 2 * HALF + 1
    lo_k = max(HALF + 1, int(np.ceil(band_hz[0] * n / fs)))
    hi_k = min(f.size - HALF - 1, int(np.floor(band_hz[1] * n / fs)))
    centres = np.arange(lo_k, hi_k - HALF, width)
    idx = centres[:, None] + np.arange(-HALF, HALF + 1)[None, :]  # (W, width)
    delta = np.arange(-HALF, HALF + 1) / HALF
    powers = delta[None, :, None] ** np.arange(DEGREE + 1)[None, None, :]  # (1, width, p)
    A = X[idx][:, :, None] * powers  # (W, width, p)
    AhA = np.einsum("wkp,wkq->wpq", A.conj(), A)
    inv = np.linalg.inv(AhA + TINY * np.eye(DEGREE + 1))
    dof_window = width - DEGREE - 1
    rows, best = np.arange(idx.shape[0]), np.argmax(np.abs(X[idx]), axis=1)  # one point per window: its best bin
    Xb = X[idx][rows, best]
    frf, std, coh = {}, {}, {}
    for r in responses:
        y = np.asarray(recording[r], float)
        Y = np.fft.rfft(y - np.median(y))[idx]  # (W, width)
        coef = np.einsum("wpq,wkq,wk->wp", inv, A.conj(), Y)
        resid = Y - np.einsum("wkp,wp->wk", A, coef)
        s2 = np.sum(np.abs(resid) ** 2, axis=1) / dof_window
        s2 = np.convolve(s2, np.ones(SMOOTH) / SMOOTH, "same")  # the noise spectrum is smooth
        ch = RECORDING_CHANNELS[r]
        if force is None:  # a sweep: its force is even across a window, and the polynomial's centre averages it
            frf[ch] = coef[:, 0]
            std[ch] = np.sqrt(np.maximum(s2 * inv[:, 0, 0].real, 0.0) / 2.0)
        else:  # hits: their spectra interfere, so a few bins of each window hold the force; the record holds
            # whole transients, so Y = G X bin by bin: the ratio at the best-forced bin is exact but for noise,
            # where a polynomial would smooth a resonance narrower than the window
            frf[ch] = Y[rows, best] / Xb
            std[ch] = np.sqrt(np.maximum(s2, 0.0) / np.abs(Xb) ** 2 / 2.0)
        coh[ch] = np.clip(1.0 - np.sum(np.abs(resid) ** 2, axis=1) / np.maximum(np.sum(np.abs(Y) ** 2, axis=1), TINY),
                          0.0, 1.0)
    return f[idx[rows, best] if force is not None else centres], frf, std, coh, 2.0 * dof_window * SMOOTH


__all__ = ["at_rest_at_the_end", "sweep_frf"]
