"""The missing-physics vocabulary (SPEC §8): each effect is an exact change to the model.

An effect knows its parameter names, defaults, bounds and a one-line physical
description, and changes the model through one or more hooks:

- ``rig(rig)``                       -> a rig with a fixed parameter replaced
- ``host(omega, rig, K1)``           -> the primary (host) dynamic stiffness Z11 - kp - iω cp
- ``capacitance(omega, rig, Cp)``    -> the piezo capacitance, wherever Cp appears
- ``shunt(omega, rig, Zs)``          -> the shunt impedance
- ``sensor(omega, channel, factor)`` -> the factor the sensor applies to a1 or a2

Hooks use only arithmetic (and ``dual.exp``), so the same code serves NumPy,
torch and the forward-mode duals behind the analytic Jacobian. Adding an
effect means adding one class here and registering it.
"""
from __future__ import annotations

import math
from typing import ClassVar

import numpy as np

from . import dual

TWO_PI = 2.0 * math.pi


def _times(factor, x):
    return x if factor is None else factor * x


class Effect:
    """Base class. Subclasses set the class attributes and override hooks."""

    name: ClassVar[str] = ""
    parameter_names: ClassVar[tuple[str, ...]] = ()
    defaults: ClassVar[dict] = {}  # values used when a parameter is not given
    neutral: ClassVar[dict] = {}  # values at which the effect vanishes
    description: ClassVar[str] = ""
    acts_on: ClassVar[str] = ""  # "sensor", "host", "piezo", "shunt", "rig"

    def __init__(self, **params):
        unknown = set(params) - set(self.parameter_names)
        if unknown:
            raise ValueError(
                f"effect {self.name}: unknown parameter(s) {sorted(unknown)}; "
                f"expected {', '.join(self.parameter_names)}"
            )
        values = dict(self.defaults)
        values.update(params)
        missing = [p for p in self.parameter_names if p not in values]
        if missing:
            raise ValueError(f"effect {self.name}: missing parameter(s) {', '.join(missing)}")
        object.__setattr__(self, "params", {p: values[p] for p in self.parameter_names})
        self._check()

    def __setattr__(self, key, val):
        raise AttributeError("effects are immutable; use .replace(**params)")

    def __getattr__(self, key):
        params = self.__dict__.get("params", {})
        if key in params:
            return params[key]
        raise AttributeError(key)

    def __repr__(self):
        inner = ", ".join(f"{k}={_fmt(v)}" for k, v in self.params.items())
        return f"effect({self.name!r}, {inner})"

    def __eq__(self, other):
        return type(self) is type(other) and self.name == other.name and all(
            _same(self.params[k], other.params[k]) for k in self.params
        )

    __hash__ = None

    def replace(self, **params) -> "Effect":
        new = dict(self.params)
        new.update(params)
        return self._rebuild(new)

    def _rebuild(self, params):
        return type(self)(**params)

    def _check(self):
        """Validate parameter values (skipped for traced/dual values)."""
        for p, (lo, hi) in self.hard_bounds().items():
            v = self.params[p]
            if not isinstance(v, (int, float, np.ndarray, np.generic, list)):
                continue  # torch tensor or dual: checked by its owner
            arr = np.asarray(v, dtype=float)
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"effect {self.name}: {p} is not finite")
            if np.any(arr < lo) or np.any(arr > hi):
                raise ValueError(f"effect {self.name}: {p}={_fmt(v)} outside [{lo:g}, {hi:g}]")

    def hard_bounds(self) -> dict:
        """Physically admissible range of each parameter."""
        return {}

    def bounds(self, rig) -> dict:
        """Search range used when the parameter is fitted."""
        return self.hard_bounds()

    def qualified(self, param: str) -> str:
        """Full parameter name used by Jacobians, e.g. 'extra_mode.f_hz'."""
        return f"{self.name}.{param}"

    # hooks: identity by default
    def rig(self, rig):
        return rig

    def host(self, omega, rig, K1):
        return K1

    def capacitance(self, omega, rig, Cp):
        return Cp

    def shunt(self, omega, rig, Zs):
        return Zs

    def sensor(self, omega, channel, factor):
        return factor


class SensorGain(Effect):
    name = "sensor_gain"
    parameter_names = ("gain_a1", "gain_a2")
    defaults = {"gain_a1": 1.0, "gain_a2": 1.0}
    neutral = {"gain_a1": 1.0, "gain_a2": 1.0}
    description = "calibration error: each accelerometer reads a constant factor off (A1 -> g1 A1, A2 -> g2 A2)"
    acts_on = "sensor"

    def hard_bounds(self):
        return {"gain_a1": (1e-3, 1e3), "gain_a2": (1e-3, 1e3)}

    def bounds(self, rig):
        return {"gain_a1": (0.5, 2.0), "gain_a2": (0.5, 2.0)}

    def sensor(self, omega, channel, factor):
        return _times(factor, self.params["gain_" + channel])


class TimeDelay(Effect):
    name = "time_delay"
    parameter_names = ("tau_s",)
    defaults = {"tau_s": 0.0}
    neutral = {"tau_s": 0.0}
    description = "acquisition latency: both channels lag by a constant time (A -> A exp(-iωτ))"
    acts_on = "sensor"

    def hard_bounds(self):
        return {"tau_s": (-1.0, 1.0)}

    def bounds(self, rig):
        return {"tau_s": (-2e-3, 2e-3)}

    def sensor(self, omega, channel, factor):
        return _times(factor, dual.exp(-1j * omega * self.params["tau_s"]))


