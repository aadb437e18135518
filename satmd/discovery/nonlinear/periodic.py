"""Designed excitation judged: the detection lines of a multisine, and one-mode level fits.

The estimates come from `satmd.signal.periodic` (the mean over periods, the best linear approximation
over realisations and its noise and nonlinear variances, Pintelon & Schoukens ch. 3-4); here they are
tested:

- at the detection lines (not excited: the odd ones left out of an odd
  multisine, every even one, the lines above the band) a linear system puts
  nothing but noise: ``P |mean_p Y(k)|² / σ²(k)`` is F(2, 2(P−1)) there, and
  `detection_lines_test` scans it over frequency (odd and even apart).

One-mode fits (`one_mode_fit`): on a generic input→output record (a circuit, a
single structure) the level dependence is read from a one-mode FRF
``A / (ωn² − ω² + 2iζωn ω) + B`` fitted near the peak at every level.
"""
from __future__ import annotations

from ...conventions import TINY

import numpy as np

from .stats import NonlinearTest, chi2_score, band_scan


def detection_lines_test(u, y, lines, fs_hz: float, band_hz=None, alpha: float = 1e-3,
                         name: str = "distortion_lines") -> NonlinearTest:
    """Output at the lines the multisine leaves out, against the noise seen over periods.

    Parameters
    ----------
    u, y : (M, P, N) periods (P ≥ 2)
    lines : excited lines
    fs_hz : sample rate
    band_hz : (lo, hi) Hz of detection lines to use (default: up to 3x the highest excited line)
    alpha : level
    name : test name

    Returns
    -------
    NonlinearTest
        ``details``: ``odd_ratio`` and ``even_ratio`` (mean output power over
        noise power at the odd and even detection lines; 1 for a linear system).
    """
    y = np.asarray(y, float)
    if y.ndim == 2:
        y = y[None]
    M, P, N = y.shape
    if P < 2:
        return NonlinearTest(name, 1.0, [], alpha, {"reason": "needs at least 2 periods"})
    Y = np.fft.rfft(y - y.mean(axis=2, keepdims=True), axis=2)
    k = np.arange(Y.shape[2])
    lines = np.asarray(lines, int)
    lo, hi = band_hz if band_hz is not None else (0.0, 3 * lines.max() * fs_hz / N)
    mask = np.ones(k.size, bool)
    mask[lines] = False
    mask[0] = False
    mask &= (k * fs_hz / N >= lo) & (k * fs_hz / N <= hi) & (k < N // 2)
    det = np.flatnonzero(mask)
    if det.size < 4:
        return NonlinearTest(name, 1.0, [], alpha, {"reason": "no detection lines: the force reaches every line "
                                                     "up to 1.5x the band"})
    mean = Y[..., det].mean(axis=1)  # (M, D)
    var = Y[..., det].var(axis=1, ddof=1)  # per-period noise variance
    from scipy import stats

    F = P * np.abs(mean) ** 2 / np.maximum(var, TINY)  # F(2, 2(P-1)) per realisation and line
    score = chi2_score(stats.f.sf(F, 2, 2 * (P - 1)), 2).sum(axis=0)
    freq = det * fs_hz / N
    p, bands, p_g, p_b = band_scan(freq, score, 2 * M, alpha)
    odd = det % 2 == 1
    ratio = (F.mean(axis=0) * (P - 2) / P) if P > 2 else F.mean(axis=0)  # E[F] = (P-1)/(P-2)·… ≈ 1 under H0
    details = {"odd_ratio": float(ratio[odd].mean()) if odd.any() else float("nan"),
               "even_ratio": float(ratio[~odd].mean()) if (~odd).any() else float("nan"),
               "p_global": p_g, "p_band": p_b, "lines": int(det.size)}
    return NonlinearTest(name, p, bands, alpha, details)


def one_mode_fit(freq, H, std, band_hz=None) -> dict:
    """Fit ``A / (ωn² − ω² + 2iζωn ω) + B`` (A, B complex) near the peak of |H|.

    Parameters
    ----------
    freq : (n,) Hz
    H : (n,) complex FRF
    std : (n,) std per Re/Im (weights)
    band_hz : (lo, hi) Hz fitted (default 0.7–1.35 × the peak frequency)

    Returns
    -------
    dict
        ``f_n_hz``, ``zeta``, their std (``f_n_std``, ``zeta_std``), ``chi2_reduced``.
    """
    from scipy.optimize import least_squares

    from ...numerics import jacobian_covariance

    freq, H, std = np.asarray(freq, float), np.asarray(H, complex), np.asarray(std, float)
    fpk = float(freq[np.argmax(np.abs(H))])
    lo, hi = band_hz if band_hz is not None else (0.7 * fpk, 1.35 * fpk)
    sel = (freq >= lo) & (freq <= hi)
    f, h, s = freq[sel], H[sel], np.maximum(std[sel], TINY)
    w = 2 * np.pi * f

    def linear_part(fn, zeta):
        wn = 2 * np.pi * fn
        basis = np.stack([1.0 / (wn ** 2 - w ** 2 + 2j * zeta * wn * w), np.ones_like(w)], axis=1)
        A = basis / s[:, None]
        coef, *_ = np.linalg.lstsq(A, h / s, rcond=None)
        return basis @ coef

    def resid(t):
        r = (linear_part(t[0], t[1]) - h) / s
        return np.concatenate([r.real, r.imag])

    best = None
    for z0 in (0.01, 0.05, 0.15):
        sol = least_squares(resid, [fpk, z0], bounds=([lo, 1e-4], [hi, 0.9]), x_scale="jac")
        if best is None or sol.cost < best.cost:
            best = sol
    assert best is not None  # three starts
    dof = max(2 * sel.sum() - 6, 1)
    sd = np.sqrt(np.maximum(np.diag(jacobian_covariance(best.jac, max(2 * best.cost / dof, 1.0))), 0.0))
    return {"f_n_hz": float(best.x[0]), "zeta": float(best.x[1]), "f_n_std": float(sd[0]),
            "zeta_std": float(sd[1]), "chi2_reduced": float(2 * best.cost / dof)}


def without_linear_response(u, y, lines) -> np.ndarray:
    """The output periods less what the best linear approximation predicts from the force at every line.

    The force is not zero between a design's lines (the shaker's interaction, a filter's skirt, noise); a
    linear rig answers it there. The BLA at the excited lines, interpolated (held at the band's edges),
    times each period's force spectrum is taken out, so the detection lines hold noise and distortion only.

    Parameters
    ----------
    u, y : (M, P, N) force and output periods
    lines : excited lines

    Returns
    -------
    ndarray (M, P, N)
    """
    u, y = np.asarray(u, float), np.asarray(y, float)
    N = u.shape[-1]
    U, Y = np.fft.rfft(u, axis=-1), np.fft.rfft(y, axis=-1)
    lines = np.asarray(lines, int)
    G = Y[..., lines].mean(axis=(0, 1)) / U[..., lines].mean(axis=(0, 1))
    k = np.arange(U.shape[-1])
    Gk = np.interp(k, lines, G.real) + 1j * np.interp(k, lines, G.imag)
    Gk[lines] = 0.0  # the excited lines are not detection lines: left as they are
    Gk[0] = 0.0
    return np.fft.irfft(Y - Gk * U, N, axis=-1)


def forced_lines(u, factor: float = 10.0, lines=None, width: int = 8, level: float = 3.0) -> np.ndarray:
    """Lines where the force stands above its own period-to-period noise.

    A linear rig answers there (a filter's skirt, a chirp's spectral tails, the shaker's interaction), so
    its response is no evidence of distortion. Two rules:

    - any line whose mean force over periods exceeds ``factor`` x its noise (power);
    - beyond the excited ``lines`` (where the best linear approximation is not known and the rig's answer
      to a weak force cannot be taken out), a line whose neighbourhood holds force: the running median of
      the force's F statistic over ``2 width + 1`` non-excited lines above ``level`` x its median under
      no force. A chirp's tail is weak line by line but present on every line.

    Parameters
    ----------
    u : (M, P, N) force periods (P ≥ 2)
    factor : power ratio over the noise of the mean that counts as force on one line
    lines : excited lines (None: the first rule only)
    width : half-width of the running median, in non-excited lines
    level : ratio of the running median over the F(2, 2(P-1)) median that counts as force

    Returns
    -------
    ndarray of int
    """
    u = np.asarray(u, float)
    if u.ndim == 2:
        u = u[None]
    M, P, N = u.shape
    if P < 2:
        return np.zeros(0, int)
    U = np.fft.rfft(u - u.mean(axis=2, keepdims=True), axis=2)
    mean = U.mean(axis=1)
    noise = np.sum(np.abs(U - mean[:, None]) ** 2, axis=1) / (P - 1) / P
    floor = np.median(noise, axis=1, keepdims=True)  # the force's noise is broad: its median is robust
    floor = np.maximum(floor, 1e-12 * np.max(np.abs(mean) ** 2, axis=1, keepdims=True))  # a noise-free force
    power = np.abs(mean) ** 2
    forced = np.any(power > factor * np.maximum(np.maximum(noise, floor), TINY), axis=0)
    if lines is not None and len(lines):
        forced |= _force_beyond(power / np.maximum(noise, TINY), np.asarray(lines, int), P, width, level)
    return np.flatnonzero(forced)


def _force_beyond(F, lines, P: int, width: int, level: float) -> np.ndarray:
    """(K,) bool: lines beyond the excited ones whose neighbourhood holds force (see `forced_lines`)."""
    from scipy import stats
    from scipy.ndimage import median_filter

    K = F.shape[-1]
    out = np.zeros(K, bool)
    free = np.ones(K, bool)
    free[lines] = False
    free[0] = False
    cand = np.flatnonzero(free & ((np.arange(K) < lines.min()) | (np.arange(K) > lines.max())))
    if cand.size == 0:
        return out
    running = median_filter(np.median(F, axis=0)[cand], size=2 * width + 1, mode="nearest")
    out[cand[running > level * stats.f.median(2, 2 * (P - 1))]] = True
    return out
