"""FRFs of an impact test: H1 over hits, std from the hit-to-hit scatter.

Each kept hit (`satmd.io.excitation`) gives a segment that starts just before
the pulse and lasts until the next hit (one length for all). The force is
windowed to its pulse (a force window: the load cell's noise between hits
carries no information), the responses are not windowed when they ring down
within the segment; when they do not, an exponential window is applied to both
and the damping it adds, ``Δζ = 1 / (τ ω)``, is reported as a measurement finding.

With ``n`` hits, ``H1 = Σ Y_i X_i* / Σ |X_i|²``; the response noise per line is
the scatter of ``Y_i − H1 X_i`` (n − 1 degrees of freedom per part), and
``var(H1) = σ² / Σ |X_i|²``. One hit alone takes its noise from the quiet tail
of its own segment (white noise assumed). The band is where the mean force
spectrum stays within 20 dB of its peak (the hammer tip's usable band).
"""
from __future__ import annotations

import numpy as np

from ..conventions import RECORDING_CHANNELS, TINY
from ..errors import DataError
from .chain import MeasurementFinding

DECAYED = 1e-3  # the response's RMS over a segment's last tenth, as a share of its first tenth: rung down
FORCE_BAND_DB = 20.0
SMOOTH = 5  # lines the hit-to-hit noise variance is averaged over


def _force_window(x, fs, start, peak, length):
    """The pulse of one hit, to where it stays below 1 % of its height, then a cosine taper; zeros after."""
    seg = np.asarray(x[start:start + length], float)
    base = np.median(seg[int(0.5 * length):]) if length > 16 else 0.0
    seg = seg - base
    p = peak - start
    height = abs(seg[p])
    look = seg[p:p + max(int(0.05 * fs), 4)]
    loud = np.flatnonzero(np.abs(look) >= 0.01 * height)
    end = min(length, p + int(loud[-1]) + 1)
    taper = max(4, int(0.002 * fs), end - (p - int(np.argmax(np.abs(seg[:p + 1][::-1]) < 0.01 * height))))
    w = np.zeros(length)
    w[:end] = 1.0
    stop = min(length, end + taper)
    w[end:stop] = 0.5 * (1 + np.cos(np.pi * np.arange(stop - end) / taper))
    return seg * w


def windowed_force(recording, excitation):
    """The record's force with every kept hit's pulse windowed (`_force_window`) and zeros between them."""
    fs, L = recording.fs_hz, excitation.segment_samples
    out = np.zeros(recording.n_samples)
    for s, p in excitation.hits:
        seg = _force_window(recording["force"], fs, s, p, L)
        out[s:s + seg.size] = seg
    return out


def whole_record_frf(recording, excitation, responses, band=None):
    """(freq_hz, frf, std, coherence, noise_dof, findings) of hits taken as one transient of the whole record.

    When the rig rests at the record's start and end and no hit was dropped, the responses of all hits
    superpose: ``Y = G X`` over the whole record with the force windowed to its pulses, and no segment
    is cut while a response still rings (the leakage of per-hit segments hits too close together).
    `satmd.io.sweepfrf.sweep_frf` fits G locally, its noise from the local residual.
    """
    from .sweepfrf import sweep_frf

    x = windowed_force(recording, excitation)
    X = np.fft.rfft(x)
    fs, n = recording.fs_hz, recording.n_samples
    f = np.fft.rfftfreq(n, 1.0 / fs)
    power = np.abs(X) ** 2
    usable = (np.arange(f.size) >= 1) & (f <= 0.8 * fs / 2)
    smooth = np.convolve(power, np.ones(15) / 15, "same")
    on = usable & (smooth >= np.max(smooth[usable]) * 10 ** (-FORCE_BAND_DB / 10))
    idx = np.flatnonzero(on)
    lo, hi = float(f[idx[0]]), float(f[idx[-1]])
    if band:
        lo = lo if band[0] is None else max(lo, band[0])
        hi = hi if band[1] is None else min(hi, band[1])
    if hi <= lo:
        raise DataError(f"the hits excite {f[idx[0]]:.4g}–{f[idx[-1]]:.4g} Hz: nothing left in {band[0]}:{band[1]} Hz")
    freq, frf, std, coh, dof = sweep_frf(recording, responses, (lo, hi), force=x)
    return freq, frf, std, coh, dof, []