class StructuralDamping(Effect):
    name = "structural_damping"
    parameter_names = ("eta",)
    defaults = {"eta": 0.0}
    neutral = {"eta": 0.0}
    description = "hysteretic loss of the host structure (k1 -> k1 (1 + iη))"
    acts_on = "host"

    def hard_bounds(self):
        return {"eta": (0.0, 10.0)}

    def bounds(self, rig):
        return {"eta": (0.0, 0.5)}

    def host(self, omega, rig, K1):
        return K1 + 1j * self.params["eta"] * rig.k1


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
    parameter_names = ("tan_delta",)
    defaults = {"tan_delta": 0.0}
    neutral = {"tan_delta": 0.0}
    description = "lossy piezo dielectric (Cp -> Cp (1 - i tanδ) wherever Cp appears)"
    acts_on = "piezo"

    def hard_bounds(self):
        return {"tan_delta": (0.0, 10.0)}

    def bounds(self, rig):
        return {"tan_delta": (0.0, 0.5)}

    def capacitance(self, omega, rig, Cp):
        return Cp * (1.0 - 1j * self.params["tan_delta"])


class ShuntCapacitance(Effect):
    name = "shunt_capacitance"
    parameter_names = ("Cs",)
    defaults = {"Cs": 0.0}
    neutral = {"Cs": 0.0}
    description = "stray capacitance across the shunt (Zs -> Zs / (1 + iω Cs Zs))"
    acts_on = "shunt"

    def hard_bounds(self):
        return {"Cs": (0.0, 1.0)}

    def bounds(self, rig):
        return {"Cs": (0.0, 1e-4)}

    def shunt(self, omega, rig, Zs):
        return Zs / (1.0 + 1j * omega * self.params["Cs"] * Zs)


class ExtraMode(Effect):
    name = "extra_mode"
    parameter_names = ("f_hz", "zeta", "mass_ratio")
    defaults = {"zeta": 0.01, "mass_ratio": 0.0}
    neutral = {"mass_ratio": 0.0}
    description = "an unmodelled host mode: mass m3 = μ m1 hung on the primary mass at frequency f3 with damping ratio ζ"
    acts_on = "host"

    def hard_bounds(self):
        return {"f_hz": (1e-3, 1e6), "zeta": (0.0, 10.0), "mass_ratio": (0.0, 100.0)}

    def bounds(self, rig):
        return {"f_hz": (5.0, 1000.0), "zeta": (1e-4, 0.2), "mass_ratio": (0.0, 0.3)}

    def host(self, omega, rig, K1):
        # u3 eliminated exactly: Z11 += -m3 ω² κ / (κ - ω²), κ = ω3² + 2iζω3ω
        w3 = TWO_PI * self.params["f_hz"]
        kappa = w3 * w3 + 2j * self.params["zeta"] * w3 * omega
        w2 = omega * omega
        m3 = self.params["mass_ratio"] * rig.m1
        return K1 - m3 * w2 * kappa / (kappa - w2)


OFFSET_PARAMETERS = ("m1", "k1", "c1", "cp", "e", "Cp")


class ParameterOffset(Effect):
    """A parameter held fixed in the model (m1, k1, c1, cp, e or Cp) is wrong."""

    parameter_names = ("value",)
    acts_on = "rig"

    def __init__(self, parameter: str, **params):
        if parameter not in OFFSET_PARAMETERS:
            raise ValueError(
                f"parameter_offset:{parameter}: offset applies to one of {', '.join(OFFSET_PARAMETERS)}"
            )
        object.__setattr__(self, "parameter", parameter)
        super().__init__(**params)

    @property
    def name(self):  # noqa: F811 - instance-specific name, e.g. parameter_offset:k1
        return f"parameter_offset:{self.parameter}"

    @property
    def description(self):
        return f"the fixed parameter {self.parameter} differs from its nominal value"

    def _rebuild(self, params):
        return ParameterOffset(self.parameter, **params)

    def hard_bounds(self):
        lo = 0.0 if self.parameter in ("c1", "cp", "e") else 1e-30
        return {"value": (lo, 1e30)}

    def bounds(self, rig):
        nominal = float(getattr(rig, self.parameter))
        lo, hi = (0.0, 5.0) if self.parameter in ("c1", "cp") else (0.5, 2.0)
        return {"value": (lo * nominal, hi * nominal)}

    def rig(self, rig):
        return rig.replace(**{self.parameter: self.params["value"]})


VOCABULARY = {
    cls.name: cls
    for cls in (SensorGain, TimeDelay, StructuralDamping, DielectricLoss, ShuntCapacitance, ExtraMode)
}
VOCABULARY_NAMES = tuple(VOCABULARY) + tuple(f"parameter_offset:{p}" for p in OFFSET_PARAMETERS)


def effect(name: str, **parameters) -> Effect:
    """Build an effect from its SPEC §8 name, e.g. ``effect("time_delay", tau_s=1e-4)``."""
    if name.startswith("parameter_offset"):
        _, _, target = name.partition(":")
        if not target:
            raise ValueError("parameter_offset needs a target, e.g. parameter_offset:k1")
        return ParameterOffset(target, **parameters)
    try:
        cls = VOCABULARY[name]
    except KeyError:
        raise ValueError(f"unknown effect {name!r}; known: {', '.join(VOCABULARY_NAMES)}") from None
    return cls(**parameters)


def _fmt(v):
    if isinstance(v, (int, float, np.generic)):
        return f"{float(v):g}"
    if isinstance(v, np.ndarray):
        return f"array{v.shape}"
    return type(v).__name__


def _same(a, b):
    try:
        return bool(np.all(np.asarray(a) == np.asarray(b)))
    except Exception:
        return a is b
