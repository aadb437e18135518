"""`fit_modes`: several modes of one FRF at once, with 95 % intervals (see `satmd.modal`).

Step 2 (step 1 is `satmd.modal.poles`): a weighted nonlinear least-squares fit
(`scipy.optimize.least_squares`) of the pole-residue model with residual terms, per channel o::

    H_o(ω) = Σ_r [A_or / (iω − λ_r) + A_or* / (iω − λ_r*)] + c0_o + c1_o (ω_c/ω)² + c2_o (ω/ω_c)²

Only the poles λ_r (as f and ζ) are searched; residues A and residual terms c (complex) are solved
linearly at every step (variable projection). The covariance of (f, ζ) is the inverse of JᵀJ of the
weighted residual, scaled by the reduced χ² when no std is given, and also when the std leaves a
misfit (χ²_red > 1: the data hold more than noise). A mode whose removal raises χ² (in those units)
by less than the BIC penalty is dropped, weakest first.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..validation import Band, Interval, Whole, validate_params

from ..numerics import jacobian_covariance, one_blas_thread, unit_columns
from .poles import stable_poles

Z95 = 1.959963984540054  # two-sided 95 % normal quantile
MIN_ZETA, MAX_ZETA_FIT = 1e-5, 0.5  # the damping a refined mode may take (at either bound it is no mode)
DEFAULT_MAX_ORDER = 60  # a dozen modes and their residual poles (the F-16's 2–15 Hz needs about this)


@dataclass(frozen=True)
class Mode:
    """One mode of a `ModalFit`.

    Attributes
    ----------
    f_hz : undamped natural frequency |λ| / 2π
    zeta : damping ratio −Re λ / |λ|
    f_std, zeta_std : their standard errors (inf when the fit cannot tell)
    residues : {channel: complex A} of the pair A / (iω − λ) + A* / (iω − λ*)
    """

    f_hz: float
    zeta: float
    f_std: float
    zeta_std: float
    residues: dict = field(default_factory=dict, repr=False)

    @property
    def f_ci95(self) -> tuple:
        """95 % interval of the natural frequency."""
        return (self.f_hz - Z95 * self.f_std, self.f_hz + Z95 * self.f_std)

    @property
    def zeta_ci95(self) -> tuple:
        """95 % interval of the damping ratio."""
        return (self.zeta - Z95 * self.zeta_std, self.zeta + Z95 * self.zeta_std)

    @property
    def pole(self) -> complex:
        """λ = −ζ ωn + i ωn √(1 − ζ²)."""
        return _pole(self.f_hz, self.zeta)

    @property
    def half_power_hz(self) -> float:
        """Half-power bandwidth 2 ζ f."""
        return 2.0 * self.zeta * self.f_hz

    def to_dict(self) -> dict:
        """f_hz, f_ci95, zeta, zeta_ci95."""
        return {"f_hz": self.f_hz, "f_ci95": list(self.f_ci95), "zeta": self.zeta, "zeta_ci95": list(self.zeta_ci95)}


@dataclass(frozen=True)
class ModalFit:
    """The modes of one FRF (one or more output channels) in a band.

    Attributes
    ----------
    modes : tuple of `Mode`, by frequency
    band_hz : (lo, hi) fitted
    channels : the output channels fitted together
    chi2_reduced : of the refined fit (in units of the std; of the channels' RMS when no std)
    weighted : whether a std weighted the fit
    coefficients : {channel: real coefficients of the model's columns} (for `predict`)
    """

    modes: tuple
    band_hz: tuple
    channels: tuple
    chi2_reduced: float
    weighted: bool
    coefficients: dict = field(default_factory=dict, repr=False)

    def predict(self, freq_hz) -> dict:
        """The fitted model at ``freq_hz``: {channel: complex FRF}."""
        C = self.basis(freq_hz)
        return {c: C @ self.coefficients[c] for c in self.channels}

    def basis(self, freq_hz) -> np.ndarray:
        """(M, K) complex columns of this fit's model at ``freq_hz``: any FRF on these poles (with the same
        residual terms) is ``basis @ c`` for real coefficients c (`predict` uses the fitted ones)."""
        return _design(2 * np.pi * np.asarray(freq_hz, float), [m.pole for m in self.modes], _centre(self.band_hz))

    def to_dict(self) -> dict:
        """band_hz, channels, chi2_reduced, weighted, modes."""
        return {"band_hz": list(self.band_hz), "channels": list(self.channels), "chi2_reduced": self.chi2_reduced,
                "weighted": self.weighted, "modes": [m.to_dict() for m in self.modes]}


@validate_params({"band_hz": [None, Band()], "n_modes": [None, Interval(Whole, 1)],
                  "max_order": [None, Interval(Whole, 2)]})
def fit_modes(freq_hz, frf, std=None, band_hz=None, n_modes=None, max_order=None, start=None) -> ModalFit:
    """Natural frequencies and damping ratios of every mode in a band, with 95 % intervals.

    Parameters
    ----------
    freq_hz : (M,) Hz, increasing (None: the grid of an FRFData ``frf``)
    frf : {channel: (M,) complex} or FRFData; the channels share their poles
    std : {channel: (M,) std of the real and imaginary parts}, or None (FRFData: its std)
    band_hz : (lo, hi) Hz to fit (default: all of ``freq_hz``)
    n_modes : keep the strongest ``n_modes`` of the modes found, without the BIC test (default: those BIC keeps)
    max_order : highest denominator order of the pole search (default 60, fewer for short data)
    start : [(f_hz, zeta), ...] poles to refine instead of searching (e.g. another level's modes); every one
        is kept unless the fit pushes it out of the band, to a damping bound or onto another

    Returns
    -------
    ModalFit
    """
    freq, names, H, S, weighted = _inputs(freq_hz, frf, std, band_hz)
    w = 2 * np.pi * freq
    band_hz = (float(freq[0]), float(freq[-1]))
    order = int(min(max_order or DEFAULT_MAX_ORDER, freq.size - 2))
    with one_blas_thread():
        found = sorted(stable_poles(w, H, S, order) if start is None else start, key=lambda c: c[0])
        x0 = np.array([c[0] for c in found] + [c[1] for c in found], float)
        x, cost, jac = _refine(w, H, S, x0, band_hz)
        if start is None:
            x, cost, jac = _prune(w, H, S, x, cost, jac, band_hz, weighted, n_modes)
        return _result(w, H, S, x, cost, jac, band_hz, names, weighted)


# --- inputs -------------------------------------------------------------------------------------------------
def _inputs(freq_hz, frf, std, band_hz):
    """(freq, channel names, H (C, M), weights S (C, M), weighted) in the band."""
    if hasattr(frf, "channels"):  # FRFData
        freq_hz = frf.freq_hz if freq_hz is None else freq_hz
        std = std if std is not None else (dict(frf.std) if frf.has_std else None)
        frf = frf.channels
    freq = np.asarray(freq_hz, float)
    names = tuple(frf)
    H = np.stack([np.asarray(frf[c], complex) for c in names])
    keep = np.ones(freq.size, bool) if band_hz is None else (freq >= band_hz[0]) & (freq <= band_hz[1])
    if keep.sum() < 8:
        raise ValueError(f"the band holds {keep.sum()} frequencies: a modal fit needs at least 8")
    freq, H = freq[keep], H[:, keep]
    if std is not None:
        S = np.stack([np.asarray(std[c], float)[keep] for c in names])
        positive = S[S > 0]
        S = np.maximum(S, 1e-6 * (np.median(positive) if positive.size else 1.0))  # a zero std is a tiny one
    else:  # each channel counts alike; the scale comes from the residual
        S = np.repeat(np.sqrt(np.mean(np.abs(H) ** 2, axis=1, keepdims=True)), freq.size, axis=1)
        S = np.maximum(S, np.finfo(float).tiny)
    return freq, names, H, S, std is not None


# --- step 2: weighted nonlinear least squares of the pole-residue model -----------------------------------
def _pole(f_hz, zeta):
    wn = 2 * np.pi * np.asarray(f_hz, float)
    zeta = np.asarray(zeta, float)
    return -zeta * wn + 1j * wn * np.sqrt(np.clip(1 - zeta ** 2, 0.0, None))


def _centre(band_hz):
    return 2 * np.pi * np.sqrt(band_hz[0] * band_hz[1])


def _design(w, poles, wc):
    """Complex columns whose real coefficients give the model: two per mode, then 2 × 3 residual terms."""
    iw = 1j * w[:, None]
    lam = np.asarray(poles, complex).reshape(1, -1)
    a, b = 1.0 / (iw - lam), 1.0 / (iw - lam.conj())
    modal = np.stack([a + b, 1j * (a - b)], axis=2).reshape(w.size, -1)  # (p + iq) / (iω − λ) + conjugate
    r = w[:, None] / wc
    residual = np.hstack([np.ones_like(r), r ** -2, r ** 2]).astype(complex)
    return np.hstack([modal, residual, 1j * residual])


class _Poles:
    """The variable-projection problem at fixed data: residual and Jacobian as functions of the poles only."""

    def __init__(self, w, H, S, band_hz):
        self.w, self.H, self.S, self.wc = w, H, S, _centre(band_hz)
        self._at = None

    def solve(self, x):
        """(weighted residual stacked over channels, coefficients per channel, Q per channel) at poles ``x``."""
        if self._at is not None and np.array_equal(self._at[0], x):
            return self._at[1]
        k = x.size // 2
        C = _design(self.w, _pole(x[:k], x[k:]), self.wc)
        res, coefs, bases = [], [], []
        for h, s in zip(self.H, self.S):
            G = C / s[:, None]
            A = np.vstack([G.real, G.imag])
            b = np.concatenate([(h / s).real, (h / s).imag])
            A, norm = unit_columns(A)
            Q, R = np.linalg.qr(A)
            qb = Q.T @ b
            coefs.append(np.linalg.lstsq(R, qb, rcond=None)[0] / norm)
            res.append(Q @ qb - b)  # minus the part of b off the model's columns
            bases.append(Q)
        out = (np.concatenate(res), coefs, bases)
        self._at = (x.copy(), out)
        return out

    def residual(self, x):
        """Weighted residual (model − data), real and imaginary parts of every channel stacked."""
        return self.solve(x)[0]

    def jacobian(self, x):
        """d residual / d (f, ζ) with the residues held (Kaufman's variable-projection approximation)."""
        _, coefs, bases = self.solve(x)
        k = x.size // 2
        f, zeta = x[:k], x[k:]
        lam = _pole(f, zeta)
        dlam = (lam / f, -2 * np.pi * f * (1 + 1j * zeta / np.sqrt(np.clip(1 - zeta ** 2, 1e-12, None))))
        iw = 1j * self.w[:, None]
        a2, b2 = 1.0 / (iw - lam) ** 2, 1.0 / (iw - lam.conj()) ** 2
        blocks = []
        for c, s, Q in zip(coefs, self.S, bases):
            A = c[0:2 * k:2] + 1j * c[1:2 * k:2]
            d = np.hstack([(A * a2 * dl + A.conj() * b2 * dl.conj()) / s[:, None] for dl in dlam])
            D = np.vstack([d.real, d.imag])
            blocks.append(D - Q @ (Q.T @ D))
        return np.vstack(blocks)


def _refine(w, H, S, x0, band_hz):
    """(x, cost, jac) of the least-squares fit of the poles ``x0`` = (f..., zeta...)."""
    from scipy.optimize import least_squares

    problem = _Poles(w, H, S, band_hz)
    k = x0.size // 2
    if k == 0:
        r = problem.residual(x0)
        return x0, 0.5 * float(r @ r), np.zeros((r.size, 0))
    lower, upper = _bounds(k, band_hz)
    x0 = np.clip(x0, lower * 1.0001, upper * 0.9999)
    sol = least_squares(problem.residual, x0, jac=problem.jacobian, bounds=(lower, upper), x_scale="jac")
    junk = _junk(sol.x, problem, band_hz)
    if junk.size:  # poles the fit pushed to a bound, onto each other or to nothing: refit without them
        return _refine(w, H, S, np.delete(sol.x, np.r_[junk, junk + k]), band_hz)
    return sol.x, float(sol.cost), problem.jacobian(sol.x)


def _bounds(k, band_hz):
    edge = 0.01 * (band_hz[1] - band_hz[0])  # a mode stays in the band: beyond it, the residual terms hold it
    lower = np.r_[np.full(k, max(band_hz[0] - edge, 0.5 * band_hz[0])), np.full(k, MIN_ZETA)]
    upper = np.r_[np.full(k, band_hz[1] + edge), np.full(k, MAX_ZETA_FIT)]
    return lower, upper


def _junk(x, problem, band_hz):
    """Indices of modes that went outside the band, to a damping bound, onto another mode, or that carry
    nothing (a peak below 1e-6 of the data's, in the weighted units): no modes but stand-ins."""
    k = x.size // 2
    f, z = x[:k], x[k:]
    out = (f < band_hz[0]) | (f > band_hz[1]) | (z <= 1.01 * MIN_ZETA) | (z >= 0.99 * MAX_ZETA_FIT)
    for i in range(k):
        twin = (np.abs(f[:i] - f[i]) <= 1e-4 * f[i]) & (np.abs(z[:i] - z[i]) <= 1e-2 * z[i])
        out[i] |= bool(twin.any())
    _, coefs, _ = problem.solve(x)
    level = max(np.abs(h / s).max() for h, s in zip(problem.H, problem.S))
    peaks = [np.hypot(c[0:2 * k:2], c[1:2 * k:2]) / (z * 2 * np.pi * f) / np.mean(s)
             for c, s in zip(coefs, problem.S)]
    out |= np.max(peaks, axis=0) < 1e-6 * level  # a mode stays when one channel shows it
    return np.flatnonzero(out)


def _scale(cost, n_res, n_par, weighted):
    """The factor on (JᵀJ)⁻¹ and on χ² differences: χ²_red without std, max(1, χ²_red) with."""
    chi2_red = 2 * cost / max(n_res - n_par, 1)
    return max(chi2_red, 1.0) if weighted else max(chi2_red, np.finfo(float).tiny)


def _n_params(k, n_channels):
    return 2 * k + n_channels * (2 * k + 6)


def _prune(w, H, S, x, cost, jac, band_hz, weighted, n_modes=None):
    """Drop the weakest mode while its removal costs less than the BIC penalty (in units of the scale), or,
    with ``n_modes``, while there are more."""
    problem, n_res, c = _Poles(w, H, S, band_hz), jac.shape[0], H.shape[0]
    while x.size:
        k = x.size // 2
        if n_modes is not None and k <= n_modes:
            break
        penalty = np.inf if n_modes is not None else (2 + 2 * c) * np.log(n_res)
        scale = _scale(cost, n_res, _n_params(k, c), weighted)
        rises = []
        for i in range(k):  # quick: the others held where they are
            r = problem.residual(np.delete(x, [i, k + i]))
            rises.append(0.5 * float(r @ r) - cost)
        i = int(np.argmin(rises))
        if 2 * rises[i] / scale > penalty:
            break
        x1, cost1, jac1 = _refine(w, H, S, np.delete(x, [i, k + i]), band_hz)
        if 2 * (cost1 - cost) / scale > penalty:
            break
        x, cost, jac = x1, cost1, jac1
    return x, cost, jac


def _result(w, H, S, x, cost, jac, band_hz, names, weighted) -> ModalFit:
    k = x.size // 2
    n_res = jac.shape[0] if k else 2 * H.size
    dof_scale = _scale(cost, n_res, _n_params(k, len(names)), weighted)
    sd = np.full(2 * k, np.inf)
    if k and np.all(np.isfinite(jac)):
        cov = jacobian_covariance(jac, dof_scale)
        if np.all(np.isfinite(cov)):  # rank deficient: no interval (inf), the mode is not determined
            sd = np.sqrt(np.abs(np.diag(cov)))
    _, coefs, _ = _Poles(w, H, S, band_hz).solve(x)
    coefficients = dict(zip(names, coefs))
    found = []
    for i in range(k):
        residues = {c: complex(coefficients[c][2 * i], coefficients[c][2 * i + 1]) for c in names}
        found.append(Mode(float(x[i]), float(x[k + i]), float(sd[i]), float(sd[k + i]), residues))
    order = np.argsort([m.f_hz for m in found])
    chi2_red = 2 * cost / max(n_res - _n_params(k, len(names)), 1)
    modes = tuple(found[i] for i in order)
    # the coefficients follow the modes' order: two per mode, then the residual terms
    cols = np.r_[np.ravel([[2 * i, 2 * i + 1] for i in order]).astype(int), np.arange(2 * k, 2 * k + 6)]
    coefficients = {c: v[cols] for c, v in coefficients.items()}
    return ModalFit(modes, band_hz, names, float(chi2_red), weighted, coefficients)
