"""FRFs from one full record by the Local Polynomial Method (Pintelon et al. 2010).

Why not Welch. Averaging windowed segments trades resolution for averages: the
Hann window smears a resonance of half-power width B_r over ≈ 2Δf and biases
its peak by about −(4/3)(Δf/B_r)² (Bendat & Piersol), a few per cent on a
lightly damped rig — far above the noise of a long record. A model fitted to
such an FRF "finds" physics that is only the window.

What the LPM does. The DFT of the whole record (no window) obeys, at every
bin k, ``Y(k) = H(k) X(k) + T(k) + V(k)``: T is the leakage/transient term of a
non-periodic record (smooth in k, it has the system's poles) and V the noise.
Around each centre bin, over ``2n+1`` neighbouring bins r = −n..n, H and T are
modelled as polynomials of degree ``R`` in r and fitted by linear least squares
(2(R+1) complex unknowns). The constant term of H's polynomial is the estimate at
the centre: full 1/T resolution, no window, leakage and transient removed. The
residual leaves ``q = 2n+1 − 2(R+1)`` complex degrees of freedom for the noise.

Independent points. Windows do not overlap, so every estimate uses its own bins
and the estimates are independent: a χ² over them is a χ² (overlapping windows
would correlate neighbours, and the tests downstream would lie).

Noise. The residual variance of each window is a noisy (q-dof) estimate of
``E|V|² = S_y + |H|² S_x``: sensor noise on the response plus force-sensor noise
seen through H. Both spectra are smooth in frequency, so ``S_y`` and ``S_x`` are
fitted locally over ±``smooth`` windows (weighted least squares, refined once)
and the variance of each estimate is that smooth level times the window's
``[(KᴴK)⁻¹]₀₀``. The std then rests on hundreds of degrees of freedom
(``noise_dof``), not on q.

Force noise also biases H low by S_x/S_xx (errors in variables, as for H1). Where
the force has a measurable noise floor outside the excited band, the bias is
estimated per window and removed; ``force_noise_bias`` records its size.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from numbers import Real

import numpy as np

from ..validation import Interval, Whole, validate_params
from ..conventions import RECORDING_CHANNELS, TINY
from ..errors import DataError
from .forcefloor import force_noise_floor, true_runs as _runs
from .memo import ContentMemo, fingerprint

_RESPONSES = RECORDING_CHANNELS


@dataclass(frozen=True)
class LPMEstimate:
    """Per-window LPM results for one recording (see the module docstring).

    Attributes
    ----------
    freq_hz : (M,) centre frequencies
    frf : dict channel -> (M,) complex estimate
    std : dict channel -> (M,) std on each of Re and Im
    coherence : dict channel -> (M,) signal / (signal + noise) power in the window
    force_noise_bias : (M,) relative bias removed (0 where no force-noise floor was seen)
    settings : dict of what was done (bins per window, degree, band, dof)
    correlation : {"a1,a2": (M,) complex} correlation of the two channels' errors (force noise)
    force_noise_bias_bound : (M,) relative bias that may remain: the bound when no floor could be told
        from the force (nothing corrected), else the uncertainty of the correction
    """

    freq_hz: np.ndarray
    frf: dict
    std: dict
    coherence: dict
    force_noise_bias: np.ndarray
    settings: dict = field(default_factory=dict)
    correlation: dict = field(default_factory=dict)
    force_noise_bias_bound: np.ndarray | None = None


def excited_band(force: np.ndarray, fs_hz: float, smooth_hz: float = 1.0, drop_db: float = 20.0):
    """(lo, hi, floor) of the band the force excites, from its spectrum.

    The force power, smoothed over ``smooth_hz``, is compared with its typical
    level in the excited region (95th percentile): bins within ``drop_db`` of it
    are excited; the band is the widest run of them (gaps under ``smooth_hz``
    bridged). ``floor`` is the per-bin noise power E|N_k|² of the force, or None
    when no noise floor can be told from the spectrum (`force_noise_floor`).
    """
    band = _excited(force, fs_hz, smooth_hz, drop_db)
    return band["lo"], band["hi"], band["floor"]["floor"]


#: what was found of recordings already read (the same force and settings: the same answer, computed once)
_EXCITED, _LPM = ContentMemo(), ContentMemo()


def _excited(force, fs_hz, smooth_hz=1.0, drop_db=20.0) -> dict:
    """The excited band (bins and Hz) and the force-noise floor verdict (`force_noise_floor`)."""
    force = np.asarray(force, dtype=float)
    return _EXCITED.answer(fingerprint(force, settings=(float(fs_hz), float(smooth_hz), float(drop_db))),
                           lambda: _find_excited(force, fs_hz, smooth_hz, drop_db))


def _find_excited(force, fs_hz, smooth_hz, drop_db) -> dict:
    n = force.size
    if not np.isfinite(fs_hz) or fs_hz <= 0:
        raise DataError(f"sample rate {fs_hz!r} Hz is not a positive number")
    if n < 64:
        raise DataError(f"the force has {n} samples: too few to find the band it excites (need at least 64)")
    X = np.fft.rfft(force - force.mean())
    f = np.fft.rfftfreq(n, 1.0 / fs_hz)
    power = np.abs(X) ** 2
    k = max(1, int(round(smooth_hz * n / fs_hz)))
    if k > f.size // 8:
        raise DataError(f"{n} samples at {fs_hz:g} Hz give {f.size} frequency lines of {fs_hz / n:.3g} Hz: "
                        f"too coarse to find the band the force excites (record at least {8 * smooth_hz:g} s)")
    smoothed = np.convolve(power, np.ones(k) / k, mode="same")
    smoothed[0] = 0.0
    level = np.percentile(smoothed[1:], 95)
    if not level > 0:
        raise DataError("the force is constant: it excites no frequency band")
    excited = smoothed > level * 10 ** (-drop_db / 10)
    runs = _runs(excited, bridge=k)
    if not runs:
        raise DataError("the force has no excited frequency band")
    i0, i1 = max(runs, key=lambda r: r[1] - r[0])
    # stay clear of the filter's edges: the smoothing spreads them over k bins
    i0, i1 = min(i0 + k, i1), max(i1 - k, i0)
    # The record is not periodic: the jump between its last and first sample leaks into the bins above the
    # band with power |jump|² / (4 sin²(πk/n)), which falls too slowly to stay under the force sensor's noise
    # floor (measured: +1.4 dB up to Nyquist for a 2.2 N jump in a 1 N RMS force, the floor put 44 % high).
    # The ramp between the two ends carries exactly that leakage: the floor is read with it removed. (Not
    # the band: below it the ramp's own 1/f² spectrum would stand out of a high-passed force.)
    ramp = force[0] + (force[-1] - force[0]) * np.arange(n) / (n - 1)
    verdict = force_noise_floor(np.abs(np.fft.rfft(force - ramp)) ** 2, f, i1 + 4 * k, level)
    return {"lo": float(f[i0]), "hi": float(f[i1]), "i0": i0, "i1": i1, "level": float(level), "floor": verdict}


@validate_params({"width_hz": [None, Interval(Real, 0, open="lo")], "degree": [Interval(Whole, 0)]})
def lpm(recording, band_hz=None, width_hz: float | None = None, degree: int = 2, smooth: int = 10,
        band=None) -> LPMEstimate:
    """LPM FRF estimates a1 = acc1/force, a2 = acc2/force on non-overlapping windows.

    Parameters
    ----------
    recording : Recording
        With ``force`` and ``acc1`` and/or ``acc2``.
    band_hz : (lo, hi), optional
        Band to estimate in Hz (either may be None); it is cut to the band the
        force excites (`excited_band`).
    width_hz : float, optional
        Width of each local window in Hz (at least 2(degree+1)+1 bins). Narrow
        windows keep the polynomial exact across resonances; wider ones give
        fewer, more precise points. Default: 0.3 Hz, narrowed to a fifth of
        the sharpest resonance's half-power width when that is smaller.
    degree : int
        Polynomial degree R of H and T in each window.
    smooth : int
        Half-width, in windows, of the local fit of the noise spectra.
    band : (lo, hi), optional
        Former name of ``band_hz`` (deprecated).

    Returns
    -------
    LPMEstimate
    """
    from ..errors import renamed_keyword
    from ..io.recdata import check_rate

    band_hz = renamed_keyword(band, band_hz, "lpm")

    check_rate(recording.meta.get("source", "recording"), recording.fs_hz)  # entry check (time in ms, ...)
    channels = ["force"] + [c for c in _RESPONSES if c in recording.channels]
    band_key = None if band_hz is None else tuple(None if b is None else float(b) for b in band_hz)
    settings = (channels, float(recording.fs_hz), band_key, width_hz, degree, smooth)  # scalars: exact reprs
    return _LPM.answer(fingerprint(*(recording[c] for c in channels), settings=settings),
                       lambda: _lpm(recording, band_hz, width_hz, degree, smooth))


def _lpm(recording, band_hz, width_hz, degree, smooth) -> LPMEstimate:
    from .chain import sharpest_resonance

    fs, n = recording.fs_hz, recording.n_samples
    x = recording["force"]
    found = _excited(x, fs)
    excited_lo, excited_hi, floor = found["lo"], found["hi"], found["floor"]  # floor: the verdict dict
    lo, hi = excited_lo, excited_hi
    band_lo, band_hi = (band_hz or (None, None))
    if band_lo is not None:
        lo = max(lo, float(band_lo))
    if band_hi is not None:
        hi = min(hi, float(band_hi))
    if hi <= lo:
        raise DataError(f"band {band_lo}:{band_hi} Hz holds no frequency bin the force excites "
                        f"({excited_lo:.1f}–{excited_hi:.1f} Hz)")
    spectra = {"force": np.fft.rfft(x - x.mean())}
    for name in _RESPONSES:
        if name in recording.channels:
            y = recording[name]
            spectra[name] = np.fft.rfft(y - y.mean())
    est = _local_fits(spectra, fs, n, lo, hi, width_hz or 0.3, degree, smooth, floor)
    if width_hz is None:
        sharp = sharpest_resonance(est.freq_hz, est.frf)
        if sharp is not None and est.settings["window_hz"] > sharp[1] / 5:
            narrower = _local_fits(spectra, fs, n, lo, hi, sharp[1] / 5, degree, smooth, floor)
            if narrower.settings["window_hz"] < est.settings["window_hz"]:
                est = narrower
    return est


def _local_fits(spectra, fs, n, lo, hi, width_hz, degree, smooth, verdict) -> LPMEstimate:
    """One LPM pass with windows of ``width_hz`` over lo..hi Hz (see the module docstring).

    ``verdict``: `force_noise_floor`'s answer; the force-noise bias is removed only where it found a floor.
    """
    floor = verdict["floor"]
    p = 2 * (degree + 1)
    half = max(p // 2, int(round(width_hz * n / fs / 2)))  # window 2·half+1 bins, > p
    width = 2 * half + 1
    df = fs / n
    first, last = int(np.ceil(lo / df)), int(np.floor(hi / df))
    centres = np.arange(first + half, last - half + 1, width)
    if centres.size < 4:
        raise DataError(f"the band {lo:g}..{hi:g} Hz holds {centres.size} LPM windows of {width} bins "
                        f"({width * df:.3g} Hz): record longer or choose a wider band")
    idx = centres[:, None] + np.arange(-half, half + 1)  # (M, W)
    u = np.arange(-half, half + 1) / max(half, 1)
    powers = u[None, :, None] ** np.arange(degree + 1)  # (1, W, R+1)
    Xw = spectra["force"][idx]
    xscale = np.sqrt(np.mean(np.abs(Xw) ** 2, axis=1))  # conditioning: X columns of unit size
    K = np.concatenate([Xw[..., None] / xscale[:, None, None] * powers,
                        np.broadcast_to(powers, Xw.shape + (degree + 1,))], axis=2)  # (M, W, p)
    Q, Rm = np.linalg.qr(K)
    Rinv = np.linalg.inv(Rm)
    c00 = np.sum(np.abs(Rinv[:, 0, :]) ** 2, axis=1) / xscale ** 2  # [(KᴴK)⁻¹]₀₀ in H's units
    q = width - p
    freq = centres * df
    sxx = np.mean(np.abs(Xw) ** 2, axis=1)
    bias = np.zeros(centres.size)
    bound = np.zeros(centres.size)
    if floor is not None:
        bias = floor / np.maximum(sxx - floor, TINY * sxx + TINY)
        bound = bias * verdict["floor_rel_std"]  # what the floor's own scatter leaves
    elif verdict["bound"] is not None:
        bound = np.minimum(verdict["bound"] / np.maximum(sxx - verdict["bound"], TINY * sxx + TINY), 1.0)
    out_h, out_std, out_coh, dof = {}, {}, {}, None
    raw_h, resid, var, raw_s2 = {}, {}, {}, {}
    for name, ch in _RESPONSES.items():
        if name not in spectra:
            continue
        Y = spectra[name][idx]
        theta = _solve(Q, Rinv, Y)
        raw_h[ch] = theta[:, 0] / xscale
        resid[ch] = Y - np.einsum("mwp,mp->mw", K, theta)
        raw_s2[ch] = np.sum(np.abs(resid[ch]) ** 2, axis=1) / max(q, 1)
    keep = np.ones(centres.size, bool)
    lev = np.sum(np.abs(Q) ** 2, axis=2)  # hat-matrix diagonal per window and bin
    for _ in range(3):  # lines (mains hum, ...) leave windows with one or two bins far above the noise
        for ch in raw_h:
            var[ch], dof = _smooth_noise(raw_s2[ch], np.abs(raw_h[ch]) ** 2, q, smooth, keep)
        lines = _line_windows(resid, var, lev, raw_s2, q, freq, 0.5 * width * df,
                              {c: np.abs(h) ** 2 * sxx for c, h in raw_h.items()}) & keep
        if not np.any(lines):
            break
        keep &= ~(lines | np.roll(lines, 1) | np.roll(lines, -1))  # and its neighbours, which the line leaks into
    for ch, h in raw_h.items():
        v = var[ch]
        out_h[ch] = (h * (1.0 + bias))[keep]  # errors in variables: the force noise pulled H towards zero
        out_std[ch] = np.sqrt(v * c00 / 2.0)[keep]
        signal = np.abs(h) ** 2 * sxx
        out_coh[ch] = (signal / (signal + v))[keep]
    correlation = {}
    if len(raw_h) == 2:
        from scipy import stats

        # windows whose residual is unusually large (a line's leakage, common to both channels) would pass for
        # force noise in the cross products: the correlation is fitted without them
        calm = keep & np.all([raw_s2[c] <= stats.chi2.isf(0.01, 2 * q) / (2 * q) * var[c] for c in raw_s2], axis=0)
        correlation["a1,a2"] = _channel_correlation(resid, raw_h, var, q, smooth, calm)[keep]
    dropped = [float(x) for x in freq[~keep]]
    freq, bias, bound = freq[keep], bias[keep], bound[keep]
    settings = {"method": "lpm", "record_s": n / fs, "bins_per_window": width, "window_hz": width * df,
                "degree": degree, "noise_dof_per_window": q, "noise_dof": dof, "smooth_windows": 2 * smooth + 1,
                "band_hz": [float(lo), float(hi)], "force_noise_floor": floor,
                "force_noise_status": verdict["status"], "force_noise_bound": verdict["bound"],
                "force_noise_slope_db_per_octave": verdict["slope_db_per_octave"],
                "force_noise_span_hz": verdict["span_hz"], "line_windows_hz": dropped}
    return LPMEstimate(freq, out_h, out_std, out_coh, bias, settings, correlation, bound)


def _line_windows(resid, var, lev, s2, q, freq, half_hz, signal, alpha: float = 1e-3):
    """Windows holding a spectral line the force does not explain (mains hum, a pick-up tone).

    Each residual bin, standardised by the noise model and its leverage, is
    exponential: |r_k|² / (σ² (1 − h_k)) ~ Exp(1). A bin beyond ln(bins / α) is
    not noise (Bonferroni at ``alpha``). A line puts one or two such bins in a
    window (two when it falls between bins) and leaves the rest of it at the
    noise. A window with more, or whose other bins still fail the χ² test, is a
    polynomial that cannot follow the FRF (a resonance narrower than the window),
    which is not the sensor chain's and is kept, in every channel: on a linear
    chain under random excitation, ζ = 1 % at 9.1 Hz in windows of 0.32 Hz, one
    bin of acc1 at the peak stood out alone while acc2 had five, and the peak
    had been dropped as interference. A window holding a multiple of 50 or 60 Hz
    whose residual fails the χ²_{2q} test is hum all the same: a strong hum line
    spreads over the whole window's fit. Residuals under 1e-6 of the signal's
    amplitude (``signal``: per-bin power) are round-off, not lines.
    """
    from scipy import stats

    mains = np.zeros(freq.size, bool)
    for m in (50.0, 60.0):
        mains |= np.abs(freq - m * np.maximum(np.round(freq / m), 1.0)) <= half_hz + 0.05
    lines = misfit = hum = np.zeros(freq.size, bool)
    n_bins = resid[next(iter(resid))].shape[1] if resid else 0
    for ch, r in resid.items():
        z = np.abs(r) ** 2 / np.maximum(var[ch][:, None] * (1.0 - lev), TINY)
        z[np.abs(r) ** 2 <= 1e-12 * signal[ch][:, None]] = 0.0
        out_bins = z > np.log(r.size / alpha)
        count = np.sum(out_bins, axis=1)
        limit = stats.chi2.isf(alpha / max(freq.size, 1), 2 * max(q, 1)) / (2 * max(q, 1))
        loud = s2[ch] > np.maximum(limit * var[ch], 1e-12 * signal[ch])
        # the rest of the window, its outlying bins left out: at the noise for a line, not for a misfit
        dof = np.maximum(q - count * q / max(n_bins, 1), 1.0)
        rest = np.sum(np.where(out_bins, 0.0, z), axis=1) / dof
        bent = rest > stats.chi2.isf(alpha / max(freq.size, 1), 2 * dof) / (2 * dof)
        lines = lines | ((count >= 1) & (count <= 2))
        misfit = misfit | (count > 2) | ((count >= 1) & bent)
        hum = hum | (mains & loud)
    return (lines & ~misfit) | hum


def _channel_correlation(resid, h, var, q, half, keep=None):
    """Correlation of the a1 and a2 estimates: both see the same force noise, E[V1 V2*] = S_x H1 H2*.

    S_x is fitted locally from the residuals' cross products (the same neighbourhood
    as the noise spectra); the correlation of the estimates is S_x H1 H2* / sqrt(v1 v2)
    (both share the window's regressors, so the [(KᴴK)⁻¹]₀₀ factors cancel).
    """
    s12 = np.sum(resid["a1"] * np.conj(resid["a2"]), axis=1) / max(q, 1)
    g12 = h["a1"] * np.conj(h["a2"])
    w = (1.0 if keep is None else keep) / np.maximum(var["a1"] * var["a2"], TINY)  # line windows: no weight
    kernel = np.ones(2 * min(half, (s12.size - 1) // 2) + 1)
    num = np.convolve(w * np.real(s12 * np.conj(g12)), kernel, mode="same")
    den = np.convolve(w * np.abs(g12) ** 2, kernel, mode="same")
    s_x = np.maximum(num / np.maximum(den, TINY), 0.0)
    rho = s_x * g12 / np.maximum(np.sqrt(var["a1"]) * np.sqrt(var["a2"]), TINY)
    scale = np.maximum(np.abs(rho) / 0.99, 1.0)  # a correlation stays inside the unit disc
    return rho / scale


def _solve(Q, Rinv, Y):
    """Least-squares θ = R⁻¹ Qᴴ y for every window."""
    qy = np.einsum("mwp,mw->mp", np.conj(Q), Y)
    return np.einsum("mpk,mk->mp", Rinv, qy)


def _smooth_noise(s2, g, q, half, keep=None):
    """Smooth E|V|² = a + b g (g = |H|²) by local weighted least squares; returns (variance, dof).

    Each raw s2 is a mean of q exponential-like terms, so its variance is
    ∝ (a + b g)²/q: the fit is weighted by the current model's inverse square and
    refined once. Negative a or b fall back to the one-term fit. Windows outside
    ``keep`` (lines) get no weight.
    """
    mask = np.ones_like(s2) if keep is None else keep.astype(float)
    kernel = np.ones(2 * min(half, (s2.size - 1) // 2) + 1)  # 'same' keeps the length only if kernel ≤ data

    def local(v):
        return np.convolve(v, kernel, mode="same")

    model = np.full_like(s2, np.median(s2[mask > 0]) if mask.any() else np.median(s2))
    for _ in range(3):
        w = mask / np.maximum(model * model, TINY)
        s00, s01, s11 = local(w), local(w * g), local(w * g * g)
        t0, t1 = local(w * s2), local(w * g * s2)
        det = s00 * s11 - s01 * s01
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (t0 * s11 - t1 * s01) / det
            b = (s00 * t1 - s01 * t0) / det
        bad = ~np.isfinite(a) | ~np.isfinite(b) | (a < 0) | (b < 0)
        a_only, b_only = t0 / np.maximum(s00, TINY), t1 / np.maximum(s11, TINY)
        res_a = local(w * (s2 - a_only * 1.0) ** 2)
        res_b = local(w * (s2 - b_only * g) ** 2)
        use_a = res_a <= res_b
        a = np.where(bad, np.where(use_a, a_only, 0.0), a)
        b = np.where(bad, np.where(use_a, 0.0, b_only), b)
        model = np.maximum(a + b * g, TINY)
    counts = local(mask)
    dof = float(2 * max(q, 1) * np.median(counts) - 4)
    return model, dof
