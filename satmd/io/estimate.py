"""FRFs and transmissibilities from time recordings: the local polynomial method (default) or Welch H1/H2.

Spectra are averaged over ``K`` windowed segments (``nperseg`` samples,
``overlap`` fraction, mean removed per segment):
``Gxx = <|X|²>``, ``Gyy = <|Y|²>``, ``Gxy = <X* Y>`` with NumPy's FFT
``X_k = Σ x_n e^{-2πikn/N}``. For ``x(t) = Re{X e^{+iωt}}`` the FFT returns
X itself, so ``H1 = Gxy / Gxx`` is the FRF in satmd's convention
(SPEC §1) with no conjugation; ``H2 = Gyy / Gyx``. The coherence is
``γ² = |Gxy|² / (Gxx Gyy)``.

Noise model (Bendat & Piersol, *Random Data*, §9.2): the random error of an
FRF estimate is circular, with standard deviation on each of Re and Im

    σ = |H| sqrt((1 − γ²) / (2 n_d γ²)),

written for H1 as ``σ² = (Gyy − |Gxy|²/Gxx) / (2 n_d Gxx)`` so that it stays
finite where γ² → 0. ``n_d`` is the number of independent averages: the
segment count reduced for overlap (Welch's correlation of overlapping
windows), minus one because the residual spectrum loses one degree of
freedom to the fitted H. A floor of 1e-10 max|H| keeps weights finite for
noise-free simulations.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import DataError
from ._common import atomic_write, warn
from .frfdata import FRFData
from .recording import Recording

_RESPONSES = {"acc1": "a1", "acc2": "a2"}
_FLOOR = 1e-10


def default_nperseg(fs_hz: float, n_samples: int) -> int:
    """Power-of-two segment length with ≈ 0.5 Hz resolution, shortened to give ≥ 16 averages.

    0.5 Hz resolves the rig's sharpest resonance (half-power width ≈ 1.6 Hz)
    with a Hann-window bias well below the noise of 16+ averages.

    Parameters
    ----------
    fs_hz : float
        Sample rate in Hz.
    n_samples : int
        Length of the record in samples.

    Returns
    -------
    int
        The smallest power of two ≥ 2·fs_hz (resolution ≤ 0.5 Hz), halved
        until the record holds at least 16 half-overlapping segments; never
        below 16 samples (so short records get fewer averages).
    """
    target = 2 ** int(np.ceil(np.log2(fs_hz * 2.0)))
    while target > 16 and 2 * n_samples // target - 1 < 16:
        target //= 2
    return int(max(16, min(target, n_samples)))


# periodic (DFT-even) cosine-sum windows, as scipy.signal.get_window builds them
_COSINE_WINDOWS = {
    "hann": (0.5, 0.5), "hanning": (0.5, 0.5), "hamming": (0.54, 0.46), "blackman": (0.42, 0.5, 0.08),
    "flattop": (0.21557895, 0.41663158, 0.277263158, 0.083578947, 0.006947368),
    "boxcar": (1.0,), "rectangular": (1.0,), "none": (1.0,),
}


def get_window(window, nperseg: int) -> np.ndarray:
    """The common windows in NumPy (importing scipy.signal takes seconds); others from scipy."""
    if isinstance(window, str) and window.lower() in _COSINE_WINDOWS:
        phase = 2.0 * np.pi * np.arange(nperseg) / nperseg
        return sum((-1) ** k * a * np.cos(k * phase) for k, a in enumerate(_COSINE_WINDOWS[window.lower()]))
    try:
        from scipy.signal import get_window as scipy_window

        return np.asarray(scipy_window(window, nperseg), dtype=float)
    except (ValueError, TypeError) as exc:
        raise DataError(f"window {window!r}: {exc}") from None


@dataclass(frozen=True)
class Spectra:
    """Averaged auto and cross spectra of a reference x and responses y (one-sided, unscaled)."""

    freq_hz: np.ndarray
    gxx: np.ndarray
    gxy: dict
    gyy: dict
    segments: int
    n_eff: float
    meta: dict = field(default_factory=dict)


def spectra(rec: Recording, reference: str, responses, nperseg=None, window="hann", overlap=0.5) -> Spectra:
    """Welch-averaged Gxx, Gxy, Gyy of ``reference`` against each of ``responses``."""
    n = rec.n_samples
    if n < 16:  # before nperseg: its range 8..n would read "8..5"
        raise DataError(f"{rec.meta.get('source', 'recording')}: {n} samples is too short to estimate spectra "
                        f"(at least 16)")
    nperseg = default_nperseg(rec.fs_hz, n) if nperseg is None else nperseg
    if isinstance(nperseg, bool) or int(nperseg) != nperseg or not 8 <= nperseg <= n:
        raise DataError(f"nperseg must be an integer in 8..{n} (the recording's length), got {nperseg}")
    nperseg = int(nperseg)
    if not 0 <= overlap < 1:
        raise DataError(f"overlap must be in [0, 1), got {overlap}")
    step = max(1, nperseg - int(round(overlap * nperseg)))
    segments = 1 + (n - nperseg) // step
    if segments < 2:
        raise DataError(f"nperseg={nperseg} leaves {segments} segment: need at least 2 averages for a "
                        f"coherence (recording has {n} samples)")
    win = get_window(window, nperseg)
    idx = np.arange(segments)[:, None] * step + np.arange(nperseg)

    def fft(name):
        seg = rec[name][idx]
        seg = seg - seg.mean(axis=1, keepdims=True)
        return np.fft.rfft(seg * win, axis=1)

    X = fft(reference)
    gxy, gyy = {}, {}
    for name in responses:
        Y = fft(name)
        gxy[name] = np.mean(np.conj(X) * Y, axis=0)
        gyy[name] = np.mean(np.abs(Y) ** 2, axis=0)
    meta = {"window": str(window), "nperseg": str(nperseg), "overlap": f"{overlap:g}", "segments": str(segments),
            "fs_hz": f"{rec.fs_hz:.12g}", "resolution_hz": f"{rec.fs_hz / nperseg:.6g}"}
    return Spectra(np.fft.rfftfreq(nperseg, 1.0 / rec.fs_hz), np.mean(np.abs(X) ** 2, axis=0), gxy, gyy,
                   segments, _effective_averages(win, step, segments), meta)


def _effective_averages(win, step, segments) -> float:
    """Welch's equivalent number of independent averages for overlapping windows."""
    norm = np.sum(win * win)
    total = 1.0
    for j in range(1, segments):
        lag = j * step
        if lag >= win.size:
            break
        rho = np.sum(win[:-lag] * win[lag:]) / norm
        total += 2.0 * (1.0 - j / segments) * rho * rho
    return segments / total


