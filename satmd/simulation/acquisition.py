"""The acquisition stage every simulated recording shares: noise on every channel, and the record's metadata.

Whatever made the clean signals (the linear convolution of `timesim`, the nonlinear integrator of
`satmd.simulation.nonlinear`), a simulated recording is taken alike: independent white Gaussian noise on
*every* channel (``force_noise`` × RMS on the force, ``noise`` × RMS on each accelerometer), then the
lab's coloured sensor noise (`satmd.simulation.conditions.SensorNoise`) on the accelerometers, and metadata that
says how it was made (the generator, the rig's values, each effect or element with its parameters).
"""
from __future__ import annotations

import numpy as np

from ..io.recording import Recording

__all__ = ["acquire", "described", "simulated_recording"]

#: what every simulated recording holds, in SI units
UNITS = {"force": "N", "acc1": "m/s^2", "acc2": "m/s^2"}


def acquire(clean: dict, fs_hz: float, noise: float, force_noise: float, rng, sensor_noise=None) -> dict:
    """The channels as the sensors report them: each clean channel plus its noise, channel after channel.

    Parameters
    ----------
    clean : {channel: (n,) samples}, ``force`` and the accelerometers.
    fs_hz : sample rate [Hz] (for coloured sensor noise).
    noise : accelerometer noise std relative to each accelerometer's RMS.
    force_noise : force-sensor noise std relative to the force's RMS.
    rng : numpy Generator (draws in channel order: the same seed gives the same record).
    sensor_noise : SensorNoise or None: pink noise, drift and hum added to the accelerometers.

    Returns
    -------
    dict
        {channel: (n,) samples}.
    """
    signals = {}
    for name, x in clean.items():
        rel = force_noise if name == "force" else noise
        if rel:
            x = x + rel * np.sqrt(np.mean(x * x)) * rng.standard_normal(x.size)
        if sensor_noise is not None and name != "force":
            x = x + sensor_noise.sample(x.size, fs_hz, np.sqrt(np.mean(x * x)), rng)
        signals[name] = x
    return signals


def simulated_recording(fs_hz: float, signals: dict, how: dict, rig, parts: dict | None = None) -> Recording:
    """A `Recording` of simulated ``signals`` whose metadata says how they were made.

    Parameters
    ----------
    fs_hz : sample rate [Hz].
    signals : {channel: samples} (`acquire`).
    how : the generator's settings (excitation, band, level, noise, seed, ...), written first.
    rig : the Rig simulated: its values follow.
    parts : further entries after the rig's (the effects or elements, the force's and the sensors' conditions).

    Returns
    -------
    Recording
    """
    meta = {"generator": "satmd simulate --time", **how}
    meta.update({k: f"{float(v):.12g}" for k, v in rig.as_dict().items()})
    meta.update(parts or {})
    return Recording(fs_hz, signals, dict(UNITS), meta)


def described(kind: str, items) -> dict:
    """``{"<kind> <name>": "p=value, ..."}`` for each effect or element simulated (metadata entries).

    Parameters
    ----------
    kind : ``effect`` or ``nonlinear``.
    items : the Effect or NonlinearElement objects.

    Returns
    -------
    dict
    """
    return {f"{kind} {it.name}": ", ".join(f"{k}={float(v):.12g}" for k, v in it.params.items()) for it in items}
