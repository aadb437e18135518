"""Candidate effects and where to start fitting them.

Each vocabulary effect gets a few starting values; effects with a location
(``extra_mode``) are scanned over the measured band. All starts of one
candidate are screened in one batched model call with the other parameters
held at the current fit, and only the best few are refined.
"""
from __future__ import annotations

import numpy as np

from ..physics.effects import OFFSET_PARAMETERS, VOCABULARY_NAMES, effect


def default_candidates() -> tuple[str, ...]:
    return VOCABULARY_NAMES


def start_grid(name: str, rig, freq_hz) -> list[dict]:
    """Starting values of the effect's own parameters."""
    if name == "sensor_gain":
        return [{"gain_a1": g1, "gain_a2": g2} for g1 in (0.93, 1.0, 1.07) for g2 in (0.93, 1.0, 1.07)]
    if name == "time_delay":
        return [{"tau_s": t} for t in (-2e-4, 0.0, 1e-4, 3e-4, 6e-4)]
    if name == "structural_damping":
        return [{"eta": x} for x in (0.003, 0.01, 0.03, 0.1)]
    if name == "dielectric_loss":
        return [{"tan_delta": x} for x in (0.003, 0.01, 0.03, 0.1)]
    if name == "shunt_capacitance":
        return [{"Cs": x} for x in (2e-7, 1e-6, 3e-6, 1e-5, 3e-5)]
    if name == "extra_mode":
        lo, hi = float(freq_hz[0]), float(freq_hz[-1])
        # resolve peaks of ζ ~ 0.3 %: geometric steps of 0.25 %
        n = int(np.ceil(np.log(hi / lo) / np.log(1.0025))) + 1
        fs = np.geomspace(lo, hi, n)
        return [{"f_hz": f, "zeta": z, "mass_ratio": m}
                for f in fs for z in (0.003, 0.01, 0.03) for m in (0.003, 0.01, 0.03)]
    if name.startswith("parameter_offset:"):
        p = name.split(":", 1)[1]
        nominal = float(getattr(rig, p))
        factors = (0.3, 0.6, 0.85, 1.2, 1.6, 2.5) if p in ("c1", "cp") else (0.75, 0.9, 0.97, 1.03, 1.1, 1.3)
        return [{"value": nominal * f} for f in factors]
    raise ValueError(f"no start grid for effect {name!r}")


def neutral_effect(name: str, rig):
    """The effect at a harmless placeholder value (parameters are set by the fit)."""
    if name == "extra_mode":
        return effect(name, f_hz=100.0, zeta=0.01, mass_ratio=0.0)
    if name.startswith("parameter_offset:"):
        p = name.split(":", 1)[1]
        assert p in OFFSET_PARAMETERS
        return effect(name, value=float(getattr(rig, p)))
    return effect(name)
