"""The lab's excitations, written without satmd: numpy and scipy.signal only.

Every force is a function ``force(n, rate)`` that returns ``n`` samples of the
force on the grid ``arange(n) / rate`` (any rate: the recording's, or the
independent simulator's finer one), starting at t = 0 with the rig at rest.
Designs (one per family of `benchmarks/excitations.py`):

``multisine``       random-phase multisine, flat amplitude at every line (full) or
                    every odd line (odd) of one period within the band, several
                    periods;
``pseudo_random``   one period of white noise shaped by a Butterworth band-pass
                    (circularly: its DFT times the filter's response), repeated;
``periodic_chirp``  one linear or logarithmic chirp over the band per period, repeated;
``slow_sweep``      one long linear or logarithmic swept sine over the band, up or down,
                    tapered in and out over a few cycles, a silent tail after it;
``fast_sweep``      the same, over a few seconds;
``hits``            half-sine or haversine pulses of 1–5 ms at random times at least one
                    ring-down apart, heights varying ±30 %;
``hit_per_file``    one such pulse per file, several files.

Nothing here reads satmd: the periodic ones are built on their own DFT grid,
the sweeps with `scipy.signal.chirp`, the pulses analytically.
"""
from __future__ import annotations

import numpy as np
import scipy.signal as sg

FAMILIES = ("multisine", "pseudo_random", "periodic_chirp", "slow_sweep", "fast_sweep", "hits", "hit_per_file")
#: the kind satmd should detect for each family
EXPECTED_KIND = {"multisine": "periodic", "pseudo_random": "periodic", "periodic_chirp": "periodic",
                 "slow_sweep": "sweep", "fast_sweep": "sweep", "hits": "impact", "hit_per_file": "impact"}


