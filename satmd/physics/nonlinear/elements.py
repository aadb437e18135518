"""The SPEC §8b elements, one class each (force law, equivalent linearisation, words).

Signals (``reads``): ``d = u2 - u1`` and ``v = d'`` across the absorber, ``u1`` and
``v1`` of the primary mass, ``i`` the shunt current (for the inductor: the
small-signal current λ / L0, see `InductorSaturation`). Equivalent values are the
Gaussian statistical linearisation ``k_eq = E[f(x) x] / E[x²]`` (= E[f'(x)] by
Stein's lemma), which is what a linear fit at that level sees.
"""
from __future__ import annotations

from ...conventions import TINY

import math

import numpy as np

from ..effects.base import Parameter
from .base import NonlinearElement, gaussian_mean

_INF = math.inf
SQRT_8_OVER_PI = math.sqrt(8.0 / math.pi)


def _pct(x) -> str:
    return f"{100 * float(x):+.1f} %"


class CubicAbsorberSpring(NonlinearElement):
    name = "cubic_absorber_spring"
    parameter_specs = (Parameter("k3", "N/m³", default=0.0, neutral=0.0, hard=(-_INF, _INF),
                                 search=(-1e16, 1e16), starts=(1e9, 1e11, 1e13)),)
    description = "cubic absorber spring: restoring force kp d + k3 d³ (k3 > 0 hardening, < 0 softening)"
    acts, reads, linear_parameter, strength = "absorber", ("d",), "kp", "k3"
    kernel_law = 0  # p0 y³

    def kernel_parameters(self):
        return (self.params["k3"], 0.0)

    def force(self, y, rig):
        d = y["d"]
        return self.params["k3"] * d * d * d

    def slope(self, y, rig):
        return 3.0 * self.params["k3"] * y["d"] ** 2

    def equivalent_value(self, rig, rms):
        return rig.kp + 3.0 * self.params["k3"] * np.asarray(rms["d"], float) ** 2

    def explain(self, rig) -> str:
        k3 = float(self.params["k3"])
        kind = "hardens" if k3 > 0 else "softens" if k3 < 0 else "is linear"
        if k3 == 0:
            return "the absorber spring is linear (k3 = 0)"
        d10 = math.sqrt(0.1 * float(rig.kp) / (3 * abs(k3)))
        return (f"the absorber spring {kind} with amplitude: restoring force kp d + k3 d³ with k3 = {k3:.3g} N/m³; "
                f"a linear fit sees kp {'up' if k3 > 0 else 'down'} by 3 k3 d_rms², 10 % at d_rms = {1e3 * d10:.3g} mm")


class CubicHostSpring(NonlinearElement):
    name = "cubic_host_spring"
    parameter_specs = (Parameter("k3", "N/m³", default=0.0, neutral=0.0, hard=(-_INF, _INF),
                                 search=(-1e17, 1e17), starts=(1e9, 1e11, 1e13)),)
    description = "cubic host spring: k1 u1 + k3 u1³ on the primary mass"
    acts, reads, linear_parameter, strength = "host", ("u1",), "k1", "k3"
    kernel_law = 0  # p0 y³

    def kernel_parameters(self):
        return (self.params["k3"], 0.0)

    def force(self, y, rig):
        u = y["u1"]
        return self.params["k3"] * u * u * u

    def slope(self, y, rig):
        return 3.0 * self.params["k3"] * y["u1"] ** 2

    def equivalent_value(self, rig, rms):
        return rig.k1 + 3.0 * self.params["k3"] * np.asarray(rms["u1"], float) ** 2

    def explain(self, rig) -> str:
        k3 = float(self.params["k3"])
        if k3 == 0:
            return "the host spring is linear (k3 = 0)"
        u10 = math.sqrt(0.1 * float(rig.k1) / (3 * abs(k3)))
        return (f"the host structure {'hardens' if k3 > 0 else 'softens'} with amplitude: k1 u1 + k3 u1³ with "
                f"k3 = {k3:.3g} N/m³; a linear fit sees k1 {'up' if k3 > 0 else 'down'} by 3 k3 u1_rms², "
                f"10 % at u1_rms = {1e3 * u10:.3g} mm")


