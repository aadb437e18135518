"""Simulated time recordings: band-limited random force through the linear model.

Method (frequency-domain synthesis of one periodic record). For ``N`` samples
at ``fs`` the force is built on the FFT grid ``f_k = k fs / N``: independent
complex Gaussian coefficients inside the excitation band, zero outside. Each
acceleration is ``A_k = H(f_k) F_k`` with ``H`` from `satmd.physics.frf`
(effects included, so sensor effects act as they do on measured FRFs), and
the inverse real FFT gives the signals. This is the exact steady-state
response of the linear model to the periodic continuation of the force, so
there are no start-up transients and no approximation beyond sampling.

Sensor noise: independent white Gaussian noise on every channel with
standard deviation ``noise × RMS`` of that channel's clean signal.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..errors import DataError
from ..physics import Rig, frf
from .recording import Recording


def simulate_recording(duration_s: float = 60.0, fs_hz: float = 1000.0, rig: Rig | None = None,
                       effects: Sequence = (), band_hz=(20.0, 200.0), force_rms: float = 1.0,
                       noise: float = 0.0, seed: int | None = None) -> Recording:
    """A recording of force, acc1, acc2 for a band-limited random force on the primary mass.

    Parameters
    ----------
    duration_s, fs_hz : length and sample rate
    rig, effects : the model (defaults: the paper's rig, no effects)
    band_hz : (lo, hi) excitation band in Hz, inside (0, fs/2)
    force_rms : RMS of the clean force in N
    noise : sensor noise std relative to each channel's RMS (0.02 = 2 %)
    seed : random seed (same seed, same recording)
    """
    rig = Rig() if rig is None else rig
    if rig.batch_shape != ():
        raise DataError("simulate_recording takes a single rig")
    for name, value in (("duration_s", duration_s), ("fs_hz", fs_hz), ("force_rms", force_rms)):
        if not np.isfinite(value) or value <= 0:
            raise DataError(f"{name} must be a finite number > 0, got {value}")
    if not np.isfinite(noise) or noise < 0:
        raise DataError(f"noise must be >= 0, got {noise}")
    n = int(round(duration_s * fs_hz))
    lo, hi = float(band_hz[0]), float(band_hz[1])
    if not 0 < lo < hi < fs_hz / 2:
        raise DataError(f"excitation band {lo:g}:{hi:g} Hz must lie inside (0, fs/2 = {fs_hz / 2:g}) Hz")
    f = np.fft.rfftfreq(n, 1.0 / fs_hz)
    band = (f >= lo) & (f <= hi)
    if np.count_nonzero(band) < 2:
        raise DataError(f"{duration_s:g} s at {fs_hz:g} Hz gives fewer than 2 frequency lines in the band")
    rng = np.random.default_rng(seed)
    F = np.zeros(f.size, dtype=complex)
    F[band] = rng.standard_normal(band.sum()) + 1j * rng.standard_normal(band.sum())
    response = frf(f[band], rig, effects, outputs=("a1", "a2"))
    spectra = {"force": F}
    for ch, name in (("a1", "acc1"), ("a2", "acc2")):
        A = np.zeros_like(F)
        A[band] = response.channel(ch) * F[band]
        spectra[name] = A
    clean = {name: np.fft.irfft(S, n) for name, S in spectra.items()}
    gain = force_rms / np.sqrt(np.mean(clean["force"] ** 2))  # linear: one scale for all channels
    signals = {}
    for name, x in clean.items():
        x = x * gain
        if noise:
            x = x + noise * np.sqrt(np.mean(x * x)) * rng.standard_normal(n)
        signals[name] = x
    meta = {"generator": "satmd simulate --time", "band_hz": f"{lo:g}:{hi:g}", "force_rms": f"{force_rms:g}",
            "noise": f"{noise:g}", "seed": str(seed)}
    meta.update({k: f"{float(v):.12g}" for k, v in rig.as_dict().items()})
    for eff in effects:
        meta[f"effect {eff.name}"] = ", ".join(f"{k}={float(v):.12g}" for k, v in eff.params.items())
    return Recording(fs_hz, signals, {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}, meta)
