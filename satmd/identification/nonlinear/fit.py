"""Fit a nonlinear element (SPEC §8b) with m2, kp, R, L to several recordings by time-domain output error.

The judge is the time-domain output error: every recording's measured force drives the one
integrator (`satmd.physics.integrate`, rig at rest at the record's start) and the simulated
a1, a2 are compared with the measured ones after ``skip_s`` (the start-up transient of an
unknown initial state), each channel weighted by its residual RMS (two passes). One
`scipy.optimize.least_squares` (trust region) runs over all recordings at once; its Jacobian
is one batched simulation per recording (forward differences in scaled coordinates).

Start: the linear parameters from `identify` on the H1 FRF of the lowest-level recording
(global search), refined in the time domain; the element's strength from a scan of
strengths expressed by what they do at the top level (x = 1: +10 % on kp, k1 or -10 % on L,
+1 N·s/m on cp), one batched simulation.

Uncertainty: the sandwich covariance B M B with B = (JᵀJ)⁻¹ and M the frequency-domain
long-run variance of Jᵀr (residual spectra smoothed per channel), so coloured residuals
(force-sensor noise through the rig) do not make the intervals too narrow.
"""
from __future__ import annotations

import math
import time
from numbers import Integral, Real

import numpy as np
from ...conventions import ACCEL_CHANNELS, DEFAULT_FREE
from ...errors import DataError
from ...signal.estimate import estimate_frf
from ...signal.lpm import excited_band
from ...numerics import batched_least_squares, force_level
from ...io.recording import Recording
from ...physics import Rig, integrate
from ...physics.nonlinear import NONLINEAR, NonlinearElement, element as make_element, response_rms
from ...validation import NAMES, Interval, Whole, check_data, validate_params
from ..fit import identify
from .result import NonlinearFit
from .drive import band_error, band_limit, excited_error, valid
from .stats import sandwich, simex_shift

__all__ = ["fit_nonlinear", "predict", "prepare", "band_error", "excited_error", "hold_shift", "linear_start",
           "simulate_batch"]

LINEAR_FREE = DEFAULT_FREE


def prepare(rec, seconds=None, band_hz=None) -> dict:
    """Force (kept to its excited band, `band_limit`), accelerations and level of one recording.

    Parameters
    ----------
    rec : Recording with force, acc1, acc2.
    seconds : use the first this many seconds (None: all).
    band_hz : (lo, hi) kept of the force (default: `satmd.signal.lpm.excited_band`).

    Returns
    -------
    dict
    """
    for ch in ("force", "acc1", "acc2"):
        if ch not in rec.channels:
            raise DataError(f"time-domain fit needs force, acc1 and acc2; the recording has no {ch}")
    fs = float(rec.fs_hz)
    n = rec.n_samples if seconds is None else min(rec.n_samples, int(round(seconds * fs)))
    F = np.asarray(rec["force"], float)[:n]
    spec = np.fft.rfft(F)
    f = np.fft.rfftfreq(n, 1.0 / fs)
    if band_hz is None:  # the one excited-band rule, as the FRF estimate and discovery read it
        band_hz = excited_band(F, fs)[:2]
    out_band = ((f > 2.0) & (f < band_hz[0] / 1.35)) | ((f > 1.35 * band_hz[1]) & (f < 0.95 * fs / 2))
    noise_var = float(np.mean(np.abs(spec[out_band]) ** 2) / n) if np.count_nonzero(out_band) > 32 else 0.0
    return {"force": band_limit(F, fs, band_hz), "acc": np.vstack([rec["acc1"][:n], rec["acc2"][:n]]), "fs_hz": fs,
            "level": force_level(rec["force"]), "band_hz": tuple(band_hz),
            "force_noise_var": noise_var}


class _Coordinates:
    """x <-> (rig, element): logs of the linear parameters, then the element's own coordinates."""

    def __init__(self, rig, free, el, rms_top):
        self.rig, self.free, self.el = rig, tuple(free), el
        self.oversample = 1
        self.extrapolate = False
        self.coords = el.coordinates(rig, rms_top) if el is not None else ()
        self.el_names = [c.name for c in self.coords]

    @property
    def names(self):
        return list(self.free) + self.el_names

    def bounds(self):
        lo = [math.log(1e-4)] * len(self.free) + [c.bounds[0] for c in self.coords]
        hi = [math.log(1e7)] * len(self.free) + [c.bounds[1] for c in self.coords]
        return np.array(lo), np.array(hi)

    def starts(self):
        """Element coordinates to scan (one list per start)."""
        return self.el.coordinate_starts(self.rig, None, self.coords) if self.el is not None else [[]]

    def encode(self, rig, el) -> np.ndarray:
        x = [math.log(float(getattr(rig, p))) for p in self.free]
        return np.array(x + [c.encode(el.params[c.name]) for c in self.coords])

    def decode(self, X):
        """(rig, [element]) for X (p,) or a batch (P, p)."""
        X = np.atleast_2d(X)
        rig = self.rig.replace(**{p: np.exp(X[:, i]) for i, p in enumerate(self.free)})
        if self.el is None:
            return rig, []
        j = len(self.free)
        return rig, [self.el.replace(**{c.name: c.decode(X[:, j + i]) for i, c in enumerate(self.coords)})]

    def physical(self, x) -> dict:
        rig, els = self.decode(x)
        out = {p: float(np.ravel(getattr(rig, p))[0]) for p in self.free}
        for el in els:
            out.update({k: float(np.ravel(v)[0]) for k, v in el.params.items()})
        return out