def periodic_from_lines(period_samples, fs, spectrum):
    """A periodic force from the complex amplitudes of one period's rfft lines (at ``fs``).

    Evaluated at another rate by zero-padding the spectrum (exact band-limited interpolation);
    the rate must be a whole multiple of ``fs``.
    """
    spectrum = np.asarray(spectrum, complex)

    def force(n, rate):
        up = int(round(rate / fs))
        if abs(up * fs - rate) > 1e-9 * rate:
            raise ValueError("rate must be a whole multiple of fs")
        m = period_samples * up
        spec = np.zeros(m // 2 + 1, complex)
        spec[: spectrum.size] = spectrum
        one = np.fft.irfft(spec, m) * up
        reps = int(np.ceil(n / m))
        return np.tile(one, reps)[:n]
    return force


def multisine(fs, period_s, band, rng, odd=False):
    """(force, info): a random-phase multisine, flat amplitude at the (odd) lines within ``band``."""
    n = int(round(period_s * fs))
    k = np.arange(n // 2 + 1)
    f = k * fs / n
    on = (f >= band[0]) & (f <= band[1]) & (k >= 1)
    if odd:
        on &= (k % 2 == 1)
    spec = np.where(on, np.exp(2j * np.pi * rng.random(k.size)), 0)
    scale = np.sqrt(np.mean(np.fft.irfft(spec, n) ** 2))
    return periodic_from_lines(n, fs, spec / scale), {"period_samples": n, "lines": int(on.sum()),
                                                      "odd": bool(odd)}


def pseudo_random(fs, period_s, band, rng, order=4):
    """(force, info): one period of Butterworth band-passed white noise, repeated (filtered circularly)."""
    n = int(round(period_s * fs))
    spec = np.fft.rfft(rng.standard_normal(n))
    f = np.fft.rfftfreq(n, 1 / fs)
    sos = sg.butter(order, band, btype="bandpass", fs=fs, output="sos")
    _, h = sg.sosfreqz(sos, worN=f, fs=fs)
    spec = spec * np.abs(h)
    spec[0] = 0
    if n % 2 == 0:
        spec[-1] = 0  # the Nyquist line: not a real-valued interpolation otherwise
    scale = np.sqrt(np.mean(np.fft.irfft(spec, n) ** 2))
    return periodic_from_lines(n, fs, spec / scale), {"period_samples": n, "filter_order": order}


def _chirp(t, f0, t1, f1, law):
    return sg.chirp(t, f0, t1, f1, method=law)


def periodic_chirp(fs, period_s, band, rng, law="linear"):
    """(force, info): one chirp lo → hi per period (whole samples), repeated."""
    n = int(round(period_s * fs))
    period = n / fs

    def force(m, rate):
        t = np.arange(m) / rate
        return _chirp(np.mod(t, period), band[0], period, band[1], law) * np.sqrt(2)
    return force, {"period_samples": n, "law": law}


def sweep(duration_s, band, law="linear", direction="up", taper_cycles=5, tail_s=0.0):
    """(force, info): one swept sine over ``duration_s``, tapered over a few cycles at each end, then
    ``tail_s`` of silence (the response rings down before the record ends)."""
    f0, f1 = (band[0], band[1]) if direction == "up" else (band[1], band[0])

    def force(m, rate):
        t = np.arange(m) / rate
        x = _chirp(t, f0, duration_s, f1, law)
        w = np.ones(m)
        for edge, f_edge in ((0.0, f0), (duration_s, f1)):
            ramp = taper_cycles / f_edge
            d = np.abs(t - edge)
            inside = d < ramp
            w[inside] *= 0.5 - 0.5 * np.cos(np.pi * d[inside] / ramp)
        w[t > duration_s] = 0.0
        return np.sqrt(2) * x * w
    span = np.log2(band[1] / band[0])
    info = {"law": law, "direction": direction, "sweep_s": duration_s, "tail_s": tail_s,
            "rate_hz_per_s": (band[1] - band[0]) / duration_s if law == "linear" else None,
            "rate_octaves_per_s": span / duration_s if law == "logarithmic" else None}
    return force, info


def sweep_rate_at(info, band, f):
    """The sweep's rate in Hz/s when it passes ``f``."""
    if info["law"] == "linear":
        return (band[1] - band[0]) / info["sweep_s"]
    return f * np.log(2) * info["rate_octaves_per_s"]


def pulse(shape, width_s):
    """The unit pulse ``shape`` (half_sine or haversine) of ``width_s`` as a function of time from its start."""
    def p(t):
        inside = (t >= 0) & (t < width_s)
        out = np.zeros(t.size)
        if shape == "half_sine":
            out[inside] = np.sin(np.pi * t[inside] / width_s)
        else:  # haversine: 1 - cos over the width
            out[inside] = 0.5 - 0.5 * np.cos(2 * np.pi * t[inside] / width_s)
        return out
    return p


def hits(times_s, heights, shape, width_s):
    """(force, info): pulses at ``times_s`` with ``heights``."""
    p = pulse(shape, width_s)

    def force(m, rate):
        t = np.arange(m) / rate
        x = np.zeros(m)
        for t0, h in zip(times_s, heights):
            lo, hi = int(np.floor(t0 * rate)), int(np.ceil((t0 + width_s) * rate)) + 1
            lo, hi = max(lo, 0), min(hi, m)
            if lo < hi:
                x[lo:hi] += h * p(t[lo:hi] - t0)
        return x
    return force, {"hits": len(times_s), "shape": shape, "width_ms": 1e3 * width_s,
                   "times_s": [round(float(t), 4) for t in times_s],
                   "heights": [round(float(h), 4) for h in heights]}


def add_noise(channels, rel, rng):
    """White noise on every channel: ``rel[name]`` times that channel's RMS."""
    return {k: v + rel[k] * np.sqrt(np.mean(v * v)) * rng.standard_normal(v.size) for k, v in channels.items()}


__all__ = ["EXPECTED_KIND", "FAMILIES", "add_noise", "hits", "multisine", "periodic_chirp", "periodic_from_lines",
           "pseudo_random", "pulse", "sweep", "sweep_rate_at"]
