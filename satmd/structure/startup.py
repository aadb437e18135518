"""Modes above the force's band, seen in the start from rest (SPEC §11: predict what was not measured).

A test that starts from rest starts with a step: the force jumps from nothing to the multisine's first
sample, and that step is the only force above the band the test ever applies. It rings every mode,
those above the band too, and a linear model fitted to the steady spectra knows none of them there (the
DFT of a whole period sees no line above the band): at the first period of a held-out level it misses by
several times the noise (on independent ground vibration tests, `benchmarks/structures_gvt.py`, four of
eight structures with no joint missed so, the periods after the first within twice the noise).

In time the start is plain to see. With the in-band poles fixed, every channel's response is linear in
the residues and the flat term (the force's first-order-hold states, `linear.modal_states`), so a pole
above the band is found by variable projection: a grid of frequencies and dampings, each pole's two
columns projected against the rest, the best refined (Nelder–Mead on frequency and log damping), kept
while it cuts what is left by at least `MIN_GAIN` and pays its parameters (BIC). The in-band residues are
fitted again with them; the model is kept only when it simulates the records better than the one it
started from. The pair's first sensor is fitted as the pair's difference, as `linear.fit_linear` does.
"""
from __future__ import annotations

import numpy as np

from ..conventions import TINY
from ..numerics import force_level
from .linear import LinearStructure, modal_states

MAX_POLES = 4          # poles above the band tried, one at a time
MIN_GAIN = 0.05        # share of the remaining misfit a pole must remove
TOP_SHARE = 0.8        # of the Nyquist frequency: beyond it an acquisition's anti-alias filter takes the response
GRID_STEP = 1.02       # the frequency grid's ratio
ZETAS = (0.003, 0.01, 0.03, 0.1)
SAME_POLE = 1e-3       # poles above the band closer than this share of their modulus are one (`_distinct`)


def band_top_hz(spectra) -> float:
    """The highest frequency the levels' forces excite (their highest line)."""
    s = spectra[0]
    return max(int(x.lines.max()) for x in spectra) * s.fs_hz / s.period_samples


def with_start_up_modes(linear: LinearStructure, recordings, spectra, between=None) -> LinearStructure:
    """`start_up_modes` of every recording when there is no joint (the structure is linear at every level), else
    of the lowest level's alone."""
    from ..signal.memo import fingerprint

    lowest = min(range(len(spectra)), key=lambda i: spectra[i].level)
    linear_ones = list(recordings) if between is None else [recordings[lowest]]
    top = band_top_hz(spectra)
    # asked again for every law the cross-validation weighs (20 s on the F-16's 73 728 samples): answered once
    key = fingerprint(linear.poles, linear.residues, linear.feedthrough,
                      *[np.asarray(r[c], float) for r in linear_ones for c in ("force", *linear.channels)],
                      settings=(linear.channels, tuple(between) if between else None, float(top),
                                tuple(float(r.fs_hz) for r in linear_ones)))
    return _FOUND.answer(key, lambda: start_up_modes(linear, linear_ones, top, between))


