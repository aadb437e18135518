"""Time recordings of a rig with nonlinear elements (SPEC §8b), as a lab would take them.

The rig starts at rest; the force is band-limited random noise (``random``, not periodic in
the record), one log sweep (``sweep``) or an odd random-phase multisine with detection lines
(``multisine``: ``realisations`` independent phase draws of ``periods`` periods each, every
realisation started from rest, so its first period holds the transient); the response comes
from the one integrator (`satmd.physics.timemodel.NonlinearRig`), and white Gaussian noise is added to
every channel (``noise`` x RMS on the accelerometers, ``force_noise`` x RMS on the force).

Multisine metadata (what an estimator needs): ``period_samples``, ``periods`` (per
realisation), ``realisations``, ``transient_periods`` (1), ``lines`` (the excited DFT lines of
one period, comma-separated); the record is realisation after realisation.
"""
from __future__ import annotations

from typing import Sequence

import numpy as np

from ..conventions import PAPER_BAND_HZ
from ..errors import DataError
from .acquisition import acquire, described, simulated_recording
from ..io.recording import Recording
from ..physics import Rig
from ..physics.timemodel import NonlinearRig
from ..physics.nonlinear.excitation import log_sweep, odd_multisine, random_force

EXCITATIONS = ("random", "sweep", "multisine")


def simulate_nonlinear_recording(rig: Rig | None = None, nonlinear: Sequence = (), level: float = 1.0,
                                 duration_s: float = 90.0, fs_hz: float = 2048.0, band_hz=PAPER_BAND_HZ,
                                 noise: float = 0.0, force_noise: float | None = None, seed: int | None = None,
                                 excitation: str = "random", periods: int = 3, realisations: int = 4,
                                 effects: Sequence = ()) -> Recording:
    """A recording (force, acc1, acc2) of the rig with nonlinear elements at drive level ``level``.

    Parameters
    ----------
    rig : Rig (default: the paper's rig); one parameter set.
    nonlinear : sequence of NonlinearElement.
    level : RMS of the clean force [N].
    duration_s : length of the record [s] (multisine: rounded down to whole periods).
    fs_hz : sample rate [Hz].
    band_hz : (lo, hi) excitation band [Hz].
    noise : accelerometer noise std relative to each accelerometer's RMS.
    force_noise : force-sensor noise relative to the force RMS (default ``noise / 2``).
    seed : random seed (force, phases, noise).
    excitation : "random", "sweep" or "multisine" (see the module docstring).
    periods, realisations : multisine layout (periods per realisation, independent realisations).
    effects : linear effects; only those that change the rig (``parameter_offset``) apply in time.

    Returns
    -------
    Recording
    """
    rig = Rig() if rig is None else rig
    if rig.batch_shape != ():
        raise DataError("simulate takes a single rig")
    for eff in effects:
        if eff.acts_on != "rig":
            raise DataError(f"effect {eff.name} has no time-domain form here; use parameter_offset or FRFs")
        rig = eff.rig(rig)
    for name, value in (("level", level), ("duration_s", duration_s), ("fs_hz", fs_hz)):
        if not np.isfinite(value) or value <= 0:
            raise DataError(f"{name} must be a finite number > 0, got {value}")
    force_noise = 0.5 * noise if force_noise is None else force_noise
    if not (np.isfinite(noise) and noise >= 0 and np.isfinite(force_noise) and force_noise >= 0):
        raise DataError(f"noise and force_noise must be >= 0, got {noise}, {force_noise}")
    if excitation not in EXCITATIONS:
        raise DataError(f"excitation must be one of {', '.join(EXCITATIONS)}, got {excitation!r}")
    lo, hi = float(band_hz[0]), float(band_hz[1])
    if not 0 < lo < hi < fs_hz / 2:
        raise DataError(f"excitation band {lo:g}:{hi:g} Hz must lie inside (0, fs/2 = {fs_hz / 2:g}) Hz")
    rng = np.random.default_rng(seed)
    n = int(round(duration_s * fs_hz))
    extra = {}
    if excitation == "multisine":
        period = n // (int(periods) * int(realisations))
        if period < 16:
            raise DataError(f"{duration_s:g} s is too short for {realisations} realisations of {periods} periods")
        forces, lines = odd_multisine(period, int(periods), int(realisations), fs_hz, (lo, hi), rng)
        forces = forces * level
        extra = {"period_samples": str(period), "periods": str(int(periods)), "realisations": str(int(realisations)),
                 "transient_periods": "1", "lines": ",".join(str(int(k)) for k in lines)}
    elif excitation == "random":
        forces = level * random_force(n, fs_hz, (lo, hi), rng)[None]
    else:
        forces = level * log_sweep(n, fs_hz, lo, hi, unit_rms=True)[None]
    # each realisation from rest (the time model: 4x and 8x the rate inside, extrapolated)
    clean = {k: np.ravel(v) for k, v in NonlinearRig(rig, tuple(nonlinear)).respond(forces, fs_hz).items()}
    signals = acquire(clean, fs_hz, noise, force_noise, rng)
    how = {"excitation": excitation, "band_hz": f"{lo:g}:{hi:g}", "force_rms": f"{level:g}", "noise": f"{noise:g}",
           "force_noise": f"{force_noise:g}", "burn_in_s": "0", "seed": str(seed), **extra}
    return simulated_recording(fs_hz, signals, how, rig, described("nonlinear", nonlinear))
