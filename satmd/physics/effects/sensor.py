"""Effects of the measurement chain on the sensors: what a1 and a2 report (SPEC §8).

They change only the measured channels a1, a2; u1, u2 and q stay the
physical states.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .. import dual
from .base import Effect, Parameter, scaled

_GAIN: dict[str, Any] = dict(default=1.0, neutral=1.0, hard=(1e-3, 1e3), search=(0.5, 2.0), starts=(0.93, 1.0, 1.07))


class SensorGain(Effect):
    name = "sensor_gain"
    parameter_specs = (Parameter("gain_a1", **_GAIN), Parameter("gain_a2", **_GAIN))
    description = "calibration error: each accelerometer reads a constant factor off (A1 -> g1 A1, A2 -> g2 A2)"
    acts_on = "sensor"

    def sensor(self, omega, channel, factor):
        return scaled(factor, self.params["gain_" + channel])

    def explain(self, rig) -> str:
        parts = []
        for ch, label in (("gain_a1", "accelerometer 1 (primary)"), ("gain_a2", "accelerometer 2 (absorber)")):
            g = float(self.params[ch])
            if g == 1.0 and any(float(v) != 1.0 for v in self.params.values()):
                continue  # a channel held at exactly 1 was not fitted (not measured): say nothing of it
            parts.append(f"{label} reads {abs(g - 1) * 100:.1f} % {'high' if g > 1 else 'low'}")
        return "; ".join(parts) + " (calibration error)"


class TimeDelay(Effect):
    name = "time_delay"
    parameter_specs = (Parameter("tau_s", "s", default=0.0, neutral=0.0, hard=(-1.0, 1.0), search=(-2e-3, 2e-3),
                                 starts=(-2e-4, 0.0, 1e-4, 3e-4, 6e-4)),)
    description = "acquisition latency: both channels lag by a constant time (A -> A exp(-iωτ))"
    acts_on = "sensor"

    def sensor(self, omega, channel, factor):
        return scaled(factor, dual.exp(-1j * omega * self.params["tau_s"]))

    def explain(self, rig) -> str:
        tau = float(self.params["tau_s"])
        # the phase error at 100 Hz, mid-band of the rig, makes the size of the delay tangible
        return (f"the acquisition {'lags' if tau > 0 else 'leads'} by {abs(tau) * 1e3:.3g} ms on both channels "
                f"(a phase error of {np.degrees(2 * np.pi * 100 * abs(tau)):.2g}° at 100 Hz)")
