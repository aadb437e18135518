"""Statistics of nonlinearity: linearity of one record, level dependence of several, band scans.

One record (random force). A nonlinear element adds to the equations of motion a
force g(state); the response then holds, beside the best linear approximation
(BLA) H·X, a term G·Z where Z is the spectrum of a nonlinear function of the
response and G is smooth in frequency (it is the transfer path of that force).
`linearity_test` fits, in non-overlapping local windows (as the local polynomial
method does), ``Y = H(r) X + T(r) + Σ_j G_j Z_j + V`` with H and the transient T
polynomials of degree R and G_j constant, and tests G = 0 window by window (an F
test with the window's own residual: the noise estimate never holds the
distortion, because the distortion has its own regressors). The regressors are
Hermite polynomials of the *standardised measured* responses (He2, He3): for a
linear system with Gaussian force and Gaussian noise every Hermite polynomial of
degree ≥ 2 of a measured signal is uncorrelated, at every lag, with everything
linear (force, noise, transient), so the test holds its level whatever the
noise colour or force spectrum; the distortion of a nonlinear one is not.
`separate_linearity_test` tests each regressor alone (2 dof per window and
channel) in windows about a resonance wide, with Bonferroni over the
regressors: a weak distortion of one shape (velocity-squared damping) is not
diluted over the degrees of freedom of every other shape.

Several records (levels or repeats). `level_dependence` compares FRF estimates
point by point against their standard deviations: under "one linear system"
every difference is noise, Σ|z|² is χ², and a band scan (Bonferroni over every
window of several widths) locates where they differ.

Each window's p-value is turned into a χ² score of the same p, so that the
global sum and the band scan of `band_scan` apply to both tests alike.
"""
from __future__ import annotations

from ...conventions import ESTIMATE_REL_FLOOR, TINY

from dataclasses import dataclass, field
from typing import Callable

import numpy as np

WIDTHS = (1, 3, 7, 15, 31)


@dataclass(frozen=True)
class NonlinearTest:
    """One test of linearity: name, p-value, bands where it fails, and its numbers.

    Attributes
    ----------
    name : ``distortion`` (one record), ``level_dependence`` (several), ...
    p_value : smallest of the global and band p-values, Bonferroni-corrected for both
    bands_hz : [[lo, hi], ...] where the test fails at its level
    alpha : level of the test
    details : dict of what the test measured (per-channel scores, dof, ...)
    """

    name: str
    p_value: float
    bands_hz: list
    alpha: float
    details: dict = field(default_factory=dict, compare=False)

    @property
    def significant(self) -> bool:
        """True when the test rejects linearity at its level."""
        return self.p_value < self.alpha

    @property
    def not_run(self) -> str | None:
        """Why the test could not run (no detection lines, too short, ...); None when it ran."""
        reason = self.details.get("reason")
        return str(reason) if reason else None

    def to_dict(self) -> dict:
        """The SPEC §9 entry: name, p_value, bands_hz; a test that could not run has no p-value, and says why."""
        if self.not_run:
            return {"name": self.name, "p_value": None, "bands_hz": [], "not_run": self.not_run}
        return {"name": self.name, "p_value": float(self.p_value),
                "bands_hz": [[round(a, 3), round(b, 3)] for a, b in self.bands_hz]}

    def report(self) -> str:
        """One line in words."""
        if self.not_run:
            return f"{self.name}: not run ({self.not_run})"
        where = ", ".join(f"{a:.1f}–{b:.1f} Hz" for a, b in self.bands_hz) or "no band alone"
        verdict = "rejects linearity" if self.significant else "consistent with a linear system"
        channel = self.channel
        carried = f"; carried most by {channel}" if channel and self.significant else ""
        return f"{self.name}: p = {self.p_value:.2g} ({verdict} at α = {self.alpha:g}); bands: {where}{carried}"

    @property
    def channel(self):
        """The channel with the largest share of the test's score (None when the test has one channel)."""
        per = self.details.get("per_channel") or {c: w["chi2"] for c, w in (self.details.get("worst") or {}).items()}
        per = {c: float(np.sum(v)) for c, v in per.items()}
        return max(per, key=per.get) if len(per) > 1 else None