class AbsorberFriction(NonlinearElement):
    name = "absorber_friction"
    parameter_specs = (
        Parameter("Fc", "N", default=0.0, neutral=0.0, hard=(0.0, _INF), search=(0.0, 100.0), starts=(0.1, 1.0, 5.0)),
        Parameter("v0", "m/s", default=1e-3, hard=(1e-12, _INF), search=(1e-5, 0.1), starts=(1e-3,)),
    )
    description = "friction in the absorber's guide: Fc tanh(v / v0) (regularised Coulomb)"
    acts, reads, linear_parameter, strength = "absorber", ("v",), "cp", "Fc"
    kernel_law = 1  # p0 tanh(y / p1)

    def kernel_parameters(self):
        return (self.params["Fc"], self.params["v0"])

    def force(self, y, rig):
        return self.params["Fc"] * np.tanh(y["v"] / self.params["v0"])

    def slope(self, y, rig):
        v0 = self.params["v0"]
        return self.params["Fc"] / v0 / np.cosh(np.clip(y["v"] / v0, -350, 350)) ** 2

    def equivalent_value(self, rig, rms):
        fc, v0 = self.params["Fc"], self.params["v0"]
        # E[f'(v)] = Fc / v0 E[sech²(v / v0)]
        sech2 = gaussian_mean(lambda x: 1.0 / np.cosh(np.clip(x / v0, -350, 350)) ** 2, np.asarray(rms["v"], float),
                              width=float(np.min(v0)))
        return rig.cp + fc / v0 * sech2

    def explain(self, rig) -> str:
        fc, v0 = float(self.params["Fc"]), float(self.params["v0"])
        c_high = fc * math.sqrt(2 / math.pi) / 0.01  # Coulomb limit at v_rms = 10 mm/s
        return (f"dry friction in the absorber: a force Fc = {fc:.3g} N against the relative velocity "
                f"(smoothed below v0 = {v0:.2g} m/s); a linear fit sees extra damping that falls with level "
                f"as Fc √(2/π) / v_rms (cp + {c_high:.3g} N·s/m at v_rms = 10 mm/s)")


class QuadraticDamping(NonlinearElement):
    name = "quadratic_damping"
    parameter_specs = (Parameter("c2", "N·s²/m²", default=0.0, neutral=0.0, hard=(0.0, _INF), search=(0.0, 1e5),
                                 starts=(10.0, 100.0, 1000.0)),)
    description = "velocity-squared damping on the absorber: c2 |v| v"
    acts, reads, linear_parameter, strength = "absorber", ("v",), "cp", "c2"
    kernel_law = 2  # p0 |y| y

    def kernel_parameters(self):
        return (self.params["c2"], 0.0)

    def force(self, y, rig):
        v = y["v"]
        return self.params["c2"] * np.abs(v) * v

    def slope(self, y, rig):
        return 2.0 * self.params["c2"] * np.abs(y["v"])

    def equivalent_value(self, rig, rms):
        return rig.cp + self.params["c2"] * SQRT_8_OVER_PI * np.asarray(rms["v"], float)

    def explain(self, rig) -> str:
        c2 = float(self.params["c2"])
        return (f"velocity-squared (air, joint) damping on the absorber: c2 |v| v with c2 = {c2:.3g} N·s²/m²; "
                f"a linear fit sees cp rise with level by c2 √(8/π) v_rms "
                f"(+{c2 * SQRT_8_OVER_PI * 0.01:.3g} N·s/m at v_rms = 10 mm/s)")


class InductorSaturation(NonlinearElement):
    """Saturating shunt inductor: dλ/di = L0 / (1 + (i/isat)²), so λ = L0 isat arctan(i / isat).

    The integrator carries the flux as the small-signal current ĩ = λ / L0 (the
    current of the linear model); the true current is ``i = isat tan(ĩ / isat)``
    and ``force`` returns ``i - ĩ`` (clipped short of the flux limit
    ``|ĩ| < isat π/2``). L0 is the rig's ``L``.
    """

    name = "inductor_saturation"
    parameter_specs = (Parameter("isat", "A", hard=(1e-12, _INF), search=(1e-4, 100.0), starts=(0.01, 0.1, 1.0)),)
    description = "a saturating shunt inductor: incremental inductance L0 / (1 + (i / isat)²)"
    acts, reads, linear_parameter, strength = "shunt", ("i",), "L", "isat"
    kernel_law = 3  # p0 tan(y / p0) - y

    def kernel_parameters(self):
        return (self.params["isat"], 0.0)

    def force(self, y, rig):
        a = self.params["isat"]
        x = np.clip(y["i"] / a, -0.999 * math.pi / 2, 0.999 * math.pi / 2)
        return a * np.tan(x) - y["i"]

    def slope(self, y, rig):
        a = self.params["isat"]
        return np.tan(np.clip(y["i"] / a, -0.999 * math.pi / 2, 0.999 * math.pi / 2)) ** 2

    def equivalent_value(self, rig, rms):
        # E[L0 / (1 + (i/a)²)] for i ~ N(0, s²) = L0 √(π/2) (a/s) erfcx(a / (√2 s)), with s the true current's RMS
        from scipy.special import erfcx  # on first use: scipy.special costs a CLI start-up a third of a second

        a = self.params["isat"]
        s = np.maximum(np.asarray(rms["i"], float), TINY)
        r = a / s
        return rig.L * np.where(r > 1e6, 1.0 - 1.0 / np.maximum(r, TINY) ** 2,
                                math.sqrt(math.pi / 2) * r * erfcx(r / math.sqrt(2)))

    def explain(self, rig) -> str:
        a = float(self.params["isat"])
        return (f"the shunt inductor saturates: its incremental inductance falls as L0 / (1 + (i / isat)²) with "
                f"isat = {a:.3g} A; a linear fit sees L fall with level, by about (i_rms / isat)² "
                f"({_pct(-0.1)} at i_rms = {1e3 * a * math.sqrt(0.1):.3g} mA)")


ELEMENT_CLASSES = (CubicAbsorberSpring, CubicHostSpring, AbsorberFriction, QuadraticDamping, InductorSaturation)