def start_up_modes(linear: LinearStructure, recordings, band_top: float, between=None) -> LinearStructure:
    """``linear`` with the modes above ``band_top`` that the recordings' start from rest shows, its in-band
    residues and flat term fitted again in time with them; ``linear`` itself when no recording starts from rest
    or no such mode pays.

    Parameters
    ----------
    linear : the structure's linear model from the steady spectra (`linear.fit_linear`)
    recordings : Recordings of a linear behaviour (the lowest level; every level when there is no joint)
    band_top : Hz, the top of the force's band
    between : a joint's pair (a, b): the fit is made with ``a`` replaced by ``a − b``

    Returns
    -------
    LinearStructure
    """
    from .spectra import warmup_of

    rest = [r for r in recordings if warmup_of(r) == 0]
    if not rest:
        return linear
    fs = float(rest[0].fs_hz)
    top = TOP_SHARE * fs / 2
    if band_top * GRID_STEP >= top:
        return linear
    data = _Data(linear, rest, fs, between)
    inband = linear.poles[linear.poles.imag / (2 * np.pi) <= band_top]
    before = data.rss_of(linear)
    grid = [_pole(f, z) for f in _geometric(band_top * GRID_STEP, top) for z in ZETAS]
    chosen = np.zeros(0, complex)
    rss = data.rss(np.concatenate([inband, chosen]))
    for _ in range(MAX_POLES):
        fixed = data.projector(np.concatenate([inband, chosen]))
        lam = max(grid, key=lambda p: data.gain(fixed, p))
        lam = _refined(lambda p: data.rss(np.concatenate([inband, chosen, [p]])), lam, band_top, top)
        new = data.rss(np.concatenate([inband, chosen, [lam]]))
        bic = data.n_rows * np.log(max(new, TINY) / max(rss, TINY)) + 2 * data.n_out * np.log(data.n_rows)
        if new > (1 - MIN_GAIN) * rss or bic >= 0:
            break
        chosen, rss = np.append(chosen, lam), new
    if chosen.size == 0:
        return linear
    chosen = _pruned(data, inband, _distinct(_together(data, inband, chosen, band_top, top)))
    if data.rss(np.concatenate([inband, chosen])) > (1 - MIN_GAIN) * before:
        return linear
    return data.fitted(np.concatenate([inband, chosen]))


def _memo():
    from ..signal.memo import ContentMemo

    return ContentMemo(size=8)


_FOUND = _memo()


def _pole(f_hz: float, zeta: float) -> complex:
    w = 2 * np.pi * f_hz
    return complex(-zeta * w, w * np.sqrt(1 - zeta ** 2))


def _geometric(lo: float, hi: float) -> np.ndarray:
    return lo * GRID_STEP ** np.arange(int(np.log(hi / lo) / np.log(GRID_STEP)) + 1)


def _refined(rss, lam: complex, lo: float, hi: float) -> complex:
    """The pole at the least ``rss`` near ``lam`` (frequency within (lo, hi) Hz, damping 0.1 % to 30 %)."""
    from scipy.optimize import minimize

    def pole(p):
        f = float(np.clip(p[0], lo, hi))
        return _pole(f, float(np.clip(np.exp(p[1]), 1e-3, 0.3)))

    start = [lam.imag / (2 * np.pi), np.log(-lam.real / abs(lam))]
    best = minimize(lambda p: rss(pole(p)), start, method="Nelder-Mead",
                    options={"xatol": 1e-3, "fatol": 1e-9, "maxiter": 120, "initial_simplex":
                             [start, [start[0] * 1.01, start[1]], [start[0], start[1] + 0.3]]})
    return pole(best.x)


def _together(data, inband, chosen, lo: float, hi: float) -> np.ndarray:
    """The poles above the band refined together (each was found with those before it fixed)."""
    from scipy.optimize import least_squares

    def poles(p):
        return np.array([_pole(f, np.exp(z)) for f, z in p.reshape(-1, 2)])

    def residual(p):
        _, rest = data.projector(np.concatenate([inband, poles(p)]))
        return (rest * data.w[None, :]).ravel()

    start = np.ravel([[p.imag / (2 * np.pi), np.log(-p.real / abs(p))] for p in chosen])
    bounds = (np.tile([lo, np.log(1e-3)], chosen.size), np.tile([hi, np.log(0.3)], chosen.size))
    fit = least_squares(residual, np.clip(start, bounds[0] + 1e-9, bounds[1] - 1e-9), bounds=bounds,
                        x_scale=np.tile([1.0, 0.1], chosen.size), max_nfev=20)
    return poles(fit.x)


def _distinct(chosen) -> np.ndarray:
    """``chosen`` less each pole that coincides with one before it (within `SAME_POLE` of it): refined together,
    two poles can run to the same corner of their bounds, and their residues, solved by least squares, then
    cancel at a hundred million times the in-band ones (a double pole, no mode): a wing's quiet channel answered
    every step of its force there (at the record's last sample 2.5 times its RMS)."""
    kept: list = []
    for p in chosen:
        if all(abs(p - q) > SAME_POLE * abs(q) for q in kept):
            kept.append(p)
    return np.array(kept, complex)


