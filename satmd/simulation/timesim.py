"""Simulated time recordings that look like the lab: a test bed for the measurement chain.

Excitation (``excitation=``):

``random``     (default) band-limited Gaussian force that is *not* periodic in
               the record: white noise filtered to the band on a longer
               record and cut, so every estimator meets leakage as it does on a
               rig.
``sweep``      one logarithmic sine sweep across the band (with 5 % cosine
               tapers so the force starts and ends at zero).
``multisine``  a periodic random-phase multisine on the record's DFT grid and
               the exact steady-state response (no transient, no leakage: the
               ideal case, kept to compare against).

Response. For ``random`` and ``sweep`` the structure starts at rest ``burn_in_s``
before the record starts (0 by default, so the start-up transient is in the
record) and the accelerations are the *linear convolution* of the force with the
model's impulse response (`satmd.physics.timemodel.LinearRig`, the linear time model),
computed by FFT on a grid long enough that the impulse response has decayed to
round-off (measured, not assumed). With
``sensor_gain`` and ``time_delay`` effects the sensors report what they do on a
rig, since the impulse response comes from `satmd.physics.frf` with effects.

Noise. Independent white Gaussian noise on *every* channel: ``noise`` × RMS on
each accelerometer (default 2 %) and ``force_noise`` × RMS on the force (default half of
``noise``: a load cell is usually cleaner than an accelerometer, never perfect).

Defaults are the lab's, not an ideal: a random non-periodic force that a shaker
rolls off above the band (`LAB_FORCE`, Butterworth order 4) and high-passes below
it (order 2), the rig at rest when the record starts, and noise on every channel.
``ideal=True`` gives the idealised recording instead (no noise unless asked, the force
cut sharply at the band edges), kept to compare against.

Lab conditions (`satmd.simulation.conditions`). ``force_spectrum=ForceSpectrum(...)``
shapes the random force as a shaker does (roll-off, high-pass, pink colour,
armature resonance) instead of cutting it sharply at the band edges;
``sensor_noise=SensorNoise(...)`` adds pink noise, drift and mains hum to the
accelerometers. The recorded force passes the same anti-aliasing roll-off as the
responses, as in a real acquisition system.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..conventions import ACCEL_CHANNELS, PAPER_BAND_HZ, RECORDING_CHANNELS
from ..errors import DataError
from ..physics import Rig, frf
from ..physics.timemodel import LinearRig
from ..physics.nonlinear.excitation import log_sweep, random_force
from .conditions import ForceSpectrum
from .acquisition import acquire, described, simulated_recording
from ..io.limits import check_memory
from ..io.recording import Recording

EXCITATIONS = ("random", "sweep", "multisine")
MAX_SAMPLES = 50_000_000  # ~1.2 GB of float64 per channel set: longer records are refused up front
_RESPONSES = tuple((ch, name) for name, ch in RECORDING_CHANNELS.items())
#: the force a shaker delivers by default: rolled off above the band and high-passed below it
LAB_FORCE = ForceSpectrum(rolloff_order=4, highpass_order=2)
#: default accelerometer noise relative to each channel's RMS (the force sensor gets half)
LAB_NOISE = 0.02


def simulate_recording(duration_s: float = 60.0, fs_hz: float = 1000.0, rig: Rig | None = None,
                       effects: Sequence = (), band_hz=PAPER_BAND_HZ, force_rms: float = 1.0,
                       noise: float | None = None, seed: int | None = None, excitation: str = "random",
                       force_noise: float | None = None, burn_in_s: float = 0.0, force_spectrum=None,
                       sensor_noise=None, ideal: bool = False) -> Recording:
    """A recording of force, acc1, acc2 for a force on the primary mass (see the module docstring).

    Parameters
    ----------
    duration_s : float
        Length of the record in s.
    fs_hz : float
        Sample rate in Hz.
    rig : Rig, optional
        The model (default: the paper's rig).
    effects : sequence of Effect
        Missing physics included in the simulation.
    band_hz : (float, float)
        Excitation band (lo, hi) in Hz, inside (0, fs/2). The response is
        rolled off smoothly from max(hi, 0.6 fs/2) to fs/2, as by an
        anti-aliasing filter.
    force_rms : float
        RMS of the clean force in N.
    noise : float, optional
        Accelerometer noise std relative to each accelerometer's RMS (default `LAB_NOISE` = 2 %;
        0 with ``ideal``).
    seed : int, optional
        Random seed (same seed, same recording).
    excitation : {"random", "sweep", "multisine"}
        Force signal; ``random`` is the realistic default.
    force_noise : float, optional
        Force-sensor noise std relative to the force RMS (default ``noise / 2``).
    burn_in_s : float
        Time the rig is excited before the record starts (0: the record starts at rest).
    force_spectrum : ForceSpectrum, optional
        Shape of the random force (`satmd.simulation.conditions`; default `LAB_FORCE`: rolled off above the band,
        high-passed below it; with ``ideal``: flat, cut sharply at the band edges).
    sensor_noise : SensorNoise, optional
        Pink noise, drift and mains hum on the accelerometers (default: white noise only).
    ideal : bool
        The idealised recording: no noise unless ``noise`` is given, a flat force cut sharply at the band
        edges unless ``force_spectrum`` is given (default False: lab conditions).

    Returns
    -------
    Recording
        Channels ``force`` [N], ``acc1``, ``acc2`` [m/s²]; ``meta`` says how it was made.
    """
    rig = Rig() if rig is None else rig
    if rig.batch_shape != ():
        raise DataError("simulate_recording takes a single rig")
    for name, value in (("duration_s", duration_s), ("fs_hz", fs_hz), ("force_rms", force_rms)):
        if not np.isfinite(value) or value <= 0:
            raise DataError(f"{name} must be a finite number > 0, got {value}")
    if noise is None:
        noise = 0.0 if ideal else LAB_NOISE
    if force_spectrum is None and not ideal:
        force_spectrum = LAB_FORCE
    force_noise = 0.5 * noise if force_noise is None else force_noise
    for name, value in (("noise", noise), ("force_noise", force_noise), ("burn_in_s", burn_in_s)):
        if not np.isfinite(value) or value < 0:
            raise DataError(f"{name} must be a finite number >= 0, got {value}")
    if excitation not in EXCITATIONS:
        raise DataError(f"excitation must be one of {', '.join(EXCITATIONS)}, got {excitation!r}")
    n = int(round(duration_s * fs_hz))
    burn = int(round(burn_in_s * fs_hz))
    check_memory(f"a recording of {duration_s:g} s (+ {burn_in_s:g} s burn-in) at {fs_hz:g} Hz",
                 recording_memory(duration_s, fs_hz, burn_in_s), "lower the sample rate or the duration")
    if n + burn > MAX_SAMPLES:
        raise DataError(f"{duration_s:g} s (+ {burn_in_s:g} s burn-in) at {fs_hz:g} Hz is {n + burn} samples; "
                        f"the simulator takes at most {MAX_SAMPLES}")
    lo, hi = float(band_hz[0]), float(band_hz[1])
    if not 0 < lo < hi < fs_hz / 2:
        raise DataError(f"excitation band {lo:g}:{hi:g} Hz must lie inside (0, fs/2 = {fs_hz / 2:g}) Hz")
    if np.count_nonzero((np.fft.rfftfreq(n, 1.0 / fs_hz) >= lo) & (np.fft.rfftfreq(n, 1.0 / fs_hz) <= hi)) < 2:
        raise DataError(f"{duration_s:g} s at {fs_hz:g} Hz gives fewer than 2 frequency lines in the band")
    rng = np.random.default_rng(seed)
    if excitation == "multisine":
        clean = _steady_state_multisine(n, fs_hz, rig, effects, lo, hi, rng)
    else:
        total = n + burn
        if excitation == "random":
            # the force goes on after the record ends: the anti-aliasing roll-off looks a few ms ahead
            force = random_force(total + int(fs_hz), fs_hz, (lo, hi), rng, force_spectrum, unit_rms=False)
        else:
            force = log_sweep(total, fs_hz, lo, hi)
        clean = LinearRig(rig, effects, hi).respond(force, fs_hz)  # force: anti-aliased as recorded
        clean = {k: v[burn:total] for k, v in clean.items()}
    gain = force_rms / np.sqrt(np.mean(clean["force"] ** 2))  # linear: one scale for all channels
    signals = acquire({k: v * gain for k, v in clean.items()}, fs_hz, noise, force_noise, rng, sensor_noise)
    how = {"excitation": excitation, "band_hz": f"{lo:g}:{hi:g}", "force_rms": f"{force_rms:g}", "noise": f"{noise:g}",
           "force_noise": f"{force_noise:g}", "burn_in_s": f"{burn_in_s:g}", "seed": str(seed),
           "conditions": "ideal" if ideal else "lab"}
    parts = {}
    if force_spectrum is not None and excitation == "random":
        parts["force_spectrum"] = ", ".join(f"{k}={v}" for k, v in force_spectrum.to_dict().items())
    if sensor_noise is not None:
        parts["sensor_noise"] = ", ".join(f"{k}={v}" for k, v in sensor_noise.to_dict().items())
    return simulated_recording(fs_hz, signals, how, rig, {**parts, **described("effect", effects)})


def recording_memory(duration_s: float, fs_hz: float, burn_in_s: float = 0.0) -> float:
    """Bytes `simulate_recording` needs (measured): the impulse response is found on a 120 s grid at
    ``fs_hz`` (about 20 kB per Hz of sample rate), the force and its convolution take about 400 bytes a sample."""
    return 2.0e4 * fs_hz + 400.0 * ((duration_s + burn_in_s) * fs_hz + fs_hz)


def _steady_state_multisine(n, fs_hz, rig, effects, lo, hi, rng) -> dict:
    """Periodic random-phase multisine on the record's DFT grid and its exact steady-state response."""
    f = np.fft.rfftfreq(n, 1.0 / fs_hz)
    band = (f >= lo) & (f <= hi)
    F = np.zeros(f.size, dtype=complex)
    F[band] = np.exp(2j * np.pi * rng.random(band.sum()))
    response = frf(f[band], rig, effects, outputs=ACCEL_CHANNELS)
    spectra = {"force": F}
    for ch, name in _RESPONSES:
        A = np.zeros_like(F)
        A[band] = response.channel(ch) * F[band]
        spectra[name] = A
    return {name: np.fft.irfft(S, n) for name, S in spectra.items()}
