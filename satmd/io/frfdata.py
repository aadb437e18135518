"""FRFData: measured or simulated FRFs on a frequency grid, with optional noise std."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import DataError

CHANNELS = ("a1", "a2", "u1", "u2", "q")
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
    """

    freq_hz: np.ndarray
    channels: dict
    std: dict = field(default_factory=dict)
    meta: dict = field(default_factory=dict)
    coherence: dict = field(default_factory=dict)

    def __post_init__(self):
        f = np.asarray(self.freq_hz, dtype=float)
        if f.ndim != 1 or f.size == 0:
            raise DataError(f"freq_hz must be a non-empty 1-D array, got shape {f.shape}")
        if not np.all(np.isfinite(f)) or np.any(f <= 0) or np.any(np.diff(f) <= 0):
            raise DataError("freq_hz must be finite, > 0 and strictly increasing")
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
        stds = {}
        for name, s in (self.std or {}).items():
            if name not in chans:
                raise DataError(f"std given for channel {name}, which has no data")
            s = np.asarray(s, dtype=float)
            if s.shape != f.shape:
                raise DataError(f"std of {name} has shape {s.shape}, frequency grid has {f.shape}")
            if not np.all(np.isfinite(s)) or np.any(s < 0):
                raise DataError(f"std of {name} must be finite and >= 0")
            stds[name] = s
        cohs = {}
        for name, g in (self.coherence or {}).items():
            if name not in chans:
                raise DataError(f"coherence given for channel {name}, which has no data")
            g = np.asarray(g, dtype=float)
            if g.shape != f.shape:
                raise DataError(f"coherence of {name} has shape {g.shape}, frequency grid has {f.shape}")
            if not np.all(np.isfinite(g)) or np.any(g < 0) or np.any(g > 1):
                raise DataError(f"coherence of {name} must lie in [0, 1]")
            cohs[name] = g
        object.__setattr__(self, "freq_hz", f)
        object.__setattr__(self, "channels", chans)
        object.__setattr__(self, "std", stds)
        object.__setattr__(self, "meta", dict(self.meta or {}))
        object.__setattr__(self, "coherence", cohs)

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
        return FRFData(self.freq_hz, chans, std, self.meta, coh)

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
        return FRFData(
            self.freq_hz[keep],
            {c: v[keep] for c, v in self.channels.items()},
            {c: s[keep] for c, s in self.std.items()},
            self.meta,
            {c: g[keep] for c, g in self.coherence.items()},
        )

    def with_std(self, std: dict) -> "FRFData":
        return FRFData(self.freq_hz, self.channels, std, self.meta, self.coherence)

    @classmethod
    def from_response(cls, response, channels=("a1", "a2"), std=None, meta=None) -> "FRFData":
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
