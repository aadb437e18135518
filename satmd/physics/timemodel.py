"""One protocol for every model that answers a sampled force in time, and satmd's two rig models.

A *time model* has ``respond(force, fs_hz) -> {signal: array}``: the clean signals a rig driven
from rest by the force samples would give its sensors, the force itself among them as the
acquisition records it. satmd's recorders (`satmd.simulate` with ``time=True``) call only that,
then add the sensors' noise (`satmd.simulation.acquisition`); anything with the method is a test bed.

- `LinearRig`: the SPEC §2 model with effects, by linear convolution with its impulse response
  (FFT on a grid long enough that the response has decayed to 1e-9: measured, not assumed),
  rolled off above the band as an anti-aliasing filter does, the force too.
- `NonlinearRig`: the rig with nonlinear elements (SPEC §8b) by the one integrator
  (`satmd.physics.integrate`), inside at 4x and 8x the rate, extrapolated (the element forces'
  hold then errs by ~(ωΔ)⁴ instead of ~1 %: the lab's rig is continuous).
- `satmd.physics.oscillator.PolynomialOscillator` (a single-degree-of-freedom oscillator with
  polynomial stiffness, the Silverbox's model) answers ``y``.

In the linear limit the first two agree (a test holds them to it).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, Sequence, runtime_checkable

import numpy as np

from ..conventions import ACCEL_CHANNELS, RECORDING_CHANNELS
from .model import frf
from .nonlinear.integrate import integrate
from .rig import Rig

__all__ = ["TimeModel", "LinearRig", "NonlinearRig", "fast_length"]

_RESPONSES = tuple((ch, name) for name, ch in RECORDING_CHANNELS.items())  # (a1, acc1), (a2, acc2)


@runtime_checkable
class TimeModel(Protocol):
    """What a recorder drives: clean signals for force samples, the rig at rest at the first one."""

    def respond(self, force: np.ndarray, fs_hz: float) -> dict:
        """{signal: array like ``force``} for force samples at ``fs_hz``."""
        ...  # pragma: no cover - a protocol


@dataclass(frozen=True)
class LinearRig:
    """The linear SATMD model (with effects) in time: FFT convolution with its impulse response.

    Parameters
    ----------
    rig : one parameter set.
    effects : missing-physics effects (SPEC §8), sensors' included.
    pass_hz : the response is rolled off smoothly from max(pass_hz, 0.6 Nyquist) to Nyquist, as by an
        anti-aliasing filter (the force too); the band below stays untouched.
    """

    rig: Rig
    effects: Sequence = ()
    pass_hz: float = 0.0

    def respond(self, force, fs_hz: float) -> dict:
        """{"force", "acc1", "acc2"} for a force (N,) that starts at sample 0 with the rig at rest.

        Parameters
        ----------
        force : (N,) samples [N].
        fs_hz : sample rate [Hz].

        Returns
        -------
        dict of (N,) arrays: the force after the anti-aliasing roll-off and the accelerations.
        """
        force = np.asarray(force, float)
        n = force.size
        size = fast_length(n + self.impulse_length(fs_hz))
        f = np.fft.rfftfreq(size, 1.0 / fs_hz)
        h = self._frf_with_dc(f)
        spectrum = np.fft.rfft(force, size)
        out = {"force": np.fft.irfft(h["rolloff"] * spectrum, size)[:n]}  # the same anti-aliasing as the responses
        out.update({name: np.fft.irfft(h[ch] * spectrum, size)[:n] for ch, name in _RESPONSES})
        return out  # in the recording's channel order: the noise is drawn in it

    def impulse_length(self, fs_hz: float, max_s: float = 120.0) -> int:
        """Samples after which every impulse response has decayed below 1e-9 of its peak (and stays there).

        Parameters
        ----------
        fs_hz : sample rate [Hz].
        max_s : the longest response looked for [s].

        Returns
        -------
        int
        """
        size = fast_length(int(max_s * fs_hz))
        f = np.fft.rfftfreq(size, 1.0 / fs_hz)
        h = self._frf_with_dc(f)
        need = int(0.5 * fs_hz)
        for ch, _ in _RESPONSES:
            ir = np.abs(np.fft.irfft(h[ch], size))
            ir[0] = 0.0  # the direct (mass-line) term is not a tail
            above = np.flatnonzero(ir[: size // 2] > 1e-9 * ir.max())
            if above.size:
                need = max(need, int(above[-1]) + 1)
        return need

    def _frf_with_dc(self, f) -> dict:
        """a1, a2 on an rfft grid from 0 Hz to Nyquist, rolled off smoothly above max(pass_hz, 0.6 Nyquist).

        Accelerations vanish at DC but tend to 1/m1 at high frequency; cut off at Nyquist that step
        rings through the whole impulse response. The raised-cosine roll-off keeps the impulse
        response short and leaves the excited band untouched.
        """
        r = frf(f[1:], self.rig, self.effects, outputs=ACCEL_CHANNELS)
        nyquist = f[-1]
        start = max(0.6 * nyquist, self.pass_hz)
        x = np.clip((f - start) / max(nyquist - start, 1e-9 * nyquist), 0.0, 1.0)
        rolloff = 0.5 + 0.5 * np.cos(np.pi * x)
        out = {}
        for ch, _ in _RESPONSES:
            h = np.zeros(f.size, dtype=complex)
            h[1:] = r.channel(ch) * rolloff[1:]
            out[ch] = h
        out["rolloff"] = rolloff
        return out


@dataclass(frozen=True)
class NonlinearRig:
    """The SATMD with nonlinear elements in time: the one integrator (`satmd.physics.integrate`).

    Parameters
    ----------
    rig : one parameter set.
    elements : NonlinearElement instances.
    oversample : the integrator's rate as a multiple of the samples'.
    extrapolate : also at twice ``oversample``, Richardson-extrapolated (the hold's Δ² error cancels).
    """

    rig: Rig
    elements: Sequence = ()
    oversample: int = 4
    extrapolate: bool = True

    def respond(self, force, fs_hz: float) -> dict:
        """{"force", "acc1", "acc2"} for force samples (N,) or independent runs (runs, N), each from rest.

        Parameters
        ----------
        force : (N,) or (runs, N) samples [N]; band-limited between samples.
        fs_hz : sample rate [Hz].

        Returns
        -------
        dict of arrays shaped like ``force``.
        """
        force = np.asarray(force, float)
        els = list(self.elements)
        r = integrate(self.rig, force, fs_hz, els, outputs=ACCEL_CHANNELS, oversample=self.oversample if els else 1,
                      extrapolate=self.extrapolate and bool(els))
        return {"force": force, "acc1": r.a1, "acc2": r.a2}


def fast_length(n: int) -> int:
    """A length >= n made of small primes (fast FFTs).

    Parameters
    ----------
    n : the least length.

    Returns
    -------
    int
    """
    from scipy.fft import next_fast_len

    return int(next_fast_len(int(n), real=True))