def impact_frf(recording, excitation, responses, band=None):
    """(freq_hz, frf, std, coherence, noise_dof, findings) of an impact recording.

    Parameters
    ----------
    recording : Recording
    excitation : an impact `satmd.io.excitation.Excitation`
    responses : recording channels (``acc1``, ``acc2``)
    band : (lo, hi) Hz, either may be None

    Returns
    -------
    tuple
        Frequencies; per FRF channel the H1 estimate, the std of each of its
        parts and the coherence over hits; the noise degrees of freedom; and the
        `MeasurementFinding` list of the windows.
    """
    fs, L = recording.fs_hz, excitation.segment_samples
    hits = list(excitation.hits)
    X = np.array([np.fft.rfft(_force_window(recording["force"], fs, s, p, L)) for s, p in hits])
    segs = {r: np.array([np.asarray(recording[r][s:s + L], float) for s, _ in hits]) for r in responses}
    segs = {r: v - v.mean(axis=1, keepdims=True) for r, v in segs.items()}
    findings = []
    tenth = max(1, L // 10)
    ring = max(float(np.sqrt(np.mean(v[:, -tenth:] ** 2)) / max(np.sqrt(np.mean(v[:, :tenth] ** 2)), TINY))
               for v in segs.values())
    # rung down: to 60 dB below the start, or into the noise the quiet lead-in before the first hit shows
    lead = hits[0][0]
    quiet = max((float(np.std(np.asarray(recording[r][:lead], float)))
                 / max(np.sqrt(np.mean(segs[r][:, :tenth] ** 2)), TINY) for r in responses), default=0.0) \
        if lead >= max(16, int(0.05 * fs)) else 0.0
    # or its tail has stopped falling: the last tenth no quieter than the one before it, the noise floor
    flat = min(float(np.sqrt(np.mean(v[:, -tenth:] ** 2)) / max(np.sqrt(np.mean(v[:, -2 * tenth:-tenth] ** 2)), TINY))
               for v in segs.values()) > 1.0 - 3.0 / np.sqrt(2.0 * tenth * len(hits))  # within its scatter
    if ring > max(DECAYED, 3.0 * quiet) and not flat:
        tau = L / fs / np.log(1.0 / DECAYED)  # the window falls to DECAYED at the segment's end
        w = np.exp(-np.arange(L) / fs / tau)
        X = np.array([np.fft.rfft(np.fft.irfft(x, L) * w) for x in X])
        segs = {r: v * w for r, v in segs.items()}
        findings.append(MeasurementFinding(
            "exponential_window",
            f"the responses have not rung down by the end of each hit's {L / fs:.3g} s segment "
            f"({100 * ring:.0f} % of their starting RMS): an exponential window (τ = {tau:.3g} s) was applied, "
            f"which adds a damping ratio of 1/(τω) = {1 / (tau * 2 * np.pi):.3g}/f[Hz] to every resonance",
            "leave longer between hits (or record longer after a single hit) so that the response rings down"))
    f = np.fft.rfftfreq(L, 1.0 / fs)
    power = np.mean(np.abs(X) ** 2, axis=0)
    k = np.arange(f.size)
    usable = (k >= 1) & (f <= 0.8 * fs / 2)
    top = np.max(power[usable])
    on = usable & (power >= top * 10 ** (-FORCE_BAND_DB / 10))
    # the band: the run of excited lines that holds the spectrum's peak
    peak = int(np.argmax(np.where(usable, power, -1)))
    lo_i, hi_i = peak, peak
    while lo_i - 1 >= 1 and on[lo_i - 1]:
        lo_i -= 1
    while hi_i + 1 < f.size and on[hi_i + 1]:
        hi_i += 1
    keep = np.zeros(f.size, bool)
    keep[lo_i:hi_i + 1] = True
    if band:
        keep &= (f >= (band[0] if band[0] is not None else -np.inf)) & (f <= (band[1] if band[1] is not None
                                                                               else np.inf))
    if keep.sum() < 2:
        raise DataError(f"the hits excite {f[lo_i]:.4g}–{f[hi_i]:.4g} Hz (within {FORCE_BAND_DB:g} dB of the force's "
                        f"peak): no band left{'' if not band else f' in {band[0]}:{band[1]} Hz'}")
    n = len(hits)
    Sxx = np.sum(np.abs(X) ** 2, axis=0)
    frf, std, coh = {}, {}, {}
    for r, v in segs.items():
        Y = np.fft.rfft(v, axis=1)
        Sxy = np.sum(Y * np.conj(X), axis=0)
        H = Sxy / np.maximum(Sxx, TINY)
        if n >= 2:  # smoothed over 5 lines: the sensor noise is smooth in frequency, and few hits give few dof
            var_y = np.convolve(np.sum(np.abs(Y - H * X) ** 2, axis=0) / (n - 1), np.ones(SMOOTH) / SMOOTH, "same")
        else:  # one hit: the noise of its quiet tail (last quarter), white
            tail = v[0, -max(8, L // 4):]
            var_y = np.full(f.size, L * np.var(tail))
        ch = RECORDING_CHANNELS[r]
        frf[ch] = H[keep]
        std[ch] = np.sqrt(var_y / np.maximum(Sxx, TINY) / 2.0)[keep]
        Syy = np.sum(np.abs(Y) ** 2, axis=0)
        coh[ch] = np.clip(np.abs(Sxy) ** 2 / np.maximum(Sxx * Syy, TINY), 0.0, 1.0)[keep]
    dof = 2.0 * (n - 1) * SMOOTH if n >= 2 else 2.0 * max(L // 4, 8)
    return f[keep], frf, std, coh, dof, findings


__all__ = ["impact_frf"]
