"""Where and whether the model misses: calibrated tests on standardised residuals.

Under the null hypothesis (the model is right and σ is the noise std) each
standardised residual z = (model − data)/σ is complex Gaussian with unit
variance per part, so |z|² summed over channels and a window of w points is
χ² with 2·C·w degrees of freedom (the fit's few parameters take little of
that). A window is significant when its p-value survives a Bonferroni
correction over all windows of all widths; significant windows merge into
bands. The global test is χ² of the whole fit against its degrees of
freedom. Both run at level ``alpha`` (default 1e-3), split between them.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..numerics import lag1_autocorrelation

WIDTHS = (1, 3, 7, 15)


@dataclass
class MismatchTest:
    significant: bool
    p_global: float
    p_band: float  # smallest Bonferroni-corrected window p-value
    bands_hz: list
    whiteness: dict  # lag-1 autocorrelation of the residual per channel
    chi2_per_point: np.ndarray  # Σ_channels |z|² at each frequency


def standardised(fit) -> dict:
    return fit.standardised_residuals()


standardized = standardised  # the former spelling (issue 25: one spelling, -ise, across the package)


def test_mismatch(fit, alpha: float = 1e-3, noise_dof: float | None = None) -> MismatchTest:
    """Global and band-wise χ² tests of a fit (see module docstring).

    ``noise_dof``: degrees of freedom behind an estimated σ; the global test
    is then an F test, which accounts for the uncertainty of the estimate.
    """
    from scipy import stats  # heavy: imported where used, not at `import satmd`

    z = standardised(fit)
    freq = fit.freq_hz
    per_point = sum(np.abs(v) ** 2 for v in z.values())  # ~ χ²_{2C}
    C = len(z)
    if noise_dof:
        p_global = float(stats.f.sf(fit.chi2_reduced, fit.dof, noise_dof))
    else:
        p_global = float(stats.chi2.sf(fit.chi2, fit.dof))
    p_band, bands_hz = scan_bands(freq, per_point, 2 * C, alpha, WIDTHS, noise_dof)
    whiteness = {c: _lag1(v) for c, v in z.items()}
    significant = (p_global < alpha / 2) or (p_band < alpha / 2)
    return MismatchTest(significant, p_global, p_band, bands_hz, whiteness, per_point)


def scan_bands(freq, score, point_dof: float, alpha: float, widths=WIDTHS, noise_dof: float | None = None):
    """The band scan, written once: windows of ``widths`` points, Bonferroni over all of them, merged.

    Parameters
    ----------
    freq : (n,) Hz
    score : (n,) per-point statistic, χ²(point_dof) under the null (σ known), or σ²-scaled when
        ``noise_dof`` is given (σ estimated with that many degrees of freedom: an F test per window)
    point_dof : degrees of freedom of one point's score
    alpha : level of the scan (windows are kept at α/2: the other half is the global test's)
    widths : window widths, in points
    noise_dof : degrees of freedom behind an estimated σ (None: σ known)

    Returns
    -------
    (p_band, bands_hz)
        Smallest Bonferroni-corrected window p-value (1 with no window) and the merged significant bands.
    """
    from scipy import stats

    score = np.asarray(score, float)
    n = score.size
    windows = []
    for w in widths:
        if w > n:
            break
        s = np.convolve(score, np.ones(w), mode="valid")
        dof = point_dof * w
        p = stats.f.sf(s / dof, dof, noise_dof) if noise_dof else stats.chi2.sf(s, dof)
        windows += [(p[i], i, i + w - 1) for i in range(p.size)]
    p_adj = np.minimum(np.array([p for p, _, _ in windows]) * len(windows), 1.0)
    spans = sorted((i0, i1) for (p, i0, i1), pa in zip(windows, p_adj) if pa < alpha / 2)
    bands: list[list[int]] = []
    for i0, i1 in spans:
        if bands and i0 <= bands[-1][1] + 1:
            bands[-1][1] = max(bands[-1][1], i1)
        else:
            bands.append([i0, i1])
    p_band = float(p_adj.min()) if p_adj.size else 1.0
    return p_band, [[float(freq[a]), float(freq[b])] for a, b in bands]


def _lag1(v: np.ndarray) -> float:
    """Lag-1 autocorrelation across frequency (≈ 0 for white residuals)."""
    if v.size < 3:
        return 0.0
    return lag1_autocorrelation(np.stack([v.real - v.real.mean(), v.imag - v.imag.mean()]))  # each part about its mean
