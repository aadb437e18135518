"""The weighted least-squares problem behind every fit: data, model, free parameters.

Residuals are ``(model - data) / sigma`` for the real and imaginary part of
every point of every fitted channel, where sigma is

- the data's std (SPEC §7) when the file gives it, so the sum of squares is
  a true χ², or
- ``s = max |x*|`` otherwise (the scaling of paper eq. 13), per channel by
  default or over all channels together (``scale="global"``, the paper's
  code); the fit is then relative and χ² is rescaled by its reduced value.

Free parameters are rig fields (``m2``) or effect parameters
(``extra_mode.f_hz``) and are optimised as corrections relative to a
nominal value, θ = θ_nom + scale·δ with scale = |θ_nom| (paper eqs. 11-12),
or a typical magnitude where the nominal value is zero.
"""
from __future__ import annotations

import copy
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np

from ..conventions import ACCEL_CHANNELS, DEFAULT_FREE
from ..errors import DataError
from ..io.frfdata import FRFData
from ..physics import Rig, frf
from ..physics.effects import Effect
from ..physics.model import resolve_parameter

# Hard bounds used when a rig parameter is free (wide: physics, not priors).
RIG_BOUNDS = {
    "m2": (1e-3, 50.0), "kp": (1e2, 1e8), "R": (0.0, 1e5), "L": (1e-5, 100.0),
    "m1": (1e-3, 1e3), "k1": (1e2, 1e9), "c1": (0.0, 1e4), "cp": (0.0, 1e4),
    "e": (0.0, 100.0), "Cp": (1e-9, 1e-2), "F0": (1e-6, 1e6),
}
# Where the global search looks (SPEC §9 ranges, slightly widened).
SEARCH_RANGES = {"m2": (0.25, 0.9), "kp": (4e4, 2.4e5), "R": (2.0, 120.0), "L": (0.015, 0.6)}
# batch_cost evaluates at most this many (parameter set, frequency) pairs at once: memory stays
# O(points) (about 64 bytes per pair and intermediate array, so ~20 MB per chunk) however large the batch.
BATCH_ELEMENTS = 1 << 18
# |data| beyond this (or a peak below its inverse) is no FRF in SI units, and squares of the
# residuals would overflow or underflow float64: refused.
MAX_ABS_VALUE = 1e100


@dataclass
class Parameter:
    name: str  # as given, e.g. "m2" or "extra_mode.f_hz"
    target: int  # -1 for the rig, else index of the effect
    field: str  # rig field or effect parameter
    lower: float
    upper: float


