"""Where a prediction misses, by frequency: inside the force's band or above it (SPEC §11's NRMSE, split).

A joint's harmonics put response where the force puts nothing. A model that predicts none of it misses by at
least that share however well it holds the band: on the F-16 at level 5 the response above the shaker's 15 Hz
is 0.19, 0.10 and 0.30 of acc1, acc2, acc3's RMS, and no law of the measured strokes between any two sensors
explains it (`benchmarks/structures_predict.py`). The split tells an engineer which of the two a miss is:
NRMSE² = in band² + above² (and below the band, where a multisine puts nothing either, rarely more than a trace).
"""
from __future__ import annotations

import numpy as np

FORCE_SHARE = 0.999  # of the force's power (about its mean) below the top of its band
ROLL_OFF = 0.01      # of a record's Nyquist frequency: `below_nyquist` turns from one to zero over its top 1 %


def _power(signal):
    """(power spectrum about the mean, its total, samples) of a signal; total 0 for one that carries none."""
    f = np.asarray(signal, float)
    power = np.abs(np.fft.rfft(f - f.mean())) ** 2
    total = float(power.sum()) if f.size >= 2 else 0.0
    return power, total, f.size


def band_top(signal, fs_hz: float, share: float = FORCE_SHARE) -> float:
    """The frequency below which a signal puts ``share`` of its power (about its mean): for a force, the top of its
    band (near the Nyquist frequency for a broadband force, whose response then has nothing above it)."""
    power, total, n = _power(signal)
    if total <= 0:
        return fs_hz / 2
    k = min(int(np.searchsorted(np.cumsum(power), share * total)), power.size - 1)
    return float(k * fs_hz / n)


def above_band(signal, fs_hz: float, top_hz: float) -> np.ndarray:
    """The part of ``signal`` (..., N) above ``top_hz`` (its spectrum there, back in time)."""
    x = np.asarray(signal, float)
    spectrum = np.fft.rfft(x, axis=-1)
    spectrum[..., np.fft.rfftfreq(x.shape[-1], 1.0 / fs_hz) <= top_hz] = 0.0
    return np.fft.irfft(spectrum, x.shape[-1], axis=-1)


def above_band_shares(simulated, measured, fs_hz: float, top_hz: float) -> tuple[float, float]:
    """(the simulation's error above the band, the measured response there), each as RMS over the measured
    response's RMS about its mean: the first is the part of the NRMSE above the band, the second the least of
    it a model that puts nothing there can reach."""
    m = np.asarray(measured, float)
    scale = float(np.sqrt(np.mean((m - m.mean()) ** 2))) or 1.0
    there = float(np.sqrt(np.mean(above_band(m, fs_hz, top_hz) ** 2)) / scale)
    error = above_band(np.asarray(simulated, float) - m, fs_hz, top_hz)
    missed = float(np.sqrt(np.mean(error ** 2)) / scale) if np.all(np.isfinite(error)) else float("inf")
    return missed, there


def below_nyquist(x, oversample: int, pad: int = 4096) -> np.ndarray:
    """``x`` (..., M) real, sampled at ``oversample`` times a record's rate, low-passed below the record's Nyquist
    frequency (a cosine roll-off over its top `ROLL_OFF`), as an acquisition's anti-alias filter does before it
    samples: taken every ``oversample``-th sample, nothing above the Nyquist frequency folds into the band. The
    record's end is mirrored over ``pad`` samples tapered to nothing, so the filter sees no step there (a
    simulation from rest starts at nothing)."""
    from scipy import fft

    x = np.asarray(x, float)
    n = x.shape[-1]
    if oversample <= 1 or n < 2:
        return x
    p = min(n, pad)
    taper = 0.5 * (1 + np.cos(np.pi * np.arange(p) / p))
    extended = np.concatenate([x, x[..., ::-1][..., :p] * taper], axis=-1)
    size = fft.next_fast_len(n + p, real=True)
    f = fft.rfftfreq(size) * 2 * oversample  # 1 at the record's Nyquist frequency
    gain = 0.5 * (1 + np.cos(np.pi * np.clip((f - 1 + ROLL_OFF) / ROLL_OFF, 0.0, 1.0)))
    return fft.irfft(fft.rfft(extended, size, axis=-1) * gain, size, axis=-1)[..., :n]


def mirrored(x, edge: int) -> tuple[np.ndarray, int]:
    """(``x`` (..., N) mirrored about its first and last samples over ``pad`` samples each, ``pad``): filtered by
    FFT, a record alone joins its end to its start in a step that a filter rings at both ends; the record is
    ``out[..., pad:pad + N]`` of the filtered mirror. ``pad`` is ``edge``, or N − 1 where the record is shorter."""
    x = np.asarray(x, float)
    pad = min(int(edge), x.shape[-1] - 1)
    if pad < 1:
        return x, 0
    return np.concatenate([x[..., pad:0:-1], x, x[..., -2:-pad - 2:-1]], axis=-1), pad


def share_outside(signal, fs_hz: float, band_hz, margin: float = 0.02) -> float:
    """The share of a signal's power (about its mean) outside ``band_hz`` (lo, hi), widened by ``margin`` of each
    end: for a force, how much of it drives the structure where a model fitted in that band was never shown it."""
    power, total, n = _power(signal)
    if total <= 0:
        return 0.0
    freq = np.fft.rfftfreq(n, 1.0 / fs_hz)
    lo, hi = band_hz
    inside = (freq >= lo * (1 - margin)) & (freq <= hi * (1 + margin))
    return float(power[~inside].sum() / total)