def band_scan(freq, score, dof, alpha, widths=WIDTHS):
    """Global and band-wise χ² tests of per-point scores (each χ²(dof) under the null).

    Returns (p_value, bands_hz, p_global, p_band): p_value = 2·min(p_global,
    p_band) (both tests at level α/2), bands where a Bonferroni-corrected window
    p-value is below α/2, merged (`satmd.discovery.locate.scan_bands`, the scan of the linear fit's residuals).
    """
    from scipy import stats

    from ..locate import scan_bands

    score = np.asarray(score, float)
    p_global = float(stats.chi2.sf(score.sum(), dof * score.size))
    p_band, bands = scan_bands(freq, score, dof, alpha, widths)
    return min(1.0, 2 * min(p_global, p_band)), bands, p_global, p_band


def chi2_score(p, dof):
    """The χ²(dof) value with upper tail p (a common scale for tests of different dof)."""
    from scipy import stats

    return stats.chi2.isf(np.clip(p, TINY, 1.0), dof)


# --- one record: distortion regressors ----------------------------------------------------------------
_SHAPES: dict[str, Callable[[np.ndarray], np.ndarray]] = {
    "square": lambda s: s * s, "cube": lambda s: s ** 3, "absv": lambda s: np.abs(s) * s, "sign": np.sign}


def distortion_regressors(signals: dict, shapes=("cube",)) -> dict:
    """Nonlinear functions of each standardised signal, made uncorrelated with every linear one.

    For a Gaussian signal s and any g, E[g(s) w] = E[g(s) s] Cov(s, w) / Var(s)
    for every w jointly Gaussian with s (Stein's lemma), so g(s) − β s with
    β = E[g s]/E[s²], and g(s) − E[g] for even g, is uncorrelated at every lag
    with the force, the noise and every linear response.

    Parameters
    ----------
    signals : {name: (n,) samples}
    shapes : any of ``square``, ``cube``, ``absv`` (|s|s: velocity-squared
        damping), ``sign`` (Coulomb friction); a dict {name: shapes} gives each signal its own

    Returns
    -------
    dict {"<name>:<shape>": (n,) regressor}
    """
    out = {}
    for name, r in signals.items():
        r = np.asarray(r, float)
        s = (r - r.mean()) / max(r.std(), TINY)
        for shape in (shapes[name] if isinstance(shapes, dict) else shapes):
            g = _SHAPES[shape](s)
            g = g - g.mean()
            out[f"{name}:{shape}"] = g - np.dot(g, s) / np.dot(s, s) * s
    return out


def linearity_test(force, responses: dict, fs_hz: float, regressors: dict, band_hz=None, window_bins: int = 0,
                   degree: int = 2, alpha: float = 1e-3, band=None) -> NonlinearTest:
    """Test one random-excitation record for nonlinear distortion (see the module docstring).

    Parameters
    ----------
    force : (n,) input samples
    responses : {channel: (n,) samples} measured outputs
    fs_hz : sample rate
    regressors : {name: (n,) samples} nonlinear regressors (e.g. `hermite_regressors` of the responses)
    band_hz : (lo, hi) Hz analysed (default: where the force has power)
    window_bins : bins per local window (default: twice the local parameters, + 1)
    degree : polynomial degree of H and of the transient in each window
    alpha : level
    band : former name of ``band_hz`` (deprecated)

    Returns
    -------
    NonlinearTest
        ``distortion``, with per-channel and per-regressor figures in ``details``
        (``explained``: fraction of the residual power the regressors explain,
        per channel, near the worst band).
    """
    from scipy import stats

    from ...errors import renamed_keyword

    band_hz = renamed_keyword(band, band_hz, "linearity_test")
    n = len(force)
    X = np.fft.rfft(np.asarray(force, float) - np.mean(force))
    Z = np.stack([np.fft.rfft(z - z.mean()) for z in regressors.values()], axis=1) if regressors else None
    df = fs_hz / n
    lo, hi = band_hz if band_hz is not None else _excited(force, fs_hz)
    nz = 0 if Z is None else Z.shape[1]
    p_h = 2 * (degree + 1)
    width = max(window_bins, 2 * (p_h + nz) + 1)
    width += 1 - width % 2
    half = width // 2
    first, last = int(np.ceil(lo / df)), int(np.floor(hi / df))
    centres = np.arange(first + half, last - half + 1, width)
    if centres.size < 4 or nz == 0:
        return NonlinearTest("distortion", 1.0, [], alpha, {"reason": "record too short for the test"})
    idx = centres[:, None] + np.arange(-half, half + 1)
    u = np.arange(-half, half + 1) / half
    powers = u[None, :, None] ** np.arange(degree + 1)
    Xw = X[idx]
    xs = np.sqrt(np.mean(np.abs(Xw) ** 2, axis=1))[:, None, None]
    K0 = np.concatenate([Xw[..., None] / xs * powers, np.broadcast_to(powers, Xw.shape + (degree + 1,))], axis=2)
    assert Z is not None  # nz > 0
    Zw = Z[idx]  # (M, W, nz)
    Zw = Zw / np.sqrt(np.mean(np.abs(Zw) ** 2, axis=1, keepdims=True))
    K1 = np.concatenate([K0, Zw], axis=2)
    q1 = width - K1.shape[2]
    dof = 2 * nz
    scores, explained, per_channel = np.zeros(centres.size), {}, {}
    for name, y in responses.items():
        Y = np.fft.rfft(np.asarray(y, float) - np.mean(y))[idx]
        rss0 = _rss(K0, Y)
        rss1 = _rss(K1, Y)
        F = ((rss0 - rss1) / nz) / np.maximum(rss1 / q1, TINY)
        p = stats.f.sf(F, dof, 2 * q1)
        s = chi2_score(p, dof)
        scores += s
        per_channel[name] = s
        explained[name] = float(np.sum(rss0 - rss1) / max(np.sum(rss0), TINY))
    freq = centres * df
    dof_all = dof * len(responses)
    # bands of ≥ 3 windows: a lone window's F tail is where non-Gaussian regressors would lie
    p_value, bands, p_global, p_band = band_scan(freq, scores, dof_all, alpha, widths=WIDTHS[1:])
    details = {"window_hz": width * df, "windows": int(centres.size), "regressors": list(regressors),
               "p_global": p_global, "p_band": p_band, "explained": explained, "freq_hz": freq,
               "scores": scores, "per_channel": per_channel, "dof": dof_all}
    return NonlinearTest("distortion", p_value, bands, alpha, details)


