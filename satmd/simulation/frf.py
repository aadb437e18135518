"""Synthetic FRF data: the model plus the measurement noise of SPEC.

Noise model: on each of the real and imaginary parts, independent Gaussian
noise with standard deviation ``std = rel * |A| + floor * max_f |A|`` per
channel, so ``rel`` is a relative error and ``floor`` a noise floor relative
to the channel's peak.
"""
from __future__ import annotations

from numbers import Real
from typing import Any, Sequence

import numpy as np

from ..conventions import ACCEL_CHANNELS
from ..errors import DataError
from ..io.frfdata import FRFData
from ..physics import PAPER_GRID_HZ, Rig, frf
from ..physics.effects import Effect
from ..validation import NAMES, Interval, validate_params


def noise_std(values: np.ndarray, rel: float, floor: float = 0.0) -> np.ndarray:
    """SPEC noise std for one channel: rel |A| + floor max|A|."""
    mag = np.abs(values)
    return rel * mag + floor * mag.max(axis=-1, keepdims=True)


@validate_params({"rig": [None, Rig], "channels": [NAMES], "meta": [None, dict], "time": [bool],
                  "level": [Interval(Real, 0, open="lo")]})
def simulate(
    freq_hz=PAPER_GRID_HZ,
    rig: Rig | None = None,
    effects: Sequence[Effect] = (),
    channels: Sequence[str] = ACCEL_CHANNELS,
    noise: float | tuple[float, float] | None = None,
    seed: int | None = None,
    meta: dict | None = None,
    *,
    time: bool = False,
    nonlinear: Sequence = (),
    level: float = 1.0,
    **time_options,
):
    """FRFData from the model, optionally with noise (std columns then included); or a time recording.

    Parameters
    ----------
    freq_hz : frequencies [Hz] (default: the paper's 60-point grid).
    rig : Rig
        Parameter values (default: the paper's rig); one rig, not a batch.
    effects : sequence of Effect
        Missing physics included in the simulated data.
    channels : channels to simulate, from a1 a2 u1 u2 q.
    noise : REL or (REL, FLOOR)
        Gaussian noise on each of Re and Im with std REL |A| + FLOOR max|A|
        per channel (the SPEC noise model); None: noise-free, no std columns.
    seed : seed of the noise.
    meta : extra header entries for the data's metadata.
    time : bool
        True: a time `Recording` (force, acc1, acc2) instead of FRFs; ``noise`` is then the
        sensor noise relative to each channel's RMS and ``freq_hz``, ``channels`` are unused.
    nonlinear : sequence of NonlinearElement
        SPEC §8b elements in the rig (time recordings only; simulated by `satmd.physics.integrate`).
    level : float
        Time recordings: RMS of the clean force in N (the drive level).
    **time_options
        ``duration_s``, ``fs_hz``, ``band_hz``, ``excitation`` (random, sweep, multisine),
        ``force_noise``; for multisines ``periods`` and ``realisations`` (see
        `simulate_nonlinear_recording`).

    Returns
    -------
    FRFData, or Recording with ``time=True``
    """
    if time:
        return _simulate_time(rig, effects, noise, seed, meta, nonlinear, level, time_options)
    if nonlinear or time_options:
        raise DataError("nonlinear elements and time options need time=True (a recording; FRFs are linear)")
    rig = Rig() if rig is None else rig
    if rig.batch_shape != ():
        raise DataError("simulate takes a single rig; loop or use satmd.physics.frf for batches")
    response = frf(freq_hz, rig, effects, outputs=tuple(channels))
    clean = {c: response.channel(c) for c in channels}
    info = {"generator": "satmd simulate"}
    info.update({k: f"{float(v):.12g}" for k, v in rig.as_dict().items()})
    for eff in effects:
        info[f"effect {eff.name}"] = ", ".join(f"{k}={float(v):.12g}" for k, v in eff.params.items())
    if not noise:
        info.update(meta or {})
        return FRFData(np.asarray(freq_hz, float), clean, {}, info)
    pair: Any = (noise, 0.0) if np.isscalar(noise) else noise
    rel, floor = pair
    if rel < 0 or floor < 0 or (rel == 0 and floor == 0):
        raise DataError(f"simulate: noise must be rel or (rel, floor), numbers >= 0 and not both 0, got {noise!r}")
    rng = np.random.default_rng(seed)
    noisy, std = {}, {}
    for c, v in clean.items():
        s = noise_std(v, rel, floor)
        noisy[c] = v + s * (rng.standard_normal(v.shape) + 1j * rng.standard_normal(v.shape))
        std[c] = s
    info.update({"noise_rel": f"{rel:g}", "noise_floor": f"{floor:g}", "seed": str(seed)})
    info.update(meta or {})
    return FRFData(np.asarray(freq_hz, float), noisy, std, info)


def _simulate_time(rig, effects, noise, seed, meta, nonlinear, level, options):
    """simulate(time=True): the linear recorder of satmd.io, or the integrator for elements and multisines."""
    noise = 0.0 if noise is None else noise
    if not np.isscalar(noise):
        raise DataError("with time=True, noise is one number: sensor noise relative to each channel's RMS")
    excitation = options.get("excitation", "random")
    if not nonlinear and excitation in ("random", "sweep") and not {"periods", "realisations"} & set(options):
        from .timesim import simulate_recording

        known = {"duration_s", "fs_hz", "band_hz", "excitation", "force_noise", "burn_in_s"}
        if set(options) - known:
            raise DataError(f"unknown time option(s) {sorted(set(options) - known)}")
        rec = simulate_recording(rig=rig, effects=effects, force_rms=level, noise=noise, seed=seed, **options)
    else:
        from .nonlinear import simulate_nonlinear_recording

        rec = simulate_nonlinear_recording(rig, nonlinear, level, noise=noise, seed=seed, effects=effects, **options)
    rec.meta.update(meta or {})
    return rec
