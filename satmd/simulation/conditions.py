"""Lab conditions for simulated recordings: a shaker's force spectrum and sensor noise that is not white.

A real shaker does not deliver a flat force cut sharply at the band edges: its
amplifier and armature roll the force off (Butterworth-like, gently or
steeply), it is high-passed below the band, the drive may be pink, and the
armature's own resonance puts a bump in the spectrum. Real sensors add more
than white noise: 1/f (pink) noise, a slow drift (thermal, ICP settling) and
mains hum at 50 or 60 Hz with its harmonics. `ForceSpectrum` and `SensorNoise`
describe these; `simulate_recording` takes them (``force_spectrum=``,
``sensor_noise=``) and `lab_conditions` draws a realistic set from a seed.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ..errors import DataError

MAINS_HZ = (50.0, 60.0)


@dataclass(frozen=True)
class ForceSpectrum:
    """Shape of the force a shaker delivers (amplitude response applied to white noise).

    Attributes
    ----------
    rolloff_order : Butterworth order of the roll-off above the band's upper edge (0: cut sharply there).
    highpass_order : Butterworth order of the high-pass at the band's lower edge (0: cut sharply there).
    colour : the force's power falls as f^-colour inside the band (0 white, 1 pink).
    resonance_hz : frequency of the shaker's armature resonance (None: none).
    resonance_q : its quality factor.
    resonance_gain : its peak amplitude gain over the smooth shape (0: none).
    """

    rolloff_order: int = 0
    highpass_order: int = 0
    colour: float = 0.0
    resonance_hz: float | None = None
    resonance_q: float = 5.0
    resonance_gain: float = 0.0

    def __post_init__(self):
        for name in ("rolloff_order", "highpass_order"):
            v = getattr(self, name)
            if int(v) != v or not 0 <= v <= 32:
                raise DataError(f"force spectrum: {name} must be an integer in 0..32, got {v}")
        if not (np.isfinite(self.colour) and -2 <= self.colour <= 3):
            raise DataError(f"force spectrum: colour must lie in [-2, 3], got {self.colour}")
        if self.resonance_hz is not None and not (np.isfinite(self.resonance_hz) and self.resonance_hz > 0):
            raise DataError(f"force spectrum: resonance_hz must be > 0, got {self.resonance_hz}")
        if not (self.resonance_q > 0 and self.resonance_gain >= 0):
            raise DataError("force spectrum: resonance_q must be > 0 and resonance_gain >= 0")

    def amplitude(self, f: np.ndarray, lo: float, hi: float) -> np.ndarray:
        """Amplitude response at frequencies ``f`` [Hz] for the band lo..hi Hz."""
        f = np.asarray(f, dtype=float)
        safe = np.maximum(f, 1e-12)
        a = np.ones_like(f)
        if self.rolloff_order:
            a /= np.sqrt(1.0 + (safe / hi) ** (2 * self.rolloff_order))
        else:
            a[f > hi] = 0.0
        if self.highpass_order:
            a /= np.sqrt(1.0 + (lo / safe) ** (2 * self.highpass_order))
        else:
            a[f < lo] = 0.0
        if self.colour:
            a *= (safe / lo) ** (-self.colour / 2)
        if self.resonance_hz and self.resonance_gain:
            r = safe / self.resonance_hz
            a *= np.abs(1.0 + self.resonance_gain * (1j * r / self.resonance_q)
                        / (1.0 - r * r + 1j * r / self.resonance_q))
        a[f <= 0] = 0.0
        return a

    def to_dict(self) -> dict:
        """Plain values, for a recording's metadata."""
        return asdict(self)


