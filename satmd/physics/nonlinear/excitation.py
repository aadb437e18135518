"""Force signals for nonlinear recordings: band-limited random noise, and odd random-phase multisines.

Odd random-phase multisine (Pintelon & Schoukens, *System Identification*, 2nd ed., §3.4):
one period of ``period`` samples excites odd DFT lines ``k = 1, 3, 5, ...`` inside the band
with a flat amplitude and independent uniform phases; in every group of four consecutive odd
lines one, drawn at random, is left out (a *detection line*: with the even lines, the
lines where a linear rig puts nothing but noise, so odd and even distortion show apart).
The lines are drawn once; each realisation draws new phases and is repeated ``periods``
times; on a rig that starts at rest the first period holds the start-up transient.
"""
from __future__ import annotations

import numpy as np

from ...errors import DataError


def random_force(n: int, fs_hz: float, band_hz, rng, shape=None, unit_rms: bool = True) -> np.ndarray:
    """Band-limited Gaussian noise, filtered on a record 4x longer and cut (not periodic in n samples).

    Parameters
    ----------
    n : samples.
    fs_hz : sample rate [Hz].
    band_hz : (lo, hi) [Hz].
    rng : numpy Generator.
    shape : the shaker's amplitude response, an object with ``amplitude(f, lo, hi)`` (e.g.
        `satmd.simulation.timesim.ForceSpectrum`); default flat, cut at lo and hi.
    unit_rms : scale to unit RMS (else the filtered noise as it is).

    Returns
    -------
    ndarray (n,)
    """
    m = 4 * n
    spectrum = np.fft.rfft(rng.standard_normal(m))
    f = np.fft.rfftfreq(m, 1.0 / fs_hz)
    if shape is None:
        spectrum[(f < band_hz[0]) | (f > band_hz[1])] = 0.0
    else:
        spectrum *= shape.amplitude(f, band_hz[0], band_hz[1])
    start = int(rng.integers(0, m - n))
    x = np.fft.irfft(spectrum, m)[start:start + n]
    return x / np.sqrt(np.mean(x * x)) if unit_rms else x


def log_sweep(n: int, fs_hz: float, lo: float, hi: float, unit_rms: bool = False) -> np.ndarray:
    """One logarithmic sine sweep lo -> hi over ``n`` samples at ``fs_hz``, tapered in and out.

    Parameters
    ----------
    n : samples.
    fs_hz : sample rate [Hz].
    lo, hi : start and end frequencies [Hz].
    unit_rms : scale to unit RMS (else peak 1).

    Returns
    -------
    ndarray (n,)
    """
    t = np.arange(n) / fs_hz
    duration = n / fs_hz
    rate = np.log(hi / lo)
    x = np.sin(2 * np.pi * lo * duration / rate * (np.exp(t / duration * rate) - 1.0))
    taper = max(1, int(0.05 * n))
    ramp = 0.5 - 0.5 * np.cos(np.pi * np.arange(taper) / taper)
    x[:taper] *= ramp
    x[n - taper:] *= ramp[::-1]
    return x / np.sqrt(np.mean(x * x)) if unit_rms else x


def odd_multisine_lines(period: int, fs_hz: float, band_hz, rng, group: int = 4) -> np.ndarray:
    """Excited DFT lines of one period: odd lines in the band, one in each ``group`` left out at random.

    Parameters
    ----------
    period : samples per period.
    fs_hz : sample rate [Hz].
    band_hz : (lo, hi) [Hz].
    rng : numpy Generator.
    group : one odd line in every ``group`` consecutive ones is a detection line.

    Returns
    -------
    ndarray of int
    """
    f0 = fs_hz / period
    k = np.arange(1, period // 2, 2)
    k = k[(k * f0 >= band_hz[0]) & (k * f0 <= band_hz[1])]
    if k.size < group:
        raise DataError(f"a {period / fs_hz:g} s period has fewer than {group} odd lines in "
                        f"{band_hz[0]:g}:{band_hz[1]:g} Hz; use longer periods")
    keep = np.ones(k.size, bool)
    for start in range(0, k.size - group + 1, group):
        keep[start + int(rng.integers(group))] = False
    return k[keep]


def odd_multisine(period: int, periods: int, realisations: int, fs_hz: float, band_hz, rng):
    """Forces (realisations, periods * period) of unit RMS and the excited lines (the same in each).

    Parameters
    ----------
    period : samples per period.
    periods : periods per realisation (the first holds the transient on a rig started at rest).
    realisations : independent random-phase realisations.
    fs_hz : sample rate [Hz].
    band_hz : (lo, hi) [Hz].
    rng : numpy Generator.

    Returns
    -------
    (ndarray, ndarray of int)
    """
    if periods < 1 or realisations < 1:
        raise DataError(f"a multisine needs periods >= 1 and realisations >= 1 (got {periods}, {realisations})")
    k = odd_multisine_lines(period, fs_hz, band_hz, rng)
    forces = []
    for _ in range(realisations):
        spectrum = np.zeros(period // 2 + 1, complex)
        spectrum[k] = np.exp(2j * np.pi * rng.random(k.size))
        one = np.fft.irfft(spectrum, period)
        one /= np.sqrt(np.mean(one * one))
        forces.append(np.tile(one, periods))
    return np.stack(forces), k