class Problem:
    """Weighted residuals r(θ) and their Jacobian for a set of free parameters."""

    def __init__(
        self,
        data: FRFData,
        rig: Rig | None = None,
        free: Sequence[str] = DEFAULT_FREE,
        channels: Sequence[str] | None = None,
        effects: Sequence[Effect] = (),
        bounds: dict | None = None,
        scale: str = "channel",
    ):
        if scale not in ("channel", "global"):
            raise DataError(f"scale must be 'channel' or 'global', got {scale!r}")
        self.data = data
        self.scale_mode = scale
        self.rig = (Rig() if rig is None else rig).validate()
        self.effects = list(effects)
        self.channels = tuple(channels) if channels else _default_channels(data)
        missing = [c for c in self.channels if c not in data.channels]
        if missing:
            raise DataError(f"channel(s) {', '.join(missing)} not in the data (has {', '.join(data.channels)})")
        if len(set(free)) != len(free) or not free:
            raise DataError(f"free parameters must be distinct and non-empty, got {list(free)}")
        self.params = [self._parameter(n, (bounds or {}).get(n)) for n in free]
        self.names = tuple(free)
        self.freq_hz = data.freq_hz
        self.target = np.stack([data[c] for c in self.channels])  # (C, F)
        n_freq = self.target.shape[1]
        if n_freq <= len(self.names):  # fewer points than unknowns: no residual dof, no noise estimate
            raise DataError(f"{n_freq} frequency point(s) for {len(self.names)} free parameters "
                            f"({', '.join(self.names)}): need at least {len(self.names) + 1} "
                            "(widen the frequency band or free fewer parameters)")
        peak = np.abs(self.target).max(initial=0.0)
        if not np.isfinite(peak) or peak > MAX_ABS_VALUE or 0 < peak < 1 / MAX_ABS_VALUE:
            raise DataError(f"data values reach {peak:.3g}: not an FRF in SI units (m/s²/N, m/N, C/N); "
                            "check the file's scaling")
        if peak == 0:
            raise DataError(f"channel(s) {', '.join(self.channels)} are all zero: nothing to fit")
        self.weighted = all(c in data.std for c in self.channels)
        if self.weighted:
            sigma = np.stack([data.std[c] for c in self.channels])
            if np.any(sigma <= 0):
                raise DataError("std columns contain zeros: cannot weight residuals (drop them or fix the file)")
            if not np.all(np.isfinite(sigma)) or sigma.max() > MAX_ABS_VALUE or peak / sigma.min() > MAX_ABS_VALUE:
                raise DataError(f"std columns span {sigma.min():.3g} to {sigma.max():.3g} for data up to {peak:.3g}: "
                                "not a noise level in SI units")
        else:
            # paper eq. 13: s = max|x*|, per channel or (scale="global") over all channels
            s = np.abs(self.target).max(axis=1, keepdims=True)
            if scale == "global":
                s = np.full_like(s, s.max())
            sigma = np.broadcast_to(np.where(s > 0, s, 1.0), self.target.shape)
        self.sigma = np.asarray(sigma, dtype=float)
        self.n_data = 2 * self.target.size
        self.pair = self._correlated_pair(data) if self.weighted else None
        self.kernel_rms_hz = float(data.estimator.get("kernel_rms_hz") or 0.0)
        decay_s = float(data.estimator.get("window_decay_s") or 0.0)
        self.window_decay_hz = 1.0 / (2.0 * np.pi * decay_s) if decay_s > 0 else 0.0

    def _correlated_pair(self, data):
        """(i, j, conj ρ, 1/sqrt(1 − |ρ|²)) for two channels whose noise is correlated, else None.

        FRFs estimated from one recording share the force sensor's noise, so their
        errors are correlated (|ρ| up to ~0.9 at resonances). Residuals are whitened
        per point (z_j = (u_j − ρ* u_i)/sqrt(1 − |ρ|²)) so that χ², the tests and the
        covariance stay exact.
        """
        for key, rho in data.correlation.items():
            a, b = key.split(",")
            if a in self.channels and b in self.channels:
                return (self.channels.index(a), self.channels.index(b), np.conj(rho),
                        1.0 / np.sqrt(1.0 - np.abs(rho) ** 2))
        return None

    def whiten(self, u: np.ndarray) -> np.ndarray:
        """Standardised residuals u = (model − data)/σ, channels first, made independent across channels."""
        if self.pair is None:
            return u
        i, j, rho_c, scale = self.pair
        extra = (None,) * (u.ndim - 2)  # trailing axes (parameters of a Jacobian)
        out = u.copy()
        out[j] = (u[j] - rho_c[(slice(None),) + extra] * u[i]) * scale[(slice(None),) + extra]
        return out

    def standardise(self, prediction: np.ndarray) -> np.ndarray:
        """(C, F) whitened standardised residuals of a prediction."""
        return self.whiten((prediction - self.target) / self.sigma)

    def standardize(self, prediction: np.ndarray) -> np.ndarray:
        """Deprecated spelling of `standardise`.

        Parameters
        ----------
        prediction : (C, F) model prediction

        Returns
        -------
        np.ndarray
        """
        _deprecated("Problem.standardize", "Problem.standardise")
        return self.standardise(prediction)

    @property
    def omega_hz(self) -> np.ndarray:
        """Deprecated name of `freq_hz` (a frequency in Hz, not an angular frequency)."""
        _deprecated("Problem.omega_hz", "Problem.freq_hz")
        return self.freq_hz

    @omega_hz.setter
    def omega_hz(self, value) -> None:
        _deprecated("Problem.omega_hz", "Problem.freq_hz")
        self.freq_hz = value

    def _parameter(self, name, bounds):
        target, field = resolve_parameter(name, self.effects)
        if bounds is None:
            if target < 0:
                bounds = RIG_BOUNDS.get(field, (-np.inf, np.inf))
            else:
                bounds = self.effects[target].bounds(self.rig)[field]
        lo, hi = float(bounds[0]), float(bounds[1])
        if not lo < hi or np.isnan(lo) or np.isnan(hi):
            raise DataError(f"bounds of {name} must satisfy lower < upper, got ({lo:g}, {hi:g})")
        return Parameter(name, target, field, lo, hi)

    # --- values ------------------------------------------------------------
    def values(self, rig=None, effects=None) -> np.ndarray:
        """Current value of every free parameter."""
        rig = self.rig if rig is None else rig
        effects = self.effects if effects is None else effects
        return np.array([getattr(rig, p.field) if p.target < 0 else effects[p.target].params[p.field]
                         for p in self.params], dtype=float)

    def apply(self, theta) -> tuple[Rig, list]:
        """Rig and effects with the free parameters set to θ (θ may be (P,) or (P, N))."""
        rig_changes, effects = {}, list(self.effects)
        for p, v in zip(self.params, theta):
            if p.target < 0:
                rig_changes[p.field] = v
            else:
                effects[p.target] = effects[p.target].replace(**{p.field: v})
        return (self.rig.replace(**rig_changes) if rig_changes else self.rig), effects

    def scales(self, nominal) -> np.ndarray:
        """Scale of the relative corrections: |θ_nom|, or a tenth of the range where θ_nom = 0."""
        nominal = np.abs(np.asarray(nominal, dtype=float))
        typical = np.array([_typical(p.lower, p.upper) for p in self.params])
        return np.where(nominal > 0, nominal, typical)

    def values_from_x(self, x, nominal) -> np.ndarray:
        return np.asarray(nominal, dtype=float) + self.scales(nominal) * np.asarray(x)

    @property
    def lower(self):
        return np.array([p.lower for p in self.params])

    @property
    def upper(self):
        return np.array([p.upper for p in self.params])

    # --- residuals -------------------------------------------------------------
    def model(self, theta, wrt=False):
        """The model as the data see it: through the estimator's smoothing when it has one."""
        rig, effects = self.apply(theta)
        # θ stays inside the bounds, so the rig was checked once (in __init__) rather than per call
        r = frf(self._eval_hz(), rig, effects, wrt=self.names if wrt else None, outputs=self.channels,
                validate=False)
        return r if not self.kernel_rms_hz else _Smoothed(r, self.freq_hz.size)

    def _eval_hz(self):
        """Where the model is evaluated: the data grid, or f ± s for an estimator with a smoothing kernel.

        A windowed (Welch) estimate is the true FRF smoothed by the window's power
        kernel; to second order that is the mean of H(f − s) and H(f + s), s the
        kernel's RMS width (for Hann s = Δf/√3, the −(4/3)(Δf/B_r)² peak bias of
        Bendat & Piersol). Comparing the model through the same kernel compares
        like with like, so the window's bias is never taken for physics. An exponential
        window (an impact test that does not ring down) is exact: the model at
        the complex frequency ``f − i/(2πτ)``.
        """
        if self.window_decay_hz:  # an exponential window e^(-t/τ) gives H(iω + 1/τ): f − i/(2πτ) in Hz
            return self.freq_hz - 1j * self.window_decay_hz
        s = self.kernel_rms_hz
        if not s:
            return self.freq_hz
        return np.concatenate([np.maximum(self.freq_hz - s, 1e-3 * self.freq_hz), self.freq_hz + s])

    def prediction(self, theta) -> np.ndarray:
        r = self.model(theta)
        return np.stack([r.channel(c) for c in self.channels])

    def residuals(self, theta) -> np.ndarray:
        """(2·C·F,) vector: [Re, Im] of (model - data)/sigma."""
        z = self.standardise(self.prediction(theta))
        return np.concatenate([z.real.ravel(), z.imag.ravel()])

    def residuals_and_jacobian(self, theta):
        r = self.model(theta, wrt=True)
        z = self.standardise(np.stack([r.channel(c) for c in self.channels]))
        J = self.whiten(np.stack([r.jac[c] for c in self.channels]) / self.sigma[..., None])  # (C, F, P)
        P = J.shape[-1]
        res = np.concatenate([z.real.ravel(), z.imag.ravel()])
        jac = np.concatenate([J.real.reshape(-1, P), J.imag.reshape(-1, P)])
        return res, jac

    def batch_cost(self, thetas: np.ndarray) -> np.ndarray:
        """Sum of squared residuals for many parameter sets at once; thetas (N, P).

        Evaluated in chunks of rows so that memory is O(points), not O(N × points).
        """
        thetas = np.asarray(thetas, dtype=float)
        rows = max(1, BATCH_ELEMENTS // self.target.shape[1])
        cost = np.zeros(thetas.shape[0])
        for a in range(0, thetas.shape[0], rows):
            rig, effects = self.apply(thetas[a:a + rows].T)
            r: Any = frf(self._eval_hz(), rig, effects, outputs=self.channels, validate=False)
            if self.kernel_rms_hz:
                r = _Smoothed(r, self.freq_hz.size)
            u = [(r.channel(c) - self.target[k]) / self.sigma[k] for k, c in enumerate(self.channels)]
            if self.pair is not None:
                i, j, rho_c, scale = self.pair
                u[j] = (u[j] - rho_c * u[i]) * scale
            for uk in u:
                cost[a:a + rows] += np.sum(np.abs(uk) ** 2, axis=-1)
        return cost

    def thinned(self, n_points: int) -> "Problem":
        """The same problem on at most ``n_points`` frequencies.

        Points are spread evenly over the data's arc length plus an even share
        over frequency, so resonances (where the FRF turns fast) keep their
        points. Used for the global search only: the final fit uses all data.

        Parameters
        ----------
        n_points : most frequencies kept.

        Returns
        -------
        Problem
            ``self`` when it has no more points, else a shallow copy on the subset.
        """
        F = self.target.shape[1]
        if F <= n_points:
            return self
        z = self.target / np.abs(self.target).max(axis=1, keepdims=True)
        step = np.abs(np.diff(z, axis=1)).sum(axis=0)
        arc = np.concatenate([[0.0], np.cumsum(step + step.mean())])  # half by change, half even
        idx = np.unique(np.searchsorted(arc, np.linspace(0.0, arc[-1], n_points)).clip(0, F - 1))
        sub = copy.copy(self)
        sub.freq_hz, sub.target, sub.sigma = self.freq_hz[idx], self.target[:, idx], self.sigma[:, idx]
        if self.pair is not None:
            i, j, rho_c, scale = self.pair
            sub.pair = (i, j, rho_c[idx], scale[idx])
        sub.n_data = 2 * sub.target.size
        return sub


class _Smoothed:
    """Channels and Jacobians of a response on [f − s, f + s], averaged back onto f."""

    def __init__(self, response, n_freq):
        self._r, self._n = response, n_freq

    def channel(self, c):
        x = self._r.channel(c)
        return 0.5 * (x[..., :self._n] + x[..., self._n:])

    @property
    def jac(self):
        n = self._n
        return {c: 0.5 * (j[..., :n, :] + j[..., n:, :]) for c, j in self._r.jac.items()}


def _typical(lo, hi):
    width = hi - lo
    return width / 10 if np.isfinite(width) and width > 0 else 1.0


def _default_channels(data: FRFData):
    acc = tuple(c for c in ACCEL_CHANNELS if c in data.channels)
    return acc or tuple(data.channels)


def _deprecated(old: str, new: str) -> None:
    import warnings

    warnings.warn(f"{old} is deprecated; use {new}", DeprecationWarning, stacklevel=3)