def _frf_from_spectra(s: Spectra, name: str, estimator: str):
    """(H, coherence, std) for one response."""
    gxx, gxy, gyy = s.gxx, s.gxy[name], s.gyy[name]
    n_d = max(s.n_eff - 1.0, 0.5)
    with np.errstate(divide="ignore", invalid="ignore"):
        coh = np.clip(np.abs(gxy) ** 2 / (gxx * gyy), 0.0, 1.0)
        if estimator == "H1":
            h = gxy / gxx
            var = np.maximum(gyy - np.abs(gxy) ** 2 / gxx, 0.0) / (2.0 * n_d * gxx)
        else:
            h = gyy / np.conj(gxy)
            var = np.abs(h) ** 2 * (1.0 - coh) / (2.0 * n_d * coh)
        std = np.sqrt(var)
    return h, coh, std


def _check_estimator(estimator):
    est = str(estimator).upper()
    if est not in ("H1", "H2"):
        raise DataError(f"estimator must be H1 or H2, got {estimator!r}")
    return est


def _usable(path, s: Spectra, arrays, band):
    """Mask of bins to keep: f > 0, inside the band, finite everywhere (force has energy)."""
    keep = s.freq_hz > 0
    lo, hi = band if band else (None, None)
    if lo is not None:
        keep &= s.freq_hz >= lo
    if hi is not None:
        keep &= s.freq_hz <= hi
    if not keep.any():
        raise DataError(f"band {lo}:{hi} Hz holds no frequency bin (0..{s.freq_hz[-1]:g} Hz)")
    finite = np.logical_and.reduce([np.isfinite(a) for a in arrays]) & (s.gxx > 0)
    dropped = int(np.count_nonzero(keep & ~finite))
    if dropped:
        warn(path, f"dropped {dropped} frequency bin(s) where the reference signal has no energy")
    keep &= finite
    if not keep.any():
        raise DataError(f"{path}: no frequency bin with excitation")
    return keep


