"""Signals of the time-domain nonlinear fit: the band-limited drive and the error on the excited band.

The model is driven by the *measured* force. The force sensor's noise outside the excited band
is provably not force (the shaker put nothing there), so it is removed before simulating:
`band_limit` keeps the band, rolls off with a raised cosine to ``ROLL`` × the band's edges and
removes the rest. The record is extended by its mirror image before the FFT, so its two ends
meet without a jump (a plain FFT filter treats the record as periodic and the jump between its
end and its start rings through the whole record: 0.6-0.9 % of the force RMS on a band-limited
random force, more than the force sensor's in-band noise). What remains is local to the record's
ends: the first seconds are skipped anyway (the rig's unknown initial state), the last
``TAIL_S`` are left out of every error (`valid`).
"""
from __future__ import annotations

from ...conventions import TINY

import numpy as np

ROLL = 1.3  # the drive's raised-cosine roll-off: from hi to ROLL * hi, and from lo to lo / ROLL
EXCITED_DB = 20.0  # a response bin is "excited" within this many dB of the response's in-band peak (smoothed)
SMOOTH_HZ = 2.0  # width of the running mean that smooths the response's spectrum for that choice
TAIL_S = 0.5  # seconds at a record's end left out of errors (the band-limit's end effect; measured < 1e-5 before)


def band_gain(f, band_hz, roll: float = ROLL) -> np.ndarray:
    """Gain of `band_limit` at frequencies ``f``: 1 in the band, raised-cosine roll-off, 0 beyond.

    Parameters
    ----------
    f : frequencies [Hz].
    band_hz : (lo, hi) kept in full.
    roll : roll-off ratio (> 1).

    Returns
    -------
    ndarray
    """
    f = np.asarray(f, float)
    lo, hi = float(band_hz[0]), float(band_hz[1])
    g = ((f >= lo) & (f <= hi)).astype(float)
    up = (f > hi) & (f < roll * hi)
    g[up] = 0.5 * (1 + np.cos(np.pi * (f[up] - hi) / ((roll - 1) * hi)))
    if lo > 0:
        dn = (f < lo) & (f > lo / roll)
        g[dn] = 0.5 * (1 + np.cos(np.pi * (lo - f[dn]) / (lo - lo / roll)))
    return g


def band_limit(x, fs: float, band_hz, roll: float = ROLL) -> np.ndarray:
    """``x`` kept to the band (mirror-extended FFT filter with the gain `band_gain`).

    Parameters
    ----------
    x : (n,) signal.
    fs : sample rate [Hz].
    band_hz : (lo, hi).
    roll : roll-off ratio.

    Returns
    -------
    ndarray (n,)
    """
    x = np.asarray(x, float)
    n = x.size
    y = np.concatenate([x, x[::-1]])
    spec = np.fft.rfft(y) * band_gain(np.fft.rfftfreq(2 * n, 1.0 / fs), band_hz, roll)
    return np.fft.irfft(spec, 2 * n)[:n]


def valid(n: int, fs: float, skip_s: float) -> slice:
    """Samples an error is computed on: after ``skip_s`` and before the last `TAIL_S` seconds.

    Parameters
    ----------
    n : samples in the record.
    fs : sample rate [Hz].
    skip_s : leading seconds left out.

    Returns
    -------
    slice
    """
    k = int(skip_s * fs)
    end = n - int(TAIL_S * fs)
    if end - k < max(64, int(0.5 * fs)):
        end = n  # a short record: keep its end rather than nothing
    return slice(k, end)


def band_error(sim, meas, fs, band_hz) -> np.ndarray:
    """Relative error per channel on the band: ‖FFT(sim − meas)‖ / ‖FFT(meas)‖ over the bins in ``band_hz``.

    Parameters
    ----------
    sim, meas : (channels, n) simulated and measured signals (same samples).
    fs : sample rate [Hz].
    band_hz : (lo, hi) kept.

    Returns
    -------
    ndarray (channels,)
    """
    sim, meas = np.atleast_2d(sim), np.atleast_2d(meas)
    f = np.fft.rfftfreq(meas.shape[-1], 1.0 / fs)
    keep = (f >= band_hz[0]) & (f <= band_hz[1])
    e = np.sum(np.abs(np.fft.rfft(sim - meas, axis=-1)[:, keep]) ** 2, axis=-1)
    m = np.sum(np.abs(np.fft.rfft(meas, axis=-1)[:, keep]) ** 2, axis=-1)
    return np.sqrt(e / np.maximum(m, TINY))


def excited_bins(meas, fs, band_hz, db: float = EXCITED_DB, smooth_hz: float = SMOOTH_HZ) -> np.ndarray:
    """Bins (of ``rfft`` of length ``meas.shape[-1]``) where each channel's measured response is excited.

    Excited: in the force's band and within ``db`` of the channel's in-band peak, the power
    spectrum smoothed over ``smooth_hz`` (a running mean, so a single noisy bin decides nothing).
    That is where the structure answers the drive (its resonances and their flanks); elsewhere in
    the band the accelerometers' noise is a large share of the recording, and an error there
    measures the sensor, not the model. The bins come from the *measured* signal only, so every
    model is judged on the same ones.

    Parameters
    ----------
    meas : (channels, n) measured signals.
    fs : sample rate [Hz].
    band_hz : (lo, hi) the force's excited band.
    db : how far below the peak a bin still counts.
    smooth_hz : smoothing width [Hz].

    Returns
    -------
    ndarray (channels, n // 2 + 1) of bool
    """
    meas = np.atleast_2d(meas)
    f = np.fft.rfftfreq(meas.shape[-1], 1.0 / fs)
    inband = (f >= band_hz[0]) & (f <= band_hz[1])
    width = max(1, int(round(smooth_hz * meas.shape[-1] / fs)))
    kernel = np.ones(width) / width
    out = np.zeros((meas.shape[0], f.size), bool)
    for c, x in enumerate(meas):
        p = np.convolve(np.abs(np.fft.rfft(x)) ** 2, kernel, mode="same")
        peak = float(np.max(p[inband])) if np.any(inband) else 0.0
        out[c] = inband & (p >= peak * 10.0 ** (-db / 10.0))
    return out


def excited_error(sim, meas, fs, band_hz, db: float = EXCITED_DB) -> np.ndarray:
    """Relative error per channel on the bins where the response is excited (`excited_bins`).

    Parameters
    ----------
    sim, meas : (channels, n) simulated and measured signals (same samples).
    fs : sample rate [Hz].
    band_hz : (lo, hi) the force's excited band.
    db : see `excited_bins`.

    Returns
    -------
    ndarray (channels,)
    """
    sim, meas = np.atleast_2d(sim), np.atleast_2d(meas)
    keep = excited_bins(meas, fs, band_hz, db)
    e = np.sum(np.abs(np.fft.rfft(sim - meas, axis=-1)) ** 2 * keep, axis=-1)
    m = np.sum(np.abs(np.fft.rfft(meas, axis=-1)) ** 2 * keep, axis=-1)
    return np.sqrt(e / np.maximum(m, TINY))