def simulate_batch(coords, X, data) -> list:
    """Simulated (P, 2, n) accelerations of each recording for a batch of coordinates X (P, p)."""
    rig, els = coords.decode(X)
    out = []
    for d in data:
        r = integrate(rig, d["force"], d["fs_hz"], els, outputs=ACCEL_CHANNELS, oversample=coords.oversample,
                      extrapolate=coords.extrapolate)
        out.append(np.stack([np.atleast_2d(r.a1), np.atleast_2d(r.a2)], axis=1))
    return out


def _residuals(sims, data, weights, skip) -> np.ndarray:
    """(P, total) weighted residuals, recordings and channels concatenated."""
    parts = []
    for sim, d, w, s in zip(sims, data, weights, skip):
        parts.append(((sim[:, :, s] - d["acc"][None, :, s]) / w[None, :, None]).reshape(sim.shape[0], -1))
    out = np.concatenate(parts, axis=1)
    return np.where(np.isfinite(out), np.clip(out, -1e6, 1e6), 1e6)  # a diverged simulation: a poor fit, not a crash


def linear_start(recordings, rig) -> Rig:
    """m2, kp, R, L from `identify` (global search) on the H1 FRF of the lowest-level recording."""
    rec = min(recordings, key=lambda r: force_level(r["force"]))
    fs = float(rec.fs_hz)
    data = estimate_frf(rec, estimator="H1", nperseg=int(min(rec.n_samples // 4, 8 * fs)))
    fit = identify(data.band(30.0, 160.0), rig=rig, warn=False)
    return rig.replace(**{p: float(fit.values[p]) for p in LINEAR_FREE})


@validate_params({"rig": [None, Rig], "start": [None, Rig], "free": [NAMES],
                  "seconds": [None, Interval(Real, 0, open="lo")], "skip_s": [Interval(Real, 0)],
                  "max_nfev": [Interval(Whole, 1)], "passes": [Interval(Whole, 1)], "simex": [Interval(Whole, 0)],
                  "seed": [Interval(Integral, 0)], "oversample": [Interval(Whole, 1)]})
def fit_nonlinear(recordings, element=None, rig: Rig | None = None, free=LINEAR_FREE, seconds: float | None = 30.0,
                  skip_s: float = 2.0, start: Rig | None = None, max_nfev: int = 40, passes: int = 2,
                  simex: int = 8, seed: int = 0, oversample: int = 4) -> NonlinearFit:
    """Fit the element's coefficient(s) with m2, kp, R, L to all recordings at once (time-domain output error).

    Parameters
    ----------
    recordings : sequence of Recording (force, acc1, acc2), e.g. one rig at several drive levels.
    element : a SPEC §8b name or NonlinearElement (its class is fitted; None: the linear model).
    rig : values of the parameters that stay fixed (default: the paper's rig).
    free : linear rig parameters fitted with the element.
    seconds : use the first this many seconds of each recording (None: all).
    skip_s : leading seconds left out of the error (the transient of an unknown start).
    start : linear rig to start from (default: `identify` on the lowest level's FRF).
    max_nfev : most least-squares iterations per pass.
    passes : weighting passes (channel weights from the previous pass's residual RMS).
    simex : draws of extra force noise for the errors-in-variables correction, in antithetic pairs
        (0: none; the final Gauss-Newton step is taken either way), see `simex_shift`.
    seed : seed of those draws.
    oversample : the integrator's rate as a multiple of the recordings' (4: the element forces'
        straight-line hold errs by ~0.05 % at 100 Hz and 2048 Hz, instead of 0.8 %); what is left of
        that error is taken out of the estimate at the end (`hold_shift`).

    Returns
    -------
    NonlinearFit
    """
    t0 = time.perf_counter()
    check_data(recordings, "recordings", (Recording,), "fit_nonlinear", single=False, many=True)
    rig = Rig() if rig is None else rig
    if isinstance(element, str):  # the class is what is fitted: start it at rest (strength from the scan)
        if element not in NONLINEAR:
            make_element(element)  # the one-line error naming the known elements
        element = NONLINEAR[element].at_rest(rig)
    el = element
    if el is not None and not isinstance(el, NonlinearElement):
        raise DataError(f"element must be a name from {', '.join(NONLINEAR)} or a NonlinearElement")
    data = [prepare(r, seconds) for r in recordings]
    base = start if start is not None else linear_start(recordings, rig)
    top = max(data, key=lambda d: d["level"])
    rms_top = {k: float(v) for k, v in response_rms(base, force=top["force"], fs_hz=top["fs_hz"]).items()}
    coords = _Coordinates(base, free, el, rms_top)
    coords.oversample = max(1, int(oversample)) if el is not None else 1  # no element force: nothing to hold
    skip = [valid(d["acc"].shape[1], d["fs_hz"], skip_s) for d in data]  # samples judged: start and end left out
    weights = [np.sqrt(np.mean(d["acc"] ** 2, axis=1)) for d in data]
    lo, hi = coords.bounds()
    x_lin = np.array([math.log(float(getattr(base, p))) for p in free])
    if el is None:
        x0 = x_lin
    else:  # scan the strength with the linear start (one batched simulation)
        X = np.array([np.concatenate([x_lin, s]) for s in coords.starts()])
        cost = 0.5 * np.sum(_residuals(simulate_batch(coords, X, data), data, weights, skip) ** 2, axis=1)
        x0 = X[int(np.argmin(cost))]
    nfev = 0
    for _ in range(max(1, passes)):
        def batch(X):  # the weights as they stand when called (the final Jacobian: the last pass's)
            return _residuals(simulate_batch(coords, X, data), data, weights, skip)

        sol, jac = batched_least_squares(batch, np.clip(x0, lo + 1e-9, hi - 1e-9), (lo, hi), max_nfev)
        nfev += sol.nfev
        x0 = sol.x
        sims = simulate_batch(coords, x0[None], data)
        weights = [np.sqrt(np.mean((s[0, :, k] - d["acc"][:, k]) ** 2, axis=1)) for s, d, k in zip(sims, data, skip)]
    r = _residuals(sims, data, weights, skip)[0]
    J = jac(x0)
    shift, cov_shift = simex_shift(coords, x0, data, weights, skip, simex, seed, simulate_batch, _residuals)
    held = hold_shift(coords, x0, J, r, data, weights, skip)
    x0 = np.clip(x0 + shift + held, lo, hi)
    lengths = [k.stop - k.start for k in skip]
    cov_x = cov_shift + sandwich(J, r, [2 * m for m in lengths], lengths, lags=int(data[0]["fs_hz"]))
    return _result(coords, x0, cov_x, data, sims, skip, 0.5 * float(r @ r), nfev, time.perf_counter() - t0,
                   {"seconds": seconds, "skip_s": skip_s, "free": list(free), "passes": passes, "simex": simex,
                    "simex_shift": (np.asarray(shift) * np.ones(x0.size)).tolist(), "hold_shift": held.tolist(),
                    "oversample": coords.oversample, "extrapolate": coords.oversample > 1})


def hold_shift(coords, x, J, r, data, weights, skip) -> np.ndarray:
    """The step that takes the integrator's hold error out of a fit made at ``coords.oversample``.

    The element forces' straight-line hold errs by ~(ωΔ)²/12 (0.05 % at 4× and 100 Hz), which a
    cubic spring's k3 absorbs as a bias of about one σ of a 30 s record. Richardson's extrapolation
    between ``oversample`` and twice it (`integrate`'s ``extrapolate``) removes the Δ² term; the fit
    is moved by the Gauss-Newton step of that change in the residuals, with the fit's Jacobian
    (the change is a small fraction of a per cent of the response: linear in the parameters). One
    simulation per recording at 2× and 1× the rate, instead of fitting at the finer rate throughout.

    Parameters
    ----------
    coords : the fit's coordinates; x : the fitted coordinates; J : the Jacobian of the residuals at x.
    r : the weighted residuals at x (at ``coords.oversample``).
    data, weights, skip : as in the fit.

    Returns
    -------
    ndarray (p,): zero when the fit has no element or runs at the recordings' own rate.
    """
    if coords.el is None or coords.oversample <= 1:
        return np.zeros(x.size)
    coords.extrapolate = True
    try:
        fine = _residuals(simulate_batch(coords, x[None], data), data, weights, skip)[0]
    finally:
        coords.extrapolate = False
    return -np.linalg.lstsq(J, fine - r, rcond=None)[0]


def _result(coords, x, cov_x, data, sims, skip, cost, nfev, wall, settings) -> NonlinearFit:
    names = coords.names
    values = coords.physical(x)
    sd_x = np.sqrt(np.maximum(np.diag(cov_x), 0.0))
    std, ci = {}, {}
    rig, els = coords.decode(x)
    for i, name in enumerate(names):
        lo_x, hi_x = x.copy(), x.copy()
        lo_x[i] -= 1.959964 * sd_x[i]
        hi_x[i] += 1.959964 * sd_x[i]
        a, b = coords.physical(lo_x)[name], coords.physical(hi_x)[name]
        ci[name] = [min(a, b), max(a, b)]
        std[name] = abs(b - a) / (2 * 1.959964)
    rig = rig.replace(**{p: float(values[p]) for p in coords.free})
    el = els[0].replace(**{k: float(values[k]) for k in els[0].parameter_names}) if els else None
    rel = {}
    for i, (s, d, k) in enumerate(zip(sims, data, skip)):
        err = s[0, :, k] - d["acc"][:, k]
        rms = np.sqrt(np.mean(d["acc"][:, k] ** 2, axis=1))
        rel[i] = {"a1": float(np.sqrt(np.mean(err[0] ** 2)) / rms[0]), "a2": float(np.sqrt(np.mean(err[1] ** 2)) / rms[1])}
    eq = {}
    if el is not None:
        vals = []
        for d in data:
            rms = response_rms(rig, force=d["force"], fs_hz=d["fs_hz"])
            vals.append(float(np.ravel(el.equivalent_linear(rig, rms).value)[0]))
        eq[el.linear_parameter] = vals
    overall = float(np.sqrt(np.mean(np.square([e for per in rel.values() for e in per.values()] or [np.nan]))))
    return NonlinearFit(el, rig, values, std, ci, [d["level"] for d in data], overall, rel, eq, cost, nfev, wall,
                        settings)


def predict(fit: NonlinearFit, recording, seconds: float | None = None, skip_s: float = 2.0) -> dict:
    """Predict a recording with a fitted model: simulated a1, a2 and the relative time-domain error.

    The model is driven by the measured force kept to its excited band (`prepare`: the force
    sensor's noise outside the band is provably not force), from rest; the first ``skip_s`` are
    left out. Three errors, RMS(simulated − measured) / RMS(measured):

    - ``rel_error_excited`` (the headline): both signals kept to the bins where the measured
      response is excited (`excited_bins`: within 20 dB of its in-band peak, i.e. the resonances
      and their flanks), where the structure answers the drive. Elsewhere the recording is mostly
      the accelerometers' noise, which no model can predict and which caps any ratio between
      models at the noise level. The bins come from the measurement: every model is judged on the
      same ones.
    - ``rel_error_band``: on the whole of the force's excited band.
    - ``rel_error``: broadband, every sample (sensor noise included).

    Parameters
    ----------
    fit : NonlinearFit.
    recording : Recording (force, acc1, acc2), e.g. a drive level held out of the fit.
    seconds : use the first this many seconds (None: all).
    skip_s : leading seconds left out of the error (and the last `TAIL_S`, see `valid`).

    Returns
    -------
    dict
        ``a1``, ``a2`` (simulated), ``band_hz``, ``rel_error``, ``rel_error_band`` and ``rel_error_excited``, each
        {"a1", "a2", "both"} ("both": the RMS of the two channels' relative errors).
    """
    d = prepare(recording, seconds)
    els = [fit.element] if fit.element is not None else []
    r = integrate(fit.rig, d["force"], d["fs_hz"], els, outputs=ACCEL_CHANNELS,
                  oversample=int(fit.settings.get("oversample", 1)), extrapolate=bool(fit.settings.get("extrapolate")))
    k = valid(d["acc"].shape[1], d["fs_hz"], skip_s)
    out = {"a1": r.a1, "a2": r.a2, "band_hz": [float(b) for b in d["band_hz"]], "rel_error": {}, "rel_error_band": {},
           "rel_error_excited": {}}
    sim = np.vstack([r.a1, r.a2])[:, k]
    meas = d["acc"][:, k]
    broad = np.sqrt(np.sum((sim - meas) ** 2, axis=1) / np.sum(meas ** 2, axis=1))
    band = band_error(sim, meas, d["fs_hz"], d["band_hz"])
    excited = excited_error(sim, meas, d["fs_hz"], d["band_hz"])
    for key, e in (("rel_error", broad), ("rel_error_band", band), ("rel_error_excited", excited)):
        out[key] = {ch: float(e[c]) for c, ch in enumerate(ACCEL_CHANNELS)}
        out[key]["both"] = float(np.sqrt(np.mean(e ** 2)))
    return out