def estimate_frf(recording: Recording, nperseg: int | None = None, window=None, overlap: float | None = None,
                 estimator: str | None = None, band=None, width_hz: float | None = None) -> FRFData:
    """FRFs a1 = acc1/force and a2 = acc2/force with std, coherence and measurement-chain findings.

    Parameters
    ----------
    recording : Recording
        With a ``force`` channel and ``acc1`` and/or ``acc2``.
    nperseg, window, overlap :
        Welch settings (samples per segment, any `scipy.signal.get_window`
        name, overlap fraction); giving any of them selects Welch H1.
    estimator : {"lpm", "H1", "H2"}, optional
        ``lpm``: the local polynomial method on the full record (the default:
        no window, full resolution, leakage and transient removed, std from the
        local residual; `satmd.io.lpm`). ``H1`` / ``H2``: Welch averaging
        (noise on the responses / on the force).
    band : (lo, hi), optional
        Band to keep in Hz, either may be None. The LPM also keeps to the band
        the force excites, and says so.
    width_hz : float, optional
        LPM window width in Hz (default: 0.3 Hz, or a fifth of the sharpest
        resonance's half-power width when that is narrower).

    Returns
    -------
    FRFData
        With ``std``, ``coherence`` and ``estimator`` (method, settings,
        ``noise_dof``, and ``measurement`` findings, see `satmd.io.chain`).
    """
    welch_given = any(v is not None for v in (nperseg, window, overlap))
    method = ("H1" if welch_given else "lpm") if estimator is None else str(estimator)
    if method.lower() == "lpm":
        if welch_given:
            raise DataError("nperseg, window and overlap are Welch settings: they do not apply to the lpm estimator")
        return _estimate_lpm(recording, band, width_hz)
    return _estimate_welch(recording, nperseg, "hann" if window is None else window,
                           0.5 if overlap is None else overlap, method, band)


def _kernel_rms_hz(win: np.ndarray, fs_hz: float):
    """RMS width of a window's power kernel |W(f)|², from Parseval: ∫f²|W|² = ∫|w'|²/(4π²).

    None for windows that do not taper to zero (boxcar): their sinc² kernel has no
    finite second moment, so no second-order model of their smoothing exists.
    """
    if win[0] > 0.01 * win.max():
        return None
    return float(fs_hz * np.sqrt(np.sum(np.diff(win) ** 2) / np.sum(win ** 2)) / (2 * np.pi))


def describe_estimate(data) -> str:
    """One line on how FRFs were estimated from a recording (empty for other FRFs)."""
    e = data.estimator
    if not e:
        return ""
    if e["method"] == "lpm":
        lo, hi = e["band_hz"]
        return (f"local polynomial method on the full {e['record_s']:g} s record, {e['points']} independent points "
                f"{lo:.1f}–{hi:.1f} Hz (the band the force excites), windows of {e['window_hz']:.3g} Hz, "
                f"noise from {e['noise_dof']:.0f} degrees of freedom")
    return (f"Welch {e['method'][6:]}, {e['window']} window, nperseg={e['nperseg']} ({e['resolution_hz']:.3g} Hz), "
            f"{e['segments']} averages")


def _check_force(recording: Recording):
    source = recording.meta.get("source", "recording")
    if "force" not in recording.channels:
        raise DataError(f"{source}: no force channel (output-only recording): FRFs need the force; "
                        f"transmissibilities A2/A1 do not (satmd.io.transmissibility)")
    responses = [r for r in _RESPONSES if r in recording.channels]
    if not responses:
        raise DataError(f"{source}: no acc1 or acc2 channel (has {', '.join(recording.channels)})")
    return source, responses


