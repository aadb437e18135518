"""Effects on the electrical side: the piezo's dielectric and the shunt (SPEC §8)."""
from __future__ import annotations

from .base import Effect, Parameter


class DielectricLoss(Effect):
    """SPEC §8 (revised) passive form of a lossy clamped capacitance.

    ``Cp -> Cp_c = Cp (1 - i tanδ)`` wherever Cp appears (Z13, Z23, Z33) and
    ``kp -> kp + e² (1/Cp_c - 1/Cp)`` wherever kp appears, so the short-circuit
    stiffness ``kp - e²/Cp`` stays real: the element only dissipates
    (½ ω Cp tanδ |V|² ≥ 0), whatever the rig. The earlier form (Cp alone) fed
    energy in at large tanδ or with c1 = cp = 0.
    """

    name = "dielectric_loss"
    parameter_specs = (Parameter("tan_delta", default=0.0, neutral=0.0, hard=(0.0, 10.0), search=(0.0, 0.5),
                                 starts=(0.003, 0.01, 0.03, 0.1)),)
    description = "lossy piezo dielectric (Cp -> Cp (1 - i tanδ), short-circuit stiffness kept real)"
    acts_on = "piezo"

    def capacitance(self, omega, rig, Cp):
        return Cp * (1.0 - 1j * self.params["tan_delta"])

    def branch(self, omega, rig, Kp):
        # e² (1/Cp_c - 1/Cp) = (e²/Cp) · i tanδ / (1 - i tanδ)
        t = self.params["tan_delta"]
        return Kp + (rig.e * rig.e / rig.Cp) * (1j * t) / (1.0 - 1j * t)

    def explain(self, rig) -> str:
        return f"the piezo's dielectric is lossy: tan δ = {self.params['tan_delta']:.3g}"


class ShuntCapacitance(Effect):
    name = "shunt_capacitance"
    parameter_specs = (Parameter("Cs", "F", default=0.0, neutral=0.0, hard=(0.0, 1.0), search=(0.0, 1e-4),
                                 starts=(2e-7, 1e-6, 3e-6, 1e-5, 3e-5)),)
    description = "stray capacitance across the shunt (Zs -> Zs / (1 + iω Cs Zs))"
    acts_on = "shunt"

    def shunt(self, omega, rig, Zs):
        return Zs / (1.0 + 1j * omega * self.params["Cs"] * Zs)

    def explain(self, rig) -> str:
        cs = float(self.params["Cs"])
        return f"a stray capacitance of {cs * 1e6:.3g} µF ({100 * cs / float(rig.Cp):.2g} % of Cp) sits across the shunt"
