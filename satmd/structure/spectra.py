"""The steady spectra of a periodic test of a structure, every channel, and two sensors' relative motion.

A ground vibration test's multisine repeats; after the start-up transient every channel is periodic
(plus noise), so each line's spectrum is the mean over the steady periods (`satmd.signal.periodic`'s
estimator), and the spread over periods is its noise. Displacements come from the accelerations by
dividing by -ω² at the lines the force excites (the band where the accelerometers carry the motion).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DataError
from ..numerics import force_level
from ..signal.excitation import excitation_of, received
from ..signal.periodic import periodic_spectra as signal_spectra


@dataclass(frozen=True)
class PeriodicSpectra:
    """One periodic recording of a structure, at the lines its force excites.

    Attributes
    ----------
    source : the recording's name
    level : force RMS (N)
    fs_hz, period_samples : sample rate and samples per period
    lines : (K,) DFT lines of one period the force excites
    force : (K,) complex mean spectrum of the force
    responses : {channel: (K,) complex mean spectrum}
    std : {channel: (K,) std of the mean's real and imaginary parts, from the spread over periods}
    whole : {channel: (n // 2 + 1,) complex mean spectrum at every line}: what a joint throws outside the lines
        the force excites (`satmd.structure.outside`); None where not kept
    """

    source: str
    level: float
    fs_hz: float
    period_samples: int
    lines: np.ndarray
    force: np.ndarray
    responses: dict
    std: dict
    whole: dict | None = None

    @property
    def freq_hz(self) -> np.ndarray:
        return self.lines * self.fs_hz / self.period_samples

    def motion(self, channel: str, whole: bool = False):
        """(displacement, velocity) over one period of ``channel`` (zeros for ``"ground"``); ``whole``: from every
        line from the band's lowest up to 0.8 of the Nyquist frequency (the harmonics a joint makes above the
        band move the sensors too; below the band the accelerometers' noise, divided by ω², would swamp it)."""
        if channel == "ground":
            return np.zeros(self.period_samples), np.zeros(self.period_samples)
        if whole and self.whole is not None:
            lines = np.arange(int(self.lines.min()), int(0.8 * (self.period_samples // 2)) + 1)
            return motion(self.whole[channel][lines], lines, self.fs_hz, self.period_samples)
        return motion(self.responses[channel], self.lines, self.fs_hz, self.period_samples)

    def relative(self, a: str, b: str, whole: bool = False):
        """(d, v): the relative displacement and velocity of sensor a to sensor b (or the ground) over one period
        (``whole``: see `motion`)."""
        (da, va), (db, vb) = self.motion(a, whole), self.motion(b, whole)
        return da - db, va - vb

    def scales(self, a: str, b: str):
        """(RMS stroke, RMS relative velocity) of a to b: the scales a joint law is written in."""
        d, v = self.relative(a, b)
        return float(np.std(d)) or 1.0, float(np.std(v)) or 1.0

    def at_lines(self, x) -> np.ndarray:
        """The spectrum of one period of ``x`` at the excited lines (the scaling of `force`)."""
        return np.fft.rfft(np.asarray(x, float), self.period_samples)[self.lines]


def motion(accel, lines, fs_hz: float, period_samples: int):
    """(displacement, velocity) over one period from an acceleration's spectrum at ``lines`` (zero elsewhere).

    Parameters
    ----------
    accel : (K,) complex spectrum (one period's rfft scaling) at ``lines``
    lines : (K,) DFT lines of one period
    fs_hz, period_samples : sample rate and samples per period

    Returns
    -------
    (ndarray, ndarray)
    """
    w = 2 * np.pi * np.asarray(lines) * fs_hz / period_samples
    X = np.zeros(period_samples // 2 + 1, complex)
    V = np.zeros(period_samples // 2 + 1, complex)
    X[lines] = accel / -(w ** 2)
    V[lines] = accel / (1j * w)
    return np.fft.irfft(X, period_samples), np.fft.irfft(V, period_samples)


def periodic_spectra(recording) -> PeriodicSpectra:
    """`PeriodicSpectra` of a recording whose force is periodic (a multisine, a periodic chirp, ...).

    Parameters
    ----------
    recording : Recording with ``force`` and one or more response channels

    Returns
    -------
    PeriodicSpectra

    Raises
    ------
    DataError
        A force that is not periodic, or fewer than two steady periods.
    """
    source = str(recording.meta.get("source", "recording"))
    rec = received(recording)
    exc = excitation_of(rec)
    if exc.kind != "periodic":
        raise DataError(f"{source}: the force is {exc.kind}, not periodic; locating a joint needs a periodic force "
                        "(a multisine, as a ground vibration test uses) at every level")
    n = exc.period_samples
    lines = np.asarray(exc.lines, int)
    force = signal_spectra(rec, exc, "force").mean(axis=0)  # (steady periods, lines) of the periodic estimator
    responses, std, whole = {}, {}, {}
    for name in rec.channels:
        if name == "force":
            continue
        Y = signal_spectra(rec, exc, name)
        responses[name] = Y.mean(axis=0)
        x = np.asarray(rec[name], float)[: exc.periods * n].reshape(exc.periods, n)[list(exc.steady)]
        whole[name] = np.fft.rfft(x.mean(axis=0))
        std[name] = np.sqrt(np.var(Y, axis=0, ddof=1) / Y.shape[0] / 2.0)
    if not responses:
        raise DataError(f"{source}: no response channel beside the force")
    return PeriodicSpectra(source, force_level(rec["force"]), float(rec.fs_hz), int(n), lines, force, responses, std,
                           whole)