def _estimate_lpm(recording: Recording, band, width_hz) -> FRFData:
    from .chain import clipping_findings, lpm_findings
    from .lpm import lpm

    source, _ = _check_force(recording)
    if recording.n_samples < 256:
        raise DataError(f"{source}: {recording.n_samples} samples is too short for a local-polynomial FRF "
                        f"estimate (need at least 256)")
    est = lpm(recording, band=band, width_hz=width_hz)
    s = est.settings
    findings = clipping_findings(recording) + lpm_findings(est.freq_hz, est.frf, est.std, s,
                                                           est.force_noise_bias, band)
    floor = 1e-10 * max(np.max(np.abs(h)) for h in est.frf.values())
    std = {c: np.maximum(v, floor) for c, v in est.std.items()}
    info = {"method": "lpm", "reference": "Pintelon et al. 2010, local polynomial method",
            "record_s": round(s["record_s"], 6), "band_hz": [round(b, 6) for b in s["band_hz"]],
            "window_hz": round(s["window_hz"], 6), "bins_per_window": s["bins_per_window"],
            "degree": s["degree"], "points": int(est.freq_hz.size), "noise_dof": round(s["noise_dof"], 1),
            "force_noise_floor_detected": s["force_noise_floor"] is not None,
            "max_force_noise_bias": float(np.max(est.force_noise_bias)),
            "measurement": [f.to_dict() for f in findings]}
    meta = {"source": str(source), "estimator": "lpm", "resolution_hz": f"{s['window_hz']:.6g}",
            "band_hz": f"{s['band_hz'][0]:.6g}:{s['band_hz'][1]:.6g}", "noise_dof": f"{s['noise_dof']:.0f}",
            "noise": "local-polynomial residual, noise spectra smoothed over "
                     f"{s['smooth_windows']} windows"}
    return FRFData(est.freq_hz, est.frf, std, meta, coherence=est.coherence, estimator=info,
                   correlation=est.correlation)


def _estimate_welch(recording: Recording, nperseg, window, overlap, estimator, band) -> FRFData:
    from .chain import clipping_findings, welch_findings

    from .lpm import excited_band

    est = _check_estimator(estimator)
    source, responses = _check_force(recording)
    s = spectra(recording, "force", responses, nperseg, window, overlap)
    # bins the force never excited are noise over noise: keep to the excited band, as the LPM does
    lo, hi, _ = excited_band(recording["force"], recording.fs_hz)
    requested = band
    band = (lo if not band or band[0] is None else max(lo, band[0]),
            hi if not band or band[1] is None else min(hi, band[1]))
    if band[1] <= band[0]:
        raise DataError(f"band {requested[0]}:{requested[1]} Hz holds no frequency bin the force excites "
                        f"({lo:.1f}–{hi:.1f} Hz)")
    results = {r: _frf_from_spectra(s, r, est) for r in responses}
    keep = _usable(source, s, [a for res in results.values() for a in res], band)
    f = s.freq_hz[keep]
    channels, std, coh = {}, {}, {}
    for r, (h, g, sd) in results.items():
        ch = _RESPONSES[r]
        channels[ch] = h[keep]
        coh[ch] = g[keep]
        std[ch] = np.maximum(sd[keep], _FLOOR * np.max(np.abs(h[keep])))
    if s.segments < 8:
        warn(source, f"only {s.segments} averages: coherence and std are rough; use a shorter nperseg")
    resolution = recording.fs_hz / int(s.meta["nperseg"])
    findings = clipping_findings(recording) + welch_findings(f, channels, std, resolution, s.segments, est)
    meta = {"source": str(source), "estimator": est, **s.meta, "n_eff": f"{s.n_eff:.4g}",
            "noise": "coherence-based std (Bendat & Piersol)"}
    info = {"method": f"welch-{est}", "window": s.meta["window"], "nperseg": int(s.meta["nperseg"]),
            "kernel_rms_hz": _kernel_rms_hz(get_window(window, int(s.meta["nperseg"])), recording.fs_hz),
            "overlap": float(s.meta["overlap"]), "segments": s.segments, "resolution_hz": resolution,
            "points": int(f.size), "noise_dof": round(2 * max(s.n_eff - 1.0, 0.5), 1),
            "measurement": [x.to_dict() for x in findings]}
    return FRFData(f, channels, std, meta, coherence=coh, estimator=info)


@dataclass(frozen=True)
class Transmissibility:
    """T = response / reference (A2/A1 by default) from an output-only recording."""

    freq_hz: np.ndarray
    value: np.ndarray
    std: np.ndarray
    coherence: np.ndarray
    meta: dict = field(default_factory=dict)

    def model(self, rig=None, effects=()) -> np.ndarray:
        """The model's A2/A1 on this grid (`model_transmissibility`)."""
        return model_transmissibility(self.freq_hz, rig, effects)

    def __len__(self):
        return self.freq_hz.size

    def __repr__(self):
        return f"Transmissibility({self.freq_hz.size} points, {self.freq_hz[0]:g}..{self.freq_hz[-1]:g} Hz)"