def separate_linearity_test(force, responses: dict, fs_hz: float, regressors: dict, band_hz=None,
                            window_hz: float = 1.5, degree: int = 3, alpha: float = 1e-3) -> NonlinearTest:
    """`linearity_test` for each regressor alone, in windows ``window_hz`` wide, Bonferroni over the regressors.

    One regressor per test costs 2 degrees of freedom per window and channel instead
    of 2 per regressor, and a window about a resonance wide (the distortion's path G
    is as smooth as the FRF) gathers its power into few windows: a velocity-squared
    damper, whose distortion is small beside its linear part, stands out where a joint
    test of every regressor in narrow windows would dilute it.

    Parameters
    ----------
    force, responses, fs_hz, regressors, band_hz : as `linearity_test`
    window_hz : local window width [Hz] (at least the bins the local model needs)
    degree : polynomial degree of H and the transient in each window
    alpha : level (each regressor's test at alpha / number of regressors)

    Returns
    -------
    NonlinearTest
        ``distortion``: the most significant regressor's test, its p-value times the
        number of regressors; ``details['per_regressor']`` gives each regressor's p-value,
        ``details['regressors']`` them from most to least significant.
    """
    if not regressors:
        return NonlinearTest("distortion", 1.0, [], alpha, {"reason": "no regressors"})
    k = len(regressors)
    bins = int(round(window_hz * len(force) / fs_hz))
    tests = {name: linearity_test(force, responses, fs_hz, {name: z}, band_hz=band_hz, window_bins=bins, degree=degree,
                                  alpha=alpha / k) for name, z in regressors.items()}
    order = sorted(tests, key=lambda n: tests[n].p_value)
    best = tests[order[0]]
    p = min(1.0, best.p_value * k)
    details = dict(best.details, regressors=order, per_regressor={n: float(tests[n].p_value) for n in order})
    return NonlinearTest("distortion", p, best.bands_hz, alpha, details)


def _rss(K, Y):
    """Residual sum of squares of the local least-squares fits Y ≈ K θ (per window)."""
    Q, _ = np.linalg.qr(K)
    proj = np.einsum("mwp,mp->mw", Q, np.einsum("mwp,mw->mp", np.conj(Q), Y))
    return np.sum(np.abs(Y - proj) ** 2, axis=1)


def _excited(force, fs_hz) -> tuple:
    """(lo, hi) Hz the force excites: the one rule (`satmd.signal.lpm.excited_band`)."""
    from ...signal.lpm import excited_band

    lo, hi, _ = excited_band(np.asarray(force, float), fs_hz)
    return lo, hi