@dataclass(frozen=True)
class SensorNoise:
    """Noise on a sensor beyond white, each relative to the channel's RMS.

    Attributes
    ----------
    pink : std of a 1/f (pink) component, relative to RMS (above 0.5 Hz).
    drift : std of a slow drift below ``drift_hz``, relative to RMS.
    drift_hz : corner of the drift.
    hum : amplitude of the mains fundamental, relative to RMS.
    mains_hz : 50 or 60.
    harmonics : relative amplitudes of the 2nd, 3rd, ... harmonics.
    """

    pink: float = 0.0
    drift: float = 0.0
    drift_hz: float = 0.5
    hum: float = 0.0
    mains_hz: float = 50.0
    harmonics: tuple = (0.3, 0.5, 0.1, 0.2)

    def __post_init__(self):
        for name in ("pink", "drift", "hum"):
            v = getattr(self, name)
            if not (np.isfinite(v) and v >= 0):
                raise DataError(f"sensor noise: {name} must be a finite number >= 0, got {v}")
        if not (self.drift_hz > 0 and self.mains_hz > 0):
            raise DataError("sensor noise: drift_hz and mains_hz must be > 0")

    def sample(self, n: int, fs_hz: float, rms: float, rng) -> np.ndarray:
        """``n`` samples of this noise for a channel of RMS ``rms`` (white noise is added elsewhere)."""
        out = np.zeros(n)
        f = np.fft.rfftfreq(n, 1.0 / fs_hz)
        if self.pink:
            out += self.pink * rms * _shaped(rng, n, np.where(f > 0.5, 1.0 / np.sqrt(np.maximum(f, 0.5)), 0.0))
        if self.drift:
            out += self.drift * rms * _shaped(rng, n, 1.0 / np.sqrt(1.0 + (f / self.drift_hz) ** 8) * (f > 0))
        if self.hum:
            t = np.arange(n) / fs_hz
            for h, amp in enumerate((1.0,) + tuple(self.harmonics), start=1):
                if h * self.mains_hz < fs_hz / 2:
                    out += self.hum * amp * rms * np.sqrt(2) * np.sin(
                        2 * np.pi * h * self.mains_hz * t + rng.uniform(0, 2 * np.pi))
        return out

    def to_dict(self) -> dict:
        """Plain values, for a recording's metadata."""
        return {**asdict(self), "harmonics": list(self.harmonics)}


def _shaped(rng, n, amplitude):
    """Gaussian noise of unit std with the given amplitude spectrum on the rfft grid of n samples."""
    spectrum = np.fft.rfft(rng.standard_normal(n)) * amplitude
    x = np.fft.irfft(spectrum, n)
    s = np.std(x)
    return x / s if s > 0 else x


def lab_conditions(seed: int) -> dict:
    """A realistic, random set of lab conditions (for `simulate_recording` keywords) from a seed.

    Force: roll-off of order 2–8 (or a sharp cut), high-pass of order 2–4, white to pink, a shaker
    resonance in a third of the cases; sensors: white noise 1–5 % (force 0.5–2 %), pink noise, drift and
    50/60 Hz hum each in about half of them.

    Parameters
    ----------
    seed : int

    Returns
    -------
    dict
        ``force_spectrum`` (ForceSpectrum), ``sensor_noise`` (SensorNoise), ``noise``, ``force_noise``.
    """
    rng = np.random.default_rng(seed)
    sharp = rng.random() < 0.2
    force = ForceSpectrum(rolloff_order=0 if sharp else int(rng.choice([2, 4, 6, 8])),
                          highpass_order=0 if sharp else int(rng.choice([2, 4])),
                          colour=float(rng.choice([0.0, 0.0, 0.5, 1.0])),
                          resonance_hz=float(rng.uniform(150, 400)) if rng.random() < 0.33 else None,
                          resonance_gain=float(rng.uniform(0.5, 3.0)))
    sensor = SensorNoise(pink=float(rng.uniform(0.005, 0.03)) if rng.random() < 0.5 else 0.0,
                         drift=float(rng.uniform(0.05, 0.5)) if rng.random() < 0.5 else 0.0,
                         hum=float(rng.uniform(0.005, 0.05)) if rng.random() < 0.5 else 0.0,
                         mains_hz=float(rng.choice(MAINS_HZ)))
    return {"force_spectrum": force, "sensor_noise": sensor, "noise": float(rng.uniform(0.01, 0.05)),
            "force_noise": float(rng.uniform(0.005, 0.02))}
