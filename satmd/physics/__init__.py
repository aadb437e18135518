"""The SATMD forward model: the rig, the effects and the batched FRF solver.

>>> from satmd.physics import Rig, frf, effect, PAPER_GRID_HZ
>>> r = frf(PAPER_GRID_HZ, Rig(), effects=[effect("time_delay", tau_s=1e-4)], wrt=["R", "L"])
>>> r.a1.shape, r.jac["a1"].shape
((60,), (60, 2))

The torch twin lives in ``satmd.physics.torch`` (imported on demand).
"""
from .effects import (
    OFFSET_PARAMETERS,
    VOCABULARY,
    VOCABULARY_NAMES,
    DielectricLoss,
    Effect,
    ExtraMode,
    MatchedFilter,
    Parameter,
    ParameterOffset,
    SensorGain,
    ShuntCapacitance,
    StructuralDamping,
    TimeDelay,
    register,
    registered_names,
    unregister,
)
from ..errors import DataError, DataTypeError
from ..validation import validate_params
from .model import CHANNELS, STATES, Response, frf, parameter_names, solve, terms
from .rig import PAPER_GRID_HZ, PARAMETER_INFO, Rig
from .nonlinear import (
    NONLINEAR,
    AbsorberFriction,
    CubicAbsorberSpring,
    CubicHostSpring,
    InductorSaturation,
    NonlinearElement,
    QuadraticDamping,
    equivalent_rig,
    integrate,
    nonlinear_names,
    register_nonlinear,
    unregister_nonlinear,
)
from .nonlinear import element as nonlinear_element
from .effects import effect as _linear_effect
from .timemodel import LinearRig, NonlinearRig, TimeModel


@validate_params({"name": [str]}, error=DataTypeError)
def effect(name: str, **parameters):
    """Build a missing-physics effect (SPEC §8) or a nonlinear element (SPEC §8b) by its name: one factory.

    Parameters
    ----------
    name : a name from `registered_names` (``parameter_offset:<p>`` for offsets) or from `nonlinear_names`.
    **parameters : values of its parameters (defaults fill the rest).

    Returns
    -------
    Effect
        A `NonlinearElement` for an element's name (it acts in the time domain: `integrate`, or
        ``simulate(time=True, nonlinear=[...])``; `frf` refuses it).
    """
    if name in NONLINEAR:
        return nonlinear_element(name, **parameters)
    try:
        return _linear_effect(name, **parameters)
    except DataError as exc:
        if str(exc).startswith(f"unknown effect {name!r}"):
            raise DataError(f"{exc}; nonlinear elements: {', '.join(NONLINEAR)}") from None
        raise

__all__ = [
    "CHANNELS", "STATES", "OFFSET_PARAMETERS", "VOCABULARY", "VOCABULARY_NAMES", "PAPER_GRID_HZ",
    "PARAMETER_INFO", "Rig", "Response", "frf", "parameter_names", "solve", "terms", "effect", "Effect",
    "SensorGain", "TimeDelay", "StructuralDamping", "DielectricLoss", "ShuntCapacitance", "ExtraMode",
    "ParameterOffset", "Parameter", "MatchedFilter", "register", "unregister", "registered_names",
    "NONLINEAR", "NonlinearElement", "CubicAbsorberSpring", "CubicHostSpring", "AbsorberFriction",
    "QuadraticDamping", "InductorSaturation", "nonlinear_element", "nonlinear_names", "integrate", "equivalent_rig",
    "register_nonlinear", "unregister_nonlinear", "TimeModel", "LinearRig", "NonlinearRig",
]
