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

from dataclasses import dataclass
from typing import Sequence

import numpy as np

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
        free: Sequence[str] = ("m2", "kp", "R", "L"),
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
        self.omega_hz = data.freq_hz
        self.target = np.stack([data[c] for c in self.channels])  # (C, F)
        self.weighted = all(c in data.std for c in self.channels)
        if self.weighted:
            sigma = np.stack([data.std[c] for c in self.channels])
            if np.any(sigma <= 0):
                raise DataError("std columns contain zeros: cannot weight residuals (drop them or fix the file)")
        else:
            # paper eq. 13: s = max|x*|, per channel or (scale="global") over all channels
            s = np.abs(self.target).max(axis=1, keepdims=True)
            if scale == "global":
                s = np.full_like(s, s.max())
            sigma = np.broadcast_to(np.where(s > 0, s, 1.0), self.target.shape)
        self.sigma = np.asarray(sigma, dtype=float)
        self.n_data = 2 * self.target.size

    def _parameter(self, name, bounds):
        target, field = resolve_parameter(name, self.effects)
        if bounds is None:
            if target < 0:
                bounds = RIG_BOUNDS.get(field, (-np.inf, np.inf))
            else:
                bounds = self.effects[target].bounds(self.rig)[field]
        return Parameter(name, target, field, float(bounds[0]), float(bounds[1]))

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
        rig, effects = self.apply(theta)
        # θ stays inside the bounds, so the rig was checked once (in __init__) rather than per call
        return frf(self.omega_hz, rig, effects, wrt=self.names if wrt else None, outputs=self.channels,
                   validate=False)

    def prediction(self, theta) -> np.ndarray:
        r = self.model(theta)
        return np.stack([r.channel(c) for c in self.channels])

    def residuals(self, theta) -> np.ndarray:
        """(2·C·F,) vector: [Re, Im] of (model - data)/sigma."""
        z = (self.prediction(theta) - self.target) / self.sigma
        return np.concatenate([z.real.ravel(), z.imag.ravel()])

    def residuals_and_jacobian(self, theta):
        r = self.model(theta, wrt=True)
        z = (np.stack([r.channel(c) for c in self.channels]) - self.target) / self.sigma
        J = np.stack([r.jac[c] for c in self.channels]) / self.sigma[..., None]  # (C, F, P)
        P = J.shape[-1]
        res = np.concatenate([z.real.ravel(), z.imag.ravel()])
        jac = np.concatenate([J.real.reshape(-1, P), J.imag.reshape(-1, P)])
        return res, jac

    def batch_cost(self, thetas: np.ndarray) -> np.ndarray:
        """Sum of squared residuals for many parameter sets at once; thetas (N, P)."""
        thetas = np.asarray(thetas, dtype=float)
        rig, effects = self.apply(thetas.T)
        r = frf(self.omega_hz, rig, effects, outputs=self.channels, validate=False)
        cost = np.zeros(thetas.shape[0])
        for k, c in enumerate(self.channels):
            cost += np.sum(np.abs((r.channel(c) - self.target[k]) / self.sigma[k]) ** 2, axis=-1)
        return cost


def _typical(lo, hi):
    width = hi - lo
    return width / 10 if np.isfinite(width) and width > 0 else 1.0


def _default_channels(data: FRFData):
    acc = tuple(c for c in ("a1", "a2") if c in data.channels)
    return acc or tuple(data.channels)

