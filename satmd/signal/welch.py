"""Welch averaging: spectra, H1/H2 FRFs with coherence and the Bendat & Piersol std.

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

import warnings

from dataclasses import dataclass, field

import numpy as np

from ..errors import DataWarning, DataError
from ..io.recording import Recording

STD_FLOOR = 1e-10


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


def frf_from_spectra(s: Spectra, name: str, estimator: str):
    """(H, coherence, std) of one response from cross- and auto-spectra (H1 or H2, std from coherence)."""
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


def check_estimator(estimator):
    """The estimator's name, upper-cased ("H1" or "H2"); anything else is refused with a DataError."""
    est = str(estimator).upper()
    if est not in ("H1", "H2"):
        raise DataError(f"estimator must be H1 or H2, got {estimator!r}")
    return est


def usable_bins(path, s: Spectra, arrays, band_hz):
    """Mask of bins to keep: f > 0, inside the band, finite everywhere (force has energy)."""
    keep = s.freq_hz > 0
    lo, hi = band_hz if band_hz else (None, None)
    if lo is not None:
        keep &= s.freq_hz >= lo
    if hi is not None:
        keep &= s.freq_hz <= hi
    if not keep.any():
        raise DataError(f"band {lo}:{hi} Hz holds no frequency bin (0..{s.freq_hz[-1]:g} Hz)")
    finite = np.logical_and.reduce([np.isfinite(a) for a in arrays]) & (s.gxx > 0)
    dropped = int(np.count_nonzero(keep & ~finite))
    if dropped:
        warnings.warn(f"{path}: dropped {dropped} frequency bin(s) where the reference signal has no energy",
                      DataWarning, stacklevel=2)
    keep &= finite
    if not keep.any():
        raise DataError(f"{path}: no frequency bin with excitation")
    return keep


def kernel_rms_hz(win: np.ndarray, fs_hz: float):
    """RMS width of a window's power kernel |W(f)|², from Parseval: ∫f²|W|² = ∫|w'|²/(4π²).

    None for windows that do not taper to zero (boxcar): their sinc² kernel has no
    finite second moment, so no second-order model of their smoothing exists.
    """
    if win[0] > 0.01 * win.max():
        return None
    return float(fs_hz * np.sqrt(np.sum(np.diff(win) ** 2) / np.sum(win ** 2)) / (2 * np.pi))