def integrate(signal, fs_hz, times: int, band_hz):
    """Band-limited integration in the frequency domain (÷ iω per time), zero outside ``band_hz``."""
    n = len(signal)
    S = np.fft.rfft(np.asarray(signal, float) - np.mean(signal))
    f = np.fft.rfftfreq(n, 1.0 / fs_hz)
    keep = (f >= band_hz[0]) & (f <= band_hz[1])
    out = np.zeros_like(S)
    out[keep] = S[keep] / (2j * np.pi * f[keep]) ** times
    return np.fft.irfft(out, n)


# --- several records: level dependence -------------------------------------------------------------------
REL_FLOOR = ESTIMATE_REL_FLOOR  # relative error an FRF estimate carries beyond its noise std


def level_dependence(freq, frfs: list, stds: list, alpha: float = 1e-3, name: str = "level_dependence",
                     dof_noise: float | None = None, rel_floor: float = REL_FLOOR, model_errors=None) -> NonlinearTest:
    """Do several FRF estimates on one grid differ beyond their noise? (see the module docstring)

    Parameters
    ----------
    freq : (M,) common frequency grid
    frfs : list over records of {channel: (M,) complex}
    stds : list over records of {channel: (M,) std on each of Re, Im}
    alpha : level
    name : test name in the report
    dof_noise : degrees of freedom behind the stds (None: known)
    rel_floor : relative error added to each std (estimator model error: ``rel_floor |H|``, with
        |H| at least 5 % of its peak)
    model_errors : optional list over records of {channel: (M,) estimated model error of the estimate}
        (e.g. local polynomial degree 2 vs 3), added to the std in quadrature

    Notes
    -----
    Two guards keep the level on real estimates: the stds are inflated by
    the median per-point score over its null median (at most ×2: a std
    estimate that is a few per cent low over hundreds of points would
    otherwise reject), and the band scan starts at 3 neighbouring points (a
    single point at the sharpest resonance carries the estimator's own bias).

    Returns
    -------
    NonlinearTest
        ``details`` holds per-point scores, the largest standardised difference
        per channel and the pair it comes from.
    """
    from scipy import stats

    k = len(frfs)
    chans = [c for c in frfs[0] if all(c in f for f in frfs)]
    scores = np.zeros(len(freq))
    dof = 0
    worst, per_channel = {}, {}
    for c in chans:
        H = np.stack([f[c] for f in frfs])
        sd = np.stack([s[c] for s in stds])
        if model_errors is not None:
            sd = np.hypot(sd, np.stack([np.asarray((m or {}).get(c, 0.0), float) * np.ones(len(freq))
                                        for m in model_errors]))
        # estimator error scales with the FRF's dynamic range: near an antiresonance it is not relative to |H|
        level = np.maximum(np.abs(H), 0.05 * np.abs(H).max(axis=1, keepdims=True))
        w = 1.0 / np.maximum(sd ** 2 + (rel_floor * level) ** 2, TINY)
        mean = np.sum(w * H, axis=0) / np.sum(w, axis=0)  # weighted mean, the "one linear system" estimate
        chi = np.sum(w * np.abs(H - mean) ** 2, axis=0)  # χ² with 2(k-1) dof per point
        if dof_noise:
            chi = chi2_score(stats.f.sf(chi / (2 * (k - 1)), 2 * (k - 1), dof_noise), 2 * (k - 1))
        scores += chi
        per_channel[c] = chi
        dof += 2 * (k - 1)
        z = np.abs(H - mean) * np.sqrt(w)
        i = int(np.argmax(chi))
        worst[c] = {"freq_hz": float(freq[i]), "chi2": float(chi[i]), "max_z": float(z[:, i].max())}
    null_median = stats.chi2.median(dof)
    inflation = float(np.clip(np.median(scores) / null_median, 1.0, 2.0))
    scores = scores / inflation
    p_value, bands, p_global, p_band = band_scan(freq, scores, dof, alpha, widths=WIDTHS[1:])
    return NonlinearTest(name, p_value, bands, alpha, {"p_global": p_global, "p_band": p_band, "scores": scores,
                                                       "freq_hz": np.asarray(freq), "dof": dof, "worst": worst,
                                                       "inflation": inflation, "per_channel": per_channel})
