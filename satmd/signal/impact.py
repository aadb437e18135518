"""FRFs of an impact test: H1 over hits, std from the hit-to-hit scatter.

Each kept hit (`satmd.signal.excitation`) gives a segment that starts just before
the pulse and lasts until the next hit (one length for all). The force is
windowed to its pulse (a force window: the load cell's noise between hits
carries no information), the responses are not windowed when they ring down
within the segment; when they do not, an exponential window is applied to both:
the estimate is then ``H(iω + 1/τ)`` exactly (the window multiplies the impulse
response), reported as a measurement finding and carried in the estimator's
``window_decay_s`` so that every fit evaluates its model there.

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
TAIL_UNDER_NOISE = 0.02  # what an exponential window leaves of a cut tail, as a share of the noise
MAX_DECAYS = 10.0  # the strongest window: e^-10 at the segment's end
FORCE_BAND_DB = 20.0
SMOOTH = 5  # lines the hit-to-hit noise variance is averaged over


def _force_window(x, fs, start, peak, length):
    """The pulse of one hit, from where it rises to where it stays below 1 % of its height, cosine tapers on
    either side; zeros elsewhere (the load cell's noise there carries nothing and biases H1 low)."""
    seg = np.asarray(x[start:start + length], float)
    base = np.median(seg[int(0.5 * length):]) if length > 16 else 0.0
    seg = seg - base
    p = peak - start
    height = abs(seg[p])
    look = seg[p:p + max(int(0.05 * fs), 4)]
    loud = np.flatnonzero(np.abs(look) >= 0.01 * height)
    end = min(length, p + int(loud[-1]) + 1)
    rise = p - int(np.argmax(np.abs(seg[:p + 1][::-1]) < 0.01 * height))  # where the pulse leaves the noise
    taper = max(4, int(0.002 * fs), end - rise)
    w = np.zeros(length)
    w[rise:end] = 1.0
    stop = min(length, end + taper)
    w[end:stop] = 0.5 * (1 + np.cos(np.pi * np.arange(stop - end) / taper))
    first = max(0, rise - taper)  # the lead-in holds only the load cell's noise: tapered in, not kept whole
    w[first:rise] = 0.5 * (1 - np.cos(np.pi * np.arange(rise - first) / max(rise - first, 1)))
    return seg * w


def windowed_force(recording, excitation):
    """The record's force with every kept hit's pulse windowed (`_force_window`) and zeros between them."""
    fs, L = recording.fs_hz, excitation.segment_samples
    out = np.zeros(recording.n_samples)
    for s, p in excitation.hits:
        seg = _force_window(recording["force"], fs, s, p, L)
        out[s:s + seg.size] = seg
    return out


def whole_record_frf(recording, excitation, responses, band_hz=None):
    """(freq_hz, frf, std, coherence, noise_dof, findings) of hits taken as one transient of the whole record.

    When the rig rests at the record's start and end and no hit was dropped, the responses of all hits
    superpose: ``Y = G X`` over the whole record with the force windowed to its pulses, and no segment
    is cut while a response still rings (the leakage of per-hit segments hits too close together).
    `satmd.signal.sweepfrf.sweep_frf` fits G locally, its noise from the local residual.
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
    if band_hz:
        lo = lo if band_hz[0] is None else max(lo, band_hz[0])
        hi = hi if band_hz[1] is None else min(hi, band_hz[1])
    if hi <= lo:
        raise DataError(f"the hits excite {f[idx[0]]:.4g}–{f[idx[-1]]:.4g} Hz: nothing left in {band_hz[0]}:{band_hz[1]} Hz")
    freq, frf, std, coh, dof = sweep_frf(recording, responses, (lo, hi), force=x)
    return freq, frf, std, coh, dof, []


def impact_frf(recording, excitation, responses, band_hz=None):
    """(freq_hz, frf, std, coherence, noise_dof, findings) of an impact recording.

    Parameters
    ----------
    recording : Recording
    excitation : an impact `satmd.signal.excitation.Excitation`
    responses : recording channels (``acc1``, ``acc2``)
    band_hz : (lo, hi) Hz, either may be None

    Returns
    -------
    tuple
        Frequencies; per FRF channel the H1 estimate, the std of each of its
        parts and the coherence over hits; the noise degrees of freedom; and the
        `MeasurementFinding` list of the windows.
    """
    fs, L = recording.fs_hz, excitation.segment_samples
    hits = list(excitation.hits)
    pulses = np.array([_force_window(recording["force"], fs, s, p, L) for s, p in hits])
    X = np.fft.rfft(pulses, axis=1)
    segs = {r: np.array([np.asarray(recording[r][s:s + L], float) for s, _ in hits]) for r in responses}
    p0 = min(p - s for s, p in hits)  # the pulse's place in its segment: the response starts there, not before
    # the sensor's offset: the segment's rest before the pulse rises (a window would spread an offset the mean of a cut
    # ring leaves, e.g. into c·W(ω) over the low lines), else the segment's mean
    segs = {r: v - (v[:, :p0 // 2] if p0 >= 16 else v).mean(axis=1, keepdims=True) for r, v in segs.items()}
    findings = []
    tenth = max(1, L // 10)
    start = {r: max(float(np.sqrt(np.mean(v[:, p0:p0 + tenth] ** 2))), TINY) for r, v in segs.items()}
    ring = max(float(np.sqrt(np.mean(v[:, -tenth:] ** 2))) / start[r] for r, v in segs.items())
    # the noise, as a share of the start: the quiet lead-in before the first hit, when there is one
    lead = hits[0][0]
    quiet = max((float(np.std(np.asarray(recording[r][:lead], float))) / start[r] for r in responses),
                default=0.0) if lead >= 16 else 0.0
    # rung down: to 60 dB below the start, or its tail has stopped falling (the last tenth no quieter than the
    # one before it, within its scatter: the noise floor). A tail still falling, even under the noise, leaks
    # into every hit alike (no average takes it out), while the window is modelled exactly: so it is windowed.
    flat = min(float(np.sqrt(np.mean(v[:, -tenth:] ** 2)) / max(np.sqrt(np.mean(v[:, -2 * tenth:-tenth] ** 2)), TINY))
               for v in segs.values()) > 1.0 - 3.0 / np.sqrt(2.0 * tenth * len(hits))
    w = np.ones(L)
    # one hit's noise, white: the quiet lead-in when there is one (a tail still ringing is no noise), else the tail
    quiet_var = {r: float(np.var(np.asarray(recording[r][:lead], float))) if lead >= 16
                 else float(np.var(v[0, -max(8, L // 4):])) for r, v in segs.items()}
    flat = flat and not (quiet > 0 and ring > 2.0 * quiet)  # a tail twice the lead-in's noise still rings
    if ring > DECAYED and not flat:
        # a tail cut at amplitude A leaks ~ (A/σ)·(τ_d/2)·sqrt(fs/T) noise std into the lines at its resonance,
        # alike in every hit: the window takes what is left of it to a fiftieth of the noise (the quiet lead-in's,
        # or the tail's own level when there is none), so the estimate is unbiased within its std
        floor = min(quiet, ring) if quiet > 0 else ring
        tau = L / fs / min(np.log(ring / (TAIL_UNDER_NOISE * floor)), MAX_DECAYS)
        w = np.exp(-np.arange(L) / fs / tau)
        X = np.array([np.fft.rfft(np.fft.irfft(x, L) * w) for x in X])
        segs = {r: v * w for r, v in segs.items()}
        findings.append(MeasurementFinding(
            "exponential_window",
            f"the responses have not rung down by the end of each hit's {L / fs:.3g} s segment "
            f"({100 * ring:.2g} % of their starting RMS): an exponential window (τ = {tau:.3g} s) was applied, "
            f"which adds a damping ratio of 1/(τω) = {1 / (tau * 2 * np.pi):.3g}/f[Hz] to every resonance; "
            "every fit sees the model through the same window (at s = iω + 1/τ), so it is not taken for damping",
            "leave longer between hits (or record longer after a single hit) so that the response rings down",
            corrected=True, values={"decay_s": tau}))
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
    if band_hz:
        keep &= (f >= (band_hz[0] if band_hz[0] is not None else -np.inf)) & (f <= (band_hz[1] if band_hz[1] is not None
                                                                               else np.inf))
    if findings:  # windowed: an offset's error c spreads as c·fs·τ/(1 + iωτ), over the lines below ~3/(2πτ)
        keep &= f >= 3.0 * fs / (2.0 * np.pi * np.sum(w))
    # a window correlates neighbouring lines (its noise bandwidth, in lines): keep lines that are independent
    step = max(1, int(round(L * np.sum(w ** 4) / np.sum(w ** 2) ** 2)))
    keep &= (k - lo_i) % step == 0
    if keep.sum() < 2:
        raise DataError(f"the hits excite {f[lo_i]:.4g}–{f[hi_i]:.4g} Hz (within {FORCE_BAND_DB:g} dB of the force's "
                        f"peak): no band left{'' if not band_hz else f' in {band_hz[0]}:{band_hz[1]} Hz'}")
    n = len(hits)
    # the load cell's noise (each segment's second half, after the pulse), per line over the force window
    var_f = float(np.mean([np.var(np.asarray(recording["force"][s + L // 2:s + L], float)) for s, _ in hits]))
    var_x = var_f * np.sum(w[pulses[0] != 0] ** 2)
    Sxx = np.sum(np.abs(X) ** 2, axis=0)
    frf, std, coh = {}, {}, {}
    for r, v in segs.items():
        Y = np.fft.rfft(v, axis=1)
        Sxy = np.sum(Y * np.conj(X), axis=0)
        H = Sxy / np.maximum(Sxx, TINY)
        # the force's noise over the force window reaches the residual through H: |H|² v_x, as sharp as the
        # resonance, so it is added as it is, and only the rest (the response's noise, smooth) is smoothed
        through_h = np.abs(H) ** 2 * var_x
        if n >= 2:  # smoothed over 5 independent lines: few hits give few dof
            width = SMOOTH * step
            rest = np.sum(np.abs(Y - H * X) ** 2, axis=0) / (n - 1) - through_h
            var_y = np.maximum(np.convolve(rest, np.ones(width) / width, "same"), 0.0) + through_h
        else:  # one hit: the noise of its lead-in or quiet tail, white, through the window
            var_y = quiet_var[r] * np.sum(w ** 2) + through_h
        ch = RECORDING_CHANNELS[r]
        frf[ch] = H[keep]
        std[ch] = np.sqrt(var_y / np.maximum(Sxx, TINY) / 2.0)[keep]
        Syy = np.sum(np.abs(Y) ** 2, axis=0)
        coh[ch] = np.clip(np.abs(Sxy) ** 2 / np.maximum(Sxx * Syy, TINY), 0.0, 1.0)[keep]
    dof = 2.0 * (n - 1) * SMOOTH if n >= 2 else 2.0 * (lead if lead >= 16 else max(L // 4, 8))
    return f[keep], frf, std, coh, dof, findings


__all__ = ["impact_frf"]
