"""A parameter held fixed in the model is wrong: ``parameter_offset:<p>`` (SPEC §8)."""
from __future__ import annotations

from ...errors import DataError
from ..rig import PARAMETER_INFO
from .base import Effect, Parameter

OFFSET_PARAMETERS = ("m1", "k1", "c1", "cp", "e", "Cp")
_DAMPING = ("c1", "cp")  # may be far off (a factor of several) and may be zero


class ParameterOffset(Effect):
    """A parameter held fixed in the model (m1, k1, c1, cp, e or Cp) is wrong."""

    family = "parameter_offset"
    variants = OFFSET_PARAMETERS
    parameter_names = ("value",)
    acts_on = "rig"

    def __init__(self, parameter: str, **params):
        if parameter not in OFFSET_PARAMETERS:
            raise DataError(
                f"parameter_offset:{parameter}: offset applies to one of {', '.join(OFFSET_PARAMETERS)}"
            )
        object.__setattr__(self, "parameter", parameter)
        super().__init__(**params)

    @classmethod
    def at_rest(cls, rig, parameter: str) -> "ParameterOffset":  # type: ignore[override]  # names its parameter
        """No offset: the rig's own value."""
        return cls(parameter, value=float(getattr(rig, parameter)))

    @property
    def name(self):  # noqa: F811 - instance-specific name, e.g. parameter_offset:k1
        return f"parameter_offset:{self.parameter}"

    @property
    def description(self):
        return f"the fixed parameter {self.parameter} differs from its nominal value"

    @property
    def parameter_specs(self):
        # neutral value, search range and starts are relative to the rig's nominal value: see bounds, starts
        lo = 0.0 if self.parameter in ("c1", "cp", "e") else 1e-30
        return (Parameter("value", PARAMETER_INFO[self.parameter][0], hard=(lo, 1e30)),)

    def _rebuild(self, params):
        return ParameterOffset(self.parameter, **params)

    def bounds(self, rig):
        nominal = float(getattr(rig, self.parameter))
        lo, hi = (0.0, 5.0) if self.parameter in _DAMPING else (0.5, 2.0)
        return {"value": (lo * nominal, hi * nominal)}

    def starts(self, rig) -> list[dict]:
        nominal = float(getattr(rig, self.parameter))
        factors = (0.3, 0.6, 0.85, 1.2, 1.6, 2.5) if self.parameter in _DAMPING else (0.75, 0.9, 0.97, 1.03, 1.1, 1.3)
        return [{"value": nominal * f} for f in factors]

    def rig(self, rig):
        return rig.replace(**{self.parameter: self.params["value"]})

    def explain(self, rig) -> str:
        p, v = self.parameter, float(self.params["value"])
        nominal, unit = float(getattr(rig, p)), PARAMETER_INFO[p][0]
        return (f"the fixed parameter {p} is {v:.4g} {unit}, {100 * (v / nominal - 1):+.1f} % from its nominal "
                f"{nominal:.4g} {unit}")