def model_transmissibility(freq_hz, rig=None, effects=()) -> np.ndarray:
    """A2/A1 of the model: absorber over primary-mass acceleration (independent of the force).

    Parameters
    ----------
    freq_hz : array_like, shape (n_freq,)
        Frequencies in Hz.
    rig : Rig, optional
        The model (default: the paper's rig); fields may be arrays that
        broadcast to a batch shape.
    effects : sequence of Effect
        Missing-physics effects applied to the model (`satmd.frf`).

    Returns
    -------
    ndarray of complex, shape (n_freq,) or batch shape + (n_freq,)
        ``a2 / a1`` of `satmd.frf` at each frequency.
    """
    from ..physics import frf

    r = frf(freq_hz, rig, effects, outputs=("a1", "a2"))
    return r.a2 / r.a1


def transmissibility(recording: Recording, nperseg: int | None = None, window="hann", overlap: float = 0.5,
                     estimator: str = "H1", band=None, reference: str = "acc1",
                     response: str = "acc2") -> Transmissibility:
    """Transmissibility response/reference with coherence and std, as `estimate_frf` does for FRFs.

    H1 assumes the noise is on ``response``; with comparable noise on both
    accelerometers H1 is biased low and H2 high where the coherence drops.

    Parameters
    ----------
    recording : Recording
        With the ``reference`` and ``response`` channels; a force channel is
        not needed (output-only recordings).
    nperseg : int, optional
        Samples per Welch segment, 8..n_samples (default: `default_nperseg`);
        it must leave at least 2 segments.
    window : str or tuple
        Window of each segment: ``hann`` (default), ``hamming``, ``blackman``,
        ``flattop``, ``boxcar``, or any `scipy.signal.get_window` name.
    overlap : float
        Overlap fraction of consecutive segments, in [0, 1).
    estimator : {"H1", "H2"}
        ``H1 = Gxy/Gxx`` (noise on the response) or ``H2 = Gyy/Gyx`` (noise on
        the reference); case does not matter.
    band : (lo, hi), optional
        Band to keep in Hz, either may be None (default: every bin above 0 Hz).
    reference : str
        Channel in the denominator (default ``acc1``, the primary mass).
    response : str
        Channel in the numerator (default ``acc2``, the absorber).

    Returns
    -------
    Transmissibility
        ``freq_hz``, complex ``value``, ``std`` (on each of Re and Im, floored
        at 1e-10 max|T|) and ``coherence`` on the kept bins (f > 0, inside
        ``band``, where the reference has energy: others are dropped with a
        `DataWarning`); ``meta`` gives the source, estimator, channels and
        Welch settings (``nperseg``, ``segments``, ``resolution_hz``, ``n_eff``, ...).

    Raises
    ------
    DataError
        A missing channel, an unknown estimator or window, Welch settings the
        record cannot support, or a band that holds no usable bin.
    """
    est = _check_estimator(estimator)
    source = recording.meta.get("source", "recording")
    for name in (reference, response):
        recording[name]  # noqa: B018 - raises a DataError naming the missing channel
    s = spectra(recording, reference, [response], nperseg, window, overlap)
    h, g, sd = _frf_from_spectra(s, response, est)
    keep = _usable(source, s, [h, g, sd], band)
    t = h[keep]
    meta = {"source": str(source), "estimator": est, "reference": reference, "response": response, **s.meta,
            "n_eff": f"{s.n_eff:.4g}"}
    return Transmissibility(s.freq_hz[keep], t, np.maximum(sd[keep], _FLOOR * np.max(np.abs(t))), g[keep], meta)


def save_transmissibility(t: Transmissibility, path) -> Path:
    """CSV: ``# satmd-transmissibility v1`` then freq_hz,t_re,t_im,t_std,coherence.

    The ``meta`` entries go in ``# key: value`` lines before the header;
    floats have 17 significant digits, and the file is written atomically.

    Parameters
    ----------
    t : Transmissibility
        As `transmissibility` returns it.
    path : str or Path
        Target file (written as CSV whatever the suffix); an existing file is replaced.

    Returns
    -------
    Path
        The path written.
    """
    path = Path(path)
    lines = ["# satmd-transmissibility v1"]
    lines += [f"# {k}: {v}" for k, v in t.meta.items() if "\n" not in f"{k}{v}"]
    lines.append("freq_hz,t_re,t_im,t_std,coherence")
    table = np.column_stack([t.freq_hz, t.value.real, t.value.imag, t.std, t.coherence])
    lines += [",".join(f"{x:.17g}" for x in row) for row in table]
    with atomic_write(path, "w") as fh:
        fh.write("\n".join(lines) + "\n")
    return path
