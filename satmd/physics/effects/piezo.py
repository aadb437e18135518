"""Effects on the electrical side: the piezo's dielectric and the shunt (SPEC §8)."""
from __future__ import annotations

from .base import Effect, Parameter


class DielectricLoss(Effect):
    """SPEC §8 form: Cp -> Cp (1 - i tanδ) in Z13, Z23 and Z33 (where Cp appears).

    Kept exactly as the SPEC defines it (measured data and the shared
    acceptance files use this form). Note that it is not strictly passive:
    Im(Z) gets an indefinite block, and for large tanδ (≳ 0.5) the input
    power can turn negative near the first resonance (tests/physics record
    this). A passive variant would also add e²(1/Cp' - 1/Cp) to the
    mechanical block.
    """

    name = "dielectric_loss"
    parameter_specs = (Parameter("tan_delta", default=0.0, neutral=0.0, hard=(0.0, 10.0), search=(0.0, 0.5),
                                 starts=(0.003, 0.01, 0.03, 0.1)),)
    description = "lossy piezo dielectric (Cp -> Cp (1 - i tanδ) wherever Cp appears)"
    acts_on = "piezo"

    def capacitance(self, omega, rig, Cp):
        return Cp * (1.0 - 1j * self.params["tan_delta"])

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
