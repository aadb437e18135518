"""Effects on the host structure (the primary mass's dynamic stiffness, SPEC §8)."""
from __future__ import annotations

import numpy as np

from .base import TWO_PI, Effect, MatchedFilter, Parameter


class StructuralDamping(Effect):
    name = "structural_damping"
    parameter_specs = (Parameter("eta", default=0.0, neutral=0.0, hard=(0.0, 10.0), search=(0.0, 0.5),
                                 starts=(0.003, 0.01, 0.03, 0.1)),)
    description = "hysteretic loss of the host structure (k1 -> k1 (1 + iη))"
    acts_on = "host"

    def host(self, omega, rig, K1):
        return K1 + 1j * self.params["eta"] * rig.k1

    def explain(self, rig) -> str:
        eta = float(self.params["eta"])
        # the viscous damping with the same loss at the first resonance (~50 Hz)
        return (f"the host structure has hysteretic loss η = {eta:.3g} (loss factor), "
                f"as much damping at resonance as c = {eta * float(rig.k1) / (2 * np.pi * 50):.3g} N·s/m at 50 Hz")


class ExtraMode(Effect):
    name = "extra_mode"
    parameter_specs = (
        Parameter("f_hz", "Hz", hard=(1e-3, 1e6), search=(5.0, 1000.0)),
        Parameter("zeta", default=0.01, hard=(0.0, 10.0), search=(1e-4, 0.2)),
        Parameter("mass_ratio", default=0.0, neutral=0.0, hard=(0.0, 100.0), search=(0.0, 0.3)),
    )
    description = "an unmodelled host mode: mass m3 = μ m1 hung on the primary mass at frequency f3 with damping ratio ζ"
    acts_on = "host"
    # a light mode is a sharp, local feature: scan its frequency (0.2 % steps resolve ζ ~ 0.3 %)
    scan = MatchedFilter(location="f_hz", step=0.002, amplitude="mass_ratio", amplitude_range=(1e-5, 0.2),
                         shapes={"zeta": (0.002, 0.005, 0.01, 0.02, 0.05)})

    def host(self, omega, rig, K1):
        # u3 eliminated exactly: Z11 += -m3 ω² κ / (κ - ω²), κ = ω3² + 2iζω3ω
        w3 = TWO_PI * self.params["f_hz"]
        kappa = w3 * w3 + 2j * self.params["zeta"] * w3 * omega
        w2 = omega * omega
        m3 = self.params["mass_ratio"] * rig.m1
        return K1 - m3 * w2 * kappa / (kappa - w2)

    def explain(self, rig) -> str:
        p = self.params
        return (f"an unmodelled host mode at {p['f_hz']:.1f} Hz with {100 * p['mass_ratio']:.2g} % of the "
                f"primary mass (ζ = {p['zeta']:.2g})")
