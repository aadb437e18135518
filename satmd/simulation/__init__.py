"""Simulators: what a lab would measure on a rig, FRFs or time recordings.

- `frf`: `simulate`, the model's FRFs plus the measurement noise of SPEC §7 (or, with nonlinear
  elements, FRFs estimated from a simulated recording);
- `timesim`: `simulate_recording`, force and accelerations in time as an acquisition would record them
  (transients, any force spectrum, coloured noise on every channel);
- `nonlinear`: `simulate_nonlinear_recording`, the same for a rig with nonlinear elements (SPEC §8b);
- `conditions`: the lab's conditions (force spectra, sensor noise, mains hum); `acquisition`: the stage
  that turns the model's response into channels (anti-alias, sampling, quantisation, clipping).

Simulators write `satmd.io` containers (`FRFData`, `Recording`); they never read files.
"""
from __future__ import annotations

from .conditions import ForceSpectrum, SensorNoise, lab_conditions
from .frf import simulate
from .nonlinear import simulate_nonlinear_recording
from .timesim import simulate_recording

__all__ = ["simulate", "simulate_recording", "simulate_nonlinear_recording", "ForceSpectrum",
           "SensorNoise", "lab_conditions"]
