"""Fit a single-mode oscillator with polynomial stiffness to one input/output record.

    ÿ + c ẏ + k y + k2 y² + k3 y³ = g·u(t − τ),      observed as y + y0 (+ d·u)

(mass 1: the input gain g carries the scale). The fit is a time-domain output error: the model is
simulated (RK4 at sub-steps, band-limited input, segments side by side; `satmd.physics.oscillator`)
and `scipy.optimize.least_squares` adjusts the parameters, with a Jacobian by forward differences
computed in one vectorised pass. It starts from the FRF: a second-order fit to the H1 estimate
gives a linear start, a linear output-error fit refines it (the best linear model, reported beside
the nonlinear one), and the nonlinear fit starts there with k2 = k3 = 0. A constant force is not a
parameter: with y0 and k2 free it would shift the whole polynomial without changing the output.

>>> import numpy as np
>>> from satmd.physics.oscillator import PolynomialOscillator
>>> w = 2 * np.pi * 20.0
>>> truth = PolynomialOscillator(k=w * w, c=2 * 0.05 * w, k3=3.0 * w * w, gain=w * w)
>>> u = np.random.default_rng(0).normal(size=4000) * 0.1
>>> fit = fit_oscillator(u, truth.simulate(u, 200.0), 200.0, delay=False)
>>> round(float(fit.model.k3 / truth.k3), 3)
1.0
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import signal
from scipy.optimize import least_squares

from ..errors import DataError
from ..numerics import batched_least_squares, jacobian_covariance
from ..physics.oscillator import PolynomialOscillator, fine_input, rk4_batch, segment_windows

T95 = 1.959963984540054
LINEAR = ("wn", "zeta", "gain", "y0", "delay", "feedthrough")
NONLINEAR = LINEAR + ("a2", "a3", "lag")


@dataclass(frozen=True)
class OscillatorFit:
    """A fitted oscillator: the nonlinear model, the best linear model and their figures.

    Attributes
    ----------
    model, linear : PolynomialOscillator
        The nonlinear fit and the linear output-error fit it started from.
    values, half_width95 : dict
        Physical parameters of ``model`` (k, c, k2, k3, gain, delay, output_offset, feedthrough,
        natural_frequency_hz, damping_ratio) and the half-widths of their 95 % intervals (from the
        Jacobian; the residual's colour is ignored, so on real data they are optimistic); ``ci95``
        gives the intervals as {name: [lo, hi]}, as every other result does.
    fs_hz : float
        Sampling frequency [Hz].
    rms_fit, rms_fit_linear : float
        RMS output error on the fitted samples (nonlinear, linear).
    n_samples, nfev : int
        Samples scored in the fit; simulations of the nonlinear fit.
    seconds : float
        Wall time of the whole fit.
    options : dict
        substeps, intersample, warmup, segment.
    """

    model: PolynomialOscillator
    linear: PolynomialOscillator
    values: dict
    half_width95: dict
    fs_hz: float
    rms_fit: float
    rms_fit_linear: float
    n_samples: int
    nfev: int
    seconds: float
    options: dict = field(default_factory=dict)

    @property
    def ci95(self) -> dict:
        """{name: [lo, hi]}: the 95 % intervals."""
        return {k: [self.values[k] - h, self.values[k] + h] for k, h in self.half_width95.items()}

    def predict(self, u, linear=False, segmented=False):
        """Simulate the fitted (or the linear) model on a new input record from rest.

        Parameters
        ----------
        u : array_like
            Input samples at the fit's sampling frequency.
        linear : bool
            The linear model instead of the nonlinear one.
        segmented : bool
            Segments side by side, each warmed up over 4× the fit's warm-up (faster; equal to the
            serial simulation only while the system forgets its start). Default: one serial run.

        Returns
        -------
        numpy.ndarray
        """
        m = self.linear if linear else self.model
        seg = {"warmup": 4 * self.options["warmup"], "length": 4 * self.options["segment"]} if segmented else {}
        return m.simulate(u, self.fs_hz, substeps=self.options["substeps"], intersample=self.options["intersample"],
                          **seg)

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {"model": self.model.to_dict(), "linear": self.linear.to_dict(), "values": dict(self.values),
                "ci95": self.ci95, "half_width95": dict(self.half_width95), "fs_hz": self.fs_hz, "rms_fit": self.rms_fit,
                "rms_fit_linear": self.rms_fit_linear, "n_samples": self.n_samples, "nfev": self.nfev,
                "seconds": self.seconds, "options": dict(self.options)}

    def report(self) -> str:
        """Parameters with intervals, and the fit errors."""
        lines = [f"oscillator fit: {self.n_samples} samples, {self.nfev} simulations, {self.seconds:.1f} s",
                 f"  rms error on the fitted samples: linear {self.rms_fit_linear:.4g}, "
                 f"nonlinear {self.rms_fit:.4g}"]
        lines += [f"  {k:>22s} = {v:.6g}" + (f" ± {self.half_width95[k]:.2g}" if k in self.half_width95 else "")
                  for k, v in self.values.items()]
        return "\n".join(lines)


def rms_error(y_model, y, lo=0, hi=None):
    """RMS of y_model − y over samples [lo, hi), absolute and as % of the RMS of y there.

    Parameters
    ----------
    y_model, y : array_like
        Simulated and measured outputs.
    lo, hi : int
        The scored samples.

    Returns
    -------
    dict
        ``rms`` (units of y), ``pct`` (% of rms(y)) and ``n`` (samples).
    """
    e = np.asarray(y_model, float)[lo:hi] - np.asarray(y, float)[lo:hi]
    ref = np.sqrt(np.mean(np.asarray(y, float)[lo:hi] ** 2))
    rms = float(np.sqrt(np.mean(e ** 2)))
    return {"rms": rms, "pct": 100.0 * rms / ref, "n": int(e.size)}


def frf_start(u, y, fs_hz, nperseg=1024):
    """Second-order start G0·ω²·e^(−sτ)/(s² + 2ζωs + ω²) fitted to the H1 FRF estimate.

    Parameters
    ----------
    u, y : numpy.ndarray
        Input and output records.
    fs_hz : float
        Sampling frequency [Hz].
    nperseg : int
        Welch segment length.

    Returns
    -------
    dict
        ``wn`` [rad/s], ``zeta``, ``gain`` (static gain y/u), ``delay`` [samples].
    """
    nper = int(min(nperseg, max(64, u.size // 8)))
    f, puu = signal.welch(u, fs_hz, nperseg=nper)
    _, puy = signal.csd(u, y, fs_hz, nperseg=nper)
    _, coh = signal.coherence(u, y, fs_hz, nperseg=nper)
    h = puy / np.where(puu > 0, puu, np.inf)
    keep = (f > 0) & (coh > 0.5) & (f < 0.45 * fs_hz) & np.isfinite(h)
    if keep.sum() < 6:
        raise DataError("too few coherent frequencies to start the oscillator fit (input too narrow or too noisy)")
    f, h = f[keep], h[keep]
    s = 2j * np.pi * f
    i = int(np.argmax(np.abs(h)))

    def model(p):
        wn, z, g0, tau = p
        return g0 * wn * wn * np.exp(-s * tau / fs_hz) / (s * s + 2 * z * wn * s + wn * wn)

    def res(p):
        r = (model(p) - h) / np.abs(h)
        return np.concatenate([r.real, r.imag])

    wn0 = 2 * np.pi * f[i]
    g0 = float(np.abs(h[i]) * 2 * 0.05)
    p = least_squares(res, [wn0, 0.05, g0 * np.sign(h[0].real or 1.0), 0.0],
                      bounds=([0.2 * wn0, 1e-4, -np.inf, -0.5], [5 * wn0, 2.0, np.inf, 20.0])).x
    return {"wn": float(p[0]), "zeta": float(p[1]), "gain": float(p[2]), "delay": float(p[3])}


class _Problem:
    """Scaled parameters ↔ oscillator, and the batched residual over the scored samples."""

    def __init__(self, u, y, fs, ranges, start, substeps, intersample, warmup, segment):
        self.u, self.y, self.fs = u, y, fs
        self.substeps, self.intersample = substeps, intersample
        sel = np.concatenate([np.arange(lo, hi) for lo, hi in ranges])
        self.su, self.sy, self.ym = float(np.std(u[sel])), float(np.std(y[sel])), float(np.mean(y[sel]))
        self.wn0 = start["wn"]
        span = min(segment, min(hi - lo - warmup for lo, hi in ranges))
        starts, masks = [], []
        for lo, hi in ranges:
            st, n = segment_windows(u.size, span, warmup, lo, hi)
            prev = lo + warmup
            for s in st:
                m = np.zeros(n, bool)
                m[max(warmup, prev - s):] = True
                prev = s + n
                starts.append(s)
                masks.append(m)
        self.starts, self.n = np.array(starts), n
        self.mask = np.stack(masks, axis=1)
        self.f = 2 * substeps
        self.idx = self.starts[None, :] * self.f + np.arange(n * self.f + 1)[:, None]
        rows = self.starts[None, :] + np.arange(n)[:, None]
        self.target = y[rows][self.mask]
        self.u_rows = u[rows]
        self.n_scored = int(self.mask.sum())
        self._cache = {}

    def oscillator(self, p, names):
        """The oscillator of scaled parameters ``p`` (named by ``names``; the rest are zero)."""
        v = dict(zip(names, p))
        wn = v["wn"] * self.wn0
        k = wn * wn
        return PolynomialOscillator(
            k=k, c=2 * v["zeta"] * wn, k2=v.get("a2", 0.0) * k / self.sy, k3=v.get("a3", 0.0) * k / self.sy ** 2,
            gain=v["gain"] * k * self.sy / self.su, delay=v.get("delay", 0.0) / self.fs,
            output_offset=self.ym + v["y0"] * self.sy, feedthrough=v.get("feedthrough", 0.0) * self.sy / self.su,
            lag=v.get("lag", 0.0) / wn)

    def _fine(self, delay):
        key = round(float(delay), 12)
        if key not in self._cache:
            if len(self._cache) > 4:
                self._cache.clear()
            self._cache[key] = fine_input(self.u, self.f, delay, self.intersample)[self.idx]
        return self._cache[key]

    def simulate(self, sets, names):
        """Model outputs on the scored samples for each parameter set (rows)."""
        oscs = [self.oscillator(p, names) for p in sets]
        keys = ("k", "c", "k2", "k3", "g", "f0", "lag")
        coef = {key: np.array([o.coefficients()[key] for o in oscs])[:, None] for key in keys}
        uf = np.stack([self._fine(o.delay * self.fs) for o in oscs], axis=1)
        x = rk4_batch(coef, uf, self.substeps, self.fs)
        out = []
        for j, o in enumerate(oscs):
            yj = x[:, j, :] + o.output_offset + o.feedthrough * self.u_rows
            out.append(yj[self.mask])
        return np.array(out)

    def fit(self, p0, names, lower, upper, max_nfev):
        """least_squares on the scaled residual; returns (result, nfev)."""
        calls = {"n": 0}

        def residuals(P):
            calls["n"] += len(P)
            return (self.simulate(list(P), names) - self.target) / self.sy

        steps = 1e-6 * np.maximum(1.0, np.abs(np.asarray(p0, float)))  # fixed at the start
        r, _ = batched_least_squares(residuals, np.asarray(p0, float), (lower, upper), max_nfev, steps=steps,
                                     gtol=1e-10)
        return r, calls["n"]


_BOUNDS = {"wn": (0.2, 5.0), "zeta": (1e-4, 2.0), "gain": (-np.inf, np.inf), "y0": (-np.inf, np.inf),
           "delay": (-0.5, 20.0), "feedthrough": (-np.inf, np.inf), "a2": (-np.inf, np.inf), "a3": (-np.inf, np.inf),
           "lag": (-1.0, 1.0)}


def _physical(problem, p, names):
    o = problem.oscillator(p, names)
    return {"k": o.k, "c": o.c, "k2": o.k2, "k3": o.k3, "gain": o.gain, "delay": o.delay,
            "output_offset": o.output_offset, "feedthrough": o.feedthrough, "lag": o.lag,
            "natural_frequency_hz": o.natural_frequency_hz, "damping_ratio": o.damping_ratio}


def _intervals(problem, r, names):
    """95 % half-widths of the physical parameters (Jacobian covariance, delta method)."""
    n, p = r.fun.size, r.x.size
    s2 = 2 * r.cost / max(n - p, 1)
    cov = jacobian_covariance(r.jac, s2)
    if not np.all(np.isfinite(cov)):  # rank deficient: no interval rather than a pseudo-inverse's
        return {}
    base = _physical(problem, r.x, names)
    grads = []
    for i in range(p):
        step = 1e-7 * max(1.0, abs(r.x[i]))
        moved = _physical(problem, r.x + np.eye(p)[i] * step, names)
        grads.append([(moved[key] - base[key]) / step for key in base])
    g = np.array(grads).T
    var = np.einsum("ij,jk,ik->i", g, cov, g)
    return {key: float(T95 * np.sqrt(max(v, 0.0))) for key, v in zip(base, var)}


def fit_oscillator(u, y, fs_hz, ranges=None, *, delay=True, feedthrough=False, quadratic=True, lag=False,
                   substeps=6, intersample="bandlimited", warmup=None, segment=None, max_nfev=60):
    """Fit ÿ + cẏ + ky + k2y² + k3y³ = g·u(t − τ) (+ y0, d·u) to a record by simulation output error.

    Parameters
    ----------
    u, y : array_like, shape (n,)
        Input and output records (one channel each, same length).
    fs_hz : float
        Sampling frequency [Hz].
    ranges : list of (int, int) or None
        Sample ranges [lo, hi) used in the fit (None: the whole record). Each range's first
        ``warmup`` samples are simulated but not scored.
    delay, feedthrough, quadratic, lag : bool
        Fit an input delay τ, a direct feedthrough d, a quadratic stiffness k2, a lag λ of the
        nonlinear force (its argument y − λẏ).
    substeps : int
        RK4 steps per sample period.
    intersample : {"bandlimited", "zoh", "foh"}
        How the input is taken between samples.
    warmup : int or None
        Samples simulated from rest before each scored segment (None: 12 time constants 1/(ζω) of
        the FRF start, at least 50).
    segment : int or None
        Scored samples per segment (None: the larger of 2·warmup and 1/64 of the fitted samples,
        which keeps both the Python loop and the arrays short).
    max_nfev : int
        Simulation budget of each least-squares stage.

    Returns
    -------
    OscillatorFit
    """
    t0 = time.perf_counter()
    u, y = np.asarray(u, dtype=float), np.asarray(y, dtype=float)
    if u.ndim != 1 or u.shape != y.shape:
        raise DataError(f"input and output must be 1-D records of the same length, got {u.shape} and {y.shape}")
    if not (np.all(np.isfinite(u)) and np.all(np.isfinite(y))):
        raise DataError("the oscillator record holds NaN or infinite samples")
    if not fs_hz > 0:
        raise DataError(f"the sampling frequency must be positive, got {fs_hz}")
    ranges = [(0, u.size)] if ranges is None else [(int(a), int(b)) for a, b in ranges]
    if any(not 0 <= a < b <= u.size for a, b in ranges):
        raise DataError(f"fit ranges {ranges} must lie inside the record of {u.size} samples")
    sel = np.concatenate([np.arange(a, b) for a, b in ranges])
    start = frf_start(u[ranges[0][0]:ranges[0][1]] if len(ranges) == 1 else u[sel],
                      y[ranges[0][0]:ranges[0][1]] if len(ranges) == 1 else y[sel], fs_hz)
    if warmup is None:
        warmup = int(np.clip(np.ceil(12 * fs_hz / (start["zeta"] * start["wn"])), 50, 20000))
    if segment is None:
        segment = max(2 * warmup, sel.size // 64)
    prob = _Problem(u, y, fs_hz, ranges, start, int(substeps), intersample, int(warmup), int(segment))
    lin_names = [n for n in LINEAR if (n != "delay" or delay) and (n != "feedthrough" or feedthrough)]
    p0 = {"wn": 1.0, "zeta": start["zeta"], "gain": start["gain"] * prob.su / prob.sy, "y0": 0.0,
          "delay": min(max(start["delay"], 0.0), 5.0), "feedthrough": 0.0, "a2": 0.0, "a3": 0.0,
          "lag": 0.0}

    def stage(names, x0):
        lo = [_BOUNDS[n][0] for n in names]
        hi = [_BOUNDS[n][1] for n in names]
        x0 = np.clip([x0[n] for n in names], np.array(lo) + 1e-12, np.array(hi) - 1e-12)
        return prob.fit(x0, names, lo, hi, max_nfev)

    r_lin, _ = stage(lin_names, p0)
    p1 = {**p0, **dict(zip(lin_names, r_lin.x))}
    nl_names = lin_names + (["a2"] if quadratic else []) + ["a3"] + (["lag"] if lag else [])
    r_nl, nfev = stage(nl_names, p1)
    linear = prob.oscillator(r_lin.x, lin_names)
    model = prob.oscillator(r_nl.x, nl_names)
    return OscillatorFit(
        model=model, linear=linear, values=_physical(prob, r_nl.x, nl_names), half_width95=_intervals(prob, r_nl, nl_names),
        fs_hz=float(fs_hz), rms_fit=float(np.sqrt(2 * r_nl.cost / r_nl.fun.size)) * prob.sy,
        rms_fit_linear=float(np.sqrt(2 * r_lin.cost / r_lin.fun.size)) * prob.sy, n_samples=prob.n_scored,
        nfev=nfev, seconds=time.perf_counter() - t0,
        options={"substeps": int(substeps), "intersample": intersample, "warmup": int(warmup), "segment": int(segment)})

