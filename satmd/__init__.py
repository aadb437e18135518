"""satmd: semi-active shunted piezoelectric tuned mass dampers.

Forward model, grey-box identification, amortized inversion, explainability
and missing-physics discovery from measured or simulated FRFs.
"""
from .errors import DataError, FormatError, SatmdError
from .io import FRFData, load_frf, save_frf
from .physics import (
    PAPER_GRID_HZ,
    DielectricLoss,
    Effect,
    ExtraMode,
    ParameterOffset,
    Rig,
    SensorGain,
    ShuntCapacitance,
    StructuralDamping,
    TimeDelay,
    effect,
    frf,
)
from .simulate import simulate

__version__ = "0.1.0"

__all__ = [
    "Rig", "frf", "effect", "Effect", "FRFData", "load_frf", "save_frf", "simulate", "PAPER_GRID_HZ",
    "SensorGain", "TimeDelay", "StructuralDamping", "DielectricLoss", "ShuntCapacitance", "ExtraMode",
    "ParameterOffset", "SatmdError", "DataError", "FormatError",
]