def _pruned(data, inband, chosen) -> np.ndarray:
    """``chosen`` less the poles each of which removes under `MIN_GAIN` of what the rest leave (two poles that
    share one mode, or a broad one the others made needless)."""
    while chosen.size > 1:
        rss = data.rss(np.concatenate([inband, chosen]))
        without = [data.rss(np.concatenate([inband, np.delete(chosen, i)])) for i in range(chosen.size)]
        i = int(np.argmin(without))
        if rss < (1 - MIN_GAIN) * without[i]:
            break
        chosen = np.delete(chosen, i)
    return chosen


class _Data:
    """The recordings in time, each over its force's RMS (a linear structure answers in proportion), the
    pair's first sensor as the pair's difference; each channel weighted by its RMS."""

    def __init__(self, linear, recordings, fs, between):
        from ..physics.nonlinear.integrate import band_limited
        from .spectra import drive_force

        self.linear, self.fs = linear, fs
        names = linear.channels
        self.ia = names.index(between[0]) if between else None
        self.ib = names.index(between[1]) if between and between[1] != "ground" else None
        us, ys = [], []
        for r in recordings:
            u = drive_force(r)  # the load cell's noise left out, as the models are driven
            scale = max(force_level(u), TINY)
            y = np.array([np.asarray(r[c], float) for c in names]) / scale
            if self.ib is not None:
                y[self.ia] = y[self.ia] - y[self.ib]
            us.append(u / scale)
            ys.append(y)
        self.u = us
        self.ub = [band_limited(u, fs) for u in us]
        self.y = np.hstack(ys).T                                       # (N, C)
        self.w = 1.0 / np.maximum(self.y.std(axis=0), TINY)
        self.n_rows, self.n_out = self.y.shape

    def columns(self, poles) -> np.ndarray:
        """(N, 2 n + 1): each pole's (Re A, Im A) columns of 2 Re(A z), and the flat term's."""
        cols = []
        for u, ub in zip(self.u, self.ub):
            z = modal_states(ub, np.asarray(poles, complex), self.fs) if len(poles) else np.zeros((0, u.size))
            cols.append(np.vstack([2 * z.real, -2 * z.imag, u[None, :]]))
        return np.hstack(cols).T

    def projector(self, poles):
        """(Q, residual of y) of the fixed columns."""
        q, _ = np.linalg.qr(self.columns(poles))
        return q, self.y - q @ (q.T @ self.y)

    def gain(self, fixed, lam) -> float:
        """The weighted misfit one more pole ``lam`` removes."""
        q, rest = fixed
        z = self.columns([lam])[:, :2]
        z = z - q @ (q.T @ z)
        qz, _ = np.linalg.qr(z)
        return float(np.sum((qz.T @ rest) ** 2 * self.w[None, :] ** 2))

    def rss(self, poles) -> float:
        _, rest = self.projector(poles)
        return float(np.sum(rest ** 2 * self.w[None, :] ** 2))

    def rss_of(self, linear) -> float:
        """The weighted misfit of ``linear`` as it is (its residues, in the fitted channels)."""
        res, feed = linear.residues.copy(), linear.feedthrough.copy()
        if self.ib is not None:
            res[self.ia] -= res[self.ib]
            feed[self.ia] -= feed[self.ib]
        X = self.columns(linear.poles)
        coef = np.hstack([res.real, res.imag, feed[:, None]]).T  # (2 n + 1, C)
        return float(np.sum((self.y - X @ coef) ** 2 * self.w[None, :] ** 2))

    def fitted(self, poles) -> LinearStructure:
        """The model at ``poles``: residues and flat terms in least squares, in the sensors' own channels."""
        n = len(poles)
        coef, *_ = np.linalg.lstsq(self.columns(poles), self.y, rcond=None)    # (2 n + 1, C)
        res = (coef[:n] + 1j * coef[n:2 * n]).T
        feed = coef[2 * n].copy()
        if self.ib is not None:
            res[self.ia] += res[self.ib]
            feed[self.ia] += feed[self.ib]
        return LinearStructure(self.linear.channels, np.asarray(poles, complex), res, feed)
