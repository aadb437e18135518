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
from .base import Coordinate, NonlinearElement, gaussian_mean

_INF = math.inf
SQRT_8_OVER_PI = math.sqrt(8.0 / math.pi)
HALF_PI = 0.999 * math.pi / 2  # the saturating inductor's flux limit, kept short of the pole


# The force laws, (p0, p1, y) -> (force, slope): NumPy functions only, so that one definition serves arrays
# (`NonlinearElement.force`) and the compiled integrator (`kernel`).
def cubic_law(p0, p1, y):
    """p0 y³."""
    return p0 * y * y * y, 3.0 * p0 * y * y


def coulomb_law(p0, p1, y):
    """p0 tanh(y / p1): regularised Coulomb friction."""
    t = np.tanh(y / p1)
    return p0 * t, p0 / p1 * (1.0 - t * t)


def velocity_squared_law(p0, p1, y):
    """p0 |y| y."""
    return p0 * np.abs(y) * y, 2.0 * p0 * np.abs(y)


def saturation_law(p0, p1, y):
    """p0 tan(y / p0) - y: the true current beyond the small-signal one (flux clipped short of its limit)."""
    t = np.tan(np.minimum(np.maximum(y / p0, -HALF_PI), HALF_PI))
    return p0 * t - y, t * t


def _pct(x) -> str:
    return f"{100 * float(x):+.1f} %"


class CubicAbsorberSpring(NonlinearElement):
    name = "cubic_absorber_spring"
    parameter_specs = (Parameter("k3", "N/m³", default=0.0, neutral=0.0, hard=(-_INF, _INF),
                                 search=(-1e16, 1e16), starts=(1e9, 1e11, 1e13)),)
    description = "cubic absorber spring: restoring force kp d + k3 d³ (k3 > 0 hardening, < 0 softening)"
    acts, reads, linear_parameter, strength, moves = "absorber", ("d",), "kp", "k3", "either"
    law = staticmethod(cubic_law)
    regressor = "d:cube"

    def kernel_parameters(self):
        return (self.params["k3"], 0.0)

    def equivalent_value(self, rig, rms):
        return rig.kp + 3.0 * self.params["k3"] * np.asarray(rms["d"], float) ** 2

    def strength_scale(self, rig, rms):
        return 0.1 * float(rig.kp) / (3 * rms["d"] ** 2)

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
    acts, reads, linear_parameter, strength, moves = "host", ("u1",), "k1", "k3", "either"
    law = staticmethod(cubic_law)
    regressor = "u1:cube"

    def kernel_parameters(self):
        return (self.params["k3"], 0.0)

    def equivalent_value(self, rig, rms):
        return rig.k1 + 3.0 * self.params["k3"] * np.asarray(rms["u1"], float) ** 2

    def strength_scale(self, rig, rms):
        return 0.1 * float(rig.k1) / (3 * rms["u1"] ** 2)

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
    acts, reads, linear_parameter, strength, moves = "absorber", ("v",), "cp", "Fc", "down"
    law = staticmethod(coulomb_law)
    regressor = "v:sign"

    def kernel_parameters(self):
        return (self.params["Fc"], self.params["v0"])

    def coordinates(self, rig, rms):
        v = rms["v"]  # Fc in units of the Coulomb limit's damping at this level, v0 of the velocity
        return (Coordinate("Fc", v * math.sqrt(math.pi / 2), "positive", (0.0, 200.0), (0.3, 1.0, 2.0, 4.0, 8.0)),
                Coordinate("v0", v, "log", (math.log(1e-4), math.log(3.0)), (math.log(0.03), math.log(0.3))))

    def trend_fixed(self, rms_levels):
        # v0 well below the slowest level's velocity: Coulomb-like, as a rub is (a trend cannot tell v0)
        return {"v0": 0.05 * min(float(r["v"]) for r in rms_levels)}

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
    acts, reads, linear_parameter, strength, moves = "absorber", ("v",), "cp", "c2", "up"
    law = staticmethod(velocity_squared_law)
    regressor = "v:absv"

    def kernel_parameters(self):
        return (self.params["c2"], 0.0)

    def equivalent_value(self, rig, rms):
        return rig.cp + self.params["c2"] * SQRT_8_OVER_PI * np.asarray(rms["v"], float)

    def strength_scale(self, rig, rms):
        return 1.0 / (math.sqrt(8 / math.pi) * rms["v"])  # x = 1: cp + 1 N·s/m

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
    acts, reads, linear_parameter, strength, moves = "shunt", ("i",), "L", "isat", "down"
    law = staticmethod(saturation_law)
    regressor = "d:cube"

    def kernel_parameters(self):
        return (self.params["isat"], 0.0)

    def coordinates(self, rig, rms):
        return (Coordinate("isat", rms["i"], "log", (math.log(0.2), math.log(1e4)),
                           tuple(math.log(v) for v in (1.2, 1.6, 2.2, 3.0, 5.0, 10.0, 30.0))),)

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
