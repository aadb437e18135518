"""FRFData: measured or simulated FRFs on a frequency grid, with optional noise std."""
from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import DataError
from .estmeta import validate_estimator

CHANNELS = ("a1", "a2", "u1", "u2", "q")
MAX_FREQ_HZ = 1e9  # no structural FRF reaches a GHz; beyond, ω² overflows in the models
MIN_FREQ_HZ = 1e-9
MAX_ABS_VALUE = 1e100  # no FRF in SI units reaches this; the fitting commands refuse it (squares overflow)
UNITS = {"a1": "m/s²/N", "a2": "m/s²/N", "u1": "m/N", "u2": "m/N", "q": "C/N"}


@dataclass(frozen=True)
class FRFData:
    """Complex FRF channels on a strictly increasing frequency grid.

    Attributes
    ----------
    freq_hz : (n,) float array
    channels : dict name -> (n,) complex array; names from ``a1 a2 u1 u2 q``
    std : dict name -> (n,) float array; standard deviation of the noise on
        each of the real and imaginary parts (SPEC §7); may be empty.
    meta : dict of strings (source, units, comments)
    coherence : dict name -> (n,) float array in [0, 1]; ordinary coherence
        of an FRF estimated from time data (may be empty).
    correlation : dict "c1,c2" -> (n,) complex; correlation coefficient
        E[e1 e2*]/(σ1 σ2) of the noise of two channels at each point (both see
        the same force-sensor noise when estimated from one recording); may be
        empty (independent channels).
    estimator : dict, JSON-ready; how FRFs estimated from a recording were
        made (method, settings, ``noise_dof`` behind the std, measurement-chain
        findings); empty for FRFs read from a file or simulated.
    bias_bound : (n,) float array or None; the relative systematic error the
        estimator may have left at each point (an uncorrected force-noise
        bias pulls H towards zero by up to this share); None when none is
        known (files, simulations).
    """

    freq_hz: np.ndarray
    channels: dict
    std: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)
    coherence: dict = field(default_factory=dict)
    estimator: dict = field(default_factory=dict)
    correlation: dict = field(default_factory=dict)
    bias_bound: np.ndarray | None = None

    def __post_init__(self):
        f = np.asarray(self.freq_hz, dtype=float)
        if f.ndim != 1 or f.size == 0:
            raise DataError(f"freq_hz must be a non-empty 1-D array, got shape {f.shape}")
        if not np.all(np.isfinite(f)) or np.any(f <= 0) or np.any(np.diff(f) <= 0):
            raise DataError("freq_hz must be finite, > 0 and strictly increasing")
        if f[-1] > MAX_FREQ_HZ or f[0] < MIN_FREQ_HZ:
            x = f[-1] if f[-1] > MAX_FREQ_HZ else f[0]
            raise DataError(f"frequency {x:.3g} Hz is outside {MIN_FREQ_HZ:g}..{MAX_FREQ_HZ:g} Hz: a wrong unit or a "
                            f"damaged file?")
        if not self.channels:
            raise DataError("FRFData needs at least one channel")
        chans = {}
        for name, v in self.channels.items():
            if name not in CHANNELS:
                raise DataError(f"unknown channel {name!r}; known: {', '.join(CHANNELS)}")
            v = np.asarray(v, dtype=complex)
            if v.shape != f.shape:
                raise DataError(f"channel {name} has shape {v.shape}, frequency grid has {f.shape}")
            if not np.all(np.isfinite(v)):
                raise DataError(f"channel {name} contains NaN or infinite values")
            chans[name] = v
        stds = _per_channel("std", self.std, chans, f.shape, lambda s: np.all(s >= 0), "must be finite and >= 0")
        cohs = _per_channel("coherence", self.coherence, chans, f.shape, lambda g: np.all((g >= 0) & (g <= 1)),
                            "must lie in [0, 1]")
        object.__setattr__(self, "freq_hz", f)
        object.__setattr__(self, "channels", chans)
        object.__setattr__(self, "std", stds)
        object.__setattr__(self, "meta", dict(self.meta or {}))
        object.__setattr__(self, "coherence", cohs)
        object.__setattr__(self, "estimator", validate_estimator(self.estimator, float(f[-1])))
        corr = {}
        for key, r in (self.correlation or {}).items():
            pair = key.split(",")
            if len(pair) != 2 or any(c not in chans for c in pair):
                raise DataError(f"correlation {key!r} must name two channels of the data as 'c1,c2'")
            r = np.asarray(r, dtype=complex)
            if r.shape != f.shape or not np.all(np.isfinite(r)) or np.any(np.abs(r) >= 1):
                raise DataError(f"correlation {key} must be finite, inside the unit circle, one per frequency")
            corr[key] = r
        object.__setattr__(self, "correlation", corr)
        if self.bias_bound is not None:
            b = np.asarray(self.bias_bound, dtype=float)
            if b.shape != f.shape or not np.all(np.isfinite(b)) or np.any(b < 0):
                raise DataError(f"bias_bound must be finite, >= 0 and one per frequency (got shape {b.shape})")
            object.__setattr__(self, "bias_bound", b)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self.channels)

    @property
    def has_std(self) -> bool:
        return bool(self.std) and all(c in self.std for c in self.channels)

    def __len__(self):
        return self.freq_hz.size

    def __getitem__(self, name) -> np.ndarray:
        try:
            return self.channels[name]
        except KeyError:
            raise DataError(f"no channel {name!r} in the data (has {', '.join(self.channels)})") from None

    def select(self, channels) -> "FRFData":
        chans = {c: self[c] for c in channels}
        std = {c: self.std[c] for c in channels if c in self.std}
        coh = {c: self.coherence[c] for c in channels if c in self.coherence}
        corr = {k: r for k, r in self.correlation.items() if all(c in chans for c in k.split(","))}
        return replace(self, channels=chans, std=std, coherence=coh, correlation=corr)

    def band(self, lo: float | None = None, hi: float | None = None) -> "FRFData":
        """Only the points with lo <= f <= hi."""
        keep = np.ones(self.freq_hz.size, dtype=bool)
        if lo is not None:
            keep &= self.freq_hz >= lo
        if hi is not None:
            keep &= self.freq_hz <= hi
        if keep.sum() == 0:
            raise DataError(f"band {lo}:{hi} Hz holds no data point (data span "
                            f"{self.freq_hz[0]:g}..{self.freq_hz[-1]:g} Hz)")
        return self.take(keep)

    def take(self, keep) -> "FRFData":
        """Only the points ``keep`` (a boolean mask or indices), every per-point array alike."""
        return replace(
            self,
            freq_hz=self.freq_hz[keep],
            channels={c: v[keep] for c, v in self.channels.items()},
            std={c: s[keep] for c, s in self.std.items()},
            coherence={c: g[keep] for c, g in self.coherence.items()},
            correlation={k: r[keep] for k, r in self.correlation.items()},
            bias_bound=None if self.bias_bound is None else self.bias_bound[keep],
        )

    def with_std(self, std: dict) -> "FRFData":
        return replace(self, std=std)

    @classmethod
    def from_response(cls, response, channels=ACCEL_CHANNELS, std=None, meta=None) -> "FRFData":
        """Wrap a single (unbatched) `satmd.physics.Response`."""
        chans = {c: np.asarray(response.channel(c)) for c in channels}
        if any(v.ndim != 1 for v in chans.values()):
            raise DataError("from_response needs a single rig, not a batch")
        return cls(response.freq_hz, chans, std or {}, meta or {})

    def __repr__(self):
        f = self.freq_hz
        s = " with std" if self.std else ""
        return (f"FRFData({len(f)} points, {f[0]:g}..{f[-1]:g} Hz, "
                f"channels {', '.join(self.channels)}{s})")


def _per_channel(what, given, chans, shape, valid, rule) -> dict:
    """Real per-channel arrays (std, coherence) checked against the data's channels and frequency grid."""
    out = {}
    for name, s in (given or {}).items():
        if name not in chans:
            raise DataError(f"{what} given for channel {name}, which has no data")
        s = np.asarray(s, dtype=float)
        if s.shape != shape:
            raise DataError(f"{what} of {name} has shape {s.shape}, frequency grid has {shape}")
        if not (np.all(np.isfinite(s)) and valid(s)):
            raise DataError(f"{what} of {name} {rule}")
        out[name] = s
    return out


def require_data(value, name: str, *types):
    """Raise a `TypeError` naming argument ``name`` unless ``value`` is one of ``types`` (default `FRFData`).

    The public entry points call this first, so ``identify([1, 2, 3])`` says
    what it wanted instead of failing deep inside with an AttributeError.
    """
    types = types or (FRFData,)
    if not isinstance(value, types):
        wanted = " or ".join(t.__name__ for t in types)
        raise TypeError(f"{name} must be {wanted} (e.g. satmd.io.load_frf(path) or load_recording(path)), "
                        f"got {type(value).__name__}")
    return value
